"""Sea states, RAO scaling and the scenario `waves:` block (ship_sim.environment.sea_state,
ship_mission.waves)."""
import math
from pathlib import Path

import numpy as np
import pytest

from ship_mission.fields import ScenarioError
from ship_mission.waves import wave_filter_parameters, wave_parameters
from ship_sim.environment.sea_state import (MODEL_RAO, SeaState, ShipWaves,
                                            mean_drift_upper_bound, pm_peak_frequency,
                                            rao_table_for)
from ship_sim.environment.wave_rao import SURGE_SWAY_YAW, load_rao_table
from ship_sim.models import make_model


def test_sea_from_wind_is_the_fully_developed_pm_sea():
    sea = SeaState.from_wind(10.0)
    assert sea.hs == pytest.approx(0.21 * 100.0 / 9.81, rel=1e-15)
    # PM peak: dS/dw = 0 at w^4 = 4 B / 5, B = 0.74 (g / V)^4
    assert sea.peak_frequency == pytest.approx((0.8 * 0.74) ** 0.25 * 9.81 / 10.0, rel=1e-12)
    assert pm_peak_frequency(sea.hs) == sea.peak_frequency


def test_same_seed_same_waves_other_seed_other_waves():
    a = ShipWaves(SeaState(hs=3.0, seed=1, spreading=True), rao_table_for('mariner', 160.93))
    b = ShipWaves(SeaState(hs=3.0, seed=1, spreading=True), rao_table_for('mariner', 160.93))
    c = ShipWaves(SeaState(hs=3.0, seed=2, spreading=True), rao_table_for('mariner', 160.93))
    ma, mb, mc = (w.motion(12.3, 7.0, 0.4)[0] for w in (a, b, c))
    assert ma.tolist() == mb.tolist() and ma.tolist() != mc.tolist()


@pytest.mark.parametrize('bad', [{'hs': -1.0}, {'hs': 3.0, 'spectrum': 'Bretschneider'},
                                 {'hs': 3.0, 'n_frequencies': 0}])
def test_bad_sea_states_are_refused(bad):
    with pytest.raises(ValueError):
        SeaState(**bad)


@pytest.mark.parametrize('vessel', ['s175', 'supply'])
def test_heave_follows_long_waves(vessel):
    # Long-wave limit: a ship rides waves much longer than itself, heave RAO -> 1 m/m.
    t = load_rao_table(vessel, 'motion')
    assert np.all(np.abs(t.amp[2, 0, :] - 1.0) < 0.02)


def test_froude_scaling():
    s175 = load_rao_table('s175', 'motion')
    lam = 2.0
    big = s175.froude_scaled(175.0 * lam)
    assert np.allclose(big.w, s175.w / math.sqrt(lam))
    assert np.allclose(big.amp[:3], s175.amp[:3]) and np.allclose(big.amp[3:], s175.amp[3:] / lam)
    force = load_rao_table('s175', 'force').froude_scaled(175.0 * lam)
    assert np.allclose(force.amp[:3], load_rao_table('s175', 'force').amp[:3] * lam ** 2)
    assert rao_table_for('container', 175.0).scale == 1.0
    assert rao_table_for('tanker', 304.8).scale == pytest.approx(304.8 / 175.0)
    with pytest.raises(ValueError, match='no wave RAOs'):
        rao_table_for('nps_auv2', 5.3)


def test_mean_drift_pushes_the_way_the_waves_travel():
    x, y = mean_drift_upper_bound(3.0, 175.0, 25.4, 0.0)          # following sea
    assert x > 0.0 and y == 0.0
    x, y = mean_drift_upper_bound(3.0, 175.0, 25.4, math.pi / 2)  # towards starboard
    assert abs(x) < 1e-9 * y and y == pytest.approx(1025.0 * 9.81 * 9.0 / 16.0 * 175.0)


def test_scenario_waves_block():
    p = wave_parameters({'hs_m': 3, 'spectrum': 'torsethaugen', 'spreading': True, 'seed': 4},
                        'f.yaml', 'vessels.a.waves.')
    assert p == {'waves_hs': 3.0, 'waves_spectrum': 'torsethaugen', 'waves_spreading': True,
                 'waves_seed': 4}
    for bad, key in (({'height': 3}, 'height'), ({'hs_m': 3, 'wind_speed_mps': 9}, 'wind_speed'),
                     ({'spectrum': 'pm'}, 'spectrum'), ({'hs_m': 40}, 'hs_m')):
        with pytest.raises(ScenarioError, match=key):
            wave_parameters(bad, 'f.yaml', 'vessels.a.waves.')


def test_an_enabled_wave_filter_is_tuned_to_the_vessels_sea():
    waves = wave_parameters({'wind_speed_mps': 10.0, 'direction_deg': 150.0}, 'f.yaml', 'w.')
    got = wave_filter_parameters(waves, {'wave_filter': True})
    # the PM peak of the fully developed 10 m/s sea
    assert got['wave_filter_peak_period'] == pytest.approx(2 * math.pi / (
        (0.8 * 0.74) ** 0.25 * 9.81 / 10.0), rel=1e-12)
    assert got['wave_filter_direction_deg'] == 150.0
    assert wave_filter_parameters(waves, {'wave_filter': False}) == {}
    assert wave_filter_parameters(waves, {'wave_filter': True, 'wave_filter_frequency': 0.5}) == {}
    assert wave_filter_parameters({}, {'wave_filter': True}) == {}
    assert wave_filter_parameters({'waves_hs': 3.0, 'waves_tp': 9.0},
                                  {'wave_filter': True})['wave_filter_peak_period'] == 9.0


def test_scenario_with_waves_gives_the_nodes_their_parameters():
    from ship_mission.launcher import node_parameters
    from ship_mission.scenario import load_scenario
    root = Path(__file__).resolve().parents[2]
    sc = load_scenario(root / 'scenarios' / 'flagship_mariner_waves.yaml')
    params, _ = node_parameters(sc, sc.vessels[0], 0, record=True)
    v, a = params['vessel_node'], params['autopilot_node']
    assert v['waves_wind_speed'] == 15.0 and v['waves_spreading'] is True
    assert v['waves_direction_deg'] == a['wave_filter_direction_deg'] == 120.0
    assert a['wave_filter'] is True
    assert a['wave_filter_peak_period'] == pytest.approx(
        2 * math.pi / pm_peak_frequency(0.21 * 15.0 ** 2 / 9.81))
    calm = load_scenario(root / 'scenarios' / 'flagship_mariner.yaml')
    params, _ = node_parameters(calm, calm.vessels[0], 0, record=True)
    assert not [k for n in params.values() for k in n if 'wave' in k]


@pytest.mark.parametrize('model_name', sorted(MODEL_RAO))
def test_surge_sway_yaw_only_equals_the_full_motion_bit_for_bit(model_name):
    """ShipWaves.motion(dofs=SURGE_SWAY_YAW) (what the 3-DOF loops compute) gives exactly the
    surge, sway and yaw of the full 6-DOF computation (==, not approx), NaN for the rest: one
    vessel and a batch, two spreading layouts, headings round the compass (every RAO heading
    segment), ahead and astern of the wave speed."""
    table = rao_table_for(model_name, make_model(model_name).length)
    keep, drop = list(SURGE_SWAY_YAW), [2, 3, 4]
    for spreading in (False, True):
        seas = [SeaState(hs=2.0 + i, tp=0.0 if i else 9.0, spectrum=s, direction=0.3 * i,
                         spreading=spreading, n_directions=8, seed=11 + i)
                for i, s in enumerate(('JONSWAP', 'Modified PM', 'Torsethaugen'))]
        psi = np.linspace(-math.pi, math.pi, 3)
        U = np.array([0.0, 7.5, 15.0])
        batch = ShipWaves(seas, table)
        for t in (0.0, 37.3, 1234.5):
            for h in np.linspace(0.0, 2.0 * math.pi, 40):
                full, part = batch.motion(t, U, psi + h), batch.motion(t, U, psi + h,
                                                                       dofs=SURGE_SWAY_YAW)
                for f, p in zip(full, part):
                    assert (p[keep] == f[keep]).all() and np.isnan(p[drop]).all()
            single = ShipWaves(seas[1], table)
            for h in np.linspace(0.0, 2.0 * math.pi, 40):
                full, part = single.motion(t, 7.5, h), single.motion(t, 7.5, h,
                                                                     dofs=SURGE_SWAY_YAW)
                for f, p in zip(full, part):
                    assert (p[keep] == f[keep]).all() and np.isnan(p[drop]).all()


@pytest.mark.parametrize('dofs', [None, SURGE_SWAY_YAW])
def test_a_batch_in_blocks_equals_the_batch_in_one_piece_bit_for_bit(monkeypatch, dofs):
    """WaveResponse runs a large batch in blocks of vessels (wave_rao.BLOCK_ELEMENTS) and
    stores the RAOs once per sea state: each vessel's motion and loads are exactly (==) those
    of the whole batch evaluated at once, across block edges (blocks of 1, 2 and 5 vessels of
    a batch of 11, 3 of them sharing one sea state), and the vessels of one sea state share
    one stored copy of their RAOs."""
    from ship_sim.environment import wave_rao
    table = rao_table_for('mariner', make_model('mariner').length)
    seas = [SeaState(hs=1.0 + 0.3 * i, direction=0.2 * i, spreading=True, n_directions=4,
                     seed=i) for i in range(8)]
    seas[8:] = [seas[3]] * 3
    waves = ShipWaves(seas, table)
    U, psi = np.linspace(0.0, 12.0, 11), np.linspace(-3.0, 3.0, 11)
    n_dofs = 6 if dofs is None else len(dofs)
    per_vessel = n_dofs * waves.response.Amp[0].size
    monkeypatch.setattr(wave_rao, 'BLOCK_ELEMENTS', 10 ** 9)
    whole = [waves.motion(t, U, psi, dofs=dofs) for t in (0.0, 55.5)]
    whole_force = waves.response.force(3.0, U, psi, waves.direction)
    for vessels in (1, 2, 5):
        monkeypatch.setattr(wave_rao, 'BLOCK_ELEMENTS', vessels * per_vessel)
        for t, ref in zip((0.0, 55.5), whole):
            for got, want in zip(waves.motion(t, U, psi, dofs=dofs), ref):
                assert got.shape == want.shape == (6, 11)
                assert np.array_equal(got, want, equal_nan=True)
        assert np.array_equal(waves.response.force(3.0, U, psi, waves.direction), whole_force)
    # 8 sea states among 11 vessels: 8 stored RAO sets, vessels 8-10 those of vessel 3.
    assert waves.response._stored_rao(dofs).shape[0] == 8
    U[8:], psi[8:] = U[3], psi[3]   # at vessel 3's speed and heading, its motion exactly
    eta, nu = waves.motion(55.5, U, psi, dofs=dofs)
    for a in (eta, nu):
        assert np.array_equal(a[:, 8:], np.repeat(a[:, [3]], 3, axis=1), equal_nan=True)
