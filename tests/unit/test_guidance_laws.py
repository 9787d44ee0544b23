"""LOS / ILOS laws and the look-ahead stability limit (ship_guidance.los, Guidance's check).

The limit is checked against Angelopoulos 2011's Table 1 (tests/data/string_stability_table1.csv) and
against the eigenvalues of the linearised loop (Angelopoulos 2011 eq. 30, dimensional form).
"""
import csv
import math
from pathlib import Path

import numpy as np
import pytest

from ship_guidance.guidance import Guidance
from ship_guidance.los import (critical_lookahead, critical_lookahead_nondim, ilos_heading,
                               ilos_integral_rate, linear_loop_matrix, los_current_offset,
                               los_heading, omega_n_from_nondim, pd_arc_offset,
                               ship_lengths_to_metres)
from ship_guidance.path import Route

# Angelopoulos 2011, Table 1 (provenance: tests/data/README.md)
TABLE = Path(__file__).resolve().parents[1] / 'data' / 'string_stability_table1.csv'
PI = math.pi


def test_los_heading_hand_values():
    assert los_heading(0.0, 100.0, 100.0) == pytest.approx(-PI / 4)   # starboard -> steer to port
    assert los_heading(0.0, -100.0, 100.0) == pytest.approx(PI / 4)
    assert los_heading(1.0, 0.0, 50.0) == pytest.approx(1.0)
    # wrapped: pi - 0.1 + pi/4 lies beyond pi
    assert los_heading(PI - 0.1, -100.0, 100.0) == pytest.approx(-PI + (PI / 4 - 0.1))
    assert los_heading(0.0, 1e9, 100.0) == pytest.approx(-PI / 2, abs=1e-6)  # at most abeam


def test_ilos_hand_values():
    # e = 10, sigma e_int = 90: the command acts on 100 m.
    assert ilos_heading(0.0, 10.0, 45.0, 100.0, 2.0) == pytest.approx(-PI / 4)
    # rate = d e / ((e + sigma e_int)^2 + d^2) = 100 * 10 / (100^2 + 100^2)
    assert ilos_integral_rate(10.0, 45.0, 100.0, 2.0) == pytest.approx(0.05)


def test_conversions_and_offsets_hand_values():
    assert ship_lengths_to_metres(2.0, 161.0) == 322.0
    assert omega_n_from_nondim(3.0, 7.7, 161.0) == pytest.approx(3.0 * 7.7 / 161.0)
    # V = 1, U = sqrt(2): crab 45 deg, offset = d tan 45 = d
    assert los_current_offset(100.0, 1.0, math.sqrt(2.0)) == pytest.approx(100.0)
    assert los_current_offset(100.0, -1.0, math.sqrt(2.0)) == pytest.approx(-100.0)
    with pytest.raises(ValueError):
        los_current_offset(100.0, 3.0, 2.0)
    # pd_arc_offset solves |e| = d tan(2 zeta U / (omega_n (R + |e|)))
    e = pd_arc_offset(300.0, 1500.0, 7.7, 0.8, 0.08)
    assert e == pytest.approx(300.0 * math.tan(2 * 0.8 * 7.7 / (0.08 * (1500.0 + e))), rel=1e-12)


def load_table():
    with open(TABLE) as f:
        return list(csv.DictReader(f))


def test_nondimensional_limit_reproduces_table_1():
    """d* = 1 / (2 zeta omega_n) in ship lengths (Angelopoulos 2011 eq. 43), all 537 rows, both vessels."""
    rows = load_table()
    assert len(rows) == 537
    for row in rows:
        z = float(row['zeta'])
        for w, star in (('wn1', 'd1_star'), ('wn2', 'd2_star')):
            d_star = critical_lookahead_nondim(z, float(row[w]))
            assert d_star == pytest.approx(float(row[star]), abs=6e-6)  # table has 6 decimals


@pytest.mark.parametrize('zeta, wn, speed', [(0.8, 0.08, 7.7), (0.4, 0.03, 4.0), (1.2, 0.2, 12.0)])
def test_limit_is_where_the_linear_loop_loses_stability(zeta, wn, speed):
    d_star = critical_lookahead(zeta, wn, speed)
    assert d_star == pytest.approx(speed / (2 * zeta * wn))
    above = np.linalg.eigvals(linear_loop_matrix(zeta, wn, speed, d_star * 1.001))
    below = np.linalg.eigvals(linear_loop_matrix(zeta, wn, speed, d_star * 0.999))
    assert above.real.max() < 0.0 < below.real.max()
    # At the limit the eigenvalues are +-i omega_n and -2 zeta omega_n (Angelopoulos 2011 eqs. 44-45).
    at = np.sort_complex(np.linalg.eigvals(linear_loop_matrix(zeta, wn, speed, d_star)))
    expected = np.sort_complex(np.array([-2 * zeta * wn, -1j * wn, 1j * wn]))
    assert at == pytest.approx(expected, abs=1e-9)


def test_nondimensional_and_dimensional_limits_agree():
    """Angelopoulos 2011 works in units of L and L/U: d/L > 1/(2 zeta omega_n') with omega_n' = omega_n L/U."""
    L, U, zeta, wn_nd = 161.0, 7.7, 0.8, 3.0
    d_dim = critical_lookahead(zeta, omega_n_from_nondim(wn_nd, U, L), U)
    assert d_dim / L == pytest.approx(critical_lookahead_nondim(zeta, wn_nd))


@pytest.mark.parametrize('sigma', [0.5, 2.0, 5.0])
def test_ilos_limit_matches_eigenvalues(sigma):
    zeta, wn, U = 0.8, 0.08, 7.7
    d_star = critical_lookahead(zeta, wn, U, sigma)
    assert d_star > critical_lookahead(zeta, wn, U)  # the integrator costs margin
    above = np.linalg.eigvals(linear_loop_matrix(zeta, wn, U, d_star * 1.001, sigma))
    below = np.linalg.eigvals(linear_loop_matrix(zeta, wn, U, d_star * 0.999, sigma))
    assert above.real.max() < 0.0 < below.real.max()


def test_guidance_refuses_unstable_lookahead():
    route = Route.polyline([(0.0, 0.0), (1000.0, 0.0)])
    d_star = 7.7 / (2 * 0.8 * 0.08)  # 60.2 m
    with pytest.raises(ValueError, match='stability limit'):
        Guidance(route, 'los', 0.9 * d_star, zeta=0.8, omega_n=0.08, speed=7.7)
    g = Guidance(route, 'los', 0.9 * d_star, zeta=0.8, omega_n=0.08, speed=7.7, allow_unstable=True)
    assert g.critical_lookahead == pytest.approx(d_star)
    Guidance(route, 'los', 1.1 * d_star, zeta=0.8, omega_n=0.08, speed=7.7)
    # ILOS needs more: (U + 4 zeta^2 sigma) / (2 zeta omega_n) = 110.2 m for sigma = 5 m/s
    with pytest.raises(ValueError, match='stability limit'):
        Guidance(route, 'ilos', 1.1 * d_star, integral_gain=5.0, zeta=0.8, omega_n=0.08, speed=7.7)
    with pytest.raises(ValueError, match='together'):
        Guidance(route, 'los', 100.0, zeta=0.8, omega_n=0.08)


@pytest.mark.parametrize('kwargs', [
    dict(law='pure_pursuit'), dict(lookahead=0.0), dict(lookahead=float('nan')),
    dict(acceptance_radius=-1.0), dict(law='ilos', integral_gain=0.0), dict(window=-5.0),
])
def test_guidance_refuses_bad_parameters(kwargs):
    route = Route.polyline([(0.0, 0.0), (1000.0, 0.0)])
    with pytest.raises(ValueError):
        Guidance(route, **kwargs)


def test_guidance_refuses_bad_inputs_without_losing_state():
    g = Guidance(Route.polyline([(0.0, 0.0), (1000.0, 0.0)]), 'ilos', 100.0, integral_gain=1.0)
    g.update(10.0, 5.0, 0.0, 1.0)
    before = g.integral
    nan, inf = float('nan'), float('inf')
    for bad in ((nan, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0, -1.0), (0.0, inf, 0.0, 1.0)):
        with pytest.raises(ValueError):
            g.update(*bad)
    assert g.integral == before


def test_guidance_single_step_hand_values():
    # North-bound line; vessel 100 m to starboard; d = 100 m -> psi_c = -45 deg.
    g = Guidance(Route.polyline([(0.0, 0.0), (1000.0, 0.0)]), 'los', 100.0)
    out = g.update(400.0, 100.0, 0.2, 1.0)
    assert out.heading_cmd == pytest.approx(-PI / 4)
    assert (out.cross_track, out.s, out.leg_index) == pytest.approx((100.0, 400.0, 0))
    assert out.distance_remaining == pytest.approx(600.0)
    assert out.heading_error == pytest.approx(-PI / 4 - 0.2)
    assert not out.finished
