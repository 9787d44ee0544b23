"""Fillets (ship_planner.fillets): tangency, radius, sweep = course change, fit errors."""
import math

import numpy as np
import pytest

from ship_planner.fillets import (FilletError, LineSpec, fillet_corner, fillet_polyline, fillet_segments,
                                  segments_to_route, suggest_fillet_radius)
from ship_sim.frames import wrap_angle


def test_right_angle_starboard_corner_by_hand():
    # North 1000 m, then east: a 90 deg starboard turn; radius 200 -> tangent points 200 m from the corner.
    f = fillet_corner((0, 0), (1000, 0), (1000, 1000), 200.0)
    assert f.entry == pytest.approx((800.0, 0.0))
    assert f.exit == pytest.approx((1000.0, 200.0))
    assert f.center == pytest.approx((800.0, 200.0))
    assert f.clockwise is True
    assert f.course_change == pytest.approx(math.pi / 2)
    assert f.tangent_length == pytest.approx(200.0)


def test_port_corner_has_its_centre_to_port():
    # East, then north: a 90 deg port turn; the centre is north of the first leg.
    f = fillet_corner((0, 0), (0, 1000), (1000, 1000), 300.0)
    assert f.clockwise is False
    assert f.course_change == pytest.approx(-math.pi / 2)
    assert f.center == pytest.approx((300.0, 700.0))


@pytest.mark.parametrize('seed', range(5))
def test_random_corners_are_tangent_with_the_right_radius_and_sweep(seed):
    rng = np.random.default_rng(seed)
    for _ in range(20):
        chi_in, turn = rng.uniform(-math.pi, math.pi), rng.uniform(-2.8, 2.8)
        r = rng.uniform(50.0, 2000.0)
        c = rng.uniform(-1e4, 1e4, 2)
        p_prev = c - 5e4 * np.array([math.cos(chi_in), math.sin(chi_in)])
        p_next = c + 5e4 * np.array([math.cos(chi_in + turn), math.sin(chi_in + turn)])
        f = fillet_corner(p_prev, c, p_next, r)
        u_in = (c - p_prev) / np.linalg.norm(c - p_prev)
        u_out = (p_next - c) / np.linalg.norm(p_next - c)
        ce, en, ex = np.array(f.center), np.array(f.entry), np.array(f.exit)
        assert np.linalg.norm(en - ce) == pytest.approx(r, rel=1e-9)
        assert np.linalg.norm(ex - ce) == pytest.approx(r, rel=1e-9)
        assert abs(np.dot(en - ce, u_in)) < 1e-6 * r          # radius at entry is normal to the leg in
        assert abs(np.dot(ex - ce, u_out)) < 1e-6 * r         # ... and at exit to the leg out
        assert f.course_change == pytest.approx(turn, abs=1e-9)
        route = segments_to_route(fillet_polyline([p_prev, c, p_next], r))
        arc = route.legs[1]
        assert arc.kind == 'arc' and arc.clockwise == (turn > 0)
        assert arc.radius == pytest.approx(r, rel=1e-9)
        assert arc.sweep == pytest.approx(abs(turn), abs=1e-9)


def test_filleted_polyline_is_tangent_everywhere_and_as_long_as_the_formula():
    pts = np.array([[0, 0], [3000, 0], [4000, 2000], [2500, 4500], [2500, 7000]], float)
    r = 700.0
    route = segments_to_route(fillet_polyline(pts, r))
    assert [leg.kind for leg in route.legs] == ['line', 'arc', 'line', 'arc', 'line', 'arc', 'line']
    for a, b in zip(route.legs[:-1], route.legs[1:]):
        assert float(wrap_angle(b.start_angle - a.end_angle)) == pytest.approx(0.0, abs=1e-9)
    legs = np.diff(pts, axis=0)
    chi = np.arctan2(legs[:, 1], legs[:, 0])
    turns = np.abs(wrap_angle(np.diff(chi)))
    expected = np.sum(np.hypot(legs[:, 0], legs[:, 1])) - np.sum(2 * r * np.tan(turns / 2)) + np.sum(r * turns)
    assert route.length == pytest.approx(expected, rel=1e-12)


def test_straight_through_corner_needs_no_arc():
    segs = fillet_polyline([(0, 0), (1000, 0), (2000, 0)], 500.0)
    assert all(isinstance(s, LineSpec) for s in segs)


def test_fillet_that_overlaps_the_next_one_names_the_waypoint_and_the_largest_radius():
    # Two 90 deg corners 300 m apart: radius 200 needs 200 + 200 m of that leg.
    with pytest.raises(FilletError) as exc:
        fillet_polyline([(0, 0), (1000, 0), (1000, 300), (2000, 300)], 200.0)
    msg = str(exc.value)
    assert 'waypoint 3' in msg and '300.0 m long' in msg
    assert 'fits both corners is 150.0 m' in msg                   # 300 / (tan 45 + tan 45)
    assert 'or 100.0 m at waypoint 3 alone' in msg                 # (300 - 200) / tan(45 deg)
    assert exc.value.corner == 1


def test_fillet_longer_than_the_first_leg_is_refused():
    with pytest.raises(FilletError, match=r'waypoint 2 .*largest radius that fits there is 100\.0 m'):
        fillet_polyline([(0, 0), (100, 0), (100, 1000)], 200.0)


def test_reversal_cannot_be_filleted():
    with pytest.raises(FilletError, match='waypoint 2.*reverses'):
        fillet_polyline([(0, 0), (1000, 0), (0, 0)], 100.0)


def test_zero_radius_keeps_a_corner():
    segs = fillet_polyline([(0, 0), (1000, 0), (1000, 1000)], 0.0)
    assert len(segs) == 2 and all(isinstance(s, LineSpec) for s in segs)
    # Per-corner radii: the first corner stays sharp, the second is rounded.
    segs = fillet_polyline([(0, 0), (1000, 0), (1000, 1000), (0, 1000)], [0.0, 300.0])
    assert [type(s).__name__ for s in segs] == ['LineSpec', 'LineSpec', 'ArcSpec', 'LineSpec']
    assert segs[1].end == pytest.approx((1000.0, 700.0))   # leg 2 stops 300 m before the corner


def test_junctions_next_to_an_arc_are_left_alone():
    from ship_planner.fillets import ArcSpec
    segs = [LineSpec((0, 0), (1000, 0)), ArcSpec((1000, 0), (1500, 500), (1000, 500), True),
            LineSpec((1500, 500), (1500, 2000))]
    assert fillet_segments(segs, [400.0, 400.0]) == segs


def test_suggested_radius():
    assert suggest_fillet_radius(1112.0) == pytest.approx(1112.0)        # R = (D / 2) / 0.5
    assert suggest_fillet_radius(1000.0, rudder_fraction=0.25) == pytest.approx(2000.0)
    assert suggest_fillet_radius(1000.0, rudder_fraction=1.0) == pytest.approx(500.0)
    for bad in [(0.0,), (float('nan'),), (1000.0, 0.0), (1000.0, 1.5)]:
        with pytest.raises(ValueError):
            suggest_fillet_radius(*bad)
