"""Guidance in closed loop with a simple plant: kinematics + Nomoto first-order yaw + the PD
heading autopilot of Angelopoulos 2011 / Simakis 1992, written here so the test depends on nothing else.

Plant (project conventions, NED, unified rudder: positive turns to port):
    n' = U cos psi + Vn,  e' = U sin psi + Ve,  psi' = r,  r' = a r + b delta,
    a = -1/T, b = -K/T; Mariner-class Nomoto constants of Lee 2004 Table 4.1 (K = 0.185 1/s,
    T = T1 + T2 - T3 = 107.3 s, U = 7.7 m/s, L = 161 m).
Autopilot: delta = k1 (psi - psi_c) + k2 r, k1 = -omega_n^2 / b, k2 = -(a + 2 zeta omega_n) / b
(Angelopoulos 2011 eq. 16/20, Simakis 1992 eqs. 2.15-2.16), rudder limited to 35 deg. zeta = 0.8, omega_n = 0.08 rad/s.
Expected values come from the linearised loop (Angelopoulos 2011 eq. 30) and the closed-form offsets in
ship_guidance.los, never from a previous run.
"""
import math

import numpy as np
import pytest

from ship_guidance.guidance import Guidance
from ship_guidance.los import linear_loop_matrix, los_current_offset, pd_arc_offset
from ship_guidance.path import Arc, Line, Route
from ship_sim.frames import wrap_angle

K, T, U, L = 0.185, 118.0 + 7.8 - 18.5, 7.7, 161.0
ZETA, WN = 0.8, 0.08
DT = 0.5


def simulate(guidance, north, east, psi, t_end, current=(0.0, 0.0), stop_when_finished=False):
    """RK4 at DT with the rudder held over each step. Columns: t, n, e, psi, r, delta, e_g, s,
    leg, psi_c, finished."""
    a, b = -1.0 / T, -K / T
    k1, k2 = -WN ** 2 / b, -(a + 2 * ZETA * WN) / b
    dmax = math.radians(35.0)
    vn, ve = current
    x = np.array([north, east, psi, 0.0])

    def f(x, d):
        return np.array([U * math.cos(x[2]) + vn, U * math.sin(x[2]) + ve, x[3], a * x[3] + b * d])

    log = []
    for i in range(int(round(t_end / DT))):
        out = guidance.update(x[0], x[1], x[2], DT)
        d = min(max(k1 * wrap_angle(x[2] - out.heading_cmd) + k2 * x[3], -dmax), dmax)
        log.append((i * DT, *x, d, out.cross_track, out.s, out.leg_index, out.heading_cmd,
                    out.finished))
        if stop_when_finished and out.finished:
            break
        f1 = f(x, d)
        f2 = f(x + 0.5 * DT * f1, d)
        f3 = f(x + 0.5 * DT * f2, d)
        x = x + DT / 6.0 * (f1 + 2 * f2 + 2 * f3 + f(x + DT * f3, d))
    return np.array(log)


T_, N_, E_, PSI_, R_, DELTA_, EG_, S_, LEG_, PSIC_, FIN_ = range(11)


def linear_response(d, e0, t):
    """Cross-track response of the linearised loop (Angelopoulos 2011 eq. 30, dimensional) from (0, 0, e0)."""
    lam, vec = np.linalg.eig(linear_loop_matrix(ZETA, WN, U, d))  # distinct eigenvalues here
    coef = np.linalg.solve(vec, np.array([0.0, 0.0, e0]))
    return (np.exp(np.outer(t, lam)) @ (vec[2] * coef)).real


@pytest.mark.parametrize('d_lengths', [3.0, 2.0])
def test_los_converges_from_200_m_offset(d_lengths):
    """Stated bounds: the overshoot is no larger than the linearised loop's (the nonlinear law's
    atan and the rudder limit only soften the command) plus 1 % of the offset, and the error is
    below 1 m after 12 time constants of the slowest linear mode."""
    d = d_lengths * L
    route = Route.polyline([(0.0, 0.0), (30000.0, 0.0)])
    g = Guidance(route, 'los', d, zeta=ZETA, omega_n=WN, speed=U)
    log = simulate(g, 0.0, 200.0, 0.0, 1200.0)
    e = log[:, EG_]
    lin = linear_response(d, 200.0, log[::4, T_])
    overshoot, lin_overshoot = max(0.0, -e.min()), max(0.0, -lin.min())
    assert overshoot <= lin_overshoot + 2.0
    tau = 1.0 / np.abs(np.linalg.eigvals(linear_loop_matrix(ZETA, WN, U, d)).real).min()
    assert np.all(np.abs(e[log[:, T_] >= 12 * tau]) < 1.0)
    assert np.all(np.diff(log[:, S_]) >= 0.0)  # progress never goes back


def tangent_arc_route(clockwise, radius=1500.0, turn=1.5 * math.pi):
    """2 km north, then a tangent arc turning ``turn`` rad to starboard (cw) or port."""
    sgn = 1.0 if clockwise else -1.0
    c = (2000.0, sgn * radius)
    th1 = math.atan2(-sgn * radius, 0.0) + sgn * turn
    end = (c[0] + radius * math.cos(th1), c[1] + radius * math.sin(th1))
    return Route([Line((0.0, 0.0), (2000.0, 0.0)), Arc((2000.0, 0.0), end, c, clockwise)])


@pytest.mark.parametrize('clockwise', [True, False])
def test_arc_steady_state_both_directions(clockwise):
    """Plain LOS settles OUTSIDE the circle by |e| = d tan(2 zeta U / (omega_n (R + |e|))) (the
    PD autopilot's heading lag in a steady turn); ILOS removes that offset."""
    d, radius = 2.0 * L, 1500.0
    route = tangent_arc_route(clockwise, radius)
    outside = -1.0 if clockwise else 1.0  # port of a cw arc / starboard of a ccw arc
    expected = pd_arc_offset(d, radius, U, ZETA, WN)

    def late(log):
        """The rows past the arc's first 60 %, before the last 50 m of the route."""
        return log[(log[:, S_] > 2000.0 + 0.6 * route.legs[1].length)
                   & (log[:, S_] < route.length - 50.0)]

    los = late(simulate(Guidance(route, 'los', d), 0.0, 0.0, 0.0, route.length / U))
    assert np.all(np.abs(los[:, EG_] - outside * expected) < 0.01 * expected)
    ilos = late(simulate(Guidance(route, 'ilos', d, integral_gain=U / 4), 0.0, 0.0, 0.0,
                         route.length / U))
    assert np.all(np.abs(ilos[:, EG_]) < 0.05 * expected)
    assert abs(ilos[-1, EG_]) < 0.005 * expected


def test_ilos_removes_cross_current_offset_los_keeps_it():
    """Current 1 m/s across a north-bound line: LOS settles at d V / sqrt(U^2 - V^2) downstream
    (crab angle asin(V/U) = 7.5 deg, e = 42.2 m for d = 2L); ILOS converges to the line."""
    d, v = 2.0 * L, 1.0
    route = Route.polyline([(0.0, 0.0), (40000.0, 0.0)])
    los = simulate(Guidance(route, 'los', d), 0.0, 0.0, 0.0, 3000.0, current=(0.0, v))
    expected = los_current_offset(d, v, U)
    assert expected == pytest.approx(d * math.tan(math.asin(v / U)))
    assert los[-1, EG_] == pytest.approx(expected, rel=1e-3)
    assert los[-1, PSI_] == pytest.approx(-math.asin(v / U), abs=1e-4)  # crabbing into it
    g = Guidance(route, 'ilos', d, integral_gain=U / 4)
    ilos = simulate(g, 0.0, 0.0, 0.0, 3000.0, current=(0.0, v))
    assert abs(ilos[-1, EG_]) < 1e-3 * expected
    assert g.integral_gain * g.integral == pytest.approx(expected, rel=1e-3)


@pytest.mark.parametrize('radius', [2.0 * L, 0.0])
def test_corner_switch_by_acceptance_circle_or_end_normal(radius):
    corner = (3000.0, 0.0)
    route = Route.polyline([(0.0, 0.0), corner, (3000.0, 4000.0)])
    g = Guidance(route, 'los', 2.0 * L, acceptance_radius=radius)
    log = simulate(g, 0.0, 0.0, 0.0, 700.0)
    i = np.nonzero(log[:, LEG_] == 1)[0][0]  # first step on the second leg
    dist = np.hypot(log[:, N_] - corner[0], log[:, E_] - corner[1])
    if radius > 0.0:
        assert dist[i] <= radius < dist[i - 1]
    else:  # past the normal to the first leg at the corner
        assert log[i, N_] >= corner[0] > log[i - 1, N_]
    assert np.all(log[i:, LEG_] == 1)
    # After the switch the reference is the second leg (extended backwards before its start).
    assert np.all(np.abs(log[i:, PSIC_] - (math.pi / 2 - np.arctan(log[i:, EG_] / (2 * L)))) < 1e-9)


def test_figure_eight_is_followed_in_order_and_finishes():
    """Through both crossings the progress keeps to its branch: legs in order, no jumps."""
    c = 1500.0
    route = Route([Line((-c, -c), (c, c)), Arc((c, c), (c, -c), (2 * c, 0.0), False),
                   Line((c, -c), (-c, c)), Arc((-c, c), (-c, -c), (-2 * c, 0.0), True)])
    g = Guidance(route, 'los', 2.0 * L, acceptance_radius=L)
    log = simulate(g, -c, -c, math.pi / 4, 1.2 * route.length / U, stop_when_finished=True)
    assert log[-1, FIN_] == 1.0
    legs = log[:, LEG_]
    assert np.all(np.diff(legs) >= 0) and set(legs) == {0, 1, 2, 3}
    ds = np.diff(log[:, S_])
    assert np.all(ds >= 0.0) and np.all(ds <= 1.5 * U * DT)
    # Second half of every leg: back on the lines, outside the loops by the steady LOS offset.
    offset = pd_arc_offset(2.0 * L, c * math.sqrt(2.0), U, ZETA, WN)
    for leg, expected in enumerate((0.0, offset, 0.0, -offset)):  # port loop: outside = +
        lo = route.leg_starts[leg] + 0.5 * route.leg_lengths[leg]
        part = log[(log[:, S_] > lo) & (log[:, S_] < route.cumulative[leg + 1] - 50.0), EG_]
        assert len(part) > 100 and np.all(np.abs(part - expected) < 0.01 * offset)
    # finished on entering the acceptance circle (radius L) of the end point
    dist_end = np.hypot(log[:, N_] - route.end[0], log[:, E_] - route.end[1])
    assert dist_end[-1] <= L < dist_end[-2]


def test_resume_mid_route_and_start_on_a_corner():
    route = Route.polyline([(0.0, 0.0), (1000.0, 0.0), (1000.0, 1000.0)])
    g = Guidance(route, 'los', 200.0)
    out = g.update(1000.0, 0.0)  # exactly on the corner: belongs to the leg leaving it
    assert out.leg_index == 1 and out.path_angle == pytest.approx(math.pi / 2)
    g.reset(s=500.0)
    out = g.update(500.0, 30.0, 0.0, 1.0)
    assert out.leg_index == 0
    assert (out.s, out.cross_track) == pytest.approx((500.0, 30.0))


@pytest.mark.parametrize('clockwise', [True, False])
def test_curvature_lead_cancels_the_autopilot_lag_on_arcs(clockwise):
    """With the turn-rate lead psi_c += (2 zeta U / omega_n) kappa the steady state on an arc
    satisfies e = d tan((2 zeta U / omega_n) (1/(R + |e|) - 1/R)), whose only solution is
    e = 0: plain LOS then keeps no offset on the arc (without the lead it keeps pd_arc_offset)."""
    d, radius = 2.0 * L, 1500.0
    route = tangent_arc_route(clockwise, radius)
    no_lead = pd_arc_offset(d, radius, U, ZETA, WN)
    g = Guidance(route, 'los', d, zeta=ZETA, omega_n=WN, speed=U, curvature_lead=True)
    log = simulate(g, 0.0, 0.0, 0.0, route.length / U)
    late = log[(log[:, S_] > 2000.0 + 0.6 * route.legs[1].length)
               & (log[:, S_] < route.length - 50.0)]
    assert len(late) > 100
    assert np.all(np.abs(late[:, EG_]) < 0.02 * no_lead)


def test_curvature_lead_needs_the_autopilot_parameters():
    with pytest.raises(ValueError, match='curvature_lead'):
        Guidance(tangent_arc_route(True), 'los', 2.0 * L, curvature_lead=True)
