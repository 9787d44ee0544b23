"""follower_node: platoon follower guidance, route + own odom + predecessor odom -> heading command.

The law (ship_guidance.follower, Angelopoulos 2011 Figure 8 / eq. 31): steer at the predecessor, which is
the gap d ahead along the route at its own cross-track, psi_c = alpha - atan((e - e_p) / d) on a
straight leg; keep the along-path gap at `spacing_m` with a speed command; follow the route with
plain LOS (look-ahead `lookahead_m`, the name guidance_node uses) while the predecessor's odometry
is stale. Options (ship_guidance.follower's docstring; off by default): `integral_gain` > 0 adds
integral action on the own cross-track error (steady offsets, e.g. a cross current, go to zero
instead of adding up down the string), `aim: path` steers with ILOS toward the route with the
look-ahead = the gap instead of at the predecessor, `curvature_lead` leads the command on curves.

Runs in the follower's namespace (/vessel_i); relative topics. QoS ship_sim.ros.qos.
Subscribes
  odom                      nav_msgs/Odometry  own odometry (ENU); created once a route arrived
  route                     nav_msgs/Path      LATCHED (ship_guidance.ros.path_msgs)
  <predecessor_odom_topic>  nav_msgs/Odometry  the predecessor's odometry, e.g. /vessel_0/odom
                                               (queued as deep as the track it fills)
Publishes, exactly once per own odom message (lockstep consumers pair by sequence):
  heading_cmd, cross_track_error, progress   as guidance_node (ship_guidance.ros.outputs);
                                             cross-track and progress refer to the route
  gap_error   std_msgs/Float64  gap - spacing_m (m, > 0: too far behind); NaN in route_fallback
and, not paired (the vessel node applies them from its next step on):
  speed_cmd   std_msgs/Float64  commanded speed (m/s), once one is known. The vessel node does
                                not take a speed command (yet): for models without a shaft
                                (mariner, nomoto*) it is information only.
  shaft_cmd   std_msgs/Float64  shaft speed (rpm) = shaft_nominal_rpm * speed_cmd /
                                speed_at_nominal_rpm, only with `shaft_control` (tanker,
                                container)
  mode        std_msgs/String   LATCHED, 'follow' or 'route_fallback', on every change
  route_complete std_msgs/Bool  LATCHED, as guidance_node

Time: the predecessor's samples are evaluated at the own odom's stamp (interpolated), its age is
measured in sim time against `predecessor_timeout_s`. In lockstep (`stepping_mode: lockstep`) the
two simulators run independently as fast as they can, so the answer to an own odom at time t
waits until a predecessor sample stamped >= t is held, at most `predecessor_wait_s` of wall time:
then the run is deterministic whatever the arrival order. After a wait runs out (warned and
counted: the run is then no longer bit-identical) the node stops waiting until the predecessor
publishes again, so a dead predecessor costs one wait and then the fallback takes over.
Samples missing from the predecessor's stream (a gap in its stamps) are counted and warned
about: the interpolation across a gap differs from the one the samples would have given.

Bad input: routes as guidance_node (ship_guidance.ros.path_msgs: refused in one line, the
previous route kept). The own and the predecessor's odometry pass the plausibility gate of
ship_guidance.ros.odom_gate (finite, within the coordinate bound, no jump faster than
`max_plausible_speed`); a refused own odom is counted, warned about (throttled) and answered
with the previous outputs (lockstep pairing holds), a refused predecessor sample is dropped;
the route is completed only on an own odom consistent with the one before.

Stability: with `autopilot_zeta`, `autopilot_omega_n` and `speed` all > 0, min_lookahead_m and
lookahead_m at or below U / (2 zeta omega_n) are refused (Angelopoulos 2011 eqs. 34, 41) unless
`allow_unstable`; a spacing below the no-amplification spacing (ship_guidance.follower) is
warned about.
"""
import collections
import math
import time

from nav_msgs.msg import Odometry, Path
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from std_msgs.msg import Bool, Float64, String

from ship_guidance.follower import (FALLBACK, FOLLOW, TRACK_MAX_SAMPLES, FollowerGuidance,
                                    PredecessorTrack, speed_to_shaft)
from ship_guidance.path import Line, Route
from ship_guidance.ros.odom_gate import OdomGate
from ship_guidance.ros.outputs import GuidancePublishers
from ship_guidance.ros.path_msgs import accept_route
from ship_sim.ros.conversions import odometry_to_ned
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.qos import LATCHED, STREAM, stream_with_depth
from ship_sim.ros.run import run_node
from ship_guidance.schema import FOLLOWER_NODE

#: The predecessor's odometry as STREAM, but queued as deep as the track: in lockstep the
#: predecessor runs ahead as fast as it can, and a keep-last queue of 100 overwrote samples not
#: yet taken whenever this process fell that many steps behind on a loaded machine.
PREDECESSOR = stream_with_depth(TRACK_MAX_SAMPLES)
#: Wall period (s) of the check that ends a lockstep wait for the predecessor.
WAIT_CHECK_PERIOD = 0.02
#: Throttle (s) of repeated warnings; also how long (sim s) route_fallback lasts before the
#: first reminder that it still does.
THROTTLE = 10.0


class FollowerNode(Node):
    def __init__(self):
        super().__init__('follower_node')
        p = self.params = NodeParameters(self, FOLLOWER_NODE)
        self.pred_topic = p.param('predecessor_odom_topic')
        spacing = p.param('spacing_m')
        d_min = p.param('min_lookahead_m')
        d_max = p.param('max_lookahead_m')
        d_fb = p.param('lookahead_m')
        acc = p.param('acceptance_radius_m')
        timeout = p.param('predecessor_timeout_s')
        self.stepping = p.param('stepping_mode')
        self.wait_s = p.param('predecessor_wait_s')
        kp = p.param('spacing_kp')
        ki = p.param('spacing_ki')
        dumax = p.param('max_speed_correction')
        self.shaft_control = p.param('shaft_control')
        self.n_nom = p.param('shaft_nominal_rpm')
        self.u_nom = p.param('speed_at_nominal_rpm')
        self.n_min = p.param('shaft_min_rpm')
        self.n_max = p.param('shaft_max_rpm')
        zeta = p.param('autopilot_zeta')
        omega = p.param('autopilot_omega_n')
        speed = p.param('speed')
        allow = p.param('allow_unstable')
        aim = p.param('aim')
        sigma = p.param('integral_gain')
        lead = p.param('curvature_lead')
        max_speed = p.param('max_plausible_speed')
        if self.shaft_control and not (self.n_nom > 0.0 and self.u_nom > 0.0):
            raise ParameterError('shaft_nominal_rpm', message='shaft_control needs '
                                 'shaft_nominal_rpm and speed_at_nominal_rpm > 0 (got '
                                 f'{self.n_nom}, {self.u_nom})')
        if self.n_max < self.n_min:
            raise ParameterError('shaft_max_rpm', self.n_max, f'>= shaft_min_rpm ({self.n_min})')
        if d_max and d_max < d_min:
            raise ParameterError('max_lookahead_m', d_max, f'0 or >= min_lookahead_m ({d_min})')
        checks = (zeta, omega, speed)
        if any(checks) and not all(checks):
            raise ParameterError('autopilot_zeta', message='the stability check needs '
                                 'autopilot_zeta, autopilot_omega_n and speed all > 0 '
                                 f'(got {zeta}, {omega}, {speed}); set all three or none')
        if lead and not all(checks):
            raise ParameterError('curvature_lead', message='curvature_lead needs '
                                 'autopilot_zeta, autopilot_omega_n and speed > 0 (got '
                                 f'{zeta}, {omega}, {speed})')
        self.track = PredecessorTrack()
        self.config = dict(spacing=spacing, min_lookahead=d_min, fallback_lookahead=d_fb,
                           max_lookahead=d_max or None, predecessor_timeout=timeout,
                           acceptance_radius=acc, spacing_kp=kp, spacing_ki=ki,
                           max_speed_correction=dumax, allow_unstable=allow, track=self.track,
                           aim=aim, integral_gain=sigma, curvature_lead=lead)
        if all(checks):
            self.config.update(zeta=zeta, omega_n=omega, speed=speed)
        self.timeout = timeout
        try:   # the parameter checks, on a dummy route
            probe = FollowerGuidance(Route([Line((0.0, 0.0), (1.0, 0.0))]), **self.config)
        except ValueError as exc:
            name = 'lookahead_m' if 'fallback' in str(exc) else 'min_lookahead_m'
            raise ParameterError(name, message=f'{name}: {exc}') from None
        for w in probe.warnings:
            self.get_logger().warning(w)

        self.out = GuidancePublishers(self, readers=p.param('heading_cmd_readers'))
        self.pub_gap = self.create_publisher(Float64, 'gap_error', STREAM)
        self.pub_speed = self.create_publisher(Float64, 'speed_cmd', STREAM)
        self.pub_shaft = (self.create_publisher(Float64, 'shaft_cmd', STREAM)
                          if self.shaft_control else None)
        self.pub_mode = self.create_publisher(String, 'mode', LATCHED)
        self.pub_complete = self.create_publisher(Bool, 'route_complete', LATCHED)
        self.m_gap, self.m_speed, self.m_shaft = Float64(), Float64(), Float64()
        # raw: path_msgs reads the pose count, and the poses, from the bytes.
        self.create_subscription(Path, 'route', self._on_route, LATCHED, raw=True)
        self.gate, self.pred_gate = OdomGate(max_speed), OdomGate(max_speed)
        self.route = None
        try:
            self.create_subscription(Odometry, self.pred_topic, self._on_pred, PREDECESSOR)
        except Exception as exc:  # noqa: BLE001 (rclpy's InvalidTopicNameException and friends)
            raise ParameterError('predecessor_odom_topic', self.pred_topic,
                                 f'a valid topic name ({exc})') from None
        self.odom_sub = None
        self.follower = None
        self.completed = False
        self.mode = None
        self.mode_since = None
        self.pending = collections.deque()   # (NedOdometry, wall arrival) awaiting the predecessor
        self.waiting_enabled = self.stepping == 'lockstep' and self.wait_s > 0.0
        self.n_bad_odom = self.n_bad_pred = self.n_wait_timeouts = 0
        self.t_first = None
        if self.stepping == 'lockstep':
            steady = Clock(clock_type=ClockType.STEADY_TIME)
            self.create_timer(WAIT_CHECK_PERIOD, self._flush, clock=steady)
        self.get_logger().info(
            f'follower of {self.pred_topic}: spacing {spacing:g} m, look-ahead in '
            f'[{d_min:g}, {d_max or math.inf:g}] m, fallback LOS {d_fb:g} m, timeout '
            f'{timeout:g} s, {self.stepping}, aim {aim}'
            + (f', integral gain {sigma:g} m/s' if sigma else '')
            + (', turn-rate lead' if lead else '')
            + (f', stability limit {probe.critical_lookahead:.1f} m'
               if probe.critical_lookahead else ''))

    # -- inputs -------------------------------------------------------------------------------
    def _on_route(self, msg):
        route = accept_route(msg, self.get_logger())
        if route is None:
            return
        self.route = route
        self.follower = FollowerGuidance(route, **self.config)
        self.completed = False
        self.pub_complete.publish(Bool(data=False))
        self.get_logger().info(f'route received: {len(route.legs)} legs, {route.length:.1f} m')
        if self.odom_sub is None:
            self.odom_sub = self.create_subscription(Odometry, 'odom', self._on_odom, STREAM)

    def _on_pred(self, msg):
        o = odometry_to_ned(msg)
        try:
            bad = self.pred_gate.check(o.t, o.north, o.east, o.psi, o.u, o.v, o.r)
            if bad is not None:
                raise ValueError(bad)
            missing = self.track.n_missing
            restarted = self.track.add(o.t, o.north, o.east, o.psi, o.u, o.v)
        except ValueError as exc:
            self.n_bad_pred += 1
            self.get_logger().warning(f'predecessor odom refused ({exc}); {self.n_bad_pred} so '
                                      'far', throttle_duration_sec=THROTTLE)
            return
        if restarted:
            self.get_logger().warning(f'predecessor time went back to {o.t:.2f} s: its track '
                                      'was restarted')
        elif self.track.n_missing > missing:
            self.get_logger().warning(
                f'predecessor samples missing before t = {o.t:.2f} s ({self.track.n_missing} so '
                'far)' + (': the run is no longer deterministic' if self.stepping == 'lockstep'
                          else ''), throttle_duration_sec=THROTTLE)
        if self.stepping == 'lockstep' and not self.waiting_enabled and self.wait_s > 0.0:
            self.waiting_enabled = True
            self.get_logger().info('predecessor publishes again: waiting for it in lockstep')
        self._flush()

    def _on_odom(self, msg):
        self.pending.append((odometry_to_ned(msg), time.monotonic()))
        self._flush()

    def _flush(self):
        """Answer the pending own odoms in order, each once the predecessor's sample at its time
        is held (lockstep), or its wait ran out, or without waiting (realtime)."""
        while self.pending:
            o, arrived = self.pending[0]
            if self.waiting_enabled:
                latest = self.track.latest_t
                if latest is None or latest < o.t:
                    if time.monotonic() - arrived < self.wait_s:
                        return
                    self.n_wait_timeouts += 1
                    self.waiting_enabled = False
                    self.get_logger().warning(
                        f'no predecessor sample for t = {o.t:.2f} s within {self.wait_s:g} s '
                        f'(wall); not waiting until it publishes again ({self.n_wait_timeouts} '
                        'such waits: the run is no longer deterministic)')
            self.pending.popleft()
            self._answer(o)

    # -- one step -----------------------------------------------------------------------------
    def _answer(self, o):
        try:
            bad = self.gate.check(o.t, o.north, o.east, o.psi, o.u, o.v, o.r)
            if bad is not None:
                raise ValueError(bad)
            if self.gate.re_anchored:
                self.get_logger().warning(
                    f'odometry moved to ({o.north:.1f}, {o.east:.1f}) m NED and stayed there: '
                    'follower guidance restarted from it')
                self.follower = FollowerGuidance(self.route, **self.config)
            out = self.follower.update(o.t, o.north, o.east, o.psi)
        except ValueError as exc:
            # Bad odom must not poison the state; answer anyway so lockstep pairing holds.
            self.n_bad_odom += 1
            self.get_logger().warning(f'odom refused ({exc}); {self.n_bad_odom} so far',
                                      throttle_duration_sec=THROTTLE)
            self.out.repeat()
            self.pub_gap.publish(self.m_gap)
            return
        if self.t_first is None:
            self.t_first = o.t
        self.out.publish_route(out.route, out.heading_cmd)
        self.m_gap.data = out.gap_error
        self.pub_gap.publish(self.m_gap)
        if math.isfinite(out.speed_cmd):
            self.m_speed.data = out.speed_cmd
            self.pub_speed.publish(self.m_speed)
            if self.pub_shaft is not None:
                self.m_shaft.data = speed_to_shaft(out.speed_cmd, self.u_nom, self.n_nom,
                                                   self.n_min, self.n_max)
                self.pub_shaft.publish(self.m_shaft)
        self._report_mode(out, o.t)
        if out.route.finished and not self.completed and self.gate.consistent:
            self.completed = True
            self.pub_complete.publish(Bool(data=True))
            self.get_logger().info(f'route complete at t = {o.t:.1f} s')

    def _report_mode(self, out, t):
        log = self.get_logger()
        if out.mode != self.mode:
            self.mode = out.mode
            self.mode_since = t
            self.pub_mode.publish(String(data=out.mode))
            if out.mode == FOLLOW:
                log.info(f'following {self.pred_topic} at t = {t:.1f} s (gap {out.gap:.1f} m)')
            elif self.t_first is not None and t - self.t_first > self.timeout:
                log.warning(f'route_fallback at t = {t:.1f} s: {out.reason}')
            else:
                log.info(f'route_fallback at start: {out.reason}')
        elif out.mode == FALLBACK and min(t - self.t_first, t - self.mode_since) > THROTTLE:
            log.warning(f'still in route_fallback at t = {t:.1f} s: {out.reason}',
                        throttle_duration_sec=THROTTLE)


def main(args=None):
    return run_node(FollowerNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
