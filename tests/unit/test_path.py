"""Path geometry (ship_guidance.path): hand-computed projections, encoding round trips, branch
safety at self-crossings and the accuracy of sampled curves.

NED: north first, east second; headings clockwise from north; e > 0 to starboard.
"""
import math

import numpy as np
import pytest

from ship_guidance.path import Arc, Line, Route, estimate_tangents

PI = math.pi
SQ2 = math.sqrt(2.0)


def angle_close(a, b, tol=1e-9):
    return abs((a - b + PI) % (2 * PI) - PI) <= tol


# ------------------------------------------------------------------------------ lines

def test_line_project_north_both_sides_and_beyond_ends():
    r = Route([Line((0.0, 0.0), (100.0, 0.0))])  # heading north
    p = r.project(50.0, 10.0)  # 10 m east = starboard
    assert (p.s, p.cross_track, p.distance, p.path_angle) == pytest.approx((50.0, 10.0, 10.0, 0.0))
    assert not p.at_start and not p.at_end
    assert r.project(50.0, -10.0).cross_track == pytest.approx(-10.0)
    before = r.project(-20.0, 5.0)
    assert before.at_start and before.s == 0.0
    assert before.cross_track == pytest.approx(5.0)  # offset from the extended line
    assert before.distance == pytest.approx(math.hypot(20.0, 5.0))
    beyond = r.project(130.0, -7.0)
    assert beyond.at_end and beyond.s == pytest.approx(100.0)
    assert beyond.cross_track == pytest.approx(-7.0)


def test_line_project_diagonal_hand_values():
    r = Route([Line((0.0, 0.0), (100.0, 100.0))])  # heading north-east, 45 deg
    p = r.project(0.0, 100.0)  # due east of the start: to starboard of a NE track
    assert p.path_angle == pytest.approx(PI / 4)
    assert p.s == pytest.approx(50.0 * SQ2)
    assert (p.north, p.east) == pytest.approx((50.0, 50.0))
    assert p.cross_track == pytest.approx(50.0 * SQ2)
    assert r.project(100.0, 0.0).cross_track == pytest.approx(-50.0 * SQ2)


def test_line_heading_south_west_sign():
    r = Route([Line((0.0, 0.0), (-100.0, 0.0))])  # heading south (pi)
    # Heading south, starboard is west (negative east).
    assert r.project(-50.0, -3.0).cross_track == pytest.approx(3.0)
    assert angle_close(r.project(-50.0, -3.0).path_angle, PI)


# ------------------------------------------------------------------------------ arcs

def circle_route(clockwise, radius=100.0):
    """A full circle about the origin as two half arcs, starting due west of the centre."""
    west, east = (0.0, -radius), (0.0, radius)
    return Route([Arc(west, east, (0.0, 0.0), clockwise), Arc(east, west, (0.0, 0.0), clockwise)])


# polar angle of the position (from north, clockwise) -> hand-computed arc length from the west
# point and tangent heading, for R = 100 m. Clockwise from west: NW, NE, SE, SW.
CW_CASES = {  # phi: (s, path angle)
    -PI / 4: (25.0 * PI, PI / 4),        # NW quadrant, moving north-east
    PI / 4: (75.0 * PI, 3 * PI / 4),     # NE, moving south-east
    3 * PI / 4: (125.0 * PI, -3 * PI / 4),  # SE, moving south-west
    -3 * PI / 4: (175.0 * PI, -PI / 4),  # SW, moving north-west
}
CCW_CASES = {  # counter-clockwise from west: SW, SE, NE, NW
    -3 * PI / 4: (25.0 * PI, 3 * PI / 4),   # SW, moving south-east
    3 * PI / 4: (75.0 * PI, PI / 4),        # SE, moving north-east
    PI / 4: (125.0 * PI, -PI / 4),          # NE, moving north-west
    -PI / 4: (175.0 * PI, -3 * PI / 4),     # NW, moving south-west
}


@pytest.mark.parametrize('clockwise, cases', [(True, CW_CASES), (False, CCW_CASES)])
@pytest.mark.parametrize('dist', [80.0, 120.0])
def test_arc_project_all_quadrants_both_directions(clockwise, cases, dist):
    r = circle_route(clockwise)
    # Clockwise: the centre is to starboard, so inside (80 m) is +20, outside (120 m) is -20.
    expected_e = (100.0 - dist) * (1.0 if clockwise else -1.0)
    for phi, (s, gamma) in cases.items():
        p = r.project(dist * math.cos(phi), dist * math.sin(phi))
        assert p.s == pytest.approx(s, abs=1e-9)
        assert angle_close(p.path_angle, gamma)
        assert p.cross_track == pytest.approx(expected_e, abs=1e-9)
        assert p.curvature == pytest.approx((1.0 if clockwise else -1.0) / 100.0)
        assert p.distance == pytest.approx(20.0)


@pytest.mark.parametrize('clockwise', [True, False])
def test_arc_frame_valid_all_around_the_centre(clockwise):
    """The full-circle guidance frame (Simakis 1992 Chapter IV without quadrant cases) agrees with the
    route projection wherever the radial foot lies on the arc, and with hand values."""
    r = circle_route(clockwise)
    sgn = 1.0 if clockwise else -1.0
    for phi in np.linspace(-PI + 0.05, PI - 0.05, 17):
        for dist in (30.0, 100.0, 170.0):
            n, e = dist * math.cos(phi), dist * math.sin(phi)
            for arc in r.legs:
                gamma, cross = arc.frame(n, e)
                assert angle_close(gamma, phi + sgn * PI / 2)
                assert cross == pytest.approx(sgn * (100.0 - dist))
            p = r.project(n, e)
            assert angle_close(p.path_angle, gamma) and p.cross_track == pytest.approx(cross)


def test_arc_attributes_hand_values():
    a = Arc((0.0, 100.0), (100.0, 0.0), (0.0, 0.0), clockwise=True)  # east, south, west, north
    assert a.sweep == pytest.approx(1.5 * PI)
    assert a.length == pytest.approx(150.0 * PI)
    assert angle_close(a.start_angle, PI) and angle_close(a.end_angle, PI / 2)
    b = Arc((0.0, 100.0), (100.0, 0.0), (0.0, 0.0), clockwise=False)  # east -> north
    assert b.length == pytest.approx(50.0 * PI)
    assert angle_close(b.start_angle, 0.0) and angle_close(b.end_angle, -PI / 2)


def test_arc_beyond_end_clamps_and_reports():
    # Quarter circle clockwise from north of the centre to east of it.
    r = Route([Arc((100.0, 0.0), (0.0, 100.0), (0.0, 0.0), True)])
    p = r.project(-50.0, 110.0)  # south-east, past the end normal; end tangent heads south
    assert p.at_end and p.s == pytest.approx(50.0 * PI)
    assert angle_close(p.path_angle, PI)
    # Heading south, starboard is west: the point is 10 m east of the tangent line -> e = -10.
    assert p.cross_track == pytest.approx(-10.0)
    q = r.project(110.0, -50.0)  # before the start (start tangent heads east)
    assert q.at_start and q.s == 0.0
    assert q.cross_track == pytest.approx(-10.0)  # 10 m north of an eastward line = port


def test_point_at_scalar_and_vector():
    r = Route([Line((0.0, 0.0), (100.0, 0.0)),
               Arc((100.0, 0.0), (200.0, 100.0), (100.0, 100.0), True)])
    n, e, a = r.point_at(100.0 + 25.0 * PI)  # halfway round the quarter circle
    assert (n, e) == pytest.approx((100.0 + 100.0 / SQ2, 100.0 - 100.0 / SQ2))
    assert a == pytest.approx(PI / 4)
    ns, es, as_ = r.point_at(np.array([-5.0, 50.0, 1e9]))
    assert ns == pytest.approx([0.0, 50.0, 200.0]) and es == pytest.approx([0.0, 0.0, 100.0])
    assert as_ == pytest.approx([0.0, 0.0, PI / 2])


# ------------------------------------------------------------------------------ validation

@pytest.mark.parametrize('make', [
    lambda: Line((0.0, 0.0), (0.0, 0.0)),
    lambda: Line((0.0, float('nan')), (1.0, 0.0)),
    lambda: Arc((0.0, 100.0), (0.0, 100.0), (0.0, 0.0), True),          # zero length
    lambda: Arc((0.0, 100.0), (0.0, -101.0), (0.0, 0.0), True),         # not on one circle
    lambda: Arc((0.0, 0.0), (0.0, 100.0), (0.0, 0.0), True),            # start on the centre
    lambda: Arc((0.0, 100.0), (100.0, 0.0), (0.0, 0.0), 'yes'),         # not a bool
    lambda: Arc((0.0, 100.0), (100.0, 0.0), (float('inf'), 0.0), True),
    lambda: Route([]),
    lambda: Route([Line((0.0, 0.0), (1.0, 0.0)), Line((1.0, 0.5), (2.0, 0.0))]),  # gap
    lambda: Route.polyline([(0.0, 0.0), (1.0, 0.0), (1.0, 0.0)]),
])
def test_invalid_geometry_is_refused(make):
    with pytest.raises(ValueError):
        make()


def test_arc_radius_tolerance_is_relative():
    Arc((0.0, 1000.0), (0.0, -1000.0005), (0.0, 0.0), True)  # 5e-7 relative: accepted
    with pytest.raises(ValueError):
        Arc((0.0, 1000.0), (0.0, -1000.01), (0.0, 0.0), True)  # 1e-5 relative: refused


# ------------------------------------------------------------------------------ pose encoding

def legs_equal(a, b, tol=1e-7):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.kind == y.kind
        assert np.allclose(x.start, y.start, atol=tol) and np.allclose(x.end, y.end, atol=tol)
        if x.kind == 'arc':
            assert x.clockwise == y.clockwise
            assert np.allclose(x.center, y.center, atol=tol * max(1.0, x.radius))


def mixed_route():
    """A corner between two lines, a line followed by a non-tangent ccw arc (corner), a tangent
    cw arc, a tangent line, and points on a circle joined by straight chords."""
    ring = [(1000.0 + 200.0 * math.sin(t), 1100.0 - 200.0 * math.cos(t))
            for t in np.linspace(0.0, 1.2 * PI, 7)]                      # starts at (1000, 900)
    return Route([
        Line((-300.0, -200.0), (0.0, 0.0)),                             # heading 33.7 deg
        Line((0.0, 0.0), (500.0, 0.0)),                                 # north: corner at 0
        Arc((500.0, 0.0), (800.0, 300.0), (800.0, 0.0), False),         # leaves heading east
        Arc((800.0, 300.0), (1000.0, 500.0), (800.0, 500.0), True),     # tangent, heading north
        Line((1000.0, 500.0), (1000.0, 900.0)),                         # tangent, heading east
    ] + [Line(ring[i], ring[i + 1]) for i in range(len(ring) - 1)])


def test_mixed_route_geometry_is_as_drawn():
    r = mixed_route()
    assert angle_close(r.legs[2].start_angle, PI / 2) and not r.legs[2].clockwise
    assert angle_close(r.legs[3].start_angle, 0.0) and angle_close(r.legs[3].end_angle, PI / 2)
    assert angle_close(r.legs[2].end_angle, r.legs[3].start_angle)


def test_to_poses_carries_start_tangents():
    r = mixed_route()
    n, e, psi = r.to_poses(max_arc_step=40.0)
    # poses: one per line, ceil(L/40) per arc, plus the end pose
    expected = sum(1 if leg.kind == 'line' else math.ceil(leg.length / 40.0) for leg in r.legs) + 1
    assert len(n) == expected
    for leg in r.legs:  # every leg start is a pose carrying that leg's start tangent
        i = np.nonzero(np.hypot(n - leg.start[0], e - leg.start[1]) < 1e-9)[0]
        assert len(i) >= 1 and any(angle_close(psi[j], leg.start_angle) for j in i)
    assert angle_close(psi[-1], r.legs[-1].end_angle)
    assert (n[-1], e[-1]) == pytest.approx(tuple(r.end))


def test_pose_round_trip_is_exact():
    r = mixed_route()
    for step in (40.0, 7.5, 1e6):
        back = Route.from_poses(*r.to_poses(step))
        legs_equal(r.legs, back.legs)
        assert back.length == pytest.approx(r.length, rel=1e-12)


def test_round_trip_survives_enu_conversion():
    from ship_sim.frames import psi_to_yaw, yaw_to_psi
    r = mixed_route()
    n, e, psi = r.to_poses(25.0)
    back = Route.from_poses(n, e, yaw_to_psi(psi_to_yaw(psi)))
    legs_equal(r.legs, back.legs)


def test_co_circular_arcs_merge_but_keep_the_geometry():
    """Consecutive arcs on one circle are indistinguishable from sub-arcs in the encoding, so a
    full circle given as two halves decodes as other arcs of the same circle (documented)."""
    r = circle_route(False)
    back = Route.from_poses(*r.to_poses(25.0))
    assert all(leg.kind == 'arc' and np.allclose(leg.center, 0.0, atol=1e-9) for leg in back.legs)
    assert back.length == pytest.approx(r.length, rel=1e-12)
    for phi in np.linspace(-3.0, 3.0, 13):
        n, e = 90.0 * math.cos(phi), 90.0 * math.sin(phi)
        p, q = r.project(n, e), back.project(n, e)
        assert (q.s, q.cross_track) == pytest.approx((p.s, p.cross_track), abs=1e-9)


def test_points_on_a_circle_joined_by_chords_stay_straight():
    pts = [(100.0 * math.cos(t), 100.0 * math.sin(t)) for t in np.linspace(0.0, PI, 9)]
    r = Route.polyline(pts)
    back = Route.from_poses(*r.to_poses(5.0))
    assert all(leg.kind == 'line' for leg in back.legs)
    legs_equal(r.legs, back.legs)


def test_from_poses_refuses_bad_poses():
    with pytest.raises(ValueError):
        Route.from_poses([0.0, 0.0], [0.0, 0.0], [0.0, 0.0])           # coincident
    with pytest.raises(ValueError):
        Route.from_poses([0.0, -10.0], [0.0, 0.0], [0.0, 0.0])         # next point behind


def test_from_poses_arc_through_next_point_hand_case():
    # Leaving the origin heading north; the next point is (100, 100): chord bearing 45 deg, so
    # delta = 45 deg, a clockwise quarter circle of radius 100 about (0, 100).
    r = Route.from_poses([0.0, 100.0], [0.0, 100.0], [0.0, 0.0])
    (arc,) = r.legs
    assert arc.kind == 'arc' and arc.clockwise
    assert arc.radius == pytest.approx(100.0) and arc.center == pytest.approx([0.0, 100.0])
    assert arc.length == pytest.approx(50.0 * PI)


# ------------------------------------------------------------------------------ self-crossings

def figure_eight(c=500.0):
    """Two straight diagonals crossing at the origin joined by 270-degree tangent arcs:
    NE line, port loop about (2c, 0), SE line... back through the origin, starboard loop."""
    rad = c * SQ2
    return Route([
        Line((-c, -c), (c, c)),                             # heading NE, through the origin
        Arc((c, c), (c, -c), (2 * c, 0.0), False),          # port (ccw) loop, 270 deg
        Line((c, -c), (-c, c)),                             # heading SE, through the origin
        Arc((-c, c), (-c, -c), (-2 * c, 0.0), True),        # starboard loop, 270 deg
    ]), rad


def test_figure_eight_is_tangent_continuous():
    r, rad = figure_eight()
    assert r.legs[1].radius == pytest.approx(rad)
    for i in range(len(r.legs) - 1):
        assert angle_close(r.legs[i].end_angle, r.legs[i + 1].start_angle, 1e-12)


def test_figure_eight_progress_does_not_jump_branches():
    r, _ = figure_eight()
    s_cross_2 = r.cumulative[2] + r.legs[2].length / 2  # second pass through the origin
    s_cross_1 = r.legs[0].length / 2
    # Without a hint the origin is ambiguous; the search returns a crossing pass.
    assert r.project(0.0, 0.0).s == pytest.approx(s_cross_1)
    # Walk the whole path with a small lateral offset, projecting with the previous s as hint.
    s_true = np.linspace(0.0, r.length, 2001)
    n, e, a = r.point_at(s_true)
    off = 3.0
    n, e = n - off * np.sin(a), e + off * np.cos(a)  # 3 m to starboard
    s_prev, got = 0.0, []
    for i in range(len(s_true)):
        p = r.project(n[i], e[i], s_hint=s_prev, window=200.0)
        got.append(p.s)
        s_prev = p.s
    got = np.array(got)
    assert np.max(np.abs(got - s_true)) < 1e-6
    # ...whereas a global search at the second crossing jumps back to the first branch.
    i2 = np.argmin(np.abs(s_true - s_cross_2))
    assert abs(r.project(n[i2], e[i2]).s - s_cross_1) < 10.0


def test_hairpin_hint_keeps_branch():
    # Out along a line, 180-degree turn of radius 30 m, back along a parallel line 60 m away.
    r = Route([Line((0.0, 0.0), (1000.0, 0.0)),
               Arc((1000.0, 0.0), (1000.0, 60.0), (1000.0, 30.0), True),
               Line((1000.0, 60.0), (0.0, 60.0))])
    # 40 m starboard of the outbound leg is 20 m from the return leg: globally closer to it.
    p_global = r.project(500.0, 40.0)
    assert p_global.leg_index == 2
    p = r.project(500.0, 40.0, s_hint=495.0, window=300.0)
    assert p.leg_index == 0 and p.s == pytest.approx(500.0) and p.cross_track == pytest.approx(40.0)


def test_bounds_restrict_the_search():
    r = Route.polyline([(0.0, 0.0), (100.0, 0.0), (100.0, 100.0)])
    p = r.project(120.0, 50.0, bounds=(0.0, 100.0))  # corner stretch only: clamped at the corner
    assert p.leg_index == 0 and p.s == pytest.approx(100.0)
    assert p.cross_track == pytest.approx(50.0)  # from the extended first leg
    q = r.project(120.0, 50.0)
    assert q.leg_index == 1 and q.cross_track == pytest.approx(-20.0)


# ------------------------------------------------------------------------------ sampled curves

A_SINE, LAM = 300.0, 3000.0
K_SINE = 2.0 * PI / LAM


def sine(x):
    """north = x, east = A sin(k x); tangent heading."""
    return x, A_SINE * np.sin(K_SINE * x), np.arctan(A_SINE * K_SINE * np.cos(K_SINE * x))


def max_kappa_prime():
    x = np.linspace(0.0, LAM, 400001)
    yp = A_SINE * K_SINE * np.cos(K_SINE * x)
    kappa = -A_SINE * K_SINE ** 2 * np.sin(K_SINE * x) / (1.0 + yp ** 2) ** 1.5
    ds = np.sqrt(1.0 + yp ** 2) * (x[1] - x[0])
    return np.max(np.abs(np.diff(kappa) / ds[:-1]))


def sampled_sine_error(h, exact_tangents):
    xs = np.arange(0.0, 2.0 * LAM + h / 2, h)
    n, e, psi = sine(xs)
    r = Route.from_curve(n, e, psi if exact_tangents else None)
    rng = np.random.default_rng(1)
    xt = rng.uniform(0.1 * LAM, 1.9 * LAM, 300)
    off = rng.uniform(-50.0, 50.0, 300)  # well inside the smallest radius of curvature (760 m)
    cn, ce, cpsi = sine(xt)
    pn, pe = cn - np.sin(cpsi) * off, ce + np.cos(cpsi) * off
    err = max(abs(r.project(pn[i], pe[i]).cross_track - off[i]) for i in range(len(xt)))
    return err, np.max(np.hypot(np.diff(n), np.diff(e)))


@pytest.mark.parametrize('exact, coef', [(True, 2.0 / 81.0), (False, 1.0 / (9.0 * math.sqrt(3.0)))])
def test_sampled_curve_cross_track_accuracy(exact, coef):
    """Tangent-arc sequences follow a smooth curve to coef * max|kappa'| * chord^3 (derivation in
    Route.from_curve), and the error falls with the cube of the spacing."""
    kp = max_kappa_prime()
    err25, c25 = sampled_sine_error(25.0, exact)
    err50, c50 = sampled_sine_error(50.0, exact)
    assert err25 <= coef * kp * c25 ** 3
    assert err50 <= coef * kp * c50 ** 3
    assert 6.0 < err50 / err25 < 10.0  # third order: 2^3 = 8
    assert err25 < (1.2e-3 if exact else 3.2e-3)  # the numbers stated in the docstring


def test_estimated_tangents_exact_on_a_circle():
    t = np.linspace(0.3, 2.0, 12)
    n, e = 50.0 * np.cos(t), 50.0 * np.sin(t)  # equally spaced, polar angle rising: clockwise
    psi = estimate_tangents(n, e)
    assert np.allclose(np.angle(np.exp(1j * (psi - (t + PI / 2)))), 0.0, atol=1e-12)
    r = Route.from_curve(n, e)
    assert len(r.legs) == 1 and r.legs[0].kind == 'arc' and r.legs[0].clockwise
    assert r.legs[0].radius == pytest.approx(50.0)
