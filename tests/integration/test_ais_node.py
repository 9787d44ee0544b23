"""ais_node as a real process: a replay file on sim time and live UDP become tracked targets.

1. Replay on sim time (the test publishes /clock): two ships reported in a file (encoded by
   pyais from known local positions) come out on `targets` as Odometry, ENU at the origin,
   child_frame_id ais_<mmsi>, at the dead-reckoned positions of the stamp's time; each
   disappears once stale_after_s has passed since its last report; a bad line is counted.
2. UDP on 127.0.0.1: sentences sent in datagrams (two in one, one bad) are tracked the same way;
   a UDP port already in use is refused in one line (exit 2).
"""
import math
import socket

import pyais
import pytest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from std_msgs.msg import UInt64MultiArray

from ship_guidance.ais import KNOT
from ship_guidance.ais_node import LOG_PERIOD_S
from ship_sim.geodetic import ned_to_geodetic
from ship_sim.ros.conversions import msg_to_time, odometry_to_ned, time_to_msg
from ship_sim.ros.qos import STREAM

ORIGIN = (34.86, 128.73)
TOL_M = 0.5                 # AIS position resolution is 0.19 m (1/10000 arc minute)


def encode(msg_type, mmsi, north, east, speed_kn, course_deg):
    """One sentence at a local position; true heading not available (511): psi = COG."""
    lat, lon = ned_to_geodetic(north, east, *ORIGIN)
    return pyais.encode_dict(dict(type=msg_type, msg_type=msg_type, mmsi=mmsi, lat=lat, lon=lon,
                                  speed=speed_kn, course=course_deg, heading=511), talker_id='AI',
                             sentence_type='VDM')[0]


def counts(msg):
    return dict(zip(msg.layout.dim[0].label.split(','), msg.data))


@pytest.mark.timeout(120)
def test_replay_file_on_sim_time(ros_graph, tmp_path):
    a, b = 257000001, 257000002
    replay = tmp_path / 'ais.nmea'
    replay.write_text('\n'.join([
        '# t_s sentence',
        '5.0 !AIVDM,1,1,,B,15M67FC000G?ufbE`FepT@3n00Sa,0*5D',          # bad checksum
        f'10.0 {encode(1, a, 1000.0, 2000.0, 10.0, 90.0)}',              # class A, due east
        f'20.0 {encode(18, b, -500.0, 300.0, 0.0, 0.0)}',                # class B, stopped
    ]) + '\n')
    stale = 15.0
    node = ros_graph.start('ship_guidance', 'ais_node', params={
        'use_sim_time': True, 'file': str(replay), 'origin_lat_deg': ORIGIN[0],
        'origin_lon_deg': ORIGIN[1], 'stale_after_s': stale, 'publish_period_s': 1.0})
    tn = ros_graph.test_node()
    targets = tn.subscribe('/targets', Odometry)
    stats = tn.subscribe('/ais_counts', UInt64MultiArray)
    clock_pub = tn.publisher('/clock', Clock, STREAM)
    assert tn.wait_for_subscribers(clock_pub, timeout=20.0)
    assert tn.wait_for_publishers(targets, timeout=20.0)
    clock = Clock()
    for k in range(1, 101):                             # sim time 0.5 .. 50 s
        time_to_msg(0.5 * k, clock.clock)
        clock_pub.publish(clock)
        tn.spin_for(0.03)
    assert tn.spin_until(lambda: len(stats) and replay_done(stats), timeout=10.0)
    by = {}
    for m in targets.messages:
        assert m.header.frame_id == 'map'
        by.setdefault(m.child_frame_id, []).append(m)
    assert set(by) == {f'ais_{a}', f'ais_{b}'}
    ta = [msg_to_time(m.header.stamp) for m in by[f'ais_{a}']]
    tb = [msg_to_time(m.header.stamp) for m in by[f'ais_{b}']]
    # Tracked from its first report until stale_after_s after it (publication every 1 s).
    assert min(ta) == pytest.approx(10.0) and max(ta) == pytest.approx(10.0 + stale)
    assert min(tb) == pytest.approx(20.0) and max(tb) == pytest.approx(20.0 + stale)
    for m in by[f'ais_{a}']:
        o = odometry_to_ned(m)
        east = 2000.0 + 10.0 * KNOT * (o.t - 10.0)           # 10 kn due east since t = 10 s
        assert abs(o.north - 1000.0) < TOL_M and abs(o.east - east) < TOL_M
        assert m.pose.pose.position.x == pytest.approx(o.east)      # ENU: x east
        assert o.psi == pytest.approx(math.pi / 2) and o.u == pytest.approx(10.0 * KNOT)
        assert abs(o.v) < 1e-9
    for m in by[f'ais_{b}']:
        o = odometry_to_ned(m)
        assert abs(o.north + 500.0) < TOL_M and abs(o.east - 300.0) < TOL_M and o.u == 0.0
    c = counts(stats.last)
    assert c['checksum'] == 1 and c['decoded'] == 2 and c['targets'] == 0
    assert node.wait_for_output(r'bad AIS input \(checksum\)', timeout=5.0)
    # Tracked / dropped targets are logged in summaries at most every LOG_PERIOD_S (wall).
    assert node.wait_for_output(f'AIS targets? [0-9, and]*{a}[0-9, and]* dropped',
                                timeout=LOG_PERIOD_S + 5.0)
    assert node.returncode is None
    assert ros_graph.stop(node) == 0


def replay_done(stats):
    """The counters have seen the whole replay (every line fed)."""
    c = counts(stats.last)
    return c['decoded'] == 2 and c['checksum'] == 1 and c['targets'] == 0


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


@pytest.mark.timeout(90)
def test_udp_input(ros_graph):
    port = free_udp_port()
    node = ros_graph.start('ship_guidance', 'ais_node', params={
        'use_sim_time': False, 'udp_port': port, 'origin_lat_deg': ORIGIN[0],
        'origin_lon_deg': ORIGIN[1], 'publish_period_s': 0.2, 'per_target_topics': True})
    assert node.wait_for_output(f'UDP 127.0.0.1:{port}', timeout=20.0)
    tn = ros_graph.test_node()
    targets = tn.subscribe('/targets', Odometry)
    own = tn.subscribe('/targets/ais_257000012/odom', Odometry)
    stats = tn.subscribe('/ais_counts', UInt64MultiArray)
    assert tn.wait_for_publishers(targets, timeout=20.0)
    lines = [encode(1, 257000011, 800.0, -1200.0, 0.0, 0.0),
             encode(3, 257000012, -2500.0, 400.0, 0.0, 0.0)]
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.sendto(('\r\n'.join(lines) + '\r\n').encode(), ('127.0.0.1', port))
        s.sendto(b'!AIVDM,1,1,,B,15M67FC000G?ufbE`Fep,0*5C\r\n', ('127.0.0.1', port))

    def both():
        return {m.child_frame_id for m in targets.messages} >= {'ais_257000011', 'ais_257000012'}
    assert tn.spin_until(both, timeout=20.0)
    assert tn.wait_for_message(own, timeout=10.0) is not None
    for m in targets.messages:
        o = odometry_to_ned(m)
        want = (800.0, -1200.0) if m.child_frame_id == 'ais_257000011' else (-2500.0, 400.0)
        assert abs(o.north - want[0]) < TOL_M and abs(o.east - want[1]) < TOL_M
    assert all(m.child_frame_id == 'ais_257000012' for m in own.messages)
    assert tn.spin_until(lambda: len(stats) and counts(stats.last)['checksum'] == 1,
                         timeout=10.0)
    assert counts(stats.last)['targets'] == 2
    assert node.returncode is None
    assert ros_graph.stop(node) == 0


@pytest.mark.timeout(60)
def test_busy_udp_port_is_refused_in_one_line(ros_graph):
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(('127.0.0.1', 0))
        port = s.getsockname()[1]
        node = ros_graph.start('ship_guidance', 'ais_node', params={'udp_port': port})
        node.wait(timeout=30.0)
    assert node.returncode == 2
    lines = node.stderr().strip().splitlines()
    assert len(lines) == 1 and 'udp_port' in lines[0] and 'in use' in lines[0]
