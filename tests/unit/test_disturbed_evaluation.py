"""Table I's in-process loop under wind and waves (issue 14, item 4; ship_mission.conditions).

- the learning environment's wind (learning.env ``wind``) is the simulator's: the same
  WindField, the same current and rudder commands give the states of ship_sim.simulator's
  VesselSimulator (whose wind physics tests/unit/test_wind.py checks) to rounding, all three
  MSS ships; a calm WindField leaves the environment bit-identical to no wind;
- the conditions are what their docstring states: Hs = 0.21 V^2 / g (MSS vw2hs) for 10 m/s at
  the Pierson-Moskowitz peak, the wind from 45 deg on the port bow of the route's course, the
  waves travelling downwind; the scenario blocks give the graph the same sea as the in-process
  SeaState;
- the loop: calm is the undisturbed computation (no wind or waves objects), a disturbed run
  repeats bit for bit, the controllers measure the plant's state plus the wave-frequency motion
  of the RAOs (output superposition), and the wave filter lowers the rudder activity the waves
  cause.
"""
import math

import numpy as np
import pytest

import evaluate_controllers as ec
from ship_mission import conditions
from ship_mission.waves import wave_parameters
from ship_mission.wind_block import check_wind
from ship_autopilot.learning.env import EnvConfig, PathFollowingBatch
from ship_guidance.path import Line, Route
from ship_planner.route_loader import load_route
from ship_sim.current import OceanCurrent
from ship_sim.environment.sea_state import ShipWaves, rao_table_for
from ship_sim.environment.wind import WindField
from ship_sim.simulator import VesselSimulator

ROUTES = ec.ROOT / 'scenarios' / 'routes'


def _line_env(model, wind, current=(0.0, 0.0)):
    env = PathFollowingBatch(model, 1, EnvConfig(mode='straight', sim_dt=0.1, control_dt=0.1),
                             routes=[Route([Line((0.0, 0.0), (20000.0, 0.0))])], wind=wind)
    env.reset(starts=[{'route': 0, 'along': 100.0, 'cross': 0.0, 'heading': 0.3,
                       'current_speed': current[0], 'current_direction': current[1]}])
    return env


@pytest.mark.parametrize('model', ['mariner', 'container', 'tanker'])
def test_env_wind_equals_the_simulator(model):
    """Gusty 20 m/s wind on the bow, 0.5 m/s current, a rudder sequence: the env's states equal
    VesselSimulator's with a WindField of the same seed (same loads, same order of steps)."""
    def wind():
        return WindField(20.0, math.radians(-45.0), gust_sd=2.0, time_constant=30.0, seed=3)
    env = _line_env(model, wind(), current=(0.5, math.radians(60.0)))
    sim = VesselSimulator(model, dt=0.1, state=env.x[0].copy(), wind=wind(),
                          current=OceanCurrent(0.5, math.radians(60.0)))
    calm = _line_env(model, None, current=(0.5, math.radians(60.0)))
    for k in range(400):
        delta = math.radians(10.0) * math.sin(2 * math.pi * k / 300.0)
        env.integrate(np.array([delta]), 1)
        calm.integrate(np.array([delta]), 1)
        sim.step(delta)
    scale = np.maximum(np.abs(sim.x), 1.0)
    assert np.all(np.abs(env.x[0] - sim.x) <= 1e-9 * scale)
    # ... and the wind acted: the calm run is elsewhere.
    m = env.model
    assert math.hypot(*(env.x[0, [m.IX, m.IY]] - calm.x[0, [m.IX, m.IY]])) > 0.5


def test_calm_wind_field_is_bit_identical():
    """A WindField of 0 m/s gives loads of exactly 0.0: the states equal the no-wind run."""
    for model in ('mariner', 'tanker'):
        a, b = _line_env(model, WindField(0.0, 1.0)), _line_env(model, None)
        for k in range(50):
            a.integrate(np.array([0.1]), 2)
            b.integrate(np.array([0.1]), 2)
        assert np.array_equal(a.x, b.x)


def test_conditions_are_as_documented():
    c10, c20 = conditions.CONDITIONS['wind10'], conditions.CONDITIONS['wind20']
    assert conditions.CONDITIONS['calm'].calm
    assert c10.hs == pytest.approx(0.21 * 10.0 ** 2 / 9.81, rel=1e-12)
    # Pierson-Moskowitz peak: w0 = (4 B / 5)^(1/4), B = 0.74 (g / V)^4 with V = hs2vw(Hs) = 10.
    w0 = (4.0 * 0.74 * (9.81 / 10.0) ** 4 / 5.0) ** 0.25
    assert c10.tp == pytest.approx(2 * math.pi / w0, rel=1e-12)
    assert (c20.spectrum, c20.hs, c20.tp) == ('Torsethaugen', 6.0, 10.0)
    assert 2 * math.pi / c20.tp > 0.6          # the double-peaked range of Torsethaugen
    course = math.radians(50.0)
    wind = conditions.wind_field(c20, course, seed=4)
    sea = conditions.sea_state(c20, course, seed=4)
    assert wind.speed_nominal == 20.0 and wind.gust_sd == pytest.approx(2.0)
    assert wind.direction_from == pytest.approx(math.radians(5.0))    # 45 deg on the port bow
    assert sea.direction == pytest.approx(math.radians(185.0))        # downwind
    assert conditions.wind_field(conditions.CONDITIONS['calm'], course) is None
    assert conditions.sea_state(conditions.CONDITIONS['calm'], course) is None
    # The course of a route: start to end (Table I's sine runs north).
    route = load_route(ROUTES / 'curved_path_mariner_000.yaml').route
    assert conditions.route_course(route) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize('name', ['wind10', 'wind20'])
def test_scenario_blocks_give_the_same_sea(name):
    """The graph's blocks (checked by the scenario loader's own functions) carry the in-process
    wind and sea: the same numbers up to the degree round trip."""
    cond, course = conditions.CONDITIONS[name], math.radians(6.88)
    wind_block, waves_block = conditions.scenario_blocks(cond, course, seed=7)
    w = check_wind(wind_block, 'test.yaml', 'wind')
    params = wave_parameters(waves_block, 'test.yaml', 'waves.')
    sea = conditions.sea_state(cond, course, seed=7)
    field = conditions.wind_field(cond, course, seed=7)
    assert w['speed_mps'] == field.speed_nominal and w['seed'] == 7
    assert math.radians(w['direction_deg']) == pytest.approx(field.direction_from, abs=1e-12)
    assert params['waves_hs'] == sea.hs and params['waves_tp'] == sea.tp
    assert params['waves_seed'] == sea.seed and params['waves_spreading'] is True
    assert math.radians(params['waves_direction_deg']) == pytest.approx(sea.direction,
                                                                        abs=1e-12)


def _table1(controller, condition, duration=60.0, wave_filter=False, n_starts=2):
    route = load_route(ROUTES / 'curved_path_mariner_000.yaml').route
    return ec.run('mariner', route, controller, ec.start_states(n_starts), 0.9, duration,
                  condition=condition, wave_filter=wave_filter, activity=True)


def test_disturbed_run_repeats_and_differs_from_calm():
    a, b = _table1('los_lead', 'wind20', 30.0), _table1('los_lead', 'wind20', 30.0)
    calm = _table1('los_lead', 'calm', 30.0)
    for key in a:
        assert np.array_equal(a[key], b[key]), key
    assert not np.array_equal(a['rudder_tv_deg'], calm['rudder_tv_deg'])


def test_controllers_measure_the_wave_motion():
    """PathFollowingBatch.measured = the plant's state plus each start's own ShipWaves.motion
    (the batch of sea states in one ShipWaves gives each its own numbers)."""
    route = load_route(ROUTES / 'curved_path_mariner_000.yaml').route
    cond = conditions.CONDITIONS['wind10']
    env = PathFollowingBatch('mariner', 2, EnvConfig(mode='straight'), routes=[route])
    env.reset(starts=[dict(s, current_speed=0.9) for s in ec.start_states(2)])
    m = env.model
    seas = [conditions.sea_state(cond, 0.0, conditions.SEED + i) for i in range(2)]
    table = rao_table_for('mariner', m.length)
    north, east, psi, u, v, r = env.measured(ShipWaves(seas, table), 37.3)
    ug, vg, rg = env.ground_velocity()
    for i in range(2):
        U = math.hypot(float(m.surge_speed(env.x)[i]), env.x[i, m.IV])
        eta, nu = ShipWaves(seas[i], table).motion(37.3, U, env.x[i, m.IPSI])
        p = env.x[i, m.IPSI]
        assert psi[i] == pytest.approx(env.x[i, m.IPSI] + eta[5], rel=1e-12, abs=1e-12)
        assert r[i] == pytest.approx(rg[i] + nu[5], rel=1e-12, abs=1e-15)
        assert u[i] == pytest.approx(ug[i] + nu[0], rel=1e-12)
        assert v[i] == pytest.approx(vg[i] + nu[1], rel=1e-12, abs=1e-12)
        assert north[i] == pytest.approx(env.x[i, m.IX] + math.cos(p) * eta[0]
                                         - math.sin(p) * eta[1], abs=1e-9)
        assert east[i] == pytest.approx(env.x[i, m.IY] + math.sin(p) * eta[0]
                                        + math.cos(p) * eta[1], abs=1e-9)
        assert eta[5] != 0.0


def test_wave_filter_lowers_rudder_activity():
    """The gain-table PD chases the wave yaw without the filter (its rate-limited rudder moves
    at the encounter frequency); behind the filter it moves less."""
    raw = _table1('los', 'wind20', duration=120.0, n_starts=1)
    filt = _table1('los', 'wind20', duration=120.0, wave_filter=True, n_starts=1)
    assert np.all(filt['rudder_tv_deg'] < 0.5 * raw['rudder_tv_deg'])


def test_batched_table_cells_equal_the_single_vessel_cells():
    """--batched runs both currents of a controller in one batch, start i keeping its seed at
    each current: every cell equals the single-vessel loop's to rounding."""
    kw = dict(models=['mariner'], n_starts=2, duration=20.0, controllers=['ilos'],
              condition='wind10')
    _, single = ec.evaluate(**kw)
    _, batched = ec.evaluate(**kw, batched=True)
    assert set(single) == set(batched) == {'mariner/0.0/ilos', 'mariner/0.9/ilos'}
    for cell, ref in single.items():
        for key, value in ref.items():
            assert batched[cell][key] == pytest.approx(value, rel=1e-12, abs=1e-12), (cell, key)
