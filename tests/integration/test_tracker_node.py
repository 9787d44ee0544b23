"""tracker_node as a real process: AIS over UDP becomes tracks with covariance on `tracks`.

A ship due east at 10 kn is reported (AIVDM, pyais-encoded from its true position at the time
of sending) five times, 1 s apart, then falls silent; a bad sentence is sent too. On `tracks`
(wall clock, published every 0.2 s): frame_id map, child_frame_id ais_<mmsi>, the position
near the truth (the AIS position resolution plus the distance run during the UDP and timer
latencies), ENU pose covariance filled and symmetric, its position sigma (colav_io, what
colav_node reads) below the sensor's after five reports and growing once they stop; twist
covariance filled; the bad sentence warned about. The node is stopped cleanly.
"""
import math
import socket
import time

import pytest
from nav_msgs.msg import Odometry

from ship_guidance.ais import KNOT
from ship_guidance.colav_io import position_sigma
from ship_guidance.tracker import TrackerConfig
from ship_sim.ros.conversions import odometry_to_ned

from test_ais_node import ORIGIN, encode, free_udp_port

MMSI = 257000021
SPEED_KN = 10.0
LATENCY_S = 0.5            # UDP poll, publication period and a loaded machine, at most


@pytest.mark.timeout(90)
def test_udp_reports_become_tracks_with_covariance(ros_graph):
    port = free_udp_port()
    node = ros_graph.start('ship_guidance', 'tracker_node', params={
        'use_sim_time': False, 'udp_port': port, 'origin_lat_deg': ORIGIN[0],
        'origin_lon_deg': ORIGIN[1], 'publish_period_s': 0.2})
    assert node.wait_for_output(f'UDP 127.0.0.1:{port}', timeout=20.0)
    tn = ros_graph.test_node()
    tracks = tn.subscribe('/tracks', Odometry)
    assert tn.wait_for_publishers(tracks, timeout=20.0)
    u = SPEED_KN * KNOT
    t0 = time.monotonic()
    sent = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.sendto(b'!AIVDM,1,1,,B,15M67FC000G?ufbE`Fep,0*5C\r\n', ('127.0.0.1', port))
        for k in range(5):
            tn.spin_until(lambda: time.monotonic() - t0 >= k, timeout=2.0, poll=0.02)
            east = 100.0 + u * (time.monotonic() - t0)
            s.sendto((encode(1, MMSI, 500.0, east, SPEED_KN, 90.0) + '\r\n').encode(),
                     ('127.0.0.1', port))
            sent.append((time.monotonic(), east))
    n_at_last = len(tracks)
    tn.spin_for(3.0)                                   # silent: prediction only
    msgs = [m for m in tracks.messages if m.child_frame_id == f'ais_{MMSI}']
    assert len(msgs) > 10 and len(tracks) > n_at_last
    assert all(m.header.frame_id == 'map' for m in msgs)
    sigma_p = TrackerConfig().position_sigma_m
    sigmas = [position_sigma(m.pose.covariance) for m in msgs]
    for m in msgs:
        c = list(m.pose.covariance)
        assert c[0] > 0.0 and c[7] > 0.0 and c[1] == c[6] and c[0] * c[7] > c[1] ** 2
        assert m.twist.covariance[0] > 0.0 and m.twist.covariance[7] > 0.0
    # after the five reports the track knows its position better than one report ...
    assert min(sigmas) < sigma_p
    # ... and once they stop, its uncertainty grows with every prediction
    tail = sigmas[-5:]
    assert all(b > a for a, b in zip(tail, tail[1:])), tail
    # the position follows the ship: at each message, within TOL of where the ship was
    # east of its last report (dead-reckoned at 10 kn), north unchanged
    tol = 3.0 * sigma_p + u * LATENCY_S
    last = odometry_to_ned(msgs[-1])
    assert abs(last.north - 500.0) < tol
    assert last.psi == pytest.approx(math.pi / 2, abs=math.radians(5.0))
    assert last.u == pytest.approx(u, abs=0.5)
    t_sent, east_sent = sent[-1]
    age = time.monotonic() - t_sent
    assert abs(last.east - (east_sent + u * age)) < tol + u * 0.5
    assert node.wait_for_output(r'bad AIS input', timeout=5.0)
    assert node.returncode is None
    assert ros_graph.stop(node) == 0
