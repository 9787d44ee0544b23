"""Turning circles and zig-zags against MSS run under Octave (RK4, h = 0.1 s, 700 s).

Reference: tests/data/mss_golden/maneuvers.json (numbers and method) and traj/*.csv
(the same runs sampled at 1 s). Commands there are in each model's native rudder sign; here
they are converted to the unified sign (positive = port) through the model's RUDDER_SIGN, so
these tests also check the sign mapping (mariner and tanker turn asymmetrically).
"""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from mss_accuracy import TURNS, run_turn
from ship_sim.maneuvers import integrate, turning_metrics, zigzag
from ship_sim.models import make_model

# provenance: tests/data/README.md
REF = Path(__file__).resolve().parents[1] / 'data' / 'mss_golden'
MANEUVERS = json.loads((REF / 'maneuvers.json').read_text())

# the scenarios and how they are run: one place, shared with scripts/mss_accuracy.py
# ours -> maneuvers.json field; the brief asks for 1 % agreement on these.
MEASURES = {
    'advance_m': 'advance_at_90deg_m',
    'transfer_m': 'transfer_at_90deg_m',
    'tactical_diameter_m': 'tactical_diameter_at_180deg_m',
    'steady_radius_m': 'steady_turning_radius_U_over_r_m',
    'final_speed_mps': 'final_speed_U_mps',
}
_runs = {}


def _turn(key):
    if key not in _runs:
        _runs[key] = run_turn(key)
    return _runs[key]


def _csv(stem):
    data = np.genfromtxt(REF / 'traj' / f'{stem}_rk4_h0.1_1s.csv', delimiter=',', names=True)
    return data


@pytest.mark.parametrize('key', TURNS)
def test_turning_circle_matches_mss(key):
    model, res, _, _ = _turn(key)
    ref = MANEUVERS['turning_circle'][key]['rk4_h0.1']
    assert res.direction == (1 if ref['turn_direction'].startswith('starboard') else -1)
    for ours, theirs in MEASURES.items():
        assert getattr(res, ours) == pytest.approx(ref[theirs], rel=0.01), ours
    assert res.time_to_90deg_s == pytest.approx(ref['time_to_90deg_s'], rel=0.01)
    assert res.max_transfer_m == pytest.approx(ref['max_transfer_m'], rel=0.01)


@pytest.mark.parametrize('key', ['mariner_turn_ui+35', 'tanker_turn_dc-10_h30',
                                 'container_turn_dc+10_n80'])
def test_turning_trajectory_matches_mss_samples(key):
    # Same equations and the same integrator as the reference: the states agree to rounding,
    # so the tolerance is far below 1 % (any real modelling difference shows up as >> 1e-6).
    model, _, t, states = _turn(key)
    ref = _csv(key)
    for when in (10.0, 100.0, 300.0, 700.0):
        row = ref[np.flatnonzero(ref['t'] == when)[0]]
        k = int(round(when / 0.1))
        assert t[k] == pytest.approx(when)
        expected = [row[n] for n in ref.dtype.names[1:1 + model.n_states]]
        np.testing.assert_allclose(states[k], expected, rtol=1e-6, atol=1e-9)
        assert model.speed(states[k]) == pytest.approx(row['U'], rel=1e-9)


@pytest.mark.parametrize('size', [10, 20])
def test_mariner_zigzag_matches_mss(size):
    model = make_model('mariner')
    res, t, states, cmds = zigzag(model, math.radians(size), math.radians(size), h=0.1,
                                  t_end=700.0)
    ref = MANEUVERS['zigzag'][f'mariner_zigzag_{size}_{size}']['rk4_h0.1']
    overshoot_deg = np.degrees(res.overshoots_rad)
    assert overshoot_deg[0] == pytest.approx(ref['first_overshoot_angle_deg'], rel=0.01)
    assert overshoot_deg[1] == pytest.approx(ref['second_overshoot_angle_deg'], rel=0.01)
    # The reference lists the first reversals; each must happen at the same step.
    listed = ref['switch_times_s']
    np.testing.assert_allclose(res.switch_times_s[:len(listed)], listed, atol=0.05)
    # The commanded rudder in the 1 s trajectory file (native ui) matches ours step by step.
    csv = _csv(f'mariner_zigzag_{size}_{size}')
    ours_ui = model.RUDDER_SIGN * cmds[::10]
    np.testing.assert_array_equal(ours_ui, csv['ui'][:len(ours_ui)])
    np.testing.assert_allclose(states[::10, model.IPSI], csv['psi'], rtol=1e-6, atol=1e-9)


def test_zigzag_first_turn_is_to_starboard_and_overshoots_are_positive():
    model = make_model('tanker')
    res, _, states, _ = zigzag(model, math.radians(10), math.radians(10), t_end=900.0)
    first = states[round(res.switch_times_s[0] / 0.1), model.IPSI]
    assert first >= math.radians(10)
    assert len(res.overshoots_rad) >= 2 and min(res.overshoots_rad) > 0


@pytest.mark.parametrize('psi0, turn', [(0.0, 1), (1.0, -1), (-2.5, 1)])
def test_turning_metrics_on_an_exact_circle(psi0, turn):
    # Circle of radius R entered at (n0, e0) heading psi0: advance = transfer = R at 90 deg,
    # tactical diameter = 2R, steady radius U/|r| = R.
    R, U, n0, e0 = 400.0, 5.0, 100.0, -50.0
    t = np.arange(0.0, 600.0, 0.5)
    r = turn * U / R
    psi = psi0 + r * t
    # Track in the frame of the initial heading, then rotated into NED.
    along = R * np.sin(r * t) * turn
    across = turn * R * (1 - np.cos(r * t))
    north = n0 + np.cos(psi0) * along - np.sin(psi0) * across
    east = e0 + np.sin(psi0) * along + np.cos(psi0) * across
    res = turning_metrics(t, north, east, np.angle(np.exp(1j * psi)), np.full_like(t, U),
                          np.full_like(t, r))
    assert res.direction == turn
    assert res.time_to_90deg_s == pytest.approx(math.pi / 2 / abs(r), rel=1e-6)
    assert res.advance_m == pytest.approx(R, rel=1e-4)
    assert res.transfer_m == pytest.approx(R, rel=1e-4)
    assert res.tactical_diameter_m == pytest.approx(2 * R, rel=1e-4)
    assert res.max_transfer_m == pytest.approx(2 * R, rel=1e-4)
    assert res.steady_radius_m == pytest.approx(R)


def test_integrate_batched_path_equals_single_vessel_path():
    model = make_model('tanker')
    x0 = model.initial_state()
    u = model.inputs(np.array([0.1, -0.1]))
    t, batch = integrate(model, np.stack([x0, x0]), u, 0.1, 30.0)
    assert batch.shape == (301, 2, model.n_states) and t[-1] == pytest.approx(30.0)
    for i in range(2):
        _, single = integrate(model, x0, u[i], 0.1, 30.0)
        np.testing.assert_allclose(batch[:, i], single, rtol=1e-13, atol=1e-12)
