"""Platoon follower guidance (ship_guidance.follower): the law of Angelopoulos 2011 eq. 31 against
hand-computed geometry, the stale-odometry fallback as a state machine in sim time, the sign of
the spacing law, and the string-gain bound against the 6x6 platoon matrix of Angelopoulos 2011 eq. 37."""
import math

import numpy as np
import pytest

from ship_guidance.follower import (FALLBACK, FOLLOW, FollowerGuidance, PredecessorTrack,
                                    SpacingController, aim_point, follower_gain,
                                    follower_heading_straight, no_amplification_spacing,
                                    speed_to_shaft)
from ship_guidance.path import Arc, Line, Route

EAST_ROUTE = Route([Line((0.0, 0.0), (0.0, 10000.0))])   # due east: alpha = pi/2


def follower(route=EAST_ROUTE, **kw):
    args = dict(spacing=400.0, min_lookahead=200.0, fallback_lookahead=500.0,
                predecessor_timeout=5.0)
    args.update(kw)
    return FollowerGuidance(route, **args)


# ---------------------------------------------------------------- the law

def test_straight_law_is_a_3_4_5_triangle():
    # e_f - e_p = 300 m across, d = 400 m along: the aim is 36.87 deg off the path, to port.
    psi = follower_heading_straight(0.0, 250.0, -50.0, 400.0)
    assert psi == pytest.approx(-math.radians(36.86989764584402), abs=1e-12)
    # follower to port of its predecessor (e_f < e_p): steer to starboard
    assert follower_heading_straight(1.0, -50.0, 250.0, 400.0) == pytest.approx(
        1.0 + math.radians(36.86989764584402), abs=1e-12)


def test_follower_aims_at_the_predecessor_on_a_straight_route():
    f = follower()
    # Route due east, starboard is south: the follower 30 m south (e_f = +30) at east 100,
    # its predecessor 10 m north (e_p = -10) at east 500: gap 400 m.
    f.add_predecessor(7.0, 10.0, 500.0, math.pi / 2, 8.0, 0.0)
    out = f.update(7.0, -30.0, 100.0, math.pi / 2)
    assert out.mode == FOLLOW and out.reason == ''
    assert out.gap == pytest.approx(400.0, abs=1e-9)
    assert out.route.cross_track == pytest.approx(30.0, abs=1e-9)
    assert out.pred_cross_track == pytest.approx(-10.0, abs=1e-9)
    assert out.lookahead == pytest.approx(400.0, abs=1e-9)
    # bearing from (-30, 100) to (10, 500): 400 m east, 40 m north
    assert out.heading_cmd == pytest.approx(math.atan2(400.0, 40.0), abs=1e-12)
    # = alpha - atan((e_f - e_p) / d), Angelopoulos 2011 eq. 31
    assert out.heading_cmd == pytest.approx(math.pi / 2 - math.atan(40.0 / 400.0), abs=1e-12)


def test_follower_aims_at_the_predecessor_on_an_arc():
    # Clockwise (starboard) arc of radius 1000 m about (0, 1000), from (0, 0) heading north.
    route = Route([Arc((0.0, 0.0), (1000.0, 1000.0), (0.0, 1000.0), clockwise=True)])
    f = follower(route, spacing=500.0)

    def at(s, offset):
        n, e, a = route.point_at(s)
        return n - offset * math.sin(a), e + offset * math.cos(a)

    pn, pe = at(600.0, -8.0)
    fn, fe = at(100.0, 5.0)
    f.add_predecessor(0.0, pn, pe, 0.0, 7.0, 0.0)
    out = f.update(0.0, fn, fe)
    assert out.gap == pytest.approx(500.0, abs=1e-6)
    assert out.route.cross_track == pytest.approx(5.0, abs=1e-9)
    assert out.pred_cross_track == pytest.approx(-8.0, abs=1e-9)
    assert out.heading_cmd == pytest.approx(math.atan2(pe - fe, pn - fn), abs=1e-9)


def test_lookahead_is_clipped_when_close_overtaken_or_far():
    alpha = math.pi / 2
    for pred_east, expect_d in ((150.0, 200.0),     # 50 m ahead: d_min
                                (-100.0, 200.0),    # overtaken (gap -200 m): d_min
                                (5100.0, 3000.0)):  # 5 km ahead: d_max
        f = follower(max_lookahead=3000.0)
        f.add_predecessor(0.0, -20.0, pred_east, alpha, 8.0, 0.0)
        out = f.update(0.0, 0.0, 100.0, alpha)
        assert out.lookahead == pytest.approx(expect_d)
        # e_f = 0, e_p = +20 (20 m south = starboard): aim 20 m to starboard at d ahead
        assert out.heading_cmd == pytest.approx(alpha + math.atan(20.0 / expect_d), abs=1e-12)


def test_atan_form_saturates_at_a_right_angle_to_the_path():
    alpha = 0.3
    big = follower_heading_straight(alpha, 1e9, 0.0, 100.0)
    assert big == pytest.approx(alpha - math.pi / 2, abs=1e-6)
    assert follower_heading_straight(alpha, -1e9, 0.0, 100.0) == pytest.approx(
        alpha + math.pi / 2, abs=1e-6)
    offsets = np.linspace(-1e6, 1e6, 2001)
    psi = follower_heading_straight(alpha, offsets, 0.0, 100.0)
    assert np.all(np.abs(psi - alpha) < math.pi / 2)
    assert np.all(np.diff(psi) < 0.0)   # further to starboard -> steer further to port


def test_aim_point_continues_past_the_route_end_and_before_its_start():
    route = Route([Line((0.0, 0.0), (1000.0, 0.0))])
    assert aim_point(route, 900.0, 300.0, 5.0) == pytest.approx((1200.0, 5.0, 0.0))
    assert aim_point(route, -400.0, 100.0, -5.0) == pytest.approx((-300.0, -5.0, 0.0))


def test_straight_function_is_what_the_follower_does():
    """The vectorised law (used by the time-domain script) equals FollowerGuidance."""
    route = Route([Line((0.0, 0.0), (10000.0, 0.0))])
    rng = np.random.default_rng(1)
    for _ in range(20):
        f = follower(route, spacing=300.0, min_lookahead=50.0)
        sf, ef, ep = rng.uniform(100, 2000), rng.uniform(-80, 80), rng.uniform(-80, 80)
        gap = rng.uniform(60.0, 900.0)
        f.add_predecessor(0.0, sf + gap, ep, 0.0, 7.0, 0.0)
        out = f.update(0.0, sf, ef)
        assert out.heading_cmd == pytest.approx(
            float(follower_heading_straight(0.0, ef, ep, gap)), abs=1e-12)


# ---------------------------------------------------------------- stale fallback

def feed(f, t0, t1, dt=0.1, speed=8.0, east0=1000.0):
    """Predecessor on the route (due east) at `speed`, samples from t0 to t1 inclusive."""
    for t in np.arange(t0, t1 + 1e-9, dt):
        f.add_predecessor(t, 0.0, east0 + speed * t, math.pi / 2, speed, 0.0)


def test_fallback_when_stale_and_recovery():
    f = follower(predecessor_timeout=5.0)
    # No predecessor yet: route LOS with the fallback look-ahead, no speed command.
    out = f.update(0.0, -50.0, 600.0, math.pi / 2)   # 50 m to starboard
    assert out.mode == FALLBACK and out.mode_changed and 'no predecessor' in out.reason
    assert out.heading_cmd == pytest.approx(math.pi / 2 - math.atan(50.0 / 500.0))
    assert math.isnan(out.gap) and math.isnan(out.speed_cmd)
    feed(f, 0.0, 10.0)
    modes = []
    for t in np.arange(0.1, 30.0, 0.1):
        if round(t, 1) == 20.0:
            feed(f, 20.0, 30.0)          # the predecessor publishes again
        out = f.update(t, 0.0, 600.0 + 8.0 * t, math.pi / 2)
        modes.append((round(t, 1), out.mode, out.mode_changed))
        if round(t, 1) == 12.0:
            speed_while_following = out.speed_cmd
        if round(t, 1) == 19.0:
            # last sample t = 10: 9 s old -> fallback, LOS on the route, speed held
            assert out.mode == FALLBACK and '9.0 s old' in out.reason
            assert out.pred_age == pytest.approx(9.0)
            assert out.heading_cmd == pytest.approx(out.route.heading_cmd)
            assert out.speed_cmd == pytest.approx(speed_while_following)
    changes = [(t, m) for t, m, c in modes if c]
    # follow from the first update with samples; fallback once the newest sample is more than
    # 5 s old (t > 15); follow again when samples come back at t = 20.
    assert changes[0] == (0.1, FOLLOW)
    assert changes[1][1] == FALLBACK and 15.0 < changes[1][0] <= 15.1 + 1e-9
    assert changes[2] == (20.0, FOLLOW)
    assert len(changes) == 3


def test_predecessor_ahead_in_time_is_fresh_and_interpolated():
    track = PredecessorTrack()
    track.add(0.0, 0.0, 0.0, 0.0, 10.0, 0.0)    # heading north at 10 m/s
    track.add(1.0, 10.0, 0.0, 0.0, 10.0, 0.0)
    track.add(2.0, 25.0, 0.0, 0.0, 20.0, 0.0)
    s = track.at(1.5)
    assert (s.north, s.v_north, s.age) == pytest.approx((17.5, 15.0, 0.0))
    s = track.at(2.5)          # beyond the newest sample: extrapolated, 0.5 s old
    assert (s.north, s.age) == pytest.approx((35.0, 0.5))
    # Once a sample at or after the query time is held, later samples change nothing: the
    # answer does not depend on how far ahead the predecessor's stream has got.
    ahead = PredecessorTrack()
    for t, n, u in ((0.0, 0.0, 10.0), (1.0, 10.0, 10.0), (2.0, 25.0, 20.0), (3.0, 50.0, 30.0),
                    (4.0, 90.0, 40.0)):
        ahead.add(t, n, 0.0, 0.0, u, 0.0)
    assert ahead.at(1.5) == three_sample_track_at(1.5)


def three_sample_track_at(t):
    tr = PredecessorTrack()
    for ts, n, u in ((0.0, 0.0, 10.0), (1.0, 10.0, 10.0), (2.0, 25.0, 20.0)):
        tr.add(ts, n, 0.0, 0.0, u, 0.0)
    return tr.at(t)


def test_track_restart_and_bad_samples():
    track = PredecessorTrack()
    assert track.at(0.0) is None
    assert track.add(5.0, 0.0, 0.0, 0.0, 1.0, 0.0) is False
    assert track.add(1.0, 3.0, 0.0, 0.0, 1.0, 0.0) is True      # time went back: restarted
    assert len(track) == 1 and track.latest_t == 1.0
    with pytest.raises(ValueError):
        track.add(2.0, math.nan, 0.0, 0.0, 1.0, 0.0)
    assert len(track) == 1


def test_track_counts_samples_missing_from_its_stream():
    """A lockstep stream is stamped k * dt (in floating point); a gap of g steps is g - 1
    samples the transport lost, whatever the rounding of the stamps."""
    dt = 0.1
    track = PredecessorTrack()
    for k in list(range(0, 50)) + list(range(53, 60)) + [70]:
        track.add(k * dt, 0.0, 0.0, 0.0, 1.0, 0.0)
    assert track.step == pytest.approx(dt) and track.n_missing == 3 + 10   # 50-52, 60-69
    track.add(0.0, 0.0, 0.0, 0.0, 1.0, 0.0)           # a restart is not a gap
    track.add(dt, 0.0, 0.0, 0.0, 1.0, 0.0)
    assert track.n_missing == 13


def test_own_time_going_back_resets_the_follower():
    f = follower()
    feed(f, 0.0, 5.0)
    f.update(4.0, 0.0, 100.0)
    out = f.update(1.0, 0.0, 100.0)     # own simulator restarted
    assert out.mode_changed and out.mode == FOLLOW


def test_bad_own_input_is_refused_without_state_change():
    f = follower()
    feed(f, 0.0, 5.0)
    f.update(1.0, 0.0, 100.0)
    with pytest.raises(ValueError):
        f.update(1.1, math.nan, 100.0)
    assert f.update(1.2, 0.0, 101.0).mode_changed is False


# ---------------------------------------------------------------- spacing

def test_spacing_sign_too_close_slows_down_too_far_speeds_up():
    for gap, sign in ((300.0, -1), (500.0, +1), (400.0, 0)):
        ctl = SpacingController(400.0, kp=0.005, ki=0.0, max_correction=1.0)
        speed, err = ctl.update(gap, 8.0, 0.1)
        assert err == pytest.approx(gap - 400.0)
        assert np.sign(round(speed - 8.0, 12)) == sign
    # through the follower: predecessor 300 m ahead at 8 m/s, set spacing 400 m
    f = follower()
    f.add_predecessor(0.0, 0.0, 400.0, math.pi / 2, 8.0, 0.0)
    out = f.update(0.0, 0.0, 100.0, math.pi / 2)
    assert out.gap_error == pytest.approx(-100.0) and out.speed_cmd < 8.0


def test_spacing_saturates_and_does_not_wind_up():
    ctl = SpacingController(400.0, kp=0.005, ki=1e-4, max_correction=1.0)
    for _ in range(10000):               # 1000 s at 1 km too far: saturated all the time
        speed, _ = ctl.update(1400.0, 8.0, 0.1)
    assert speed == pytest.approx(9.0)
    assert ctl.integral == 0.0           # never integrated while saturated
    speed, _ = ctl.update(400.0, 8.0, 0.1)
    assert speed == pytest.approx(8.0)   # back at the set gap: no wound-up correction
    assert SpacingController(400.0).update(0.0, 0.5, 0.1)[0] >= 0.0   # never astern


def test_speed_to_shaft():
    assert speed_to_shaft(8.217233 / 2, 8.217233, 80.0) == pytest.approx(40.0)
    assert speed_to_shaft(20.0, 8.0, 80.0, 1.0, 80.0) == 80.0
    assert speed_to_shaft(0.0, 8.0, 80.0, 1.0, 80.0) == 1.0


# ---------------------------------------------------------------- stability checks

MARINER = dict(zeta=0.8, omega_n=0.04795563, speed=7.7175)   # ship_autopilot gains entry


def test_lookahead_below_the_limit_is_refused():
    limit = 7.7175 / (2 * 0.8 * 0.04795563)     # 100.58 m
    with pytest.raises(ValueError, match='min_lookahead'):
        follower(min_lookahead=0.99 * limit, **MARINER)
    with pytest.raises(ValueError, match='fallback_lookahead'):
        follower(fallback_lookahead=limit, **MARINER)     # at the limit: marginal, refused
    f = follower(min_lookahead=0.5 * limit, allow_unstable=True, **MARINER)
    assert f.critical_lookahead == pytest.approx(limit)
    ok = follower(min_lookahead=1.01 * limit, **MARINER)
    assert ok.critical_lookahead == pytest.approx(limit)
    with pytest.raises(ValueError, match='together'):
        follower(zeta=0.8)


def test_spacing_warnings():
    amp = 4 * 0.8 * 7.7175 / 0.04795563          # 514.9 m
    assert any('grow from vessel to vessel' in w
               for w in follower(spacing=0.9 * amp, **MARINER).warnings)
    assert follower(spacing=1.1 * amp, **MARINER).warnings == []
    assert any('aims beyond' in w for w in follower(spacing=150.0).warnings)


def platoon_gain(zeta, omega_n, d, speed, nu):
    """|y_1 / y_0| at frequencies nu from the follower block of string_stability's 6x6 matrix
    (Angelopoulos 2011 eq. 37): the leader's y enters the follower's r equation as the input."""
    from ship_guidance.string_stability import string_matrix
    a = string_matrix([zeta, zeta], [omega_n, omega_n], [d, d], speed)
    a22, b = a[3:, 3:], a[3:, 2]
    return np.array([abs(np.linalg.solve(1j * w * np.eye(3) - a22, b)[2]) for w in nu])


@pytest.mark.parametrize('zeta', [0.5, 0.8, 1.2])
def test_no_amplification_spacing_is_where_the_gain_peak_reaches_one(zeta):
    w, u = 0.05, 8.0
    d0 = no_amplification_spacing(zeta, w, u)
    nu = np.linspace(1e-4, 3.0, 6000) * w
    above = platoon_gain(zeta, w, 1.01 * d0, u, nu)
    below = platoon_gain(zeta, w, 0.97 * d0, u, nu)
    assert above.max() <= 1.0 + 1e-9
    assert below.max() > 1.0 + 1e-6
    # the closed form of the transfer function agrees with the matrix
    assert follower_gain(zeta, w, 0.97 * d0, u, nu) == pytest.approx(below, rel=1e-9)


def test_gain_near_the_routh_limit_is_large():
    """At 1.1 d* (zeta 0.8) one follower amplifies its predecessor's oscillation ~19 times."""
    zeta, w, u = 0.8, 0.05, 8.0
    d = 1.1 * u / (2 * zeta * w)
    peak = platoon_gain(zeta, w, d, u, np.linspace(0.8, 1.2, 4001) * w).max()
    assert peak > 10.0


# ---------------------------------------------------------------- extensions: integral, aim,
# turn-rate lead, past the route's end

def run_in_current(f, pred_offset, current_south, speed=8.0, duration=2000.0, dt=1.0,
                   heading_lag=10.0, route_angle=math.pi / 2):
    """Follower f on EAST_ROUTE, kinematic: heading follows the command with a first-order lag
    (s), velocity = speed along the heading + a current setting south (to starboard of the
    route) at current_south (m/s). Predecessor on a parallel line pred_offset m to starboard
    (south), moving east at the follower's steady along-path speed. -> (own e, output)."""
    along = math.sqrt(speed ** 2 - current_south ** 2)
    north, east, psi = -60.0, 0.0, route_angle
    for k in range(int(duration / dt)):
        t = k * dt
        f.add_predecessor(t, -pred_offset, 400.0 + along * t, route_angle, along, 0.0)
        out = f.update(t, north, east, psi)
        psi += dt * float(wrap(out.heading_cmd - psi)) / heading_lag
        north += dt * (speed * math.cos(psi) - current_south)
        east += dt * speed * math.sin(psi)
    return out.route.cross_track, out


def wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def crab_offset(d, current, speed):
    """LOS steady offset d V / sqrt(U^2 - V^2) (m) in a cross current V at speed U."""
    return d * current / math.sqrt(speed ** 2 - current ** 2)


@pytest.mark.parametrize('pred_offset', [0.0, 20.0])
def test_document_law_keeps_the_current_offset_on_top_of_the_predecessors(pred_offset):
    """Angelopoulos 2011 eq. 31 has no integral: in a steady cross current V the follower settles
    d V / sqrt(U^2 - V^2) downstream of its predecessor, so offsets add up down the string."""
    d, v = 400.0, 0.5
    f = follower(min_lookahead=d, max_lookahead=d)
    e, out = run_in_current(f, pred_offset, v)
    assert out.mode == FOLLOW and out.lookahead == d
    assert e == pytest.approx(pred_offset + crab_offset(d, v, 8.0), abs=0.05)   # 25.05 m more


@pytest.mark.parametrize('aim', ['predecessor', 'path'])
@pytest.mark.parametrize('pred_offset', [0.0, 20.0])
def test_integral_action_drives_the_own_cross_track_to_zero(aim, pred_offset):
    d, v, u, sigma = 400.0, 0.5, 8.0, 2.0   # sigma = U / 4: critically damped
    f = follower(min_lookahead=d, max_lookahead=d, aim=aim, integral_gain=sigma)
    e, out = run_in_current(f, pred_offset, v, speed=u)
    assert abs(e) < 0.05
    # the integral holds the crab angle asin(V / U): sigma e_int - (e_p if aiming at the
    # predecessor) = d tan(asin(V / U)) = d V / sqrt(U^2 - V^2)
    held = sigma * out.integral - (pred_offset if aim == 'predecessor' else 0.0)
    assert held == pytest.approx(crab_offset(d, v, u), abs=0.05)


def test_path_aim_without_integral_ignores_the_predecessors_offset():
    """aim 'path' is LOS toward the route with d = the gap: the offset is the vessel's own."""
    d, v = 400.0, 0.5
    e, _ = run_in_current(follower(min_lookahead=d, max_lookahead=d, aim='path'), 35.0, v)
    assert e == pytest.approx(crab_offset(d, v, 8.0), abs=0.05)


def test_path_aim_is_ilos_with_the_gap_as_look_ahead():
    f = follower(aim='path', integral_gain=1.5)
    f.integral = 4.0                                # e_int (s): sigma e_int = 6 m
    f.add_predecessor(0.0, -50.0, 600.0, math.pi / 2, 8.0, 0.0)   # e_p = 50: ignored
    out = f.update(0.0, -30.0, 100.0, math.pi / 2)                # e_f = 30, gap 500
    assert out.heading_cmd == pytest.approx(math.pi / 2 - math.atan(36.0 / 500.0), abs=1e-12)
    # predecessor aim with the same integral: alpha - atan((e_f - e_p + sigma e_int) / d)
    g = follower(aim='predecessor', integral_gain=1.5)
    g.integral = 4.0
    g.add_predecessor(0.0, -50.0, 600.0, math.pi / 2, 8.0, 0.0)
    out = g.update(0.0, -30.0, 100.0, math.pi / 2)
    assert out.heading_cmd == pytest.approx(math.pi / 2 - math.atan(-14.0 / 500.0), abs=1e-12)


def test_bad_extension_options_are_refused():
    with pytest.raises(ValueError, match='aim'):
        follower(aim='leader')
    with pytest.raises(ValueError, match='integral_gain'):
        follower(integral_gain=-1.0)
    with pytest.raises(ValueError, match='curvature_lead'):
        follower(curvature_lead=True)
    # the integral raises the stability limit to (U + 4 zeta^2 sigma) / (2 zeta omega_n)
    ilos_limit = (7.7175 + 4 * 0.8 ** 2 * 2.0) / (2 * 0.8 * 0.04795563)   # 167.3 m
    with pytest.raises(ValueError, match='min_lookahead'):
        follower(min_lookahead=0.99 * ilos_limit, integral_gain=2.0, **MARINER)
    follower(min_lookahead=1.01 * ilos_limit, integral_gain=2.0, **MARINER)


@pytest.mark.parametrize('aim', ['predecessor', 'path'])
def test_curvature_lead_on_an_arc(aim):
    """psi_c += (2 zeta U / omega_n) kappa, kappa = +1/R on a clockwise arc (guidance.py)."""
    r = 1000.0
    route = Route([Arc((0.0, 0.0), (1000.0, 1000.0), (0.0, 1000.0), clockwise=True),
                   Line((1000.0, 1000.0), (1000.0, 3000.0))])
    zeta, w, u = 0.8, 0.12, 7.7175

    def cmd(lead, s_own, s_pred):
        f = follower(route, spacing=500.0, aim=aim, zeta=zeta, omega_n=w, speed=u,
                     curvature_lead=lead)
        pn, pe, _ = route.point_at(s_pred)
        f.add_predecessor(0.0, float(pn), float(pe), 0.0, u, 0.0)
        n, e, _ = route.point_at(s_own)
        return f.update(0.0, float(n) - 3.0, float(e)).heading_cmd

    assert cmd(True, 300.0, 800.0) - cmd(False, 300.0, 800.0) == pytest.approx(
        2 * zeta * u / (w * r), abs=1e-12)
    # on the straight leg there is no lead
    assert cmd(True, 1700.0, 2200.0) == pytest.approx(cmd(False, 1700.0, 2200.0), abs=1e-12)


def test_past_the_end_the_follower_goes_straight_and_the_gap_is_real():
    """A quarter arc then 1 km east, ending at (1000, 1000): the follower and its predecessor
    both pass the end; the follower keeps the end tangent (no turn back once it is d beyond
    the end), and the gap is the distance along it (not the clamped s_p - s_f = 0)."""
    route = Route([Arc((0.0, -1000.0), (1000.0, 0.0), (0.0, 0.0), clockwise=True),
                   Line((1000.0, 0.0), (1000.0, 1000.0))])       # ends at (1000, 1000), east
    for aim, sigma in (('predecessor', 0.0), ('path', 2.0)):
        f = follower(route, spacing=400.0, aim=aim, integral_gain=sigma)
        u, dt = 8.0, 0.5
        north, east, psi = 1000.0, 700.0, math.pi / 2       # 300 m before the end, on the path
        for k in range(int(300.0 / dt)):                     # 2.4 km: far past the end
            t = k * dt
            f.add_predecessor(t, 1000.0, 1100.0 + u * t, math.pi / 2, u, 0.0)   # 400 m ahead
            out = f.update(t, north, east, psi)
            assert out.heading_cmd == pytest.approx(math.pi / 2, abs=1e-9)
            assert out.gap == pytest.approx(400.0, abs=1e-6)
            # arc pi/2 x 1000 m, then the line and its extension: east - 0
            assert out.s == pytest.approx(math.pi / 2 * 1000.0 + east, abs=1e-6)
            psi = out.heading_cmd                             # perfect heading
            north += dt * u * math.cos(psi)
            east += dt * u * math.sin(psi)
        assert east > 2500.0 and north == pytest.approx(1000.0, abs=1e-6)
        assert out.route.finished


def test_extended_arc_length_before_the_start_and_inside():
    route = Route([Line((0.0, 0.0), (1000.0, 0.0))])
    f = follower(route)
    f.add_predecessor(0.0, 300.0, 5.0, 0.0, 8.0, 0.0)
    out = f.update(0.0, -150.0, 7.0)         # 150 m before the start
    assert out.s == pytest.approx(-150.0) and out.gap == pytest.approx(450.0)
    # the aim point is d = 450 m ahead of the follower along the extended route: the predecessor
    assert out.heading_cmd == pytest.approx(math.atan2(5.0 - 7.0, 450.0), abs=1e-12)
