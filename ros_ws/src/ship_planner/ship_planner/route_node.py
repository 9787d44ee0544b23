"""route_node: publishes a route file as nav_msgs/Path on `route` (reliable + transient_local).

Parameters (see config/route.yaml):
  route_file      path of a route file (.yaml route or .wpt waypoint table); a relative path
                  is looked up in the working directory, then in share/ship_planner/config/routes
  length_unit_m   metres per table unit for .wpt tables (0: the table's own unit)
  max_arc_step_m  longest sub-arc between two Path poses (m); sub-arcs also turn by at most
                  0.1 rad so small-radius arcs stay round in plots
  watch_period_s  how often the file is checked for changes (s, 0: never)

The route is republished when `route_file` (or another parameter) is changed at runtime or the
file changes on disk. An invalid route is refused with a message that names the file and the
line or row: at start the node exits (code 2) with that one line; later, the change is refused
(parameter) or logged once per edit and the last good route stays published (file edit). That
covers every bad file: invalid content, bytes that are not UTF-8, a FIFO, directory or device
in place of the file, and routes beyond the bounds of ship_planner.route_data.
"""
import os

from ament_index_python.packages import PackageNotFoundError, get_package_share_directory
from nav_msgs.msg import Path
from rclpy.node import Node

from ship_guidance.ros.path_msgs import route_to_path_msg
from ship_planner.route_loader import RouteError, load_route
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.qos import LATCHED
from ship_sim.ros.run import run_node
from ship_planner.schema import ROUTE_NODE

#: Sub-arcs of the Path turn by at most this much (rad), so plots of small-radius arcs stay round.
MAX_ARC_TURN = 0.1


def arc_step(route, max_step):
    """Sub-arc length for the Path: at most max_step (m) and MAX_ARC_TURN of turn on any arc."""
    radii = [leg.radius for leg in route.legs if leg.kind == 'arc']
    return min([max_step] + [MAX_ARC_TURN * r for r in radii])


def resolve_route_file(name):
    """Absolute path of a route file: as given, else in the package's config/routes folder."""
    if os.path.isabs(name) or os.path.exists(name):
        return os.path.abspath(name)
    try:
        shared = os.path.join(get_package_share_directory('ship_planner'), 'config', 'routes', name)
    except PackageNotFoundError:
        shared = None
    if shared and os.path.exists(shared):
        return shared
    raise RouteError(f'route file not found (looked in {os.getcwd()} and the package\'s '
                     f'config/routes)', file=name)


class RouteNode(Node):
    def __init__(self):
        super().__init__('route_node')
        self.params = NodeParameters(self, ROUTE_NODE)
        p = self.params
        p.param('length_unit_m', on_change=lambda _v: self._publish())
        p.param('max_arc_step_m', on_change=lambda _v: self._publish())
        # Declared last: its check reads the route with the parameters above.
        p.param('route_file', check=self._check_route_file, on_change=lambda _v: self._publish())
        watch = p.param('watch_period_s')
        self.pub = self.create_publisher(Path, 'route', LATCHED)
        self._mtime = None          # mtime of the file of the published route (None: none yet)
        self._seen_mtime = None     # mtime last looked at by the watcher (good or refused)
        self._publish()
        if watch > 0.0:
            # Wall-clock timer: a file edit should show up even while sim time is paused.
            self.create_timer(watch, self._watch, clock=self._wall_clock())

    def _wall_clock(self):
        from rclpy.clock import Clock, ClockType
        return Clock(clock_type=ClockType.STEADY_TIME)

    def _load(self, name=None):
        name = self.params.value('route_file') if name is None else name
        unit = self.params.value('length_unit_m') or None
        path = resolve_route_file(name)
        return path, load_route(path, length_unit_m=unit)

    def _check_route_file(self, name):
        try:
            self._load(name)
        except (ValueError, OSError) as exc:   # RouteError is a ValueError
            return str(exc)
        return None

    def _publish(self):
        try:
            path, plan = self._load()
            mtime = os.path.getmtime(path)
            msg = route_to_path_msg(plan.route, self.get_clock().now().to_msg(),
                                    arc_step(plan.route, self.params.value('max_arc_step_m')))
        except (ValueError, OSError) as exc:   # RouteError is a ValueError
            if self._mtime is None:  # nothing published yet: this is a start-up failure
                raise ParameterError('route_file', message=f'route_file: {exc}') from None
            self.get_logger().error(f'{exc}; keeping the last valid route')
            return
        self._mtime = self._seen_mtime = mtime
        self.pub.publish(msg)
        self.get_logger().info(
            f"route '{plan.name}' from {path}: {len(plan.route.legs)} legs, "
            f'{plan.route.length:.1f} m, {len(msg.poses)} poses')

    def _watch(self):
        try:
            path = resolve_route_file(self.params.value('route_file'))
            mtime = os.path.getmtime(path)
        except (RouteError, OSError):
            return
        if mtime != self._seen_mtime:
            self._seen_mtime = mtime   # a refused edit is reported once, not every period
            self.get_logger().info(f'{path} changed on disk; republishing')
            self._publish()


def main(args=None):
    return run_node(RouteNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
