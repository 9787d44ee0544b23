"""The optimal-route planner on the real shoreline (GSHHG full resolution from the roaring-landmask
wheel, offline): a small box at Busan, round Yeongdo. Loading the shoreline data takes 5-10 s
(once per process); the planning itself a few seconds."""
import math

import numpy as np
import pytest

pytest.importorskip('roaring_landmask')

from ship_planner.chart import shoreline_chart
from ship_planner.optimal_route import PlannerConfig, plan_route

BOX = (35.03, 35.11, 129.01, 129.11)          # Busan south port, Yeongdo, the approaches
START = (35.060, 129.040)                      # south of Songdo, west of Yeongdo
GOAL = (35.090, 129.085)                       # east of Yeongdo, off the north port breakwaters


def test_route_round_yeongdo_exists_keeps_the_clearance_and_reports_its_ratio(tmp_path):
    chart = shoreline_chart(*BOX, 50.0, cache_dir=str(tmp_path))
    start = np.array(chart.to_ned(*START))
    goal = np.array(chart.to_ned(*GOAL))
    cfg = PlannerConfig(clearance_m=100.0, fillet_radius_m=300.0, candidates=1, population=30, generations=100,
                        stall_generations=30)
    plan = plan_route(chart, start, goal, cfg)
    # Yeongdo lies between: the straight line crosses land
    t = np.linspace(0.0, 1.0, 400)[:, None]
    assert not chart.lookup(chart.water, start + t * (goal - start)).all()
    # the route keeps 100 m from the shoreline, checked on a raster 2.5 times finer
    fine = shoreline_chart(*BOX, 20.0, origin=chart.origin, cache_dir=str(tmp_path))
    route = plan.route()
    pts = []
    for leg in route.legs:
        s = np.linspace(0.0, leg.length, max(2, int(leg.length / 2.0)))
        n, e, _ = leg.point_at(s)
        pts.append(np.column_stack([n, e]))
    pts = np.vstack(pts)
    i, j, inside = fine.cell_index(pts)
    assert inside.all()
    d = fine.distance_to_land()[i, j]
    assert d.min() >= cfg.clearance_m - math.sqrt(2.0) * fine.resolution_m
    # never shorter than the shortest path at the same clearance, and close to it
    assert plan.length >= plan.shortest.length - 1e-6
    print(f'\nYeongdo: route {plan.length:.0f} m, shortest path {plan.shortest.length:.0f} m, '
          f'ratio {plan.length_ratio:.4f}, heading change {math.degrees(plan.heading_change):.0f} deg '
          f'vs {math.degrees(plan.shortest.heading_change):.0f} deg, min distance on the fine raster {d.min():.0f} m')
    assert plan.length_ratio < 1.15
