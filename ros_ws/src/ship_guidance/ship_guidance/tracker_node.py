"""tracker_node: AIS (NMEA 0183 AIVDM over UDP) -> Kalman tracks with covariance on `tracks`.

Input: NMEA lines on UDP `udp_address`:`udp_port` (one or more per datagram), the way a live
receiver relays AIS and the way aivdm_out_node sends the simulated vessels' AIS (its `udp`
parameter: point it here). Decoding is ship_guidance.ais's (the same checks as ais_node); each
position report is stamped with the node's clock on arrival (sim time with use_sim_time) and
goes to the tracker (ship_guidance.tracker: a nearly-constant-velocity Kalman filter per MMSI,
late reports retrodicted, tracks deleted after a silence that depends on the report class). A
report without SOG or COG updates the position only. Polls are bounded as in ais_node
(UDP_MAX_DATAGRAMS, UDP_POLL_BUDGET_S).

Output: every `publish_period_s` of the node's clock, each live track predicted to now as
nav_msgs/Odometry on `tracks`: ENU at (`origin_lat_deg`, `origin_lon_deg`), frame_id `map`,
child_frame_id `ais_<mmsi>` (ais_node's names), orientation the reported true heading (else
the estimated COG), twist FLU over ground, pose and twist covariance filled
(tracker.odometry_covariances). colav_node takes it as its `targets_topic` (`tracks`) and widens
each target's safe distance by its position uncertainty (colav_node `uncertainty_k`).

Parameters: `udp_port` (required, 1-65535), `udp_address` (default 127.0.0.1), the origin,
`publish_period_s` (1 s), and the filter's noise model (ship_guidance.tracker.TrackerConfig):
`process_noise` (q, m^2/s^3), `position_sigma_m`, `sog_sigma_kn`, `cog_sigma_deg` (defaults:
the AIS sensor model's), `reprocess_window_s` (how late a report may come and still be used).
Bad AIS input is counted and warned about (throttled); it never stops the node.
"""
import math

from nav_msgs.msg import Odometry
from rclpy.clock import Clock, ClockType
from rclpy.node import Node

from ship_guidance.ais import KNOT, AisTracker
from ship_guidance.ais_node import child_frame
from ship_guidance.ros.udp import UDP_POLL_S, bind_udp, udp_lines
from ship_guidance.schema import TRACKER_NODE
from ship_guidance.tracker import AisReport, Tracker, TrackerConfig, odometry_covariances
from ship_sim.ros.conversions import make_odometry
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.qos import STREAM
from ship_sim.ros.run import run_node

class TrackerNode(Node):
    def __init__(self):
        super().__init__('tracker_node')
        p = NodeParameters(self, TRACKER_NODE)
        port = p.param('udp_port')
        address = p.param('udp_address')
        lat0 = p.param('origin_lat_deg')
        lon0 = p.param('origin_lon_deg')
        period = p.param('publish_period_s')
        config = TrackerConfig(
            process_noise=p.param('process_noise'),
            position_sigma_m=p.param('position_sigma_m'),
            sog_sigma_mps=KNOT * p.param('sog_sigma_kn'),
            cog_sigma_rad=math.radians(p.param('cog_sigma_deg')),
            reprocess_window_s=p.param('reprocess_window_s'))
        if not port:
            raise ParameterError('udp_port', message='give the UDP port AIS arrives on '
                                 '(udp_port)')
        self.sock = bind_udp(address, port)
        self.decoder = AisTracker(lat0, lon0)
        self.tracker = Tracker(config)
        self.n_bad = 0
        self.used = {}            # MMSI -> the decoder's report count already tracked
        self.pub = self.create_publisher(Odometry, 'tracks', STREAM)
        self.create_timer(period, self._publish)
        self.create_timer(UDP_POLL_S, self._poll, clock=Clock(clock_type=ClockType.STEADY_TIME))
        self.get_logger().info(f'tracker: AIS on UDP {address}:{port}; origin {lat0:.6f}, '
                               f'{lon0:.6f}; q {config.process_noise:g} m^2/s^3')

    def _now(self):
        return self.get_clock().now().nanoseconds * 1e-9

    def _poll(self):
        t = self._now()
        for line in udp_lines(self.sock, self.get_logger()):
            self._feed(line, t)

    def _feed(self, line, t):
        """Decode one line; a new position report goes to the tracker."""
        dec = self.decoder
        no_velocity = dec.bad['velocity_not_available']
        mmsi = dec.feed(line, t)
        n_bad = sum(dec.bad.values()) - dec.bad['velocity_not_available']
        if n_bad > self.n_bad:
            self.n_bad = n_bad
            reason, text = dec.last_bad
            self.get_logger().warning(f'skipped bad AIS input ({reason}): {text[:90]!r}; '
                                      f'{n_bad} so far', throttle_duration_sec=5.0)
        track = dec.tracks.get(mmsi) if mmsi is not None else None
        if track is None or track.reports == self.used.get(mmsi, 0):
            return                                 # static data only, or nothing usable
        self.used[mmsi] = track.reports
        velocity = dec.bad['velocity_not_available'] == no_velocity
        self.tracker.update(AisReport(
            mmsi, t, track.north, track.east, track.sog if velocity else None,
            track.cog if velocity else None, track.heading,
            'A' if track.klass == 'A' else 'B', track.moored))

    def _publish(self):
        now = self._now()
        for mmsi in self.decoder.prune(now):
            self.used.pop(mmsi, None)
        for est in self.tracker.tracks(now):
            psi = est.heading if est.heading is not None else est.cog
            d = est.cog - psi
            msg = make_odometry(now, est.north, est.east, psi, est.sog * math.cos(d),
                                est.sog * math.sin(d), 0.0, child_frame(est.mmsi))
            pose, twist = odometry_covariances(est, psi)
            msg.pose.covariance = pose
            msg.twist.covariance = twist
            self.pub.publish(msg)

    def destroy_node(self):
        self.sock.close()
        super().destroy_node()


def main(args=None):
    return run_node(TrackerNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
