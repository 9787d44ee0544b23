"""Stale inputs end safely: what a vessel does when its controller goes quiet.

1. realtime: a rudder_cmd of 0.3 rad, then silence. After command_timeout_s of sim time the
   vessel_node centres the rudder (the actual rudder, rate-limited, reaches 0) and warns once;
   a new command is followed again.
2. lockstep: the controller answers a few steps, then stops. After lockstep_max_timeouts
   consecutive lockstep timeouts the node ends with exit code 1 and one error line naming the
   count, instead of creeping on one step per timeout for ever.
3. realtime graph (vessel_node + autopilot_node, pairing latest): heading_cmd comes for a while,
   then stops. The autopilot warns that the command is stale and keeps steering to the last
   heading: the ship holds it (yaw within a few degrees, no drift away).
"""
import math

import numpy as np
import pytest
from nav_msgs.msg import Odometry
from std_msgs.msg import Float64

from ship_sim.ros.conversions import msg_to_time, quaternion_to_yaw

NS = '/vessel_0'


@pytest.mark.timeout(90)
def test_realtime_rudder_centred_after_command_timeout(ros_graph):
    timeout_s = 10.0
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS,
                          params={'model': 'mariner', 'stepping_mode': 'realtime', 'speedup': 20.0,
                                  'command_timeout_s': timeout_s})
    tn = ros_graph.test_node()
    rudder = tn.subscribe(f'{NS}/rudder', Float64)
    odom = tn.subscribe(f'{NS}/odom', Odometry)
    cmd = tn.publisher(f'{NS}/rudder_cmd', Float64)
    assert tn.wait_for_subscribers(cmd, timeout=15.0)
    assert tn.wait_for_message(odom, timeout=15.0) is not None
    cmd.publish(Float64(data=0.3))
    # The rudder reaches the command (mariner: 5 deg/s, 0.3 rad in 3.4 s) ...
    assert tn.spin_until(lambda: len(rudder) and rudder.last.data > 0.299, timeout=15.0)
    # ... then, with no further command, goes back to the centre (the Mariner's rudder servo
    # approaches it exponentially once inside its rate limit).
    assert tn.spin_until(lambda: abs(rudder.last.data) < 1e-3, timeout=30.0)
    # One rudder message per 0.1 s step: sim time between two of them is their index difference.
    # It turns back exactly command_timeout_s after the command came (the step before it moved).
    values = np.array([m.data for m in rudder.messages])
    moved = int(np.argmax(values != 0.0))
    back = moved + int(np.argmax(np.diff(values[moved:]) < 0.0)) + 1
    assert timeout_s - 0.2 <= (back - moved) * 0.1 <= timeout_s + 0.3
    assert sim.wait_for_output(r'no rudder_cmd for .* rudder centred', timeout=5.0)
    cmd.publish(Float64(data=-0.2))   # commands again: followed
    assert tn.spin_until(lambda: rudder.last.data < -0.199, timeout=15.0)
    assert sim.wait_for_output(r'rudder_cmd again', timeout=5.0)
    assert sim.returncode is None
    assert ros_graph.stop(sim) == 0


@pytest.mark.timeout(90)
def test_lockstep_ends_after_consecutive_timeouts(ros_graph):
    answered, max_timeouts, timeout = 5, 3, 0.3
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS,
                          params={'model': 'mariner', 'stepping_mode': 'lockstep',
                                  'lockstep_timeout': timeout,
                                  'lockstep_max_timeouts': max_timeouts})
    tn = ros_graph.test_node()
    cmd = tn.publisher(f'{NS}/rudder_cmd', Float64)
    state = {'n': 0}

    def answer(msg):
        if state['n'] < answered:
            state['n'] += 1
            cmd.publish(Float64(data=0.0))

    odom = tn.subscribe(f'{NS}/odom', Odometry, callback=answer)
    assert tn.spin_until(lambda: sim.returncode is not None, timeout=45.0), 'never ended'
    assert sim.returncode == 1
    err = sim.output()
    assert f'no rudder_cmd for {max_timeouts} consecutive steps' in err
    assert 'Traceback' not in err
    # steps 0..answered were answered; then max_timeouts - 1 held steps went out before the end
    assert len(odom) == answered + max_timeouts


@pytest.mark.timeout(120)
def test_autopilot_holds_last_heading_when_heading_cmd_goes_stale(ros_graph):
    params = {'use_sim_time': True, 'vessel_model': 'mariner', 'pairing': 'latest',
              'heading_timeout_s': 5.0}
    ap = ros_graph.start('ship_autopilot', 'autopilot_node', namespace=NS, params=params)
    tn = ros_graph.test_node()
    heading = tn.publisher(f'{NS}/heading_cmd', Float64)
    assert tn.wait_for_subscribers(heading, timeout=15.0)
    # x40: the 500 s of sim time below take 12.5 s of wall time (each wait allows 40 s).
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS,
                          params={'model': 'mariner', 'stepping_mode': 'realtime', 'speedup': 40.0,
                                  'initial_yaw_deg': 90.0})
    odom = tn.subscribe(f'{NS}/odom', Odometry)
    target = math.radians(60.0)   # a 30 deg turn to starboard (ENU yaw 90 -> 60 deg)

    def yaw():
        return quaternion_to_yaw(odom.last.pose.pose.orientation)

    def commanding():
        heading.publish(Float64(data=target))
        return len(odom) and msg_to_time(odom.last.header.stamp) > 200.0

    assert tn.spin_until(commanding, timeout=40.0, poll=0.05)
    assert abs(yaw() - target) < math.radians(3.0), 'did not reach the commanded heading'
    t_stop = msg_to_time(odom.last.header.stamp)
    n0 = len(odom)
    # silence: 300 s of sim time more
    assert tn.spin_until(lambda: msg_to_time(odom.last.header.stamp) > t_stop + 300.0, timeout=40.0)
    assert ap.wait_for_output(r'heading_cmd stale', timeout=5.0)
    later = np.array([quaternion_to_yaw(m.pose.pose.orientation) for m in odom.messages[n0:]])
    # holds the last heading: no drift away from it (a centred or frozen rudder would not)
    assert np.max(np.abs(np.angle(np.exp(1j * (later - target))))) < math.radians(3.0)
    assert sim.returncode is None and ap.returncode is None
