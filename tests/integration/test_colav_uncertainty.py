"""colav_node as a real process reads a target's pose covariance (issue 31 item 3).

One target on `tracks` crosses from starboard and would pass 1100 m ahead of the own ship:
beyond d_safe (926 m), so while its covariance is zero the decisions keep the nominal course
(offset 0). The same target with a position covariance of sigma = 150 m per axis has the safe
distance d_safe + uncertainty_k sigma = 1226 m, and the decisions alter course to starboard.
"""
import math

import numpy as np
import pytest
from nav_msgs.msg import Odometry
from std_msgs.msg import Float64, Float64MultiArray

from ship_guidance.colav_io import DECISION_COLUMNS
from ship_guidance.colav_params import ColavParams
from ship_guidance.cpa import velocity
from ship_sim.ros.conversions import make_odometry
from ship_sim.ros.qos import STREAM_KEPT

NS = '/vessel_0'
U = 6.1733                                  # m/s
PSI = math.pi / 2                           # own ship heading east (NED)
TCPA, LATERAL, SIGMA = 480.0, 1100.0, 150.0
OFFSET = DECISION_COLUMNS.index('course_offset_rad')


def target_at(t):
    """The target crossing from starboard (heading north), passing LATERAL ahead at TCPA."""
    v_o, v_t = velocity(PSI, U), velocity(0.0, U)
    rel = v_t - v_o
    ahead = np.array([-rel[1], rel[0]]) / np.hypot(*rel) * LATERAL      # left of rel: ahead
    p0 = (v_o - v_t) * TCPA + ahead
    return p0 + v_t * t


@pytest.mark.timeout(60)
def test_a_target_covariance_widens_the_safe_distance(ros_graph):
    p = ColavParams()
    assert p.d_safe_m < LATERAL < p.d_safe_m + p.uncertainty_k * SIGMA
    node = ros_graph.start('ship_guidance', 'colav_node', namespace=NS, params={
        'use_sim_time': True, 'targets_topic': 'tracks', 'decision_period_s': 1.0})
    tn = ros_graph.test_node()
    odom = tn.publisher(f'{NS}/odom', Odometry)
    ref = tn.publisher(f'{NS}/heading_ref', Float64, STREAM_KEPT)
    tracks = tn.publisher(f'{NS}/tracks', Odometry)
    decisions = tn.subscribe(f'{NS}/colav_decision', Float64MultiArray)
    for pub in (odom, ref, tracks):
        assert tn.wait_for_subscribers(pub, timeout=20.0), node.report()
    offsets = {}
    for k in range(12):
        t = float(k)
        sigma = 0.0 if k < 6 else SIGMA
        north, east = target_at(t)
        msg = make_odometry(t, north, east, 0.0, U, 0.0, 0.0, 'ais_257000031')
        msg.pose.covariance[0] = msg.pose.covariance[7] = sigma ** 2
        tracks.publish(msg)
        tn.spin_for(0.3 if k == 0 else 0.05)
        odom.publish(make_odometry(t, 0.0, U * t, PSI, U, 0.0, 0.0, 'vessel_0/base_link'))
        ref.publish(Float64(data=0.0))              # ENU yaw 0: east
        assert tn.wait_for_message(decisions, 10.0, count=k + 1) is not None, node.report()
        offsets[k] = decisions.messages[k].data[OFFSET]
    assert [offsets[k] for k in range(6)] == [0.0] * 6, offsets
    assert all(offsets[k] > 0.0 for k in range(6, 12)), offsets
    assert ros_graph.stop(node) == 0
