"""YAML route files (ship_planner.yaml_route_reader): parsing in ENU and lat/lon, and every validation
error with the file name and the line of the offending value."""
import math
import pathlib
import textwrap

import pytest

from ship_sim.geodetic import WGS84_A, WGS84_E2
from ship_planner.route_data import RouteError
from ship_planner.yaml_route_reader import load_route_yaml, parse_route_yaml

CONFIG = pathlib.Path(__file__).resolve().parents[2] / 'ros_ws/src/ship_planner/config/routes'

HEAD = """\
name: test
source: unit test
frame: enu
"""


def doc(body, head=HEAD):
    return head + textwrap.dedent(body)


def line_of(text, marker):
    """1-based line of the first line of text containing marker (the fixture's own numbering)."""
    return next(i for i, line in enumerate(text.splitlines(), start=1) if marker in line)


def error(text, filename='bad_route.yaml'):
    with pytest.raises(RouteError) as exc:
        parse_route_yaml(text, filename)
    return exc.value


# ---- parsing -----------------------------------------------------------------------------------

def test_enu_waypoints_become_ned_lines():
    plan = parse_route_yaml(doc("""
        waypoints:
          - [0, 0]
          - [1000, 0]           # 1000 m east
          - {x_m: 1000, y_m: 2000}
        """))
    legs = plan.route.legs
    assert [leg.kind for leg in legs] == ['line', 'line']
    assert tuple(legs[0].end) == pytest.approx((0.0, 1000.0))      # NED (north, east)
    assert tuple(legs[1].end) == pytest.approx((2000.0, 1000.0))
    assert legs[0].angle == pytest.approx(math.pi / 2)               # course 090
    assert plan.route.length == pytest.approx(3000.0)
    assert plan.name == 'test' and plan.source == 'unit test' and plan.frame == 'enu'
    assert plan.origin_lat_deg is None
    assert plan.waypoints_ned.tolist() == [[0, 0], [0, 1000], [2000, 1000]]


def test_latlon_waypoints_are_mapped_to_the_tangent_plane_at_the_origin():
    plan = parse_route_yaml("""
name: geo
source: unit test
frame: wgs84
origin: {lat_deg: 60.0, lon_deg: 5.0}
waypoints:
  - [60.0, 5.0]
  - {lat_deg: 60.001, lon_deg: 5.0}
  - [60.001, 5.002]
""")
    lat = math.radians(60.0)
    w = 1.0 - WGS84_E2 * math.sin(lat) ** 2
    m_radius = WGS84_A * (1.0 - WGS84_E2) / w ** 1.5            # meridian radius of curvature
    n_radius = WGS84_A / math.sqrt(w)                            # prime vertical radius
    north = m_radius * math.radians(0.001)                       # ~111.4 m
    east = n_radius * math.cos(lat) * math.radians(0.002)        # ~111.7 m
    pts = plan.waypoints_ned
    assert pts[1] == pytest.approx([north, 0.0], abs=0.01)
    assert pts[2] == pytest.approx([north, east], abs=0.01)
    assert plan.origin_lat_deg == 60.0 and plan.origin_lon_deg == 5.0 and plan.frame == 'wgs84'


def test_legs_by_course_and_length_and_arcs_by_end_point_or_sweep():
    plan = parse_route_yaml(doc("""
        start: [0, 0]
        legs:
          - {course_deg: 0, length_m: 1000}            # north to (0, 1000) ENU
          - type: arc                                  # starboard quarter circle, radius 500
            center: [500, 1000]
            direction: clockwise
            to: [500, 1500]
          - type: arc                                  # then a port half circle, radius 500
            center: [1000, 1500]
            direction: port
            sweep_deg: 180
        """))
    line, arc1, arc2 = plan.route.legs
    assert tuple(line.end) == pytest.approx((1000.0, 0.0))
    assert arc1.clockwise and arc1.radius == pytest.approx(500.0) and arc1.sweep == pytest.approx(math.pi / 2)
    assert not arc2.clockwise and arc2.sweep == pytest.approx(math.pi)
    assert tuple(arc2.end) == pytest.approx((1500.0, 1500.0))        # NED of ENU (1500, 1500)
    assert plan.route.length == pytest.approx(1000.0 + 250.0 * math.pi + 500.0 * math.pi)


def test_example_file_loads_with_its_fillets():
    plan = load_route_yaml(CONFIG / 'example_enu.yaml')
    t = 600.0 * math.tan(math.radians(22.5))          # tangent length of the 45 deg, 600 m fillet
    expected = (1000.0 + 500.0 * math.pi + 1000.0     # north leg, 90 deg fillet R 1000, east leg
                + 500.0 * math.pi                     # the given quarter arc, R 1000
                + (2000.0 - t) + 600.0 * math.pi / 4 + (1500.0 - t))
    assert plan.route.length == pytest.approx(expected, rel=1e-12)
    assert plan.file.endswith('example_enu.yaml')
    assert (plan.origin_lat_deg, plan.origin_lon_deg) == (58.0, 9.0)


def test_fillet_radius_per_waypoint_overrides_the_global_one():
    plan = parse_route_yaml(doc("""
        fillet_radius_m: 300
        waypoints:
          - [0, 0]
          - {x_m: 0, y_m: 1000, fillet_radius_m: 0}
          - [1000, 1000]
          - [1000, 0]
        """))
    kinds = [leg.kind for leg in plan.route.legs]
    assert kinds == ['line', 'line', 'arc', 'line']
    assert plan.route.legs[2].radius == pytest.approx(300.0)


# ---- errors: each names the file and the line ----------------------------------------------------

def test_fewer_than_two_points():
    text = doc("""
        waypoints:
          - [0, 0]
        """)
    e = error(text)
    assert 'at least 2 waypoints' in str(e)
    assert e.line == line_of(text, '- [0, 0]') and str(e).startswith(f'bad_route.yaml:{e.line}:')


@pytest.mark.parametrize('value', ['.nan', '.inf', '-.inf'])
def test_non_finite_coordinates(value):
    text = doc(f"""
        waypoints:
          - [0, 0]
          - [100, {value}]
        """)
    e = error(text)
    assert 'waypoint 2 y_m must be finite' in str(e) and e.line == line_of(text, value)


def test_duplicate_consecutive_points_make_a_zero_length_leg():
    text = doc("""
        waypoints:
          - [0, 0]
          - [500, 500]
          - [500, 500]   # again
        """)
    e = error(text)
    assert 'zero-length leg' in str(e) and 'waypoint 3' in str(e)
    assert e.line == line_of(text, '# again')


def test_arc_end_off_its_circle_gives_both_distances():
    text = doc("""
        start: [0, 0]
        legs:
          - type: arc
            center: [1000, 0]
            direction: clockwise
            to: [1000, 1050]     # 1050 m from the centre, the start is 1000 m from it
        """)
    e = error(text)
    assert 'not on one circle' in str(e)
    assert '1000.000 m' in str(e) and '1050.000 m' in str(e)
    assert e.line == line_of(text, 'to: [1000, 1050]')


def test_arc_within_tolerance_is_snapped_so_legs_join():
    plan = parse_route_yaml(doc("""
        start: [0, 0]
        legs:
          - {type: arc, center: [1000, 0], direction: clockwise, to: [1000, 1000.05]}
          - {to: [2000, 1000]}
        """))
    assert plan.route.legs[0].radius == pytest.approx(1000.0)


def test_unknown_key_is_named_with_a_suggestion():
    text = doc("""
        fillet_radius: 500
        waypoints: [[0, 0], [100, 0]]
        """)
    e = error(text)
    assert 'unknown key "fillet_radius"' in str(e) and 'did you mean "fillet_radius_m"' in str(e)
    assert e.line == line_of(text, 'fillet_radius:')


def test_unknown_key_in_a_leg():
    text = doc("""
        start: [0, 0]
        legs:
          - {to: [100, 0]}
          - {to: [100, 100], speed: 3}
        """)
    e = error(text)
    assert 'leg 2: unknown key "speed"' in str(e) and e.line == line_of(text, 'speed: 3')


@pytest.mark.parametrize('snippet, message', [
    ('fillet_radius_m: abc\nwaypoints: [[0, 0], [100, 0]]\n', 'fillet_radius_m must be a number'),
    ('fillet_radius_m: true\nwaypoints: [[0, 0], [100, 0]]\n', 'fillet_radius_m must be a number'),
    ('fillet_radius_m: -5\nwaypoints: [[0, 0], [100, 0]]\n', 'fillet_radius_m must be >= 0'),
    ('waypoints: 5\n', 'waypoints must be a list'),
    ('waypoints: [[0, 0], [1, 2, 3]]\n', 'waypoint 2 must be [x_m, y_m]'),
    ('waypoints: [[0, 0], "east"]\n', 'waypoint 2 must be [x_m, y_m] or a mapping'),
])
def test_wrong_types(snippet, message):
    text = HEAD + snippet
    e = error(text)
    assert message in str(e)
    assert e.line == len(HEAD.splitlines()) + 1


def test_missing_and_wrong_top_level_keys():
    e = error('name: x\nframe: enu\nwaypoints: [[0, 0], [1, 0]]\n')
    assert 'missing required key "source"' in str(e) and e.line == 1
    e = error('name: x\nsource: y\nframe: ned\nwaypoints: [[0, 0], [1, 0]]\n')
    assert 'frame must be one of enu, wgs84' in str(e) and e.line == 3
    e = error('name: x\nsource: y\nframe: wgs84\nwaypoints: [[0, 0], [1, 0]]\n')
    assert 'needs an "origin' in str(e) and e.line == 3
    e = error(HEAD + 'waypoints: [[0, 0], [1, 0]]\ncurve: {type: sine}\n')
    assert 'exactly one of' in str(e)
    e = error(HEAD + 'name: again\nwaypoints: [[0, 0], [1, 0]]\n')
    assert 'given twice' in str(e) and e.line == 4


def test_fillet_that_does_not_fit_names_the_waypoint_and_its_line():
    text = doc("""
        fillet_radius_m: 400
        waypoints:
          - [0, 0]
          - [0, 1000]
          - {x_m: 300, y_m: 1000, name: narrow}
          - [300, 0]
        """)
    e = error(text)
    # Two 90 deg corners 300 m apart; the second one's fillet (400 m) cannot fit.
    assert 'waypoint 3 "narrow"' in str(e) and 'does not fit' in str(e)
    assert 'fits both corners is 150.0 m' in str(e)             # 300 m / (tan 45 + tan 45)
    assert e.line == line_of(text, 'narrow')


def test_yaml_syntax_error_has_its_line():
    text = HEAD + 'waypoints: [[0, 0], [1, 0]\nother: 1\n'
    e = error(text)
    assert 'not valid YAML' in str(e) and e.line is not None


def test_missing_file_is_a_route_error(tmp_path):
    with pytest.raises(RouteError, match='cannot read'):
        load_route_yaml(tmp_path / 'nope.yaml')


def test_latlon_far_from_the_origin_is_refused():
    text = """name: geo
source: unit test
frame: wgs84
origin: {lat_deg: 60.0, lon_deg: 5.0}
waypoints:
  - [60.0, 5.0]
  - [61.0, 5.0]
"""
    e = error(text)
    assert 'km from the origin' in str(e) and e.line == 7
