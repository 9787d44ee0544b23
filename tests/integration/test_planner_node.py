"""planner_node as a real process (colcon install tree) on a small synthetic chart.

The chart is an image written by the test: 100 x 60 pixels of 50 m (5 km east x 3 km north),
dark = land: an island x 2000..3000 m, y 800..2200 m (ENU) right across the straight line from
start (500, 1500) to goal (4500, 1500), and a coast band y < 300 m. The image convention
(ship_planner.chart.image_chart, the node's docstring): north up, one pixel per cell, the
lower-left pixel covers x, y in [0, res].

1. the node plans once and publishes nav_msgs/Path on `route` with reliable + transient_local
   QoS: a test node that subscribes AFTER the node has published still receives it (latched);
   the Path (frame 'map') decodes to a route whose ends are the start and the goal, and every
   point of it (lines and fillet arcs, sampled every 5 m) keeps the clearance from every land
   pixel, measured on the image itself as the distance to the pixel's square; the route file
   the node writes reads back as the same route;
2. a start on land, a goal inside the clearance, a clearance that leaves no navigable
   connection, a missing chart file and a raster above max_cells each end the node at start
   with exit code 2 and ONE error line that says what to change.
"""
import math

import numpy as np
import pytest
from nav_msgs.msg import Path
from PIL import Image

from ship_guidance.ros.path_msgs import path_msg_to_route
from ship_planner.route_loader import load_route
from ship_sim.ros.qos import LATCHED

NS = '/vessel_0'
RES = 50.0
W, H = 100, 60
START = (500.0, 1500.0)          # ENU (x east, y north), m
GOAL = (4500.0, 1500.0)
CLEARANCE = 150.0
FILLET = 300.0
# A small search so the test stays fast (~5 s of planning); the route only has to be valid.
SEARCH = {'candidates': 1, 'population': 30, 'generations': 50, 'seed': 3}


def land_mask():
    """(H, W) bool, row 0 = southernmost pixel row; pixel (r, c) covers x in [c, c+1] res,
    y in [r, r+1] res."""
    x = (np.arange(W) + 0.5) * RES
    y = (np.arange(H) + 0.5) * RES
    X, Y = np.meshgrid(x, y)
    island = (X > 2000.0) & (X < 3000.0) & (Y > 800.0) & (Y < 2200.0)
    coast = Y < 300.0
    return island | coast


@pytest.fixture
def chart_png(tmp_path):
    path = tmp_path / 'island.png'
    img = np.where(land_mask()[::-1], 0, 255).astype(np.uint8)   # image row 0 is the north edge
    Image.fromarray(img).save(path)
    return path


def params(chart, **extra):
    p = {'chart_file': str(chart), 'resolution_m': RES, 'points_frame': 'enu',
         'start_x_m': START[0], 'start_y_m': START[1], 'goal_x_m': GOAL[0], 'goal_y_m': GOAL[1],
         'clearance_m': CLEARANCE, 'fillet_radius_m': FILLET, **SEARCH}
    p.update(extra)
    return p


def distance_to_land(east, north):
    """Distance (m) from each point to the nearest land pixel, each pixel a res x res square."""
    r, c = np.nonzero(land_mask())
    cx, cy = (c + 0.5) * RES, (r + 0.5) * RES
    dx = np.maximum(np.abs(east[:, None] - cx[None]) - 0.5 * RES, 0.0)
    dy = np.maximum(np.abs(north[:, None] - cy[None]) - 0.5 * RES, 0.0)
    return np.hypot(dx, dy).min(axis=1)


def route_samples(route, step=5.0):
    s = np.linspace(0.0, route.length, int(math.ceil(route.length / step)) + 1)
    north, east, _ = route.point_at(s)
    return north, east


@pytest.mark.timeout(60)
def test_publishes_a_latched_route_that_keeps_the_clearance(ros_graph, chart_png, tmp_path):
    out = tmp_path / 'planned.yaml'
    node = ros_graph.start('ship_planner', 'planner_node', namespace=NS,
                           params=params(chart_png, route_file_out=str(out), route_name='island_test'))
    assert node.wait_for_output(r"route 'island_test' published", timeout=45.0), node.output()[-2000:]
    assert node.returncode is None, 'planner_node ended after publishing'

    # Subscribe only now: a latched (transient_local) route reaches a late joiner.
    tn = ros_graph.test_node()
    inbox = tn.subscribe(f'{NS}/route', Path, qos=LATCHED)
    msg = tn.wait_for_message(inbox, timeout=10.0)
    assert msg is not None, 'the late subscriber never got the route: is it latched?'
    assert msg.header.frame_id == 'map'
    route = path_msg_to_route(msg)

    n0, e0, _ = route.point_at(0.0)
    n1, e1, _ = route.point_at(route.length)
    assert math.hypot(e0 - START[0], n0 - START[1]) < 0.01
    assert math.hypot(e1 - GOAL[0], n1 - GOAL[1]) < 0.01

    north, east = route_samples(route)
    d = distance_to_land(east, north)
    assert d.min() >= CLEARANCE, f'route comes {d.min():.1f} m from land (clearance {CLEARANCE} m)'

    # The route file reads back as the same route (coordinates written to 1 cm, radii to 1 m).
    back = load_route(out)
    assert back.name == 'island_test' and back.frame == 'enu'
    assert abs(back.route.length - route.length) < 1.0
    nb, eb = route_samples(back.route)
    assert distance_to_land(eb, nb).min() >= CLEARANCE

    # The chart it planned on, latched too: every land pixel of the image is land in the grid
    # (the chart may extend past the image; cells there are what its reader made of them).
    from nav_msgs.msg import OccupancyGrid
    grid = tn.wait_for_message(tn.subscribe(f'{NS}/chart', OccupancyGrid, qos=LATCHED), 10.0)
    assert grid is not None and grid.header.frame_id == 'map'
    from ship_guidance.land_mask import LandMask
    mask = LandMask.from_occupancy(grid.data, grid.info.width, grid.info.height,
                                   grid.info.resolution, grid.info.origin.position.x,
                                   grid.info.origin.position.y)
    r, c = np.indices(land_mask().shape)
    centres = np.stack([(r + 0.5) * RES, (c + 0.5) * RES], axis=-1)      # NED (north, east)
    assert np.array_equal(mask.hits(centres), land_mask())

    assert ros_graph.stop(node) == 0


# (parameters that break the plan, words the one error line must contain)
REFUSED = {
    'start_on_land': ({'start_x_m': 2500.0, 'start_y_m': 1500.0}, ('start', 'on land', 'move it')),
    'goal_in_clearance': ({'goal_x_m': 3080.0}, ('goal', 'inside the clearance', 'move it',
                                                 'lower the clearance')),
    # 800 m + grid margin closes both gaps round the island (800 m north, 500 m south) while the
    # ends stay 1200 m from land
    'no_connection': ({'clearance_m': 800.0}, ('no navigable connection', 'lower the clearance')),
    'missing_chart_file': ({'chart_file': '/no/such/chart.png'}, ('chart', 'does not exist')),
    'raster_too_large': ({'max_cells': 1000}, ('6,000 cells', 'resolution of at least')),
}


@pytest.mark.timeout(60)
@pytest.mark.parametrize('case', sorted(REFUSED))
def test_refuses_an_impossible_plan_in_one_line_with_exit_2(ros_graph, chart_png, case):
    extra, words = REFUSED[case]
    node = ros_graph.start('ship_planner', 'planner_node', namespace=NS, params=params(chart_png, **extra))
    assert node.wait(timeout=30.0) == 2, node.output()[-2000:]
    errors = [line for line in node.stderr().splitlines() if line.startswith('planner_node:')]
    assert len(errors) == 1, node.stderr()
    for word in words:
        assert word in errors[0], errors[0]
    # Everything else on stderr is the progress log; nothing was published.
    others = [line for line in node.output().splitlines()
              if line.strip() and not line.startswith(('planner_node:', '[INFO]'))]
    assert not others, others


@pytest.mark.timeout(60)
def test_sigint_while_planning_ends_the_node_at_once_without_a_traceback(ros_graph, chart_png):
    """Planning runs in a callback; a stop signal is only noted there (ship_sim.ros.run), and
    the planner's progress calls poll it (stop_requested), so a long search ends at once."""
    import signal
    import time
    long_search = dict(SEARCH, population=200, generations=100000)
    node = ros_graph.start('ship_planner', 'planner_node', namespace=NS,
                           params=params(chart_png, **long_search))
    assert node.wait_for_output(r'planning: clearance', timeout=30.0), node.report()
    node.popen.send_signal(signal.SIGINT)
    t0 = time.monotonic()
    assert node.wait(timeout=10.0) == 0, node.report()
    print(f'planner_node ended {time.monotonic() - t0:.2f} s after SIGINT')
    assert 'Traceback' not in node.output() and 'FATAL' not in node.output()
