"""Optimal routes on synthetic charts with known answers (ship_planner.optimal_route and its
parts: centre-line candidates, convex corridors, GA, fillets, route file)."""
import math

import numpy as np
import pytest

from ship_planner import ga
from ship_planner.chart import ChartError, polygon_chart, segments_clear
from ship_planner.corridor import build_corridor, polygon_clear
from ship_planner.optimal_route import PlannerConfig, plan_route, route_yaml_text
from ship_planner.yaml_route_reader import parse_route_yaml
from ship_planner.shortest_path import polyline_length

FAST = dict(population=40, generations=150, stall_generations=40)


def circle(centre, radius, n=240):
    th = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.column_stack([centre[0] + radius * np.cos(th), centre[1] + radius * np.sin(th)])


def rect(n0, n1, e0, e1):
    return np.array([[n0, e0], [n1, e0], [n1, e1], [n0, e1]], dtype=float)


def around_circle_length(a, b, centre, radius, far_side=False):
    """Shortest path from a to b around a disc (tangent - arc - tangent), both points outside;
    far_side: the way round the other side of the disc."""
    a, b, c = (np.asarray(v, float) for v in (a, b, centre))
    da, db = np.hypot(*(a - c)), np.hypot(*(b - c))
    ta, tb = math.sqrt(da * da - radius * radius), math.sqrt(db * db - radius * radius)
    total = math.acos(np.dot(a - c, b - c) / (da * db))
    if far_side:
        total = 2.0 * math.pi - total
    arc = total - math.acos(radius / da) - math.acos(radius / db)
    if arc <= 0.0:
        return float(np.hypot(*(b - a)))
    return ta + tb + radius * arc


def route_samples(plan, step=5.0):
    route = plan.route()
    out = []
    for leg in route.legs:
        t = np.linspace(0.0, leg.length, max(2, int(math.ceil(leg.length / step)) + 1))
        n, e, _ = leg.point_at(t)
        out.append(np.column_stack([n, e]))
    return np.vstack(out)


def distance_to_polygon(points, poly):
    """Exact distance (m) from points to a polygon's boundary (its inside counts as 0)."""
    from matplotlib.path import Path

    p = np.asarray(points, float)
    a, b = poly, np.roll(poly, -1, axis=0)
    ab = b - a
    t = np.clip(np.einsum('pkd,kd->pk', p[:, None, :] - a[None], ab) / np.sum(ab * ab, axis=1), 0.0, 1.0)
    foot = a[None] + t[..., None] * ab[None]
    d = np.hypot(*(p[:, None, :] - foot).transpose(2, 0, 1)).min(axis=1)
    d[Path(poly).contains_points(p)] = 0.0
    return d


# ---- known answers ---------------------------------------------------------------------------
def test_straight_channel_gives_a_straight_route():
    walls = [rect(300.0, 1000.0, -500.0, 6500.0), rect(-1000.0, -300.0, -500.0, 6500.0)]
    chart = polygon_chart(walls, (-1000.0, 1000.0, -500.0, 6500.0), 25.0)
    cfg = PlannerConfig(clearance_m=100.0, fillet_radius_m=500.0, **FAST)
    plan = plan_route(chart, (0.0, 0.0), (0.0, 6000.0), cfg)
    assert len(plan.waypoints) == 2
    assert plan.length == pytest.approx(6000.0, abs=1e-6)
    assert plan.heading_change == 0.0
    assert plan.length_ratio == pytest.approx(1.0, abs=1e-9)


@pytest.fixture(scope='module')
def island():
    """A disc island of radius 1000 m centred 300 m north of the line from start to goal."""
    centre, radius = (300.0, 0.0), 1000.0
    chart = polygon_chart([circle(centre, radius)], (-4000.0, 4000.0, -6000.0, 6000.0), 50.0)
    cfg = PlannerConfig(clearance_m=200.0, fillet_radius_m=0.0, energy_weight=0.0, **FAST)
    plan = plan_route(chart, (0.0, -5000.0), (0.0, 5000.0), cfg)
    return chart, plan, centre, radius, cfg


def test_single_island_route_goes_round_the_shorter_side(island):
    chart, plan, centre, radius, cfg = island
    pts = route_samples(plan)
    abeam = pts[np.abs(pts[:, 1] - centre[1]) < 50.0]
    assert len(abeam) and np.all(abeam[:, 0] < centre[0] - radius)          # south of the island
    # the north side would be longer: even its exact lower bound exceeds the route
    north = around_circle_length((0.0, -5000.0), (0.0, 5000.0), centre, radius + cfg.clearance_m, far_side=True)
    assert plan.length < north


def test_route_never_shorter_than_the_shortest_path_and_within_the_stated_ratio(island):
    chart, plan, centre, radius, cfg = island
    lower = around_circle_length((0.0, -5000.0), (0.0, 5000.0), centre, radius + cfg.clearance_m)
    # the baseline is a clear path (so >= the exact lower bound) and nearly exact: the raster's
    # clearance zone reaches up to one cell + the grid margin further than the disc
    upper = around_circle_length((0.0, -5000.0), (0.0, 5000.0), centre,
                                 radius + cfg.clearance_m + chart.grid_margin + chart.resolution_m)
    assert lower <= plan.shortest.length <= upper
    assert plan.length >= plan.shortest.length - 1e-6
    assert plan.length_ratio <= 1.01            # stated ratio for distance-only planning (w = 0, R = 0)


def test_ga_alone_on_a_centre_line_corridor_comes_within_one_percent_of_the_shortest_path(island):
    # without the shortest path as a candidate the GA must find the short way itself: the
    # centre line of the open water runs 1.5 km further from the island than the shortest path
    chart, _, centre, radius, cfg = island
    own = PlannerConfig(**{**cfg.__dict__, 'path_candidates': False, 'refine': False})
    plan = plan_route(chart, (0.0, -5000.0), (0.0, 5000.0), own)
    assert set(plan.origins) == {'centre line'}
    centre_line = polyline_length(plan.candidates[plan.chosen])
    assert centre_line > 1.2 * plan.shortest.length                    # the GA has work to do
    assert plan.shortest.length - 1e-6 <= plan.length <= 1.01 * plan.shortest.length


def test_route_keeps_the_clearance_checked_exactly_and_on_a_finer_raster():
    centre, radius, clearance = (300.0, 0.0), 1000.0, 200.0
    poly = circle(centre, radius)
    chart = polygon_chart([poly], (-4000.0, 4000.0, -6000.0, 6000.0), 50.0)
    cfg = PlannerConfig(clearance_m=clearance, fillet_radius_m=800.0, **FAST)
    plan = plan_route(chart, (0.0, -5000.0), (0.0, 5000.0), cfg)
    assert any(r > 0 for r in plan.radii)
    pts = route_samples(plan, step=2.0)
    assert distance_to_polygon(pts, poly).min() >= clearance            # exact geometry
    fine = polygon_chart([poly], (-4000.0, 4000.0, -6000.0, 6000.0), 10.0)
    i, j, inside = fine.cell_index(pts)
    assert inside.all()
    d_fine = fine.distance_to_land()[i, j]
    assert d_fine.min() >= clearance - math.sqrt(2.0) * fine.resolution_m
    # the shortest path obeys the same constraint
    sp = np.vstack([np.linspace(p, q, 200) for p, q in zip(plan.shortest.points[:-1], plan.shortest.points[1:])])
    assert distance_to_polygon(sp, poly).min() >= clearance


def test_fillets_use_the_vessel_radius_and_the_route_file_reads_back():
    chart = polygon_chart([circle((300.0, 0.0), 1000.0)], (-4000.0, 4000.0, -6000.0, 6000.0), 50.0)
    cfg = PlannerConfig(clearance_m=200.0, fillet_radius_m=800.0, **FAST)
    plan = plan_route(chart, (0.0, -5000.0), (0.0, 5000.0), cfg)
    arcs = [s for s in plan.segments if hasattr(s, 'center')]
    assert arcs and all(np.hypot(*(np.array(a.start) - a.center)) == pytest.approx(r, rel=1e-9)
                        for a, r in zip(arcs, [r for r in plan.radii if r > 0]))
    assert np.all((plan.radii == 800.0) | (plan.radii >= 400.0))      # never below the minimum (R / 2)
    text = route_yaml_text(plan, chart, 'island_test', 'test')
    back = parse_route_yaml(text, 'island_test.yaml')
    assert back.frame == 'enu'
    assert np.allclose(back.waypoints_ned, plan.waypoints, atol=0.01)
    assert back.route.length == pytest.approx(plan.length, abs=0.05)


def test_planning_is_deterministic_for_a_seed(island):
    chart, plan, centre, radius, cfg = island
    again = plan_route(chart, (0.0, -5000.0), (0.0, 5000.0), cfg)
    assert np.array_equal(again.waypoints, plan.waypoints)


def test_two_islands_candidates_and_corridor_polygons_are_convex_and_clear():
    polys = [circle((0.0, 0.0), 700.0), circle((1500.0, 2500.0), 600.0)]
    chart = polygon_chart(polys, (-3000.0, 4000.0, -4000.0, 6000.0), 50.0)
    free = chart.free_mask(150.0)
    plan = plan_route(chart, (-200.0, -3500.0), (1000.0, 5500.0),
                      PlannerConfig(clearance_m=150.0, fillet_radius_m=0.0, **FAST))
    assert len(plan.candidates) >= 2
    rng = np.random.default_rng(0)
    for cand in plan.candidates:
        cor = build_corridor(chart, free, cand, polyline_length(cand) / 12)
        for poly in cor.polygons():
            assert polygon_clear(chart, free, poly)
        # any point on each crossing line gives clear legs: the convex-polygon guarantee
        t = rng.random((50, cor.n))
        t[0], t[1], t[2] = 0.0, 1.0, 0.5                 # the port ends, the starboard ends, the middles
        for row in t:
            pts = np.vstack([cor.start, cor.waypoints(row), cor.goal])
            assert segments_clear(chart, free, pts[:-1], pts[1:]).all()


# ---- the GA on its own -------------------------------------------------------------------------
def test_real_coded_ga_finds_a_known_minimum_and_repeats_with_its_seed():
    target = np.linspace(0.1, 0.9, 8)

    def cost(x):
        return np.sum((x - target) ** 2, axis=1)

    r1 = ga.minimize(cost, 8, population=40, generations=300, seed=3)
    r2 = ga.minimize(cost, 8, population=40, generations=300, seed=3)
    assert np.array_equal(r1.x, r2.x)
    assert np.abs(r1.x - target).max() < 0.02
    assert r1.history == sorted(r1.history, reverse=True)        # elitism: the best never gets worse
    x, f, _ = ga.refine(cost, r1.x)
    assert f <= r1.cost and np.abs(x - target).max() < 1e-3


# ---- errors ------------------------------------------------------------------------------------
@pytest.fixture(scope='module')
def harbour():
    """An island and a closed lagoon (water ringed by land)."""
    ring = [rect(2000.0, 3000.0, 2000.0, 3000.0), rect(2300.0, 2700.0, 2300.0, 2700.0)]
    return polygon_chart([circle((0.0, 0.0), 500.0), ring], (-2000.0, 4000.0, -2000.0, 4000.0), 50.0)


def test_start_on_land_says_so(harbour):
    with pytest.raises(ChartError, match='start .* is on land: move it into open water'):
        plan_route(harbour, (0.0, 0.0), (-1500.0, 1500.0), PlannerConfig(clearance_m=100.0))


def test_goal_inside_the_clearance_names_the_clearance_that_would_work(harbour):
    with pytest.raises(ChartError) as err:
        plan_route(harbour, (-1500.0, -1500.0), (0.0, 600.0), PlannerConfig(clearance_m=300.0))
    msg = str(err.value)
    assert 'goal' in msg and 'inside the clearance of 300 m' in msg
    allowed = float(msg.split('lower the clearance to ')[1].split(' m')[0])
    # the goal is ~100 m from the island's edge; land cell centres are within a cell of it
    assert 0.0 < allowed < 100.0


def test_no_navigable_connection_is_reported(harbour):
    with pytest.raises(ChartError, match='no navigable connection between start and goal'):
        plan_route(harbour, (-1500.0, -1500.0), (2500.0, 2500.0), PlannerConfig(clearance_m=50.0))


def test_point_outside_the_chart_is_reported(harbour):
    with pytest.raises(ChartError, match='outside the chart'):
        plan_route(harbour, (-1500.0, -1500.0), (9000.0, 0.0), PlannerConfig(clearance_m=50.0))
