"""Ocean current: direction convention, drift of a vessel at rest, Gauss-Markov statistics."""
import numpy as np
import pytest

from ship_sim.current import OceanCurrent, add_current_to_kinematics, apply_current_drift
from ship_sim.integrators import rk4_step
from ship_sim.models.nomoto import Nomoto1, Nomoto2


def test_direction_is_where_the_water_flows_to_clockwise_from_north():
    assert OceanCurrent(0.9, 0.0).velocity_ne() == pytest.approx((0.9, 0.0))
    assert OceanCurrent(0.9, np.pi / 2).velocity_ne() == pytest.approx((0.0, 0.9))
    assert OceanCurrent(0.9, np.pi).velocity_ne() == pytest.approx((-0.9, 0.0))
    vn, ve = OceanCurrent(0.5, np.deg2rad(30.0)).velocity_ne()
    assert (vn, ve) == pytest.approx((0.5 * np.sqrt(3) / 2, 0.25))


def run(model, x, u, h, n, vn, ve):
    f = lambda x, u: add_current_to_kinematics(model, model.rhs(x, u), vn, ve)  # noqa: E731
    for _ in range(n):
        x = rk4_step(f, x, u, h)
    return x


def test_vessel_at_rest_drifts_exactly_with_the_current():
    cur = OceanCurrent(0.7, np.deg2rad(120.0))
    vn, ve = cur.velocity_ne()
    m = Nomoto1('mariner', U=0.0)
    x0 = m.initial_state(north=100.0, east=-50.0, psi=0.3)
    # Rudder working (the hull turns on the spot) does not move a vessel at rest in the water.
    x = run(m, x0, m.inputs(0.2), 0.5, 400, vn, ve)
    assert x[m.IX] == pytest.approx(100.0 + 200.0 * 0.7 * np.cos(np.deg2rad(120.0)), abs=1e-9)
    assert x[m.IY] == pytest.approx(-50.0 + 200.0 * 0.7 * np.sin(np.deg2rad(120.0)), abs=1e-9)
    assert x[m.IPSI] != pytest.approx(0.3)


def test_moving_vessel_track_is_water_track_plus_current():
    # Relative-velocity model: over ground = through water + current * t, for any manoeuvre.
    m = Nomoto2('mariner')
    x0 = m.initial_state(psi=-1.0)
    u = m.inputs(-0.3)
    still = run(m, x0, u, 1.0, 300, 0.0, 0.0)
    moved = run(m, x0, u, 1.0, 300, -0.4, 0.3)
    d = moved - still
    assert d[m.IX] == pytest.approx(-0.4 * 300, abs=1e-9)
    assert d[m.IY] == pytest.approx(0.3 * 300, abs=1e-9)
    others = [i for i in range(m.n_states) if i not in (m.IX, m.IY)]
    np.testing.assert_array_equal(d[others], 0.0)
    # The shortcut (step without current, then drift) gives the same state.
    x = x0
    for _ in range(300):
        x = apply_current_drift(m, rk4_step(m.rhs, x, u, 1.0), -0.4, 0.3, 1.0)
    np.testing.assert_allclose(x, moved, rtol=0, atol=1e-9)


def test_add_current_is_pure_and_broadcasts_over_vessels():
    m = Nomoto1('tanker')
    X = np.stack([m.initial_state(psi=p) for p in (0.0, 1.0, 2.0)])
    xd = m.rhs(X, m.inputs(np.zeros(3)))
    before = xd.copy()
    vn, ve = np.array([0.1, 0.2, 0.3]), np.array([-0.1, 0.0, 0.1])
    out = add_current_to_kinematics(m, xd, vn, ve)
    np.testing.assert_array_equal(xd, before)
    np.testing.assert_allclose(out[:, m.IX] - xd[:, m.IX], vn)
    np.testing.assert_allclose(out[:, m.IY] - xd[:, m.IY], ve)


def test_constant_current_does_not_change():
    cur = OceanCurrent(0.9, 1.0, seed=1)
    assert not cur.varying
    v0 = cur.velocity_ne()
    for _ in range(10):
        cur.advance(5.0)
    assert cur.velocity_ne() == v0


def gm(seed, **kw):
    params = dict(speed=1.0, direction=0.5, speed_time_constant=100.0, speed_noise=2e-4,
                  direction_time_constant=200.0, direction_noise=1e-4, seed=seed)
    params.update(kw)
    cur = OceanCurrent(**params)
    out = []
    for _ in range(200):
        cur.advance(1.0)
        out.append(cur.velocity_ne())
    return np.array(out)


def test_gauss_markov_is_reproducible_by_seed():
    a, b, c = gm(7), gm(7), gm(8)
    np.testing.assert_array_equal(a, b)
    assert np.max(np.abs(a - c)) > 1e-3
    assert np.std(a[:, 0]) > 1e-3  # it does vary


def test_gauss_markov_mean_std_and_correlation():
    # V_dot = -(V - V0)/T + w, intensity q: stationary std sqrt(q T / 2) = 0.1 m/s for
    # q = 2e-4 (m/s)^2/s, T = 100 s. 4000 independent currents; tolerances are 5 standard
    # errors of the estimates (bounds at V0 +- 5 sigma, practically never reached).
    n, T, sigma = 4000, 100.0, 0.1
    cur = OceanCurrent(1.0, 0.0, speed_time_constant=T, speed_noise=2 * sigma ** 2 / T,
                       speed_min=0.5, speed_max=1.5, seed=11, shape=(n,))
    for _ in range(500):          # 5 T: variance at (1 - exp(-10)) of stationary
        cur.advance(1.0)
    s0 = cur.speed.copy()
    for _ in range(10):
        cur.advance(10.0)         # large steps are exact too
    s1 = cur.speed
    assert np.mean(s1) == pytest.approx(1.0, abs=5 * sigma / np.sqrt(n))
    assert np.std(s1) == pytest.approx(sigma, abs=5 * sigma / np.sqrt(2 * n))
    rho = np.corrcoef(s0, s1)[0, 1]   # lag T: exp(-1)
    assert rho == pytest.approx(np.exp(-1), abs=5 * (1 - np.exp(-2)) / np.sqrt(n))
    vn, ve = cur.velocity_ne()
    np.testing.assert_allclose(vn, s1)
    np.testing.assert_allclose(ve, 0.0, atol=1e-15)


def test_gauss_markov_speed_is_bounded_and_direction_has_its_mean():
    # Bounds at +-1 sigma: reached often, never passed; symmetric, so the mean stays V0.
    n = 2000
    cur = OceanCurrent(0.8, 1.2, speed_time_constant=50.0, speed_noise=2 * 0.1 ** 2 / 50.0,
                       speed_min=0.7, speed_max=0.9, direction_time_constant=50.0,
                       direction_noise=2 * 0.2 ** 2 / 50.0, seed=3, shape=(n,))
    lo = hi = 0
    for _ in range(300):
        cur.advance(1.0)
        assert np.all((cur.speed >= 0.7) & (cur.speed <= 0.9))
        lo += np.sum(cur.speed == 0.7)
        hi += np.sum(cur.speed == 0.9)
    assert lo > 1000 and hi > 1000
    assert np.mean(cur.speed) == pytest.approx(0.8, abs=5 * 0.1 / np.sqrt(n))
    assert np.mean(cur.direction) == pytest.approx(1.2, abs=5 * 0.2 / np.sqrt(n))


@pytest.mark.parametrize('kwargs, param', [
    (dict(speed=-0.1), 'speed'),
    (dict(speed=float('inf')), 'speed'),
    (dict(speed=1.0, speed_time_constant=0.0, speed_noise=1e-3), 'speed_time_constant'),
    (dict(speed=1.0, speed_noise=-1.0), 'speed_noise'),
    (dict(speed=1.0, speed_max=0.5), 'speed_max'),
    (dict(speed=1.0, speed_min=2.0), 'speed_min'),
])
def test_invalid_parameters_are_refused_by_name(kwargs, param):
    with pytest.raises(ValueError, match=rf'\b{param}\b'):
        OceanCurrent(**kwargs)


def test_advance_refuses_negative_dt():
    with pytest.raises(ValueError, match=r'\bdt\b'):
        OceanCurrent(1.0).advance(-1.0)
