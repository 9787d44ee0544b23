"""Simakis 1992 waypoint tables (ship_planner.waypoint_table, quarter_circle_routes): the figure eight and the
quarter-circle comparison routes, and table validation errors with row and line numbers."""
import math
import pathlib

import numpy as np
import pytest

from ship_planner.route_data import RouteError
from ship_planner.quarter_circle_routes import POINT_COUNTS, quarter_circle_points, table_texts
from ship_planner.waypoint_table import load_waypoint_table, parse_waypoint_table
from ship_sim.frames import wrap_angle

ROUTES = pathlib.Path(__file__).resolve().parents[2] / 'scenarios/routes'


@pytest.fixture(scope='module')
def eight():
    return load_waypoint_table(ROUTES / 'figure_eight_003.wpt', length_unit_m=1.0)


def test_figure_eight_legs_join_and_are_tangent_except_the_first_corner(eight):
    legs = eight.route.legs                      # Route() itself refuses legs that do not join
    assert [leg.kind for leg in legs] == ['line', 'line', 'arc', 'line', 'arc', 'arc', 'arc', 'arc',
                                          'line', 'arc', 'arc']
    turns = [float(wrap_angle(b.start_angle - a.end_angle)) for a, b in zip(legs[:-1], legs[1:])]
    assert turns[0] == pytest.approx(math.pi / 2)          # (15, 0): north -> east, a sharp corner
    assert np.allclose(turns[1:], 0.0, atol=1e-9)          # every other join is smooth


def test_figure_eight_geometry_by_hand(eight):
    legs = eight.route.legs
    arcs = [leg for leg in legs if leg.kind == 'arc']
    assert all(a.radius == pytest.approx(5.0) for a in arcs)
    # ICCW = 1 (rows 3, 10, 11) turns from +x (north) towards +y (east): starboard = clockwise in NED.
    assert [a.clockwise for a in arcs] == [True, False, False, False, False, True, True]
    # 15 + 10 straight, quarter circle, 2, full circle (4 quarters), 2, half circle; radius 5.
    assert eight.route.length == pytest.approx(29.0 + 5.0 * (math.pi / 2 + 2 * math.pi + math.pi))
    # The two loops turn opposite ways (what makes an eight): +360 deg low (corner + arcs), -360 deg up.
    sweep = [a.sweep * (1 if a.clockwise else -1) for a in arcs]
    assert math.pi / 2 + sweep[0] + sum(sweep[5:]) == pytest.approx(2 * math.pi)
    assert sum(sweep[1:5]) == pytest.approx(-2 * math.pi)
    # The upper loop is closed and the route passes its waist point (8, 15) twice.
    assert tuple(legs[4].start) == pytest.approx((8.0, 15.0)) and tuple(legs[7].end) == pytest.approx((8.0, 15.0))
    # The table does not close the lower loop: it ends at (6, 5), the run started at (0, 0).
    assert tuple(eight.route.end) == pytest.approx((6.0, 5.0))


def test_figure_eight_metadata_and_scaling(eight):
    assert 'Simakis 1992' in eight.source and eight.frame == 'simakis_xy'
    sw = eight.extras['switching']
    assert [s['mode'] for s in sw] == ['radius'] * 11             # TURN = 0 everywhere: distance to waypoint
    assert sw[0]['distance_m'] == 1.0 and sw[1]['distance_m'] == 0.1
    native = load_waypoint_table(ROUTES / 'figure_eight_003.wpt')
    assert native.extras['length_unit_m'] == pytest.approx(7.3 * 0.3048)
    mariner = load_waypoint_table(ROUTES / 'figure_eight_003.wpt', length_unit_m=160.93)
    assert mariner.route.length == pytest.approx(160.93 * eight.route.length)
    assert mariner.route.legs[2].radius == pytest.approx(5 * 160.93)


def test_quarter_circle_points_are_equally_spaced_on_the_circle():
    for n in POINT_COUNTS:
        p = quarter_circle_points(n)
        assert len(p) == n
        assert np.allclose(np.hypot(p[:, 0] - 0.0, p[:, 1] - 10.0), 10.0)
        chords = np.hypot(*np.diff(p, axis=0).T)
        assert np.allclose(chords, 2 * 10.0 * math.sin(math.pi / 4 / (n - 1)))
        assert p[0] == pytest.approx([0, 0]) and p[-1] == pytest.approx([10, 10])


def test_shipped_quarter_circle_files_are_what_the_generator_writes():
    for name, text in table_texts().items():
        assert (ROUTES / name).read_text(encoding='utf-8') == text, f'{name}: regenerate with quarter_circle_routes'


def test_quarter_circle_routes_approach_the_arc():
    arc = load_waypoint_table(ROUTES / 'quarter_circle_arc_003.wpt', length_unit_m=1.0).route
    assert len(arc.legs) == 1 and arc.legs[0].clockwise
    assert arc.legs[0].sweep == pytest.approx(math.pi / 2)
    assert arc.legs[0].start_angle == pytest.approx(0.0)      # tangent to the initial heading PSI = 0
    for n in POINT_COUNTS:
        poly = load_waypoint_table(ROUTES / f'quarter_circle_{n:02d}pts_003.wpt', length_unit_m=1.0).route
        assert len(poly.legs) == n - 1
        north, east, _ = poly.point_at(np.linspace(0.0, poly.length, 2001))
        # The chords cut inside the circle by at most the sagitta R (1 - cos(half the step angle)).
        r = np.hypot(north, east - 10.0)
        sagitta = 10.0 * (1.0 - math.cos(math.pi / 4 / (n - 1)))
        assert 10.0 - r.min() == pytest.approx(sagitta, rel=1e-3)
        assert r.max() == pytest.approx(10.0, abs=1e-5)


# ---- errors ----------------------------------------------------------------------------------------

HEAD = '#@ name: t\n#@ source: unit test\nx y TURN D PATH ICCW x0 y0\n'


def bad(text):
    with pytest.raises(RouteError) as exc:
        parse_waypoint_table(text, 'bad.wpt')
    return exc.value


@pytest.mark.parametrize('row, message', [
    ('15.0 0.0 0 1.0 0 0 0.0', 'expected 8 columns'),
    ('15.0 zero 0 1.0 0 0 0.0 0.0', 'column y must be a number'),
    ('15.0 nan 0 1.0 0 0 0.0 0.0', 'column y must be finite'),
    ('15.0 0.0 2 1.0 0 0 0.0 0.0', 'TURN must be 0 or 1'),
    ('15.0 0.0 0 -1 0 0 0.0 0.0', 'D (switching distance) must be >= 0'),
    ('10.0 0.0 0 1.0 0 0 0.0 0.0', 'zero-length leg'),             # row 1 ended at (10, 0) already
    ('15.0 5.0 0 0.1 1 1 10.0 0.0', 'arc centre (10, 0) is the arc start itself'),
])
def test_row_errors_name_row_and_line(row, message):
    e = bad(HEAD + '10.0 0.0 0 1.0 0 0 0.0 0.0\n' + row + '\n')
    assert message in str(e)
    assert e.row == 2 and e.line == 5 and str(e).startswith('bad.wpt: row 2 (line 5): ')


def test_arc_off_its_circle_gives_both_distances():
    # From (0, 0) about (0, 10): radius 10; the end (10, 11) is sqrt(101) = 10.0499 from the centre.
    e = bad(HEAD + '10.0 11.0 0 0.1 1 1 0.0 10.0\n')
    assert 'not on one circle' in str(e) and '10.0000' in str(e) and '10.0499' in str(e) and e.row == 1


def test_file_level_errors():
    assert 'at least 2 points' in str(bad('#@ name: t\n#@ source: s\n'))
    assert 'missing directive "#@ source' in str(bad('#@ name: t\n1 0 0 0 0 0 0 0\n'))
    e = bad('#@ name: t\n#@ sorce: s\n1 0 0 0 0 0 0 0\n')
    assert 'unknown directive' in str(e) and e.line == 2
    e = bad(HEAD + '#@ start: 0\n1 0 0 0 0 0 0 0\n')
    assert 'start must be two finite numbers' in str(e) and e.line == 4
