"""nav_display_node: map- and viewer-ready topics of one vessel (thin; pure part in nav_display).

Subscribes `route` (nav_msgs/Path, reliable + transient_local) and, once the route has come
(`wait_for_route`; else at once), `odom_topic`:
- `odom_display` (the default): vessel_node's odom of every `display_every`-th step
  (reliable + transient_local, a deep history: ship_sim.ros.qos.DISPLAY). The simulator picks
  the steps, the display gets every one of them from step 0 however late it subscribes or far
  it lags (up to DISPLAY_DEPTH frames), and nobody waits for it: its frames are the same on
  every lockstep run, at one callback per frame. Waiting for the route first puts the route in
  every frame, also the first ones.
- any other name: an odom stream of every step (reliable, the graph's stream QoS, from when it
  subscribes); the frames are then chosen by stamp below, as they come.
Publishes, at most `display_rate_hz` times per second of sim time (the first odom at or after
each display period, on the odom stamps):
  fix           sensor_msgs/NavSatFix  WGS-84 position of the ship in the tangent plane at
                (`origin_lat_deg`, `origin_lon_deg`), the scenario's origin (Map panels;
                default nav_display.DEFAULT_ORIGIN_DEG, open water, never 0/0)
  nav_markers   visualization_msgs/MarkerArray  hull outline and fill at the true length and
                heading and the vessel's name in every frame; the wake trail of the last
                `trail_length_s` (a point every `trail_period_s`) in the frames that add a
                point, the route in the first frame and then every `route_period_s`
                (ship_guidance.ros.nav_display_msgs; targets and CPA points: colav_markers).
                Viewers keep a marker until the same namespace and id replace it, so the
                route and trail stay on screen between updates; serialising the route's and
                trail's hundreds of points in every frame was most of the node's CPU.
  heading       std_msgs/Float64  the ship's ENU yaw (rad) from odom, for plot panels that
                cannot take a yaw out of a quaternion (beside heading_cmd)
The hull length is the model's length between perpendiculars (`model`) unless `length_m` > 0.
"""
import math
import struct

from nav_msgs.msg import Odometry, Path
from rclpy.node import Node
from sensor_msgs.msg import NavSatFix
from std_msgs.msg import Float64
from visualization_msgs.msg import MarkerArray

from ship_guidance.nav_display import Throttle, Trail
from ship_guidance.ros.nav_display_msgs import display_markers, navsat_fix, route_marker
from ship_sim.frames import psi_to_yaw
from ship_sim.models import make_model
from ship_sim.ros import odometry_cdr as cdr
from ship_sim.ros.conversions import base_link_frame, odometry_to_ned, time_to_msg
from ship_sim.ros.params import NodeParameters
from ship_sim.ros.qos import DISPLAY, LATCHED, STREAM
from ship_sim.ros.run import run_node
from ship_guidance.schema import NAV_DISPLAY_NODE

_STAMP = struct.Struct('<iI')   # builtin_interfaces/Time at the start of the CDR body


class NavDisplayNode(Node):
    def __init__(self):
        super().__init__('nav_display_node')
        p = NodeParameters(self, NAV_DISPLAY_NODE)
        model = p.param('model')
        length = p.param('length_m')
        rate = p.param('display_rate_hz')
        trail_s = p.param('trail_length_s')
        trail_dt = p.param('trail_period_s')
        route_dt = p.param('route_period_s')
        self.lat0 = p.param('origin_lat_deg')
        self.lon0 = p.param('origin_lon_deg')
        self.odom_topic = p.param('odom_topic')
        wait_route = p.param('wait_for_route')
        self.length = length if length > 0.0 else float(make_model(model).length)
        self.throttle = Throttle(rate)
        self.trail_throttle = Throttle(1.0 / trail_dt)
        self.route_throttle = Throttle(1.0 / route_dt)
        self.trail = Trail(max(2, int(math.ceil(trail_s / trail_dt)) + 1))
        self.route = None
        self.name = self.get_namespace().strip('/') or 'vessel'
        self.frame = base_link_frame(self.get_namespace())
        self.pub_fix = self.create_publisher(NavSatFix, 'fix', STREAM)
        self.pub_markers = self.create_publisher(MarkerArray, 'nav_markers', STREAM)
        self.pub_heading = self.create_publisher(Float64, 'heading', STREAM)
        self.odom_sub = None
        self.create_subscription(Path, 'route', self._on_route, LATCHED)
        if not wait_route:
            self._subscribe_odom()

    def _subscribe_odom(self):
        qos = DISPLAY if self.odom_topic.rsplit('/', 1)[-1] == 'odom_display' else STREAM
        self.odom_sub = self.create_subscription(Odometry, self.odom_topic, self._on_odom, qos,
                                                 raw=True)

    def _on_route(self, msg):
        self.route = route_marker(msg.header.stamp, [(ps.pose.position.x, ps.pose.position.y)
                                                     for ps in msg.poses], self.length)
        if self.odom_sub is None:
            self._subscribe_odom()

    def _on_odom(self, data):
        # From a per-step stream most steps are not shown: read only the stamp of those
        # (ship_sim.ros.odometry_cdr).
        if data[:2] == cdr.XCDR1_LE:
            sec, nanosec = _STAMP.unpack_from(data, cdr.HEADER_BYTES)
            if not self.throttle.due(sec + 1e-9 * nanosec):
                return
            o = odometry_to_ned(data)
        else:
            o = odometry_to_ned(data)
            if not self.throttle.due(o.t):
                return
        if not (math.isfinite(o.north) and math.isfinite(o.east)):
            return
        trail = ()
        if self.trail_throttle.due(o.t):
            self.trail.add(o.east, o.north)
            trail = self.trail.points
        route = self.route if self.route_throttle.due(o.t) else None
        stamp = time_to_msg(o.t)
        yaw = float(psi_to_yaw(o.psi))
        self.pub_fix.publish(navsat_fix(stamp, self.frame, o.east, o.north, self.lat0, self.lon0))
        self.pub_heading.publish(Float64(data=yaw))
        self.pub_markers.publish(display_markers(stamp, self.name, o.east, o.north, yaw,
                                                 self.length, route, trail))


def main(args=None):
    return run_node(NavDisplayNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
