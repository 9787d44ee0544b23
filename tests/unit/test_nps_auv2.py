"""NPS AUV II (Simakis 1992): equations of motion, Nomoto reduction, Simakis's PD gains, closed loop.

Vehicle data below are copied by hand from Simakis's listings (NOMO.FOR / SIMU.FOR) so that
the tests check the model's algebra against the original equations (2.1)-(2.2), not against
its own formulas.
"""
import numpy as np
import pytest

from ship_sim.integrators import rk4_step
from ship_sim.models import make_model
from ship_sim.models.nps_auv2 import NpsAuv2

# Simakis 1992 listings: weight 435 lb, Iz 45 slug ft^2, L 7.3 ft, rho 1.94 slug/ft^3, g 32.2,
# xG 0.0104 ft; nondimensional derivatives; bow/stern ratio -1.
L_FT, RHO = 7.3, 1.94
MASS = 435.0 / 32.2 / (0.5 * RHO * L_FT ** 3)
IZ = 45.0 / (0.5 * RHO * L_FT ** 5)
XG = 0.0104 / L_FT
YVD, YRD, NVD, NRD = -0.0343, 0.0, 0.0, -0.00047
YV, YR, NV, NR = -0.107, 0.0, 0.0, -0.0039
Y_DELTA = 0.01241 - 0.01241               # stern + ratio * bow
N_DELTA = -0.337 * 0.01241 - 0.283 * 0.01241


def nondimensional_model():
    """NpsAuv2 in Simakis's units: unit speed and length, time in L/U."""
    return NpsAuv2(U=1.0, length=1.0)


def test_derivatives_satisfy_equations_2_1_and_2_2():
    # m (v_dot + u r + xG r_dot) = Yrdot r_dot + Yvdot v_dot + Yr u r + Yv u v + Yd u^2 delta
    # Iz r_dot + m xG (v_dot + u r) = Nrdot r_dot + Nvdot v_dot + Nr u r + Nv u v + Nd u^2 delta
    m = nondimensional_model()
    rng = np.random.default_rng(3)
    for _ in range(5):
        x = m.initial_state()
        x[m.IV], x[m.IR], x[m.IDELTA] = rng.normal(scale=0.1, size=3)
        xd = m.rhs(x, m.inputs(x[m.IDELTA]))
        vd, rd = xd[m.IV], xd[m.IR]
        v, r, d = x[m.IV], x[m.IR], x[m.IDELTA]
        lhs_y = MASS * (vd + r + XG * rd) - YRD * rd - YVD * vd
        lhs_n = IZ * rd + MASS * XG * (vd + r) - NRD * rd - NVD * vd
        assert lhs_y == pytest.approx(YR * r + YV * v + Y_DELTA * d, abs=1e-12)
        assert lhs_n == pytest.approx(NR * r + NV * v + N_DELTA * d, abs=1e-12)


def test_kinematics_2_3_to_2_5():
    m = NpsAuv2(U=1.5)
    x = m.initial_state(psi=0.6)
    x[m.IV], x[m.IR] = 0.2, -0.05
    xd = m.rhs(x, m.inputs(0.0))
    assert xd[m.IX] == pytest.approx(1.5 * np.cos(0.6) - 0.2 * np.sin(0.6))
    assert xd[m.IY] == pytest.approx(1.5 * np.sin(0.6) + 0.2 * np.cos(0.6))
    assert xd[m.IPSI] == -0.05 and xd[m.IU] == 0.0


def test_dimensional_form_is_the_scaled_nondimensional_one():
    # Similarity: v = U v', r = (U/L) r', t = (L/U) t'
    #   =>  v_dot = U^2/L f_v',  r_dot = U^2/L^2 f_r'.
    U, L = 1.8, 2.225
    dim, nd = NpsAuv2(U=U, length=L), nondimensional_model()
    x, xn = dim.initial_state(), nd.initial_state()
    x[dim.IV], x[dim.IR], x[dim.IDELTA] = 0.1 * U, -0.2 * U / L, 0.15
    xn[nd.IV], xn[nd.IR], xn[nd.IDELTA] = 0.1, -0.2, 0.15
    fd, fn = dim.rhs(x, dim.inputs(0.15)), nd.rhs(xn, nd.inputs(0.15))
    assert fd[dim.IV] == pytest.approx(U ** 2 / L * fn[nd.IV], rel=1e-12)
    assert fd[dim.IR] == pytest.approx(U ** 2 / L ** 2 * fn[nd.IR], rel=1e-12)
    a, b = dim.nomoto_ab()
    an, bn = nd.nomoto_ab()
    assert (a, b) == pytest.approx((an * U / L, bn * (U / L) ** 2), rel=1e-12)


def yaw_transfer(m):
    """Exact r/delta of eqs. (2.8)-(2.9) from the model's Jacobian: (A, B, C) of [v, r]."""
    x0 = m.initial_state()
    eps = 1e-6
    idx = [m.IV, m.IR]
    A = np.zeros((2, 2))
    for k, i in enumerate(idx):
        d = np.zeros(m.n_states)
        d[i] = eps
        A[:, k] = ((m.rhs(x0 + d, m.inputs(0.0)) - m.rhs(x0 - d, m.inputs(0.0)))[idx] / (2 * eps))
    d = np.zeros(m.n_states)
    d[m.IDELTA] = eps
    B = (m.rhs(x0 + d, m.inputs(0.0)) - m.rhs(x0 - d, m.inputs(0.0)))[idx] / (2 * eps)
    return A, B, np.array([0.0, 1.0])


def test_nomoto_reduction_keeps_static_gain_and_first_moment():
    # Seed eq. (2.11): Taylor expansion of delta/r in s, two terms kept. So the first-order
    # G1(s) = b / (s - a) has G1(0) = G(0) and G1'(0) = G'(0) of the exact r/delta (2.10):
    # G(0) = -C A^-1 B, G'(0) = -C A^-2 B.
    m = nondimensional_model()
    A, B, C = yaw_transfer(m)
    g0 = -C @ np.linalg.solve(A, B)
    g1 = -C @ np.linalg.solve(A, np.linalg.solve(A, B))
    a, b = m.nomoto_ab()
    assert -b / a == pytest.approx(g0, rel=1e-8)
    assert -b / a ** 2 == pytest.approx(g1, rel=1e-8)
    # Unified sign: positive rudder turns to port (b < 0); the vehicle is course stable (a < 0).
    assert a < 0 and b < 0


def test_simakis_pd_gains_at_wn_3_zeta_0_8():
    # Simakis 1992, Sec. III.B: for wn = 3.0, zeta = 0.8 "the gains k1, k2 are about 3.2 and 1.2"
    # (read from its Fig. 4, nondimensional). Eqs. (2.15)-(2.16):
    wn, zeta = 3.0, 0.8
    a, b = nondimensional_model().nomoto_ab()
    k1 = -wn ** 2 / b
    k2 = -(a + 2 * zeta * wn) / b
    assert k1 == pytest.approx(3.2, abs=0.1)  # Simakis 1992 quotes one decimal
    assert k2 == pytest.approx(1.2, abs=0.1)


def test_closed_loop_straight_line_as_simu_for():
    # SIMU.FOR, straight line from (0, 0) to (10, 10) (Fig. 14), nondimensional, look-ahead 1:
    # delta = k1 sin(psi - psi_c - alpha) + k2 r, psi_c = -atan(y'/d), |delta| <= 0.4. The
    # vehicle starts heading north; the line heads 45 deg: a starboard turn, i.e. a negative
    # rudder that saturates at -0.4 rad first (Simakis's Fig. 15 shows about -23 deg).
    m = NpsAuv2(U=1.0, length=1.0, rudder_time_constant=0.01, rudder_rate_max=100.0)
    wn, zeta, d, alpha = 3.0, 0.8, 1.0, np.pi / 4
    a, b = m.nomoto_ab()
    k1, k2 = -wn ** 2 / b, -(a + 2 * zeta * wn) / b
    x = m.initial_state()
    h = 0.01
    rudder = []
    for _ in range(3000):  # 30 L/U
        yp = x[m.IY] * np.cos(alpha) - x[m.IX] * np.sin(alpha)
        psi_c = -np.arctan(yp / d)
        dc = np.clip(k1 * np.sin(x[m.IPSI] - psi_c - alpha) + k2 * x[m.IR], -0.4, 0.4)
        rudder.append(dc)
        x = rk4_step(m.rhs, x, m.inputs(dc), h)
    assert min(rudder) == -0.4 and rudder[0] == -0.4
    yp = x[m.IY] * np.cos(alpha) - x[m.IX] * np.sin(alpha)
    assert abs(yp) < 1e-3                               # on the line
    assert x[m.IPSI] == pytest.approx(alpha, abs=1e-3)  # heading along it


def test_registry_defaults_and_validation():
    m = make_model('nps_auv2')
    assert m.name == 'nps_auv2'
    assert m.length == pytest.approx(7.3 * 0.3048)
    assert m.rudder_max == 0.4
    with pytest.raises(ValueError, match=r'\bU\b'):
        NpsAuv2(U=0.0)
    with pytest.raises(ValueError, match=r'\blength\b'):
        NpsAuv2(length=-2.0)
    with pytest.raises(ValueError, match=r'\bbow_stern_ratio\b'):
        NpsAuv2(bow_stern_ratio=3.0)


def test_batched_rhs_matches_single():
    m = NpsAuv2()
    rng = np.random.default_rng(2)
    X = rng.normal(scale=0.3, size=(4, m.n_states))
    U = rng.normal(scale=0.2, size=(4, 1))
    np.testing.assert_allclose(m.rhs(X, U), np.array([m.rhs(x, u) for x, u in zip(X, U)]),
                               rtol=1e-14, atol=0)
