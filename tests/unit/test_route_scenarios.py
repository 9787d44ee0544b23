"""The shipped route files: every one loads and cites its source; the designed routes have the
turns they claim (Lee 2004 course changes, Mariner-sized radii, smooth joins)."""
import math
import pathlib
import re

import numpy as np
import pytest

from ship_planner.route_loader import load_route
from ship_planner.route_data import RouteError
from ship_sim.frames import wrap_angle

ROOT = pathlib.Path(__file__).resolve().parents[2]
FILES = sorted(list((ROOT / 'scenarios/routes').glob('*.yaml')) + list((ROOT / 'scenarios/routes').glob('*.wpt'))
               + list((ROOT / 'ros_ws/src/ship_planner/config/routes').glob('*.yaml')))
#: A citation by author and year, e.g. 'Simakis 1992', 'Martinsen and Lekkas 2018'.
CITATION = re.compile(r'\b[A-Z][A-Za-z-]+(?: and [A-Z][A-Za-z-]+| et al\.)? (?:19|20)\d\d\b')
MARINER_MIN_RADIUS_M = 800.0     # ~1.4 x the Mariner's steady turning radius at 35 deg (556 m)


def load(name):
    return load_route(ROOT / 'scenarios/routes' / name)


def turns(route):
    return np.array([float(wrap_angle(b.start_angle - a.end_angle)) for a, b in zip(route.legs[:-1], route.legs[1:])])


def test_the_expected_files_are_shipped():
    names = {f.name for f in FILES}
    for expected in ('figure_eight_003.wpt', 'quarter_circle_arc_003.wpt', 'quarter_circle_13pts_003.wpt',
                     'route_following_mariner_004.yaml', 'route_following_tanker_004.yaml',
                     'curved_path_mariner_000.yaml', 'curved_path_container_000.yaml',
                     'curved_path_tanker_000.yaml', 'curved_spline_mariner_000.yaml', 'flagship_mariner.yaml',
                     'example_enu.yaml', 'example_wgs84.yaml'):
        assert expected in names


@pytest.mark.parametrize('path', FILES, ids=[f.name for f in FILES])
def test_every_route_file_loads_and_cites_a_source(path):
    plan = load_route(path)
    assert plan.name == path.stem
    assert plan.route.length > 0.0
    assert CITATION.search(plan.source) or 'designed' in plan.source.lower()


@pytest.mark.parametrize('name, kink', [
    ('flagship_mariner.yaml', 1e-9), ('route_following_mariner_004.yaml', 1e-9),
    ('route_following_tanker_004.yaml', 1e-9),
    # Sampled curves are tangent arcs through the samples: each leaves its sample along the exact
    # tangent and arrives at the next off by ~ |dkappa/ds| h^2 / 6 (3e-5 rad at h = 10 m).
    ('curved_path_mariner_000.yaml', 1e-4), ('curved_spline_mariner_000.yaml', 1e-4)])
def test_designed_routes_are_smooth(name, kink):
    assert np.max(np.abs(turns(load(name).route))) < kink


@pytest.mark.parametrize('name', ['flagship_mariner.yaml', 'route_following_mariner_004.yaml',
                                  'curved_path_mariner_000.yaml', 'curved_spline_mariner_000.yaml'])
def test_mariner_routes_turn_no_tighter_than_the_mariner_can_follow(name):
    route = load(name).route
    assert 1.0 / np.max(np.abs(route.curvatures)) >= MARINER_MIN_RADIUS_M - 1e-6


@pytest.mark.parametrize('name, radius', [('route_following_mariner_004.yaml', 800.0),
                                          ('route_following_tanker_004.yaml', 1500.0)])
def test_lee_routes_have_the_course_changes_of_its_tests(name, radius):
    arcs = [leg for leg in load(name).route.legs if leg.kind == 'arc']
    assert np.degrees([a.sweep for a in arcs]) == pytest.approx([30, 45, 60, 90, 45])
    assert [a.clockwise for a in arcs] == [False, True, False, True, False]     # port, stbd, port, stbd, port
    assert all(a.radius == pytest.approx(radius) for a in arcs)


def test_flagship_route():
    plan = load('flagship_mariner.yaml')
    assert len(plan.waypoints_ned) == 5                        # 4 legs
    assert 3e3 < plan.route.length < 15e3
    arcs = [leg for leg in plan.route.legs if leg.kind == 'arc']
    assert len(arcs) == 3 and {a.clockwise for a in arcs} == {True, False}
    assert all(800.0 <= a.radius <= 1500.0 for a in arcs)


def test_unknown_extension_is_refused(tmp_path):
    with pytest.raises(RouteError, match='unknown route file type'):
        load_route(tmp_path / 'route.csv')


def test_spline_smallest_radius_is_as_documented():
    r = 1.0 / np.max(np.abs(load('curved_spline_mariner_000.yaml').route.curvatures))
    assert r == pytest.approx(1250.0, rel=0.02)
    assert math.isfinite(r)
