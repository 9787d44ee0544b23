"""colav_node: collision avoidance between guidance and autopilot (thin; logic in colav_io).

Subscribes `odom` (own ship, nav_msgs/Odometry ENU), `heading_ref` (std_msgs/Float64, the
nominal ENU yaw: guidance_node's heading_cmd, remapped; reliable + transient_local, so its
publisher must offer transient_local too, as guidance_node's does) and targets as nav_msgs/Odometry: the
`targets_topic` (default `targets`, relative: the vessel namespace's; ais_node publishes every
AIS target there, each named by its child_frame_id) and each of `target_topics` (full vessels
stepping in lockstep, e.g. `/vessel_1/odom`; the topic names the target). With
`targets_sync_topic` (ais_node's `targets_sync` with `publish_on_clock`, std_msgs/UInt64MultiArray
``[stamp_ns, targets]``) the many-target topic is waited for too (colav_io.SyncedSource).
Publishes, exactly once per own odom (`pairing` sequence, for lockstep: the n-th odom paired
with the n-th heading_ref, as the autopilot pairs; latest, for realtime: with the last
heading_ref, no waiting for lockstep targets, odom before the first heading_ref unanswered):
  heading_cmd       std_msgs/Float64  ENU yaw the autopilot follows: heading_ref unchanged (the
                    same float) unless the last decision alters course, else heading_ref plus
                    the decided offset
  speed_factor_cmd  std_msgs/Float64  nominal speed factor (1) x the decided multiplier
and at each decision (every `decision_period_s` of sim time, on the own stamps):
  colav_targets     std_msgs/Float64MultiArray  per target (sorted by name)
                    [tcpa_s, dcpa_m, situation, role, range_m, bearing_rad] (colav_io)
  colav_decision    std_msgs/Float64MultiArray  [t_s, mode, course_offset_rad,
                    speed_multiplier, threat, n_targets] (mode codes in colav_io.MODE_CODES)
  colav_markers     visualization_msgs/MarkerArray  d_safe circles around the targets, the
                    CPA points of own ship and target, the commanded course as an arrow
With `chart_topic` it also subscribes a nav_msgs/OccupancyGrid (latched, e.g. a map server's
`/map`): SB-MPC then scores grounding against its land cells widened by `grounding_clearance_m`
(ship_guidance.land_mask); decisions before it arrives have no chart.

Determinism: a decision at own stamp t uses each target's latest state stamped <= t,
dead-reckoned to t, and waits (the own odom is queued, lockstep holds the own simulator) until
every `target_topics` target has a sample stamped >= t, so it does not depend on message
timing. A lockstep target silent for `lockstep_target_timeout_s` of wall time is no longer
waited for (warned; waited for again once it speaks); any target whose newest usable state is
older than `target_stale_s` of sim time is left out, and forgotten.

Target uncertainty: a target's safe distance is `d_safe_m` + `uncertainty_k` (default 2) x
its position sigma, the square root of the largest eigenvalue of the x-y block of its
pose.covariance (colav_io.position_sigma; tracker_node's `tracks` fill it, ais_node and the
simulators leave it zero: d_safe_m itself).

Bad input (counted, warned about with the count, throttled; the node keeps its state):
- a target state no ship can have (non-finite, beyond 1e7 m from the origin, faster than
  50 m/s: colav_io.target_problem, ship_sim.bounds) is refused; beyond `max_targets` live
  targets the farthest from the own ship are left out (colav_io.TargetTracks);
- a non-finite heading_ref: the last finite one is held in its place (before any, the own
  heading) and decisions go on, as autopilot_node holds its last heading_cmd
  (colav_io.RefHold); a non-finite own odom is answered with the held command, no decision;
- a chart whose grid reaches beyond 1e7 m from the origin, or is not finite, is refused
  (ship_guidance.land_mask) and the previous one kept.
"""
import time

from nav_msgs.msg import OccupancyGrid, Odometry
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension, UInt64MultiArray
from visualization_msgs.msg import MarkerArray

from ship_guidance import colav_io
from ship_guidance.colav_methods import make_colav
from ship_guidance.colav_params import ColavParams
from ship_guidance.land_mask import LandMask
from ship_guidance.own_ship_prediction import OwnShipModel
from ship_guidance.ros.colav_markers import colav_markers
from ship_sim.frames import psi_to_yaw, yaw_to_psi
from ship_sim.pacing import SequencePairer
from ship_sim.ros.conversions import odometry_to_ned
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.held_start import held_publisher
from ship_sim.ros.qos import LATCHED, STREAM, STREAM_KEPT, stream_with_depth
from ship_sim.ros.run import run_node
from ship_guidance.schema import COLAV_NODE, LISTS, OWN_SHIP_KEYS, SCALARS

# A lockstep target's queue: the target may publish many steps before the own ship starts or
# once its gate has stopped waiting for the own ship (vessel_node's lockstep_follower_window),
# and a decision may use any of them (the depth takes no part in QoS matching).
LOCKSTEP_TARGET = stream_with_depth(colav_io.MAX_SAMPLES_PER_TARGET)


class ColavRosNode(Node):
    def __init__(self):
        super().__init__('colav_node')
        p = NodeParameters(self, COLAV_NODE)
        method = p.param('method')
        period = p.param('decision_period_s')
        self.targets_topic = p.param('targets_topic')
        self.sync_topic = p.param('targets_sync_topic')
        stale = p.param('target_stale_s')
        max_targets = p.param('max_targets')
        self.wait_timeout = p.param('lockstep_target_timeout_s')
        self.pairing = p.param('pairing')
        self.has_shaft = p.param('has_shaft')
        held = {t: p.param(f'{t}_readers') for t in ('heading_cmd', 'speed_factor_cmd')}
        chart_topic = p.param('chart_topic')
        values = {name: p.param(name) for name, *_ in SCALARS}
        lists = {name: p.param(name) for name, *_ in LISTS}
        topics = [t for t in lists.pop('target_topics') if t.strip()]
        try:
            params = ColavParams.from_dict({k: v for k, v in {**values, **lists}.items()
                                            if k not in OWN_SHIP_KEYS})
            ship = OwnShipModel.from_dict({**{k: values[k] for k in OWN_SHIP_KEYS},
                                           'has_shaft': self.has_shaft})
        except (TypeError, ValueError) as exc:
            raise ParameterError('d_safe_m', message=f'colav parameters: {exc}') from None
        self.colav = make_colav(method, params, ship)
        self.params = params
        self.schedule = colav_io.DecisionSchedule(period)
        self.tracks = colav_io.TargetTracks(stale, max_targets)
        self.ref_hold = colav_io.RefHold()
        self.n_bad_charts = 0
        self.sync = colav_io.SyncedSource() if self.sync_topic and self.targets_topic else None
        self.lockstep_topics = topics
        self.pairer = SequencePairer()
        self.pending = []          # (odom NED, heading_ref) pairs not answered yet
        self.latest_ref = None     # latest pairing: the last heading_ref
        self.decision = None
        self.wait_since = None
        self.warned = set()

        # Lockstep: the autopilot takes the n-th heading_cmd, the simulator the n-th
        # speed_factor_cmd as step n's; the first ones wait until their named readers matched.
        self.pub_heading = held_publisher(
            self, self.create_publisher(Float64, 'heading_cmd', STREAM), held['heading_cmd'])
        self.pub_speed = held_publisher(
            self, self.create_publisher(Float64, 'speed_factor_cmd', STREAM),
            held['speed_factor_cmd'])
        self.pub_targets = self.create_publisher(Float64MultiArray, 'colav_targets', STREAM)
        self.pub_decision = self.create_publisher(Float64MultiArray, 'colav_decision', STREAM)
        self.pub_markers = self.create_publisher(MarkerArray, 'colav_markers', STREAM)
        self.m_targets = Float64MultiArray()
        self.m_decision = Float64MultiArray()
        self.m_decision.layout.dim = [MultiArrayDimension(
            label=','.join(colav_io.DECISION_COLUMNS), size=len(colav_io.DECISION_COLUMNS),
            stride=1)]
        for topic in topics:
            self.create_subscription(Odometry, topic, self._lockstep_target(topic),
                                     LOCKSTEP_TARGET)
        if self.targets_topic:
            self.create_subscription(Odometry, self.targets_topic, self._on_targets, STREAM)
        if self.sync is not None:
            self.create_subscription(UInt64MultiArray, self.sync_topic, self._on_sync, STREAM)
        if chart_topic:
            self.create_subscription(OccupancyGrid, chart_topic, self._on_chart, LATCHED)
        # Kept for a late match (qos.STREAM_KEPT): a missed heading_ref 0 would pair every
        # later odom with the next step's reference and stall the lockstep graph step by step.
        self.create_subscription(Float64, 'heading_ref', self._on_ref, STREAM_KEPT)
        self.create_subscription(Odometry, 'odom', self._on_odom, STREAM, raw=True)
        self.create_timer(0.2, self._drain, clock=Clock(clock_type=ClockType.STEADY_TIME))
        self.get_logger().info(f'colav {method}: decision every {period:g} s, d_safe '
                               f'{params.d_safe_m:g} m, lockstep targets {topics or "none"}')

    # --- inputs ---------------------------------------------------------------------------

    def _lockstep_target(self, topic):
        def callback(msg):
            self._add_target(topic, msg, lockstep=True)
            self._drain()
        return callback

    def _on_chart(self, msg):
        info, q = msg.info, msg.info.origin.orientation
        try:
            if (q.x, q.y, q.z) != (0.0, 0.0, 0.0):
                raise ValueError('a rotated grid origin is not supported')
            land = LandMask.from_occupancy(
                msg.data, info.width, info.height, info.resolution, info.origin.position.x,
                info.origin.position.y, clearance_m=self.params.grounding_clearance_m)
        except ValueError as exc:
            self.n_bad_charts += 1
            self.get_logger().error(f'chart refused: {exc}; keeping the previous one '
                                    f'({self.n_bad_charts} refused so far)')
            return
        self.colav.land = land
        blocked = self.colav.land.blocked
        self.get_logger().info(
            f'chart {info.width} x {info.height} cells of {info.resolution:g} m: '
            f'{blocked.mean():.1%} land or within {self.params.grounding_clearance_m:g} m of it'
            + ('' if self.colav.method == 'sbmpc' else f' (not used by {self.colav.method})'))

    def _on_targets(self, msg):
        self._add_target(msg.child_frame_id, msg, lockstep=False)
        if self.sync is not None:
            self.sync.received(_stamp_ns(msg))
        self._drain()

    def _on_sync(self, msg):
        if len(msg.data) >= 2:
            self.sync.announced(int(msg.data[0]), int(msg.data[1]))
            self.warned.discard(self.sync_topic)
            self._drain()

    def _add_target(self, name, msg, lockstep):
        o = odometry_to_ned(msg)
        state = colav_io.target_state(name, o.north, o.east, o.psi, o.u, o.v,
                                      colav_io.position_sigma(msg.pose.covariance))
        tracks = self.tracks
        why = tracks.add(name, _stamp_ns(msg), state, time.monotonic(), lockstep)
        if why is None:
            self.warned.discard(name)
        elif why == 'evicted':
            self.get_logger().warning(f'more than {tracks.max_targets} live targets: the '
                                      f'farthest left out ({tracks.n_evicted} so far)',
                                      throttle_duration_sec=5.0)
        else:
            refused = ', '.join(f'{k} {v}' for k, v in tracks.refused.items())
            self.get_logger().warning(f'target {name} refused: {tracks.last_refused[1]} '
                                      f'(refused so far: {refused})', throttle_duration_sec=5.0)

    def _on_odom(self, data):
        if self.pairing == 'latest':
            if self.latest_ref is not None:   # nothing to pass on before guidance has spoken
                self.pending.append((odometry_to_ned(data), self.latest_ref))
                self._drain()
            return
        self.pairer.push_a(odometry_to_ned(data))
        self._pair()

    def _on_ref(self, msg):
        if self.pairing == 'latest':
            self.latest_ref = msg.data
            return
        self.pairer.push_b(msg.data)
        self._pair()

    def _pair(self):
        self.pending.extend(self.pairer.pairs())
        self._drain()

    # --- decisions ------------------------------------------------------------------------

    def _drain(self):
        while self.pending:
            o, ref = self.pending[0]
            t_ns = colav_io.to_ns(o.t)
            if (self.pairing == 'sequence' and self.schedule.due(t_ns)
                    and not self._targets_ready(t_ns)):
                return
            self.pending.pop(0)
            self.wait_since = None
            self._answer(t_ns, o, ref)

    def _answer(self, t_ns, o, ref):
        held = self.ref_hold.update(ref)
        if not _finite(ref):
            self.get_logger().warning(f'heading_ref {ref} refused (not finite): holding the '
                                      f'previous one ({self.ref_hold.n_refused} so far)',
                                      throttle_duration_sec=5.0)
            if held is None:      # no finite heading_ref yet: hold the own heading
                held = float(psi_to_yaw(o.psi)) if _finite(o.psi) else ref
            ref = held
        if not (all(map(_finite, o)) and _finite(ref)):
            # Refused odometry: answer with the held command (pairing holds), no decision.
            self._publish(ref, self.decision)
            return
        self.tracks.reference = (o.north, o.east)
        if self.schedule.due(t_ns):
            self.schedule.decided(t_ns)
            own = colav_io.ship_state(o.north, o.east, o.psi, o.u, o.v, o.r)
            targets = self.tracks.at(t_ns)
            nominal = yaw_to_psi(ref)
            self.decision = self.colav.decide(o.t, own, targets, nominal, 1.0)
            self._publish_decision(o.t, own, targets)
        self._publish(ref, self.decision)

    def _publish(self, ref, decision):
        self.pub_heading.publish(Float64(data=colav_io.command_yaw(ref, decision)))
        self.pub_speed.publish(Float64(data=colav_io.speed_factor(1.0, decision)))

    def _publish_decision(self, t, own, targets):
        d = self.decision
        rows = colav_io.target_rows(own, targets, d)
        self.m_targets.layout.dim = [
            MultiArrayDimension(label=','.join(tg.name for tg in targets), size=len(targets),
                                stride=len(rows)),
            MultiArrayDimension(label=','.join(colav_io.TARGET_COLUMNS),
                                size=len(colav_io.TARGET_COLUMNS),
                                stride=len(colav_io.TARGET_COLUMNS))]
        self.m_targets.data = rows
        self.pub_targets.publish(self.m_targets)
        self.m_decision.data = colav_io.decision_row(t, d, len(targets))
        self.pub_decision.publish(self.m_decision)
        radii = [self.params.safe_distance(tg.position_sigma_m) for tg in targets]
        self.pub_markers.publish(colav_markers(t, own, targets, d, radii))

    def _targets_ready(self, t_ns):
        missing = self.tracks.waiting_for(t_ns, self.lockstep_topics)
        if self.sync is not None and not self.sync.ready(t_ns):
            missing.append(self.sync_topic)
        missing = [n for n in missing if n not in self.warned]
        if not missing:
            return True
        now = time.monotonic()
        if self.wait_since is None:
            self.wait_since = now
        if now - self.wait_since < self.wait_timeout:
            return False
        for name in missing:
            self.warned.add(name)
            self.get_logger().warning(f'target {name} silent for {self.wait_timeout:g} s (wall): '
                                      'deciding without waiting for it (no longer deterministic)')
        return True


def _finite(x):
    return x == x and abs(x) != float('inf')


def _stamp_ns(msg):
    s = msg.header.stamp
    return s.sec * colav_io.NS_PER_S + s.nanosec


def main(args=None):
    return run_node(ColavRosNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
