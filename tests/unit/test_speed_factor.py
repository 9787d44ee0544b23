"""The speed factor on a shaft (ship_sim.speed_factor) and its wiring by the launcher."""
import math
from pathlib import Path

import pytest

from ship_mission.launcher import node_parameters
from ship_mission.scenario import load_scenario
from ship_sim.simulator import VesselSimulator
from ship_sim.speed_factor import scaled_shaft

ROOT = Path(__file__).resolve().parents[2]
HEAD_ON = ROOT / 'scenarios' / 'head_on_mariner_2.yaml'


def test_factor_one_keeps_the_command_itself_and_no_shaft_stays_none():
    assert scaled_shaft(70.123456789, 1.0) == 70.123456789
    assert scaled_shaft(70.0, 0.5) == 35.0
    assert scaled_shaft(70.0, -0.3) == 0.0
    assert scaled_shaft(None, 0.5) is None
    with pytest.raises(ValueError):
        scaled_shaft(70.0, math.nan)


def _steady_speed(factor, seconds=1500.0):
    sim = VesselSimulator('container', dt=0.1)
    shaft = scaled_shaft(sim.shaft_command, factor)
    for _ in range(int(seconds / 0.1)):
        sim.step(0.0, shaft)
    return sim.speed_water()


def test_container_steady_speed_scales_with_the_factor():
    """Thrust and resistance are both quadratic (in shaft speed and ship speed) in container.m,
    so the steady speed is proportional to the shaft speed: half the shaft, half the speed."""
    full = VesselSimulator('container', dt=0.1).speed_water()     # trim at the nominal shaft
    assert _steady_speed(1.0, 60.0) == pytest.approx(full, rel=1e-9)
    assert _steady_speed(0.5) == pytest.approx(full / 2, rel=0.01)


def test_launcher_turns_the_speed_factor_on_for_colav_vessels_with_a_shaft(scenario_variant):
    sc = load_scenario(HEAD_ON)
    own = node_parameters(sc, sc.vessels[0], 0, record=True)[0]
    tgt = node_parameters(sc, sc.vessels[1], 1, record=True)[0]
    assert own['vessel_node']['speed_factor_input'] is True
    assert own['colav_node']['has_shaft'] is False            # the Mariner has no shaft input
    assert 'speed_factor_input' not in tgt['vessel_node']     # no colav, nothing to act on

    def container(d):
        d['vessels']['vessel_0']['model'] = 'container'
        d['vessels']['vessel_0'].pop('speed_mps')
    sc = load_scenario(scenario_variant(HEAD_ON, container))
    own = node_parameters(sc, sc.vessels[0], 0, record=True)[0]
    assert own['vessel_node']['speed_factor_input'] is True
    assert own['colav_node']['has_shaft'] is True
