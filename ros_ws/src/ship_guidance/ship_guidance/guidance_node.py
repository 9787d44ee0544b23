"""guidance_node: route + odom -> heading command (LOS / ILOS / arc / curved paths).

Subscribes `odom` (nav_msgs/Odometry, ENU) and `route` (nav_msgs/Path, reliable +
transient_local; see ship_guidance.ros.path_msgs for how lines and arcs are carried).
Publishes, exactly once per odom message (so lockstep consumers can pair by sequence):
  heading_cmd        std_msgs/Float64  ENU yaw command (rad)
  cross_track_error  std_msgs/Float64  m, positive when the vessel is to starboard of the path
  progress           std_msgs/Float64MultiArray  [s (m), distance remaining (m), leg index,
                     finished (0/1), path angle (ENU yaw, rad), curvature (1/m, + = port turn)]
and `route_complete` (std_msgs/Bool, latched) once the end of the route is reached; with
`publish_path_state`, also `path_state` (std_msgs/Float64MultiArray, one per odom): the
path-relative state of the learned steering policy (ship_guidance.path_state,
STATE_NAMES order, SI, NED/FRD).

The odom subscription is created only when the first valid route has arrived, so a lockstep
simulator that waits for its odom subscribers never starts before the guidance can answer.
A new route restarts the guidance (it snaps to the closest point of the new route).
Routes beyond the limits of ship_guidance.ros.path_msgs (frame, pose count, coordinates) are
refused in one line and the previous route is kept. Odometry passes the plausibility gate of
ship_guidance.ros.odom_gate (finite, within the coordinate bound, no jump faster than
`max_plausible_speed`): a refused odom is counted, warned about (throttled) and still answered
with the previous outputs, so lockstep pairing holds; the route is completed only on an odom
consistent with the one before (one outlier cannot latch `route_complete`).
The look-ahead is given in metres or, if `lookahead_ship_lengths` > 0, in ship lengths.
If the paired autopilot's `autopilot_zeta`, `autopilot_omega_n` and the `speed` are given,
a look-ahead below the stability limit d > U / (2 zeta omega_n) is refused unless
`allow_unstable` is true.

The law (`law`) is one of ship_guidance.guidance: los, ilos, or course (course-change
experiments, Lee 2004, sec. 5.2): the heading command follows the time schedule
`course_schedule_deg` = [t0, course0, t1, course1, ...] (sim time in s, strictly increasing;
course in degrees, NED, clockwise from north) and ignores the route's geometry;
cross_track_error and progress still refer to the route, but `route_complete` is never
reported: a course experiment ends at its duration.
"""

from nav_msgs.msg import Odometry, Path
from rclpy.node import Node
from std_msgs.msg import Bool, Float64MultiArray, MultiArrayDimension

from ship_guidance.guidance import Guidance, course_schedule_for
from ship_guidance.ros.odom_gate import OdomGate
from ship_guidance.ros.outputs import GuidancePublishers
from ship_guidance.ros.path_msgs import accept_route
from ship_sim.ros.conversions import odometry_to_ned
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.qos import LATCHED, STREAM
from ship_sim.ros.run import run_node
from ship_guidance.schema import GUIDANCE_NODE

class GuidanceNode(Node):
    def __init__(self):
        super().__init__('guidance_node')
        p = self.params = NodeParameters(self, GUIDANCE_NODE)
        self.law = p.param('law')
        self.schedule = self._declare_course_schedule()
        self.lookahead_m = p.param('lookahead_m')
        self.lookahead_l = p.param('lookahead_ship_lengths')
        self.ship_length = p.param('ship_length_m')
        acc_m = p.param('acceptance_radius_m')
        acc_l = p.param('acceptance_radius_ship_lengths')
        self.sigma = p.param('integral_gain')
        zeta = p.param('autopilot_zeta')
        omega = p.param('autopilot_omega_n')
        speed = p.param('speed')
        self.allow_unstable = p.param('allow_unstable')
        self.want_path_state = p.param('publish_path_state')
        self.curvature_lead = p.param('curvature_lead')
        self.arc_los_point = p.param('arc_los_point')
        max_speed = p.param('max_plausible_speed')
        uses_lengths = self.lookahead_l > 0.0 or acc_l > 0.0
        if uses_lengths and self.ship_length <= 0.0:
            raise ParameterError('ship_length_m', self.ship_length,
                                 '> 0 when a *_ship_lengths parameter is used')
        self.lookahead = self.lookahead_l * self.ship_length if self.lookahead_l else self.lookahead_m
        self.acceptance = acc_l * self.ship_length if acc_l else acc_m
        checks = (zeta, omega, speed)
        self.stability = dict(zeta=zeta, omega_n=omega, speed=speed) if all(checks) else {}
        if any(checks) and not all(checks):
            raise ParameterError('autopilot_zeta', message='the stability check needs '
                                 'autopilot_zeta, autopilot_omega_n and speed all > 0 '
                                 f'(got {zeta}, {omega}, {speed}); set all three or none')
        self._validate_lookahead()

        self.out = GuidancePublishers(self, readers=p.param('heading_cmd_readers'))
        self.features = self.pub_state = None
        if self.want_path_state:
            # Imported only when asked for: the one implementation the policy was trained on.
            from ship_guidance.path_state import STATE_NAMES, PathFeatures
            self.features = PathFeatures()
            self.pub_state = self.create_publisher(Float64MultiArray, 'path_state', STREAM)
            self.m_state = Float64MultiArray()
            self.m_state.layout.dim = [MultiArrayDimension(label=','.join(STATE_NAMES),
                                                           size=len(STATE_NAMES), stride=1)]
        self.pub_complete = self.create_publisher(Bool, 'route_complete', LATCHED)
        # raw: path_msgs reads the pose count, and the poses, from the bytes.
        self.create_subscription(Path, 'route', self._on_route, LATCHED, raw=True)
        self.gate = OdomGate(max_speed)
        self.odom_sub = None
        self.guidance = None
        self.t_prev = None
        self.completed = False
        self.n_bad_odom = 0

    def _declare_course_schedule(self):
        """(times, courses) for the course law, None otherwise. A list parameter, dynamically
        typed (its default is empty) so integers are accepted too."""
        values = self.params.param('course_schedule_deg')
        try:
            return course_schedule_for(self.law, values)
        except (TypeError, ValueError) as exc:
            raise ParameterError('course_schedule_deg', values, str(exc)) from None

    def _validate_lookahead(self):
        """Refuse an unstable look-ahead at start (a dummy route carries the check)."""
        from ship_guidance.path import Line, Route
        try:
            self._make_guidance(Route([Line((0.0, 0.0), (1.0, 0.0))]))
        except ValueError as exc:
            name = 'lookahead_ship_lengths' if self.lookahead_l else 'lookahead_m'
            if str(exc).startswith('arc_los_point'):
                name = 'arc_los_point'
            raise ParameterError(name, message=f'{name}: {exc}') from None

    def _make_guidance(self, route):
        return Guidance(route, law=self.law, lookahead=self.lookahead,
                        acceptance_radius=self.acceptance, integral_gain=self.sigma,
                        allow_unstable=self.allow_unstable, curvature_lead=self.curvature_lead,
                        course_schedule=self.schedule, arc_los_point=self.arc_los_point,
                        **self.stability)

    def _on_route(self, msg):
        route = accept_route(msg, self.get_logger())
        if route is None:
            return
        self.guidance = self._make_guidance(route)
        if self.features is not None:
            self.features.reset()
        self.t_prev = None
        self.completed = False
        self.pub_complete.publish(Bool(data=False))
        self.get_logger().info(f'route received: {len(route.legs)} legs, {route.length:.1f} m, '
                               f'law {self.law}, look-ahead {self.lookahead:.1f} m')
        if self.odom_sub is None:
            # raw: odometry_to_ned reads the CDR bytes (cheaper than rclpy's conversion).
            self.odom_sub = self.create_subscription(Odometry, 'odom', self._on_odom, STREAM,
                                                     raw=True)

    def _on_odom(self, msg):
        o = odometry_to_ned(msg)
        bad = self.gate.check(o.t, o.north, o.east, o.psi, o.u, o.v, o.r)
        if bad is None and self.gate.re_anchored:
            self.get_logger().warning(f'odometry moved to ({o.north:.1f}, {o.east:.1f}) m NED '
                                      'and stayed there: guidance restarted from it')
            self.guidance.reset()
            if self.features is not None:
                self.features.reset()
            self.t_prev = None
        out = None
        if bad is None:
            dt = 0.0 if self.t_prev is None else o.t - self.t_prev
            try:
                out = self.guidance.update(o.north, o.east, o.psi, max(dt, 0.0), t=o.t)
            except ValueError as exc:
                bad = str(exc)
        if out is None:
            # Bad odom must not poison the guidance; answer anyway so lockstep pairing holds.
            self.n_bad_odom += 1
            self.get_logger().warning(f'odom refused ({bad}); {self.n_bad_odom} so far',
                                      throttle_duration_sec=5.0)
            self.out.repeat()
            if self.pub_state is not None:
                self.pub_state.publish(self.m_state)
            return
        self.t_prev = o.t
        self.out.publish_route(out)
        if self.pub_state is not None:
            self.m_state.data = self.features(out.cross_track, out.path_angle, out.curvature,
                                              o.psi, o.u, o.v, o.r, max(dt, 0.0)).tolist()
            self.pub_state.publish(self.m_state)
        if (out.finished and not self.completed and self.guidance.reports_completion
                and self.gate.consistent):
            self.completed = True
            self.pub_complete.publish(Bool(data=True))
            self.get_logger().info(f'route complete at t = {o.t:.1f} s')


def main(args=None):
    return run_node(GuidanceNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
