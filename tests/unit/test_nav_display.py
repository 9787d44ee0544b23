"""The pure helpers of nav_display_node: hull outline, geodetic fix, display throttle, trail."""
import math

import numpy as np
import pytest

from ship_guidance.nav_display import DEFAULT_BEAM_RATIO, Throttle, Trail, enu_to_geodetic, hull_outline
from ship_sim.geodetic import WGS84_A, WGS84_E2, geodetic_to_ned


@pytest.mark.parametrize('yaw', [0.0, 0.7, math.pi / 2, -2.5, math.pi])
@pytest.mark.parametrize('length', [160.93, 304.8, 2.225])
def test_hull_outline_has_the_true_length_and_points_along_the_heading(yaw, length):
    x, y = 1234.5, -678.9
    poly = hull_outline(x, y, yaw, length)
    assert np.allclose(poly[0], poly[-1])                      # closed
    heading = np.array([math.cos(yaw), math.sin(yaw)])
    across = np.array([-math.sin(yaw), math.cos(yaw)])
    along = (poly - [x, y]) @ heading
    side = (poly - [x, y]) @ across
    # Bow to stern: the model's length, centred on the position.
    assert along.max() == pytest.approx(length / 2.0, rel=1e-12)
    assert along.min() == pytest.approx(-length / 2.0, rel=1e-12)
    # The one point at the front is the bow, on the centre line (the ship points along yaw).
    bow = poly[np.argmax(along)]
    assert np.allclose(bow, [x + heading[0] * length / 2, y + heading[1] * length / 2])
    # Widest part: the beam, symmetric about the centre line.
    assert side.max() == pytest.approx(length * DEFAULT_BEAM_RATIO / 2.0, rel=1e-12)
    assert side.min() == pytest.approx(-side.max(), rel=1e-12)


def test_hull_outline_refuses_a_non_positive_length():
    with pytest.raises(ValueError, match='length'):
        hull_outline(0.0, 0.0, 0.0, 0.0)


@pytest.mark.parametrize('lat0, lon0', [(59.9, 10.7), (-33.9, 151.2), (0.0, 0.0), (35.1, 129.0)])
def test_fix_of_a_known_offset_inverts_the_geodetic_module(lat0, lon0):
    x, y = 2500.0, -1800.0                                     # east, north (m)
    lat, lon = enu_to_geodetic(x, y, lat0, lon0)
    north, east = geodetic_to_ned(lat, lon, lat0, lon0)
    assert (east, north) == pytest.approx((x, y), abs=1e-6)


def test_fix_of_small_offsets_follows_the_radii_of_curvature():
    """1 km north moves latitude by 1 km / M (meridian radius), 1 km east moves longitude by
    1 km / (N cos lat) (prime vertical): WGS-84 geometry, independent of the module's code. The
    tangent plane shortens 1 km by s^3 / (6 R^2) ~ 4e-9 m and the radii change by ~1e-4 over
    1 km at 60 deg, so 1e-3 relative covers both."""
    lat0, lon0 = 60.0, 5.0
    phi = math.radians(lat0)
    w = 1.0 - WGS84_E2 * math.sin(phi) ** 2
    meridian = WGS84_A * (1.0 - WGS84_E2) / w ** 1.5
    prime = WGS84_A / math.sqrt(w)
    lat, lon = enu_to_geodetic(0.0, 1000.0, lat0, lon0)
    assert math.radians(lat - lat0) == pytest.approx(1000.0 / meridian, rel=1e-3)
    assert lon == pytest.approx(lon0, abs=1e-12)
    lat, lon = enu_to_geodetic(1000.0, 0.0, lat0, lon0)
    assert math.radians(lon - lon0) == pytest.approx(1000.0 / (prime * math.cos(phi)), rel=1e-3)


def test_throttle_passes_the_display_rate_in_sim_time():
    """10 Hz simulator steps, 2 Hz display: one stamp in five, the first of each half second."""
    th = Throttle(2.0)
    stamps = [round(0.1 * k, 10) for k in range(101)]           # 0 .. 10 s
    shown = [t for t in stamps if th.due(t)]
    assert shown == pytest.approx([0.5 * i for i in range(21)])


def test_throttle_with_steps_coarser_than_the_period_passes_every_step():
    th = Throttle(10.0)
    assert all(th.due(t) for t in (0.0, 0.5, 1.0, 1.5))


def test_throttle_starts_over_when_time_goes_back():
    th = Throttle(1.0)
    assert th.due(100.0) and not th.due(100.5)
    assert th.due(3.0)                                          # a new simulator: show at once
    assert not th.due(3.2) and th.due(4.0)


def test_throttle_refuses_a_zero_rate():
    with pytest.raises(ValueError, match='rate'):
        Throttle(0.0)


def test_trail_is_bounded_and_keeps_the_newest():
    tr = Trail(5)
    for k in range(12):
        tr.add(k, -k)
    assert len(tr) == 5
    assert list(tr.points) == [(float(k), float(-k)) for k in range(7, 12)]


def test_display_markers_carry_the_hull_route_and_trail():
    from ship_guidance.ros.nav_display_msgs import display_markers, navsat_fix, route_marker
    from ship_sim.ros.conversions import time_to_msg
    from visualization_msgs.msg import Marker
    stamp = time_to_msg(12.5)
    route = route_marker(time_to_msg(0.0), [(0.0, 0.0), (0.0, 1000.0)], 160.93)
    arr = display_markers(stamp, 'vessel_0', 10.0, 20.0, 0.3, 160.93, route,
                          [(0.0, 0.0), (5.0, 5.0), (10.0, 20.0)])
    by_ns = {m.ns: m for m in arr.markers}
    assert set(by_ns) == {'hull', 'hull_fill', 'label', 'route', 'trail'}
    assert all(m.header.frame_id == 'map' for m in arr.markers)
    assert all(m.header.stamp == stamp for m in arr.markers if m.ns != 'route')
    hull = np.array([(p.x, p.y) for p in by_ns['hull'].points])
    assert np.allclose(hull, hull_outline(10.0, 20.0, 0.3, 160.93))
    # The fill covers the outline's area exactly (triangles of a fan over a convex polygon).
    fill = np.array([(p.x, p.y) for p in by_ns['hull_fill'].points]).reshape(-1, 3, 2)
    assert by_ns['hull_fill'].type == Marker.TRIANGLE_LIST
    tri_area = 0.5 * np.abs(np.cross(fill[:, 1] - fill[:, 0], fill[:, 2] - fill[:, 0])).sum()
    px, py = hull[:, 0], hull[:, 1]
    assert tri_area == pytest.approx(0.5 * abs(np.dot(px[:-1], py[1:]) - np.dot(px[1:], py[:-1])))
    assert by_ns['route'].type == Marker.LINE_STRIP and len(by_ns['route'].points) == 2
    assert [(p.x, p.y) for p in by_ns['trail'].points][-1] == (10.0, 20.0)
    assert by_ns['label'].text == 'vessel_0'
    fix = navsat_fix(stamp, 'vessel_0/base_link', 2500.0, -1800.0, 59.9, 10.7)
    assert (fix.latitude, fix.longitude) == pytest.approx(enu_to_geodetic(2500.0, -1800.0, 59.9, 10.7))
    assert fix.header.frame_id == 'vessel_0/base_link' and fix.status.status == 0
