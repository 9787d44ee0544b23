"""The float fast paths agree with the numpy paths they shortcut (same arithmetic, so the same
results to rounding): Route.project on a few legs, HeadingController.update for one vessel,
VesselSimulator.nav_state, and odometry_to_ned on serialized (raw) Odometry.

Each fast path is compared against the general path on many random inputs; a wrong branch,
index or sign in a fast path shows up as a mismatch, not as a small number.
"""
import math

import numpy as np
import pytest

import ship_guidance.path as path_mod
from ship_autopilot.gains import build_autopilot
from ship_guidance.path import Arc, Line, Route
from ship_sim.current import OceanCurrent
from ship_sim.simulator import BatchSimulator, VesselSimulator


def _mixed_route():
    """Lines and arcs of both turning directions, joined tangentially and at corners."""
    a1 = Arc((1000.0, 0.0), (1500.0, 500.0), (1000.0, 500.0), clockwise=True)
    a2 = Arc((1500.0, 1500.0), (2000.0, 2000.0), (2000.0, 1500.0), clockwise=False)
    return Route([Line((0.0, 0.0), (1000.0, 0.0)), a1, Line((1500.0, 500.0), (1500.0, 1500.0)),
                  a2, Line((2000.0, 2000.0), (2000.0, 3000.0)),
                  Line((2000.0, 3000.0), (1200.0, 3400.0))])


@pytest.mark.parametrize('route', [_mixed_route(),
                                   Route.polyline([(0.0, 0.0), (100.0, 5.0), (180.0, 60.0),
                                                   (200.0, 200.0), (150.0, 320.0)])])
def test_route_projection_float_path_matches_numpy_path(route, monkeypatch):
    rng = np.random.default_rng(7)
    lo_n, lo_e = np.min(route._p0, axis=0) - 300.0
    hi_n, hi_e = np.max(route._p0, axis=0) + 300.0
    cases = []
    for _ in range(400):
        n, e = rng.uniform(lo_n, hi_n), rng.uniform(lo_e, hi_e)
        hint = rng.uniform(0.0, route.length)
        w = tuple(rng.uniform(1.0, 0.6 * route.length, 2))
        bounds = tuple(sorted(rng.uniform(0.0, route.length, 2)))
        cases += [((n, e), {}), ((n, e), {'s_hint': hint, 'window': w}),
                  ((n, e), {'s_hint': hint, 'window': w[0], 'bounds': bounds})]
    fast = [route.project(*args, **kw) for args, kw in cases]
    monkeypatch.setattr(path_mod, 'FEW_LEGS', 0)  # every search through the numpy path
    slow = [route.project(*args, **kw) for args, kw in cases]
    for (args, kw), f, s in zip(cases, fast, slow):
        assert f.leg_index == s.leg_index, (args, kw)
        for name in ('s', 'north', 'east', 'path_angle', 'cross_track', 'distance'):
            assert getattr(f, name) == pytest.approx(getattr(s, name), rel=1e-12, abs=1e-9), \
                (name, args, kw)
        assert (f.curvature, f.at_start, f.at_end) == (s.curvature, s.at_start, s.at_end)


def test_route_along_float_path_matches_the_legs():
    route = _mixed_route()
    rng = np.random.default_rng(3)
    for _ in range(200):
        i = int(rng.integers(len(route.legs)))
        n, e = rng.uniform(-500.0, 3500.0, 2)
        assert route.along(i, n, e) == pytest.approx(float(route.legs[i].along(n, e)),
                                                     rel=1e-12, abs=1e-9)


@pytest.mark.parametrize('shape', ['hard', 'tanh'])
def test_pd_float_path_matches_the_array_path(shape):
    gains = {'k1': 1.3, 'k2': 40.0}
    scalar = build_autopilot('pd', gains, math.radians(35.0), math.radians(5.0), shape)
    batch = build_autopilot('pd', gains, math.radians(35.0), math.radians(5.0), shape)
    batch.reset(np.zeros(1))  # a batch of one vessel always takes the array path
    rng = np.random.default_rng(11)
    for k in range(500):
        psi, psi_c = rng.uniform(-math.pi, math.pi, 2)
        r = rng.uniform(-0.02, 0.02)
        dt = 0.1 if k % 50 else 0.0  # dt = 0 is refused: both hold and count
        a = scalar.update(psi, r, psi_c, dt)
        b = batch.update(np.array([psi]), np.array([r]), np.array([psi_c]), np.array([dt]))
        assert isinstance(a, float)
        assert a == pytest.approx(float(b[0]), rel=1e-12, abs=1e-15)
    assert scalar.n_rejected == batch.n_rejected == 10


def test_pd_float_path_refuses_nan_like_the_array_path():
    ctrl = build_autopilot('pd', {'k1': 1.0, 'k2': 10.0}, 0.6, 0.1)
    first = ctrl.update(0.2, 0.0, 0.0, 0.1)
    assert ctrl.update(math.nan, 0.0, 0.0, 0.1) == first   # held
    assert ctrl.n_rejected == 1 and not ctrl.last_ok
    assert ctrl.update(0.2, 0.0, 0.0, 0.1) != first         # back on the float path, moving
    assert ctrl.last_ok


def test_vessel_nav_state_matches_the_batch_simulator():
    current = dict(speed=0.4, direction=math.radians(70.0))
    one = VesselSimulator('mariner', north=10.0, east=-5.0, psi=3.0,
                          current=OceanCurrent(**current))
    many = BatchSimulator('mariner', n=1, north=10.0, east=-5.0, psi=3.0,
                          current=OceanCurrent(**current))
    for k in range(300):
        delta = 0.3 * math.sin(0.01 * k)
        one.step(delta)
        many.step(delta)
        a = one.nav_state()
        b = many.nav_state()
        assert all(isinstance(v, float) for v in a)
        assert a == pytest.approx(tuple(float(np.asarray(v).reshape(-1)[0]) for v in b),
                                  rel=1e-12, abs=1e-12)


def test_odometry_from_raw_bytes_equals_from_the_message():
    from rclpy.serialization import serialize_message
    from ship_sim.ros.conversions import _odometry_cdr_fields, make_odometry, odometry_to_ned
    rng = np.random.default_rng(5)
    # Frame ids of every length modulo 8 move the doubles to every alignment case.
    for frame, child in [('map', 'vessel_0/base_link'), ('', ''), ('m', 'ab'), ('abcd', 'xyz'),
                         ('a' * 7, 'b' * 9)]:
        for _ in range(50):
            t = float(rng.uniform(0.0, 1e5))
            n, e, psi, u, v, r = rng.uniform(-1e4, 1e4, 6)
            msg = make_odometry(t, n, e, psi, u, v, r, child, frame_id=frame)
            msg.pose.covariance[0] = 3.0   # non-zero covariances must not shift the twist
            msg.twist.covariance[35] = -1.0
            raw = serialize_message(msg)
            assert odometry_to_ned(raw) == odometry_to_ned(msg)
    # Anything but XCDR1 little endian, or a short buffer, is left to rclpy's deserialisation.
    other = bytearray(raw)
    other[1] = 0x07  # CDR2 little endian: 8-byte values aligned to 4, another layout
    assert _odometry_cdr_fields(bytes(other)) is None
    assert _odometry_cdr_fields(raw[:-8]) is None
    assert _odometry_cdr_fields(raw) is not None
