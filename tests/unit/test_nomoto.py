"""Nomoto models: step response, servo, frequency response, reduction, presets, validation.

Reference values are those of Lee 2004 Table 2.2 (Table 4.1 for the cargo ship's T3), written
here by hand; expected responses are the closed-form Nomoto solutions in the unified rudder
sign (positive delta turns to port: r = -K delta (1 - exp(-t/T)) in steady turning).
"""
import numpy as np
import pytest

from ship_sim.integrators import rk4_step
from ship_sim.models import make_model
from ship_sim.models.nomoto import Nomoto1, Nomoto2

# Lee 2004, Table 2.2: (K 1/s, T1 s, T2 s, T3 s, L m, U m/s), K in Lee's printed sign.
TABLE = {'mariner': (0.185, 118.0, 7.8, 18.5, 161.0, 7.7),
         'tanker': (-0.019, -124.1, 16.4, 46.0, 350.0, 8.1)}


def simulate(model, x, u, h, n):
    xs = [x]
    for _ in range(n):
        x = rk4_step(model.rhs, x, u, h)
        xs.append(x)
    return np.array(xs)


def settled_rudder_state(model, delta):
    """Straight running with the rudder already at delta (servo at rest)."""
    x = model.initial_state()
    x[model.IDELTA] = delta
    return x, model.inputs(delta)


def test_presets_follow_table_2_2():
    for name, (K, T1, T2, T3, L, U) in TABLE.items():
        m1, m2 = Nomoto1(name), Nomoto2(name)
        assert m1.K == K and m1.T == pytest.approx(T1 + T2 - T3)
        assert (m2.K, m2.T1, m2.T2, m2.T3) == (K, T1, T2, T3)
        assert m1.length == L and m1.U == U and m2.initial_state()[m2.IU] == U


def test_nomoto_ab_unified_sign():
    # Mariner: T = 118.0 + 7.8 - 18.5 = 107.3 s, K = 0.185 1/s: a = -1/T, b = -K/T < 0.
    a, b = Nomoto1('mariner').nomoto_ab()
    assert a == pytest.approx(-1 / 107.3) and b == pytest.approx(-0.185 / 107.3)
    # Tanker: T = -124.1 + 16.4 - 46.0 = -153.7 s (course unstable, a > 0), b still < 0.
    a, b = Nomoto2('tanker').nomoto_ab()
    assert a == pytest.approx(1 / 153.7) and b == pytest.approx(-0.019 / 153.7)
    assert b < 0


def test_nomoto1_step_response_matches_closed_form():
    m = Nomoto1('mariner')
    K, T = 0.185, 118.0 + 7.8 - 18.5
    delta = 0.1
    x0, u = settled_rudder_state(m, delta)
    h, n = 0.5, 800
    xs = simulate(m, x0, u, h, n)
    t = h * np.arange(n + 1)
    r_exact = -K * delta * (1 - np.exp(-t / T))
    psi_exact = -K * delta * (t - T * (1 - np.exp(-t / T)))
    np.testing.assert_allclose(xs[:, m.IR], r_exact, rtol=0, atol=1e-9)
    np.testing.assert_allclose(xs[:, m.IPSI], psi_exact, rtol=0, atol=1e-7)
    # Steady turn to port: radius U / |r| = 7.7 / (0.185 * 0.1) = 416.2 m about a centre on
    # the port side (north, east) + R (sin psi, -cos psi); checked over the last 200 s of
    # 1000 s (transient exp(-800/107.3) < 1e-3), an arc of about 0.74 rad.
    xs = simulate(m, xs[-1], u, h, 1200)
    late = xs[-400:]
    R = 7.7 / (0.185 * delta)
    centre = late[-1, [m.IX, m.IY]] + R * np.array([np.sin(late[-1, m.IPSI]),
                                                    -np.cos(late[-1, m.IPSI])])
    dist = np.hypot(late[:, m.IX] - centre[0], late[:, m.IY] - centre[1])
    np.testing.assert_allclose(dist, R, rtol=1e-3)


def test_servo_lag_rate_and_angle_limits():
    m = Nomoto1('mariner')  # servo 1 s, 5 deg/s, 40 deg
    x = m.initial_state()
    # Small step: linear first-order lag delta = dc (1 - exp(-t / 1 s)).
    xs = simulate(m, x, m.inputs(0.01), 0.05, 100)
    t = 0.05 * np.arange(101)
    np.testing.assert_allclose(xs[:, m.IDELTA], 0.01 * (1 - np.exp(-t)), atol=1e-9)
    # Large step: the rate limit holds, then the command saturates at rudder_max.
    xd = m.rhs(x, m.inputs(1.5))
    assert xd[m.IDELTA] == pytest.approx(np.deg2rad(5.0))
    xs = simulate(m, x, m.inputs(1.5), 0.1, 400)
    assert np.max(np.diff(xs[:, m.IDELTA])) <= np.deg2rad(5.0) * 0.1 + 1e-12
    assert xs[-1, m.IDELTA] == pytest.approx(np.deg2rad(40.0), abs=1e-9)
    assert m.rudder_angle(xs[-1]) == pytest.approx(np.deg2rad(40.0), abs=1e-9)


def jacobian(f, x, u, eps=1e-6):
    """Central-difference Jacobians (df/dx, df/du) of f(x, u)."""
    n, m = x.size, u.size
    A, B = np.zeros((n, n)), np.zeros((n, m))
    for i in range(n):
        d = np.zeros(n)
        d[i] = eps
        A[:, i] = (f(x + d, u) - f(x - d, u)) / (2 * eps)
    for j in range(m):
        d = np.zeros(m)
        d[j] = eps
        B[:, j] = (f(x, u + d) - f(x, u - d)) / (2 * eps)
    return A, B


def heading_frequency_response(model, w):
    """psi/delta_c (delta_c -> heading) of the linearised model at straight running."""
    x0 = model.initial_state()
    A, B = jacobian(model.rhs, x0, model.inputs(0.0))
    # Yaw subsystem: drop u, v, north, east (they do not feed back into r, psi, delta).
    keep = [i for i in range(model.n_states) if i not in (model.IU, model.IV, model.IX, model.IY)]
    A, B = A[np.ix_(keep, keep)], B[keep]
    c = np.zeros(len(keep))
    c[keep.index(model.IPSI)] = 1.0
    return np.array([c @ np.linalg.solve(1j * wk * np.eye(len(keep)) - A, B[:, 0]) for wk in w])


@pytest.mark.parametrize('name', ['mariner', 'tanker'])
def test_nomoto2_transfer_function(name):
    K, T1, T2, T3, _, _ = TABLE[name]
    m = Nomoto2(name)
    Ts = m.rudder_time_constant
    w = np.array([1e-3, 1e-2, 0.03, 0.1, 0.5])
    s = 1j * w
    servo = 1 / (1 + Ts * s)
    expected = -K * (1 + T3 * s) / (s * (1 + T1 * s) * (1 + T2 * s)) * servo
    np.testing.assert_allclose(heading_frequency_response(m, w), expected, rtol=1e-6)


def test_nomoto1_transfer_function():
    K, T1, T2, T3, _, _ = TABLE['mariner']
    T = T1 + T2 - T3
    m = Nomoto1('mariner')
    w = np.array([1e-3, 1e-2, 0.1])
    s = 1j * w
    expected = -K / (s * (1 + T * s)) / (1 + m.rudder_time_constant * s)
    np.testing.assert_allclose(heading_frequency_response(m, w), expected, rtol=1e-6)


@pytest.mark.parametrize('name', ['mariner', 'tanker'])
def test_nomoto2_reduces_to_nomoto1_at_low_frequency(name):
    # G2/G1 = 1 + O(s^2): same static gain and first moment (T = T1 + T2 - T3).
    w = np.array([1e-4, 1e-5])
    g2 = heading_frequency_response(Nomoto2(name), w)
    g1 = heading_frequency_response(Nomoto1(name), w)
    err = np.abs(g2 / g1 - 1)
    assert err[0] < 1e-3
    assert err[0] / err[1] == pytest.approx(100, rel=0.05)  # error scales as w^2


def test_nomoto2_step_heading_converges_to_nomoto1():
    # Same asymptote psi = -K (int delta dt - T delta): the heading difference dies out with
    # the transient. Both start at zero rudder and get the same servo response delta(t) (a
    # rudder *already* at delta would skip the T3 delta_dot impulse of the second order).
    delta = 0.05
    m1, m2 = Nomoto1('mariner'), Nomoto2('mariner')
    h, n = 1.0, 1500
    p1 = simulate(m1, m1.initial_state(), m1.inputs(delta), h, n)[:, m1.IPSI]
    p2 = simulate(m2, m2.initial_state(), m2.inputs(delta), h, n)[:, m2.IPSI]
    assert abs(p1[-1]) > 10.0
    assert abs(p2[-1] - p1[-1]) < 1e-4 * abs(p1[-1])
    assert abs(p2[100] - p1[100]) > 1e-2 * abs(p1[100])  # but they differ during the transient


def test_speed_scaling_keeps_turning_radius():
    # K ~ U and T ~ 1/U (Fossen's nondimensional K', T'): steady radius U / (K delta) is kept.
    base = Nomoto1('mariner')
    slow = Nomoto1('mariner', U=3.85, speed_scaling=True)
    assert slow.K == pytest.approx(0.185 * 3.85 / 7.7)
    assert slow.T == pytest.approx(107.3 * 7.7 / 3.85)
    assert slow.U / slow.K == pytest.approx(base.U / base.K)


def test_batched_rhs_matches_single():
    m = Nomoto2('tanker')
    rng = np.random.default_rng(1)
    X = rng.normal(size=(5, m.n_states))
    U = rng.normal(scale=0.2, size=(5, 1))
    np.testing.assert_array_equal(m.rhs(X, U), np.array([m.rhs(x, u) for x, u in zip(X, U)]))


def test_registry_and_explicit_gains():
    m = make_model('nomoto1', preset=None, K=0.5, T=20.0, U=3.0, length=30.0)
    assert (m.name, m.K, m.T, m.U, m.length) == ('nomoto1', 0.5, 20.0, 3.0, 30.0)
    assert make_model('nomoto2', preset='tanker').name == 'nomoto2'


@pytest.mark.parametrize('cls, kwargs, param', [
    (Nomoto1, dict(preset='ferry'), 'preset'),
    (Nomoto1, dict(U=-1.0), 'U'),
    (Nomoto1, dict(U=float('nan')), 'U'),
    (Nomoto1, dict(length=0.0), 'length'),
    (Nomoto1, dict(rudder_max=0.0), 'rudder_max'),
    (Nomoto1, dict(rudder_rate_max=-0.1), 'rudder_rate_max'),
    (Nomoto1, dict(rudder_time_constant=0.0), 'rudder_time_constant'),
    (Nomoto1, dict(preset=None, K=0.2), 'T'),
    (Nomoto1, dict(K=0.0), 'K'),
    (Nomoto2, dict(T2=-3.0), 'T2'),
    (Nomoto2, dict(preset=None, K=0.1, T1=10.0, T2=2.0), 'T3'),
])
def test_invalid_parameters_are_refused_by_name(cls, kwargs, param):
    with pytest.raises(ValueError, match=rf'\b{param}\b'):
        cls(**kwargs)


def test_error_message_gives_value_and_range():
    with pytest.raises(ValueError, match=r'U = -1\.0 .*\[0\.0, 30\.0\]'):
        Nomoto1(U=-1.0)
