"""planner_node: plans an optimal route on a chart once at start and publishes it on `route`.

Method: ship_planner.optimal_route (Lee 2004, Chapter 3: closing + thinning of the navigable-water
image -> candidate routes, adjacent convex polygons -> crossing lines, real-coded GA trading
distance against turning; fillets sized for the vessel). Charts: ship_planner.chart (GSHHG / OSM
shoreline of a latitude/longitude box, an S-57 ENC cell, or an image with dark land).

Output: the same contract as route_node: nav_msgs/Path on `route`, ENU, frame 'map', reliable +
transient_local depth 1 (ship_sim.ros.qos.LATCHED), encoded by
ship_guidance.ros.path_msgs.route_to_path_msg (lines and fillet arcs exactly). The 'map' frame is
the tangent plane at the chart's origin (origin_lat_deg/lon_deg, default the box centre), the same
frame route_node gives for the route file this node can write (route_file_out).

Also `chart` (nav_msgs/OccupancyGrid, latched, published before the route): the raster it planned
on, 100 = land or too shallow (ship_planner.ros.chart_msgs); colav_node's `chart_topic` takes it for
SB-MPC's grounding cost, RViz and Foxglove draw it as a map.

Parameters (all read-only; see config/planner.yaml for a commented example):
  chart_file          '' for the real shoreline of the box; else an S-57 ENC cell (.000) or an
                      image (north up, dark land, light water, one pixel per resolution_m cell,
                      lower-left pixel centre at (res/2, res/2) m ENU)
  shoreline           gshhg | osm (shoreline data for the box)
  box_lat_min_deg, box_lat_max_deg, box_lon_min_deg, box_lon_max_deg
                      chart box (deg); needed for the shoreline, optional for an ENC cell
  origin_lat_deg, origin_lon_deg   origin of the 'map' frame (deg; nan: the box centre); with an
                      image chart it geo-references the image's (0, 0)
  points_frame        wgs84 (start/goal_lat/lon_deg) | enu (start/goal_x/y_m: metres east and
                      north of the origin, or in the image's frame)
  start_*, goal_*     the two ends (nan = not given; the frame's pair must be given)
  resolution_m, max_cells, draft_m, cache_dir, use_cache    chart raster
  clearance_m         distance kept from land (m)
  turning_diameter_m  vessel turning diameter: fillet radius = suggest_fillet_radius(D) (= D)
  fillet_radius_m     fillet radius (m), used instead of the turning diameter when > 0
  min_fillet_radius_m smallest radius a tight corner may fall back to (0: half the radius)
  energy_weight       metres of sailing worth one radian of course change
  candidates, max_lines, population, generations, seed, refine    the search
  route_file_out      '' or a route YAML file to write (schema ship_planner.route_yaml)
  route_name          name written in that file
  max_arc_step_m      longest sub-arc between two Path poses (m)

The constructor only checks the parameters; planning runs once the node spins (a one-shot
timer: the node is on the graph while it plans), with progress logged from start to end (chart
build, candidates, GA generations every 50, result); Ctrl-C or SIGTERM during planning ends the
node at the next progress line. Any problem (a bad parameter, a point on land or inside the
clearance, no navigable connection, a box too large for the resolution, an unreadable chart file)
ends the node with ONE line on stderr, naming the parameter or carrying ChartError's suggested
fix, and exit code 2 (as ship_sim.ros.run.run_node does at start); it never publishes a fallback
straight line.
Replanning on a parameter change is not supported: restart the node.
"""
import math
import os
import sys
import time

from nav_msgs.msg import OccupancyGrid, Path
from rclpy.clock import Clock, ClockType
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

from ship_guidance.ros.path_msgs import route_to_path_msg
from ship_planner.chart import (IMAGE_EXTENSIONS, ChartError, chart_from_file,
                                enc_chart, shoreline_chart)
from ship_planner.fillets import suggest_fillet_radius
from ship_planner.optimal_route import PlannerConfig, plan_route, route_yaml_text
from ship_planner.ros.chart_msgs import chart_to_occupancy_grid
from ship_planner.route_loader import RouteError
from ship_planner.yaml_route_reader import load_route_yaml
from ship_sim.frames import enu_to_ned_xy
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.qos import LATCHED
from ship_sim.ros.run import finish, run_node, stop_requested
from ship_planner.schema import BOX_KEYS, PLANNER_NODE

class PlannerNode(Node):
    def __init__(self):
        super().__init__('planner_node')
        self.params = NodeParameters(self, PLANNER_NODE)
        self._t0 = time.perf_counter()
        self._p = self._declare_all()
        self.pub = self.create_publisher(Path, 'route', LATCHED)
        self.pub_chart = self.create_publisher(OccupancyGrid, 'chart', LATCHED)
        # Plan once the node spins (it is on the graph meanwhile): a one-shot steady timer, so
        # it fires without /clock under use_sim_time.
        self._plan_timer = self.create_timer(0.0, self._plan_once,
                                             clock=Clock(clock_type=ClockType.STEADY_TIME))
        self.get_logger().info('parameters accepted; planning starts as soon as the node spins')

    def _plan_once(self):
        self._plan_timer.cancel()
        try:
            self._plan_and_publish(self._p)
        except ParameterError as exc:
            # The same one line and exit code as a refusal at start (ship_sim.ros.run.run_node).
            prog = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else 'planner_node'
            print(f'{prog}: {exc}', file=sys.stderr, flush=True)
            finish(self, 2)
        except ExternalShutdownException:
            pass   # Ctrl-C or SIGTERM while planning: the spin ends with the context

    def _plan_and_publish(self, p):
        self._say('planning the route')
        chart, start, goal = self._chart_and_points(p)
        plan = self._plan(p, chart, start, goal)
        if p['route_file_out']:
            self._write_route_file(p, chart, plan)
        stamp = self.get_clock().now().to_msg()
        self.pub_chart.publish(chart_to_occupancy_grid(chart, stamp))   # before the route
        msg = route_to_path_msg(plan.route(), stamp, p['max_arc_step_m'])
        self.pub.publish(msg)
        self.get_logger().info(
            f"route '{p['route_name']}' published: {len(plan.waypoints)} waypoints, {plan.length:.1f} m "
            f'(shortest path {plan.shortest.length:.1f} m, ratio {plan.length_ratio:.4f}), {len(msg.poses)} poses; '
            f'planning {plan.timings["total"]:.1f} s, {time.perf_counter() - self._t0:.1f} s since start')

    # ---- parameters ----------------------------------------------------------------------------
    def _declare_all(self):
        p = self.params.declare_schema()
        self._check_combinations(p)
        return p

    def _check_combinations(self, p):
        """What a single range cannot say: which of the optional values must be given together."""
        box = [p[k] for k in BOX_KEYS]
        given = [not math.isnan(v) for v in box]
        if any(given) and not all(given):
            missing = next(k for k, g in zip(BOX_KEYS, given) if not g)
            raise ParameterError(missing, p[missing], 'give all four box_*_deg values or none')
        if all(given):
            for lo, hi in ((BOX_KEYS[0], BOX_KEYS[1]), (BOX_KEYS[2], BOX_KEYS[3])):
                if not p[lo] < p[hi]:
                    raise ParameterError(hi, p[hi], f'more than {lo} = {p[lo]:g}')
        elif not p['chart_file']:
            raise ParameterError(BOX_KEYS[0], box[0], "a latitude: the shoreline chart needs the box "
                                 "(box_*_deg), or give chart_file")
        if math.isnan(p['origin_lat_deg']) != math.isnan(p['origin_lon_deg']):
            name = 'origin_lat_deg' if math.isnan(p['origin_lat_deg']) else 'origin_lon_deg'
            raise ParameterError(name, p[name], 'give both origin_lat_deg and origin_lon_deg, or neither')
        keys = ('lat_deg', 'lon_deg') if p['points_frame'] == 'wgs84' else ('x_m', 'y_m')
        for end in ('start', 'goal'):
            for axis in keys:
                name = f'{end}_{axis}'
                if math.isnan(p[name]):
                    raise ParameterError(name, p[name], f"a finite number: points_frame is {p['points_frame']}, "
                                         f"so {end}_{keys[0]} and {end}_{keys[1]} must be given")
        image = p['chart_file'].lower().endswith(IMAGE_EXTENSIONS)
        if image and p['points_frame'] == 'wgs84' and math.isnan(p['origin_lat_deg']):
            raise ParameterError('points_frame', 'wgs84', "enu for an image chart, unless origin_lat_deg and "
                                 'origin_lon_deg geo-reference it')

    # ---- planning --------------------------------------------------------------------------------
    def _say(self, text):
        # Called by the pure modules between steps: a Ctrl-C or SIGTERM ends the planning here.
        if stop_requested(self):
            raise ExternalShutdownException()
        self.get_logger().info(f'[{time.perf_counter() - self._t0:6.1f} s] {text}')

    def _chart_and_points(self, p):
        origin = None if math.isnan(p['origin_lat_deg']) else (p['origin_lat_deg'], p['origin_lon_deg'])
        box = None if math.isnan(p[BOX_KEYS[0]]) else tuple(p[k] for k in BOX_KEYS)
        path = p['chart_file']
        self._say(f'building the chart ({path or p["shoreline"] + " shoreline"}, {p["resolution_m"]:g} m cells)')
        try:
            if not path:
                chart = shoreline_chart(*box, p['resolution_m'], origin=origin, provider=p['shoreline'],
                                        cache_dir=p['cache_dir'] or None, max_cells=p['max_cells'],
                                        use_cache=p['use_cache'], progress=self._say)
            elif path.lower().endswith('.000'):
                chart = enc_chart(path, p['resolution_m'], draft_m=p['draft_m'] or None, box=box, origin=origin,
                                  max_cells=p['max_cells'], progress=self._say)
            else:
                chart = chart_from_file(path, p['resolution_m'], origin=origin, max_cells=p['max_cells'])
        except ChartError as exc:
            raise ParameterError('chart_file' if path else 'resolution_m',
                                 message=f'cannot build the chart: {exc}') from None
        self._say(f'chart: {chart.shape[0]} x {chart.shape[1]} cells, {chart.source}')
        try:
            if p['points_frame'] == 'wgs84':
                start = chart.to_ned(p['start_lat_deg'], p['start_lon_deg'])
                goal = chart.to_ned(p['goal_lat_deg'], p['goal_lon_deg'])
            else:
                start = enu_to_ned_xy(p['start_x_m'], p['start_y_m'])
                goal = enu_to_ned_xy(p['goal_x_m'], p['goal_y_m'])
        except ChartError as exc:
            raise ParameterError('points_frame', message=f'points_frame: {exc}') from None
        return chart, [float(v) for v in start], [float(v) for v in goal]

    def _plan(self, p, chart, start, goal):
        if p['fillet_radius_m'] > 0.0:
            radius = p['fillet_radius_m']
        elif p['turning_diameter_m'] > 0.0:
            radius = suggest_fillet_radius(p['turning_diameter_m'])
        else:
            radius = 0.0
        if p['min_fillet_radius_m'] > radius:
            raise ParameterError('min_fillet_radius_m', p['min_fillet_radius_m'],
                                 f'at most the fillet radius ({radius:g} m from fillet_radius_m / turning_diameter_m)')
        self._fillet_radius = radius
        cfg = PlannerConfig(clearance_m=p['clearance_m'], fillet_radius_m=radius,
                            min_fillet_radius_m=p['min_fillet_radius_m'] or None, energy_weight=p['energy_weight'],
                            candidates=p['candidates'], max_lines=p['max_lines'], population=p['population'],
                            generations=p['generations'], seed=p['seed'], refine=p['refine'])
        self._say(f'planning: clearance {cfg.clearance_m:g} m, fillet radius {radius:g} m, energy weight '
                  f'{cfg.energy_weight:g} m/rad, GA {cfg.population} x {cfg.generations} (seed {cfg.seed})')
        try:
            return plan_route(chart, start, goal, cfg, progress=self._say)
        except ChartError as exc:
            raise ParameterError('route', message=f'cannot plan the route: {exc}') from None

    def _write_route_file(self, p, chart, plan):
        out = os.path.abspath(p['route_file_out'])
        cfg = plan.config
        comments = [
            'Planned by ship_planner planner_node (ship_planner.optimal_route: Lee 2004, Chapter 3).',
            f'Chart: {chart.source}; clearance {cfg.clearance_m:g} m (+ {chart.grid_margin:.0f} m grid margin).',
            f'Route {plan.length / 1e3:.3f} km with fillets; exact-grid shortest path '
            f'{plan.shortest.length / 1e3:.3f} km (ratio {plan.length_ratio:.4f}); planning '
            f'{plan.timings["total"]:.1f} s.',
            '',
        ]
        text = route_yaml_text(
            plan, chart, p['route_name'], f'planned by planner_node on {chart.source}; method of Lee 2004, '
            'Chapter 3 (ship_planner.optimal_route)',
            description=f'Optimal route, clearance {cfg.clearance_m:g} m, fillet radius {self._fillet_radius:g} m, '
                        f'energy weight {cfg.energy_weight:g} m/rad', comments=comments)
        try:
            os.makedirs(os.path.dirname(out), exist_ok=True)
            tmp = f'{out}.{os.getpid()}.tmp'
            with open(tmp, 'w', encoding='utf-8') as f:
                f.write(text)
            os.replace(tmp, out)
        except OSError as exc:
            raise ParameterError('route_file_out', message=f'route_file_out: cannot write {out}: '
                                 f'{exc.strerror}') from None
        try:
            back = load_route_yaml(out)         # the file must read back as the same route
        except RouteError as exc:
            raise ParameterError('route_file_out', message=f'route_file_out: the written file does not '
                                 f'read back: {exc}') from None
        self._say(f'wrote {out} ({len(plan.waypoints)} waypoints, {back.route.length:.1f} m as read back)')


def main(args=None):
    return run_node(PlannerNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
