"""aivdm_out_node: the simulation's vessels as NMEA 0183 AIS (AIVDM/AIVDO) over UDP and to a file.

Subscribes one nav_msgs/Odometry topic per vessel (`vessels`, JSON text: a list of
``{"topic", "mmsi", "class", "own", "name", "callsign", "ship_type", "length_m", "beam_m",
"antenna_x_m", "antenna_y_m"}``, only topic and mmsi required; ship_guidance.aivdm_out.VesselInfo)
and runs every odometry sample through the AIS sensor model (ship_guidance.ais_sensor: report
intervals of ITU-R M.1371-5, losses, noise, antenna offset, reception delay; its parameters
below) on the odometry stamps (sim time: the node needs no clock). Each received message goes
out as its sentences, in one UDP datagram to `udp` (``host:port``, e.g. OpenCPN's or gpsd's
``udp://`` input; empty: none) and as lines appended to `file` (empty: none). Positions are
WGS-84 in the tangent plane at (`origin_lat_deg`, `origin_lon_deg`), the scenario's origin.
"""
import json
import math
import socket

from nav_msgs.msg import Odometry
from rclpy.node import Node

from ship_guidance.ais_sensor import SensorConfig, Truth
from ship_guidance.aivdm_out import AivdmOut, VesselInfo
from ship_sim.ros.conversions import odometry_to_ned
from ship_sim.ros.params import NodeParameters, ParameterError
from ship_sim.ros.qos import stream_with_depth
from ship_sim.ros.run import run_node
from ship_guidance.schema import AIVDM_OUT_NODE, SENSOR_PARAMETERS

#: Odometry samples each subscription queues: 100 s of sim time at dt 0.1 s. Nobody waits for
#: this node (it is outside the lockstep loop), so while it is descheduled on a loaded machine
#: the simulators run on; STREAM's 100 samples (1.4 s of wall time at 7x real time) overflowed
#: once under test load and one position report went out 1.4 s late. Reports must come from every
#: sample: the report times are drawn from the odometry stamps.
ODOM_QUEUE = 1000
ODOM_IN = stream_with_depth(ODOM_QUEUE)

VESSEL_KEYS = {'topic', 'mmsi', 'class', 'own', 'name', 'callsign', 'ship_type', 'length_m',
               'beam_m', 'antenna_x_m', 'antenna_y_m'}


def parse_vessels(text):
    """[(topic, VesselInfo)] from the `vessels` JSON text; ValueError says what is wrong."""
    try:
        items = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f'not JSON ({exc.msg} at character {exc.pos})') from None
    if not isinstance(items, list) or not items:
        raise ValueError('a non-empty JSON list of vessels')
    out = []
    for i, v in enumerate(items):
        if not isinstance(v, dict) or 'topic' not in v or 'mmsi' not in v:
            raise ValueError(f'vessel {i}: a mapping with at least topic and mmsi')
        extra = set(v) - VESSEL_KEYS
        if extra:
            raise ValueError(f'vessel {i}: unknown key {sorted(extra)[0]!r}; allowed: '
                             f'{", ".join(sorted(VESSEL_KEYS))}')
        kw = {k: v[k] for k in v if k not in ('topic', 'class')}
        try:
            info = VesselInfo(klass=v.get('class', 'A'), **kw)
        except TypeError as exc:
            raise ValueError(f'vessel {i}: {exc}') from None
        out.append((str(v['topic']), info))
    return out


def parse_udp(text):
    """``host:port`` -> (host, port), '' -> None; ValueError otherwise."""
    if not text:
        return None
    host, sep, port = text.rpartition(':')
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ValueError('host:port, e.g. 127.0.0.1:10110, or empty for none')
    return host, int(port)


class AivdmOutNode(Node):
    def __init__(self):
        super().__init__('aivdm_out_node')
        p = NodeParameters(self, AIVDM_OUT_NODE)
        text = p.param('vessels')
        udp = p.param('udp')
        path = p.param('file')
        lat0 = p.param('origin_lat_deg')
        lon0 = p.param('origin_lon_deg')
        seed = p.param('seed')
        cfg = {name: p.param(name) for name, *_ in SENSOR_PARAMETERS}
        try:
            vessels = parse_vessels(text)
        except ValueError as exc:
            raise ParameterError('vessels', text[:60], str(exc)) from None
        try:
            self.dest = parse_udp(udp)
        except ValueError as exc:
            raise ParameterError('udp', udp, str(exc)) from None
        try:
            self.out = AivdmOut(lat0, lon0, SensorConfig(seed=seed, **cfg))
            for _, info in vessels:
                self.out.add(info)
        except ValueError as exc:
            raise ParameterError('vessels', text[:60], str(exc)) from None
        self.sock = None
        if self.dest is not None:
            self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.file = None
        if path:
            try:
                self.file = open(path, 'a', encoding='ascii', buffering=1)
            except OSError as exc:
                raise ParameterError('file', path, f'a writable file ({exc.strerror})') from None
        self.sent = 0
        self.last_stamp = {}        # mmsi -> last odometry stamp (s)
        self.step_s = {}            # mmsi -> smallest stamp step seen (s): the sim's dt
        for topic, info in vessels:
            self.create_subscription(Odometry, topic,
                                     lambda data, m=info.mmsi: self._on_odom(m, data), ODOM_IN,
                                     raw=True)
        where = ([f'UDP {self.dest[0]}:{self.dest[1]}'] if self.dest else []) + \
            ([f'file {path}'] if path else [])
        self.get_logger().info(f'AIVDM out: {len(vessels)} vessels -> '
                               f'{", ".join(where) or "nowhere (no udp, no file)"}')

    def _on_odom(self, mmsi, data):
        o = odometry_to_ned(data)
        if not all(math.isfinite(x) for x in o):
            self.get_logger().warning(f'odometry of {mmsi} not finite: skipped',
                                      throttle_duration_sec=5.0)
            return
        self._watch_stamps(mmsi, o.t)
        c, s = math.cos(o.psi), math.sin(o.psi)
        vn, ve = o.u * c - o.v * s, o.u * s + o.v * c
        truth = Truth(o.t, o.north, o.east, o.psi, math.hypot(vn, ve), math.atan2(ve, vn), o.r)
        for _, lines in self.out.step(mmsi, truth):
            self._send(lines)

    def _watch_stamps(self, mmsi, t):
        # A report falls due on the first sample at or after its time: samples that never came
        # (dropped by DDS under load, or a queue overflow) make it late. Say so, with how much.
        last = self.last_stamp.get(mmsi)
        self.last_stamp[mmsi] = t
        if last is None or t <= last:
            return
        step = self.step_s.get(mmsi)
        if step is None or t - last < step:
            self.step_s[mmsi] = step = t - last
        if t - last > 1.5 * step:
            self.get_logger().warning(f'odometry of {mmsi} jumped {t - last:.2f} s at t = '
                                      f'{last:.2f} s (samples missing): a report due then is late')

    def _send(self, lines):
        self.sent += 1
        if self.sock is not None:
            try:
                self.sock.sendto(('\r\n'.join(lines) + '\r\n').encode('ascii'), self.dest)
            except OSError as exc:
                self.get_logger().warning(f'UDP send to {self.dest[0]}:{self.dest[1]} failed: '
                                          f'{exc.strerror or exc}', throttle_duration_sec=5.0)
        if self.file is not None:
            self.file.write('\n'.join(lines) + '\n')

    def destroy_node(self):
        if self.sock is not None:
            self.sock.close()
        if self.file is not None:
            self.file.close()
        super().destroy_node()


def main(args=None):
    return run_node(AivdmOutNode, args=args)


if __name__ == '__main__':
    raise SystemExit(main())
