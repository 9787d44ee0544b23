"""Fuzzy PID autopilot of Lee 2004 Chapter 5.

The fuzzy blocks are checked against Lee's own closed forms, written here by hand:
eqs. (5.11)-(5.12) and Table 5.1 (block 1), eqs. (5.13)-(5.14) and Table 5.1 (block 2), and
the gains at the origin GU G / 4 (eqs. 5.18-5.22). Behaviour: course changes of 30/45/60/90 deg
(Lee 2004 Figs. 5.8-5.11) on a linear first-order Nomoto plant (K = 0.185 1/s, T = 107.3 s,
the cargo ship of Lee 2004 Table 4.1) with a constant rudder offset as disturbance: the PD
keeps the steady-state error -d/k1 (r_dot = 0 needs delta = -d, i.e. k1 e = -d), the fuzzy
PID removes it.
"""
import math

import numpy as np
import pytest

from ship_autopilot.fuzzy_pid import (FuzzyPIDAutopilot, FuzzyPIDGains, fuzzy_block1,
                                      fuzzy_block2, scaling_from_pid, scheduled_gains)
from ship_autopilot.pd import PDAutopilot, nomoto_ab, pd_gains
from ship_autopilot.rudder import RudderLimiter

DEG = math.pi / 180.0
L = 2.0  # not 1, so that a misplaced L shows


def seed_block1(xe, xr):
    """Eqs. (5.11), (5.12) inside [-L, L]^2; Table 5.1 (block 1) outside."""
    ie, ir = abs(xe) <= L, abs(xr) <= L
    if ie and ir:
        return 0.5 * L * (xe + xr) / (2 * L - max(abs(xe), abs(xr)))
    if not ie and ir:                       # (IC9-16)1: (GR psi_r +- L) / 2
        return (xr + math.copysign(L, xe)) / 2
    if ie and not ir:                       # (GE psi_e +- L) / 2
        return (xe + math.copysign(L, xr)) / 2
    if xe > 0 and xr > 0:                   # (IC17)1
        return L
    if xe < 0 and xr < 0:                   # (IC19)1
        return -L
    return 0.0                              # (IC18)1, (IC20)1


def seed_block2(xr, xa):
    """Eqs. (5.13), (5.14) with the constant 0.5 inside; Table 5.1 (block 2) outside."""
    if abs(xa) > L:
        return math.copysign(0.5 * L, xa)
    if abs(xr) > L:
        return 0.5 * xa
    return 0.5 * L * xa / (2 * L - max(abs(xr), abs(xa)))


def test_block1_matches_lee_closed_forms_everywhere():
    rng = np.random.default_rng(1)
    pts = rng.uniform(-2.5 * L, 2.5 * L, size=(4000, 2))
    pts = np.vstack([pts, [[0, 0], [L, L], [-L, L], [3 * L, -0.5 * L], [0.3, 3 * L]]])
    got = fuzzy_block1(pts[:, 0], pts[:, 1], L)
    want = np.array([seed_block1(*p) for p in pts])
    assert np.max(np.abs(got - want)) < 1e-12


def test_block2_matches_lee_closed_forms_everywhere():
    rng = np.random.default_rng(2)
    pts = rng.uniform(-2.5 * L, 2.5 * L, size=(4000, 2))
    got = fuzzy_block2(pts[:, 0], pts[:, 1], L)
    want = np.array([seed_block2(*p) for p in pts])
    assert np.max(np.abs(got - want)) < 1e-12


def test_blocks_are_odd_and_bounded():
    x = np.linspace(-3 * L, 3 * L, 61)
    xe, xr = np.meshgrid(x, x)
    assert fuzzy_block1(-xe, -xr, L) == pytest.approx(-fuzzy_block1(xe, xr, L), abs=1e-15)
    assert fuzzy_block2(-xe, -xr, L) == pytest.approx(-fuzzy_block2(xe, xr, L), abs=1e-15)
    assert np.max(np.abs(fuzzy_block1(xe, xr, L))) == pytest.approx(L)
    assert np.max(np.abs(fuzzy_block2(xe, xr, L))) == pytest.approx(0.5 * L)


def test_gains_at_origin_and_their_scheduling():
    g = FuzzyPIDGains(GE=2.0, GR=30.0, GA=0.05, GU=1.5, L=L)
    ctrl = FuzzyPIDAutopilot(g, RudderLimiter(1.0))
    eps = 1e-7
    # Eqs. (5.18)-(5.20) at the origin: K = 0.5 L GU G / (2 L) = GU G / 4.
    assert ctrl.command(eps, 0.0, 0.0) / eps == pytest.approx(1.5 * 2.0 / 4, rel=1e-6)
    assert ctrl.command(0.0, eps, 0.0) / eps == pytest.approx(1.5 * 30.0 / 4, rel=1e-6)
    assert ctrl.command(0.0, 0.0, eps) / eps == pytest.approx(1.5 * 0.05 / 4, rel=1e-6)
    assert g.linear_gains() == pytest.approx((0.75, 11.25, 0.01875))
    # Along the error axis the proportional gain grows to twice its origin value at the edge
    # |GE psi_e| = L (Fig. 5.6): U / psi_e = 0.5 L GU GE / (2L - GE |psi_e|).
    e = np.linspace(0.05, 1.0, 20)  # GE e up to 2 = L
    kp_measured = ctrl.command(e, 0.0, 0.0) / e
    assert kp_measured == pytest.approx(0.5 * L * 1.5 * 2.0 / (2 * L - 2.0 * e), rel=1e-12)
    assert kp_measured[-1] == pytest.approx(2 * 0.75)
    kp, kd, ki = scheduled_gains(e, 0.0, 0.0, g)
    assert kp == pytest.approx(kp_measured, rel=1e-12)


def test_scaling_from_pid_hand_values():
    # kp = 1, kd = 20, ki = 0.005, e_sat = 0.5 rad, L = 1: GU = 4 kp e_sat = 2, GE = 4/2,
    # GR = 80/2, GA = 0.02/2.
    g = scaling_from_pid(1.0, 20.0, 0.005, 0.5)
    assert (g.GU, g.GE, g.GR, g.GA, g.L) == pytest.approx((2.0, 2.0, 40.0, 0.01, 1.0))
    assert g.linear_gains() == pytest.approx((1.0, 20.0, 0.005))
    assert g.saturation_points() == pytest.approx((0.5, 0.025, 100.0))
    with pytest.raises(ValueError, match='ki'):
        scaling_from_pid(1.0, 20.0, 0.0, 0.5)
    with pytest.raises(ValueError, match='GU'):
        FuzzyPIDGains(GE=1.0, GR=1.0, GA=1.0, GU=float('nan'))


# -- closed loop on a linear Nomoto plant ------------------------------------------------------
K_PLANT, T_PLANT = 0.185, 107.3
A, B = nomoto_ab(K_PLANT, T_PLANT)
WN, ZETA = 0.05, 0.8
K1, K2 = pd_gains(A, B, omega_n=WN, zeta=ZETA)            # 1.45, 40.99
GAINS = scaling_from_pid(K1, K2, K1 * WN / 10, 30 * DEG)
CHANGES = np.array([30.0, 45.0, 60.0, 90.0]) * DEG
OFFSET = 3 * DEG                              # constant rudder offset (yaw moment) disturbance


def run(ctrl, psi_c, t_end, dt=0.1, disturbance=OFFSET):
    """Batch closed loop: exact step of psi_dot = r, r_dot = a r + b (delta + d), delta held."""
    psi = np.zeros_like(psi_c)
    r = np.zeros_like(psi_c)
    ctrl.reset()
    e = math.exp(A * dt)
    psis, deltas, integrals = [], [], []
    for _ in range(int(round(t_end / dt))):
        delta = ctrl.update(psi, r, psi_c, dt)
        r_inf = -B * (delta + disturbance) / A
        psi = psi + r_inf * dt + (r - r_inf) * (e - 1.0) / A
        r = r_inf + (r - r_inf) * e
        psis.append(psi)
        deltas.append(delta)
        integrals.append(ctrl.state.get('integral', 0.0))
    return np.array(psis), np.array(deltas), np.array(integrals)


def test_course_changes_pd_keeps_offset_fuzzy_pid_removes_it():
    max_angle, max_rate = 35 * DEG, 5 * DEG
    pd = PDAutopilot(K1, K2, RudderLimiter(max_angle, max_rate))
    fz = FuzzyPIDAutopilot(GAINS, RudderLimiter(max_angle, max_rate),
                           integration_band=10 * DEG)
    psi_pd, d_pd, _ = run(pd, CHANGES, 1000.0)
    psi_fz, d_fz, _ = run(fz, CHANGES, 1000.0)
    err_pd = (psi_pd[-1] - CHANGES) / DEG
    err_fz = (psi_fz[-1] - CHANGES) / DEG
    # PD: e = -d / k1 = -3 deg / 1.45 = -2.069 deg for every course change.
    assert err_pd == pytest.approx(np.full(4, -3.0 / K1), rel=0.01)
    # Fuzzy PID: steady-state error below 0.05 deg (2 % of the PD's).
    assert np.all(np.abs(err_fz) < 0.05)
    # The rudder never exceeds its limit (it did reach it: the 90 deg change saturates).
    assert np.all(np.abs(d_fz) <= max_angle) and np.all(np.abs(d_pd) <= max_angle)
    assert np.max(np.abs(d_fz)) == pytest.approx(max_angle)
    # And the course change itself stays well damped: overshoot below 1 deg.
    assert np.all(np.max(psi_fz - CHANGES, axis=0) < 1 * DEG)


def test_anti_windup_bounds_overshoot_after_long_saturation():
    # A slow 10 deg rudder (2.33 deg/s, the tanker's) saturates for minutes during a 90 deg
    # course change; the error stays large meanwhile, the situation in which an integrator
    # winds up.
    def limiter():
        return RudderLimiter(10 * DEG, 2.33 * DEG)
    psi_c = np.array([90 * DEG])
    with_aw = FuzzyPIDAutopilot(GAINS, limiter(), integration_band=10 * DEG)
    without = FuzzyPIDAutopilot(GAINS, limiter(), anti_windup=False)
    psi_aw, d_aw, i_aw = run(with_aw, psi_c, 1000.0)
    psi_no, _, _ = run(without, psi_c, 1000.0)
    saturated_s = np.sum(np.abs(d_aw) >= 10 * DEG - 1e-12) * 0.1
    assert saturated_s > 60.0                       # a long saturation did happen
    overshoot_aw = np.max(psi_aw - psi_c) / DEG
    overshoot_no = np.max(psi_no - psi_c) / DEG
    assert overshoot_aw < 1.0                       # bounded with anti-windup ...
    assert overshoot_no > 5.0                       # ... and not without it
    assert abs(psi_aw[-1, 0] - psi_c[0]) < 0.05 * DEG
    # The integrator never leaves the universe |GA psi_a| <= L (clamp).
    assert np.all(np.abs(GAINS.GA * i_aw) <= GAINS.L * (1 + 1e-12))


def test_batch_equals_scalar_and_bad_input_holds_state():
    lim = RudderLimiter(35 * DEG, 5 * DEG)
    batch = FuzzyPIDAutopilot(GAINS, lim)
    singles = [FuzzyPIDAutopilot(GAINS, lim) for _ in CHANGES]
    psi = np.array([0.01, -0.02, 0.03, 0.0])
    r = np.array([0.001, 0.0, -0.002, 0.003])
    for k in range(20):
        psi_k = psi + 0.001 * k
        if k == 7:
            psi_k[2] = np.inf
        out = batch.update(psi_k, r, psi_k + 0.05, 0.1)
        ref = [s.update(*args, 0.1) for s, *args in zip(singles, psi_k, r, psi_k + 0.05)]
        assert out == pytest.approx(ref, rel=1e-12, abs=1e-15)
    assert batch.state['integral'] == pytest.approx([s.state['integral'] for s in singles])
    # The held vessel skipped one integration step: 19 steps of -0.05 rad * 0.1 s.
    assert singles[2].state['integral'] == pytest.approx(19 * -0.005)
    assert singles[2].n_rejected == 1
