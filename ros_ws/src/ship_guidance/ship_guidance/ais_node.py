"""ais_node: AIS targets (NMEA 0183 AIVDM/AIVDO) from a replay file and/or UDP -> Odometry.

Inputs (either or both):
- `file`: a replay file (ship_guidance.ais.parse_replay: ``<t_s> <sentence>`` per line, or the
  sentence alone at `file_rate_hz`), fed on the node's clock: with use_sim_time, a line is fed
  once sim time reaches `file_time_offset_s` + t_s (a scenario's sim time starts at 0); on the
  wall clock, times count from the node's start. Each sentence is fed with its own time.
  The file must be a regular file of at most MAX_REPLAY_BYTES (ship_sim.safe_load: a FIFO, a
  device or a directory is refused in one line, exit code 2, before anything is read).
- `udp_port` > 0: NMEA lines (one or more per datagram) on UDP `udp_address`:`udp_port`, the way
  OpenCPN, AIS-catcher and gpsd relay live AIS; stamped with the node's clock on arrival. One
  poll reads at most UDP_MAX_DATAGRAMS and works at most UDP_POLL_BUDGET_S (wall time), so a
  flood cannot starve the node's own publications: what a poll leaves waits in the socket's
  buffer, and the kernel drops what overflows it.

Every `publish_period_s` of the node's clock (or, with `publish_on_clock`, at every /clock
message, stamped exactly with it) it publishes each live target (ship_guidance.ais:
dead-reckoned to now, dropped after `stale_after_s` without a report) as nav_msgs/Odometry on
`targets`, ENU at the geodetic origin (`origin_lat_deg`, `origin_lon_deg`), frame_id `map`,
child_frame_id `ais_<mmsi>`, orientation the true heading (else the COG), twist FLU from SOG
and COG; with `per_target_topics` also on `targets/ais_<mmsi>/odom`. `ais_counts`
(std_msgs/UInt64MultiArray, names in the layout's label) carries the counters. Bad input is
counted by reason and warned about (throttled); it never stops the node. Targets tracked and
dropped are logged in one summary line each at most every LOG_PERIOD_S (wall time).

Lockstep (`publish_on_clock`, as the launcher runs it): the targets of a step are followed by one
`targets_sync` (std_msgs/UInt64MultiArray ``[stamp_ns, targets]``, labels in the layout): every
target of that stamp is out, and how many there were. One message per step, whatever the number
of targets, so colav_node (`targets_sync_topic`) can wait until it holds every target up to its
own stamp, and the recorder can acknowledge the step: the run stays deterministic and lossless.
With `wait_readers` (full node names), the node announces that it is ready on /graph_ready once
`targets` and `targets_sync` serve each of them (ship_sim.ros.ready); the launcher starts the
simulators only then, so neither the recorder nor a colav_node misses step 0.
"""
import math
import time

from nav_msgs.msg import Odometry
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rosgraph_msgs.msg import Clock as ClockMsg
from std_msgs.msg import MultiArrayDimension, UInt64MultiArray

from ship_guidance.ais import BAD_REASONS, AisTracker, parse_replay
from ship_sim.ros.conversions import make_odometry
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.qos import CLOCK_STEPS, STREAM
from ship_sim.ros.readiness import names_param
from ship_sim.ros.ready import ReadyWhenMatched
from ship_sim.ros.run import run_node
from ship_sim.safe_load import InputError, read_regular_file
from ship_guidance.ros.udp import (UDP_MAX_DATAGRAMS, UDP_POLL_BUDGET_S, UDP_POLL_S,  # noqa: F401
                                    bind_udp, udp_lines)
from ship_guidance.schema import AIS_NODE

COUNT_NAMES = ('decoded', 'ignored', 'pending_fragments', 'targets') + BAD_REASONS
SYNC_NAMES = ('stamp_ns', 'targets')
LOG_PERIOD_S = 5.0         # wall time between two summaries of targets tracked / dropped
LOG_LISTED = 5             # MMSIs named in a summary line
#: Largest replay file: about 1.3 million sentences, a day of a busy port's receiver.
MAX_REPLAY_BYTES = 100_000_000
NS_PER_S = 1_000_000_000


def child_frame(mmsi):
    return f'ais_{mmsi}'


class AisNode(Node):
    def __init__(self):
        super().__init__('ais_node')
        p = self.params = NodeParameters(self, AIS_NODE)
        path = p.param('file')
        rate = p.param('file_rate_hz')
        offset = p.param('file_time_offset_s')
        port = p.param('udp_port')
        address = p.param('udp_address')
        lat0 = p.param('origin_lat_deg')
        lon0 = p.param('origin_lon_deg')
        stale = p.param('stale_after_s')
        period = p.param('publish_period_s')
        self.per_target = p.param('per_target_topics')
        self.on_clock = p.param('publish_on_clock')
        wait = names_param(p.param('wait_readers'))
        if not path and not port:
            raise ParameterError('file', message='give a replay file (file) or a UDP port '
                                 '(udp_port), or both')
        self.replay = []
        if path:
            try:
                text = read_regular_file(path, MAX_REPLAY_BYTES, binary=True).decode('ascii', 'replace')
            except InputError as exc:
                raise ParameterError('file', path, f'a readable regular file ({exc})') from None
            self.replay = parse_replay(text.splitlines(), rate, offset)
        self.sock = None
        if port:
            self.sock = bind_udp(address, port)
        self.tracker = AisTracker(lat0, lon0, stale)
        self.sim_time = self.get_parameter('use_sim_time').value
        self.t_base = 0.0 if self.sim_time or self.on_clock else self._now()
        self.next_line = 0
        self.n_bad = 0
        self.live = set()
        self.news = {'tracked': [], 'dropped': []}   # MMSIs not logged yet
        self.logged_at = None                        # monotonic time of the last summary
        self.pub = self.create_publisher(Odometry, 'targets', STREAM)
        self.pubs = {}
        self.pub_counts = self.create_publisher(UInt64MultiArray, 'ais_counts', STREAM)
        self.m_counts = UInt64MultiArray()
        self.m_counts.layout.dim = [MultiArrayDimension(label=','.join(COUNT_NAMES),
                                                        size=len(COUNT_NAMES), stride=1)]
        if self.on_clock:
            self.pub_sync = self.create_publisher(UInt64MultiArray, 'targets_sync', STREAM)
            self.m_sync = UInt64MultiArray()
            self.m_sync.layout.dim = [MultiArrayDimension(label=','.join(SYNC_NAMES),
                                                          size=len(SYNC_NAMES), stride=1)]
            self.create_subscription(ClockMsg, '/clock', self._on_clock, CLOCK_STEPS)
            self.ready = ReadyWhenMatched(self, lambda: (self.pub, self.pub_sync), wait)
        else:
            self.create_timer(period, self._tick)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        if self.sock is not None:
            self.create_timer(UDP_POLL_S, self._poll_udp, clock=steady)
        # Summaries held back by the throttle come out even when the node's clock stops.
        self.create_timer(1.0, self._log_news, clock=steady)
        self.get_logger().info(
            f'AIS: {len(self.replay)} replay lines'
            + (f', UDP {address}:{port}' if port else '')
            + f'; origin {lat0:.6f}, {lon0:.6f}; stale after {stale:.0f} s')

    def _now(self):
        return self.get_clock().now().nanoseconds * 1e-9

    def _feed(self, line, t):
        self.tracker.feed(line, t)
        n_bad = sum(self.tracker.bad.values()) - self.tracker.bad['velocity_not_available']
        if n_bad > self.n_bad:
            self.n_bad = n_bad
            reason, text = self.tracker.last_bad
            self.get_logger().warning(f'skipped bad AIS input ({reason}): {text[:90]!r}; '
                                      f'{n_bad} so far', throttle_duration_sec=5.0)

    def _poll_udp(self):
        t = self._now() - self.t_base
        for line in udp_lines(self.sock, self.get_logger()):
            self._feed(line, t)

    def _on_clock(self, msg):
        stamp_ns = msg.clock.sec * NS_PER_S + msg.clock.nanosec
        n = self._tick(stamp_ns / NS_PER_S, msg.clock)
        self.m_sync.data = [stamp_ns, n]
        self.pub_sync.publish(self.m_sync)

    def _tick(self, now=None, stamp=None):
        """Feed the replay lines due, publish the live targets at ``now`` (default: the node's
        clock; stamped ``stamp``, a builtin_interfaces/Time, when given) and the counts; returns
        the number of targets published."""
        now = self._now() if now is None else now
        t = now - self.t_base
        replay = self.replay
        while self.next_line < len(replay) and replay[self.next_line][0] <= t:
            t_line, line = replay[self.next_line]
            self._feed(line, t_line)
            self.next_line += 1
        targets = self.tracker.targets(t)
        live = {s.mmsi for s in targets}
        self.news['dropped'] += sorted(self.live - live)
        self.news['tracked'] += sorted(live - self.live)
        self.live = live
        self._log_news()
        for s in targets:
            d = s.cog - s.psi
            msg = make_odometry(now, s.north, s.east, s.psi, s.sog * math.cos(d),
                                s.sog * math.sin(d), 0.0, child_frame(s.mmsi))
            if stamp is not None:
                msg.header.stamp = stamp
            self.pub.publish(msg)
            if self.per_target:
                pub = self.pubs.get(s.mmsi)
                if pub is None:
                    pub = self.pubs[s.mmsi] = self.create_publisher(
                        Odometry, f'targets/{child_frame(s.mmsi)}/odom', STREAM)
                pub.publish(msg)
        tr = self.tracker
        self.m_counts.data = [sum(tr.decoded.values()), sum(tr.ignored.values()),
                              tr.pending_fragments, len(targets)] + [tr.bad[r] for r in BAD_REASONS]
        self.pub_counts.publish(self.m_counts)
        return len(targets)

    def _log_news(self):
        """One line each for the targets tracked and dropped since the last, at most every
        LOG_PERIOD_S: a flood of new targets must not flood the log."""
        news = self.news
        if not (news['tracked'] or news['dropped']):
            return
        now = time.monotonic()
        if self.logged_at is not None and now - self.logged_at < LOG_PERIOD_S:
            return
        self.logged_at = now
        if news['tracked']:
            self.get_logger().info(f"{_listed(news['tracked'])} tracked")
        if news['dropped']:
            self.get_logger().info(f"{_listed(news['dropped'])} dropped (no report for more "
                                   f'than {self.tracker.stale_after_s:.0f} s)')
        self.news = {'tracked': [], 'dropped': []}

    def destroy_node(self):
        if self.sock is not None:
            self.sock.close()
        super().destroy_node()


def _listed(mmsis):
    """'AIS target 1' / 'AIS targets 1, 2 and 3' / 'AIS targets 1, ..., 5 and 995 more'."""
    if len(mmsis) == 1:
        return f'AIS target {mmsis[0]}'
    head = ', '.join(str(m) for m in mmsis[:LOG_LISTED])
    rest = len(mmsis) - LOG_LISTED
    if rest <= 0:
        head, _, last = head.rpartition(', ')
        return f'AIS targets {head} and {last}'
    return f'AIS targets {head} and {rest} more'


def main(args=None):
    return run_node(AisNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
