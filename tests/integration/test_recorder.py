"""ship_mission.recorder as a real process, as the launcher starts it, against a test node
publishing a tiny graph.

The test node latches a route *before* the recorder starts (a late recorder must still get it,
through transient_local), then publishes /clock, odom and rudder for N steps. The recorder is
stopped with SIGINT, as the launcher stops it, and must leave a complete bag: every message,
exact Odometry stamps, rudder log times from /clock (sim time), the route's offered QoS, a
display topic that lags the graph logged at its own stamps, /tf from the odom, zstd chunks, and
two independent readers (mcap + mcap-ros2-support, rosbags) agreeing with metadata.yaml.
"""
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import yaml
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry, Path as PathMsg
from rosbags.highlevel import AnyReader
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import NavSatFix
from std_msgs.msg import Float64, UInt64

from ship_mission.bag import read_bag
from ship_mission.bag_check import cross_check
from ship_mission.launcher import RECORDER
from ship_mission.processes import die_with_parent
from ship_sim.ros.qos import LATCHED, RECORD_ACK, STREAM

NS = '/vessel_0'
STEP_NS = 100_000_000
N = 200
ACK = '/recorder_ack'  # the recorder's acknowledgement of complete steps (--ack)
FIX_LAG = 30          # steps the display topic's stamps trail the graph (as nav_display_node)


def _wait_for(path, pattern, timeout, proc):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        text = path.read_text(errors='replace') if path.exists() else ''
        if re.search(pattern, text):
            return True
        if proc.poll() is not None:
            return False
        time.sleep(0.05)
    return False


@pytest.mark.timeout(60)
def test_recorder_process_records_a_late_latched_route_and_every_step(ros_graph, tmp_path):
    tn = ros_graph.test_node()
    route_pub = tn.publisher(f'{NS}/route', PathMsg, LATCHED)
    path = PathMsg()
    path.header.frame_id = 'map'
    for x in (0.0, 100.0, 250.0):
        ps = PoseStamped()
        ps.pose.position.x, ps.pose.orientation.w = x, 1.0
        path.poses.append(ps)
    route_pub.publish(path)  # before the recorder exists
    clock_pub = tn.publisher('/clock', Clock, STREAM)
    odom_pub = tn.publisher(f'{NS}/odom', Odometry, STREAM)
    rudder_pub = tn.publisher(f'{NS}/rudder', Float64, STREAM)
    fix_pub = tn.publisher(f'{NS}/fix', NavSatFix, STREAM)

    bag = tmp_path / 'run' / 'bag'
    covered = ','.join(('/clock', f'{NS}/odom', f'{NS}/rudder'))
    acks = tn.subscribe(ACK, UInt64)
    out = tmp_path / 'recorder.out'
    with open(out, 'wb') as fout:
        rec = subprocess.Popen([sys.executable, str(RECORDER), str(bag), '--ack', f'{ACK}={covered}'],
                               env=ros_graph.env, stdout=fout,
                               stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, start_new_session=True,
                               preexec_fn=die_with_parent)
    try:
        for topic in ('/clock', f'{NS}/odom', f'{NS}/rudder', f'{NS}/route', f'{NS}/fix'):
            assert _wait_for(out, f'recording {re.escape(topic)} ', 20.0, rec), out.read_text()
        for pub in (clock_pub, odom_pub, rudder_pub, fix_pub):
            assert tn.wait_for_subscribers(pub, timeout=10.0)
        for k in range(1, N + 1):
            c = Clock()
            c.clock.sec, c.clock.nanosec = divmod(k * STEP_NS, 1_000_000_000)
            clock_pub.publish(c)
            o = Odometry()
            o.header.stamp = c.clock
            o.header.frame_id, o.child_frame_id = 'map', 'vessel_0/base_link'
            o.pose.pose.position.x, o.pose.pose.orientation.w = 0.5 * k, 1.0
            odom_pub.publish(o)
            rudder_pub.publish(Float64(data=0.001 * k))
            if k > FIX_LAG:   # the display of step k - FIX_LAG, published now
                f = NavSatFix()
                f.header.stamp.sec, f.header.stamp.nanosec = divmod((k - FIX_LAG) * STEP_NS, 1_000_000_000)
                fix_pub.publish(f)
            tn.spin_once(0.0)
            time.sleep(0.002)
        # The recorder's lockstep acknowledgement: every step of the three topics is written.
        assert tn.spin_until(lambda: len(acks) and acks.last.data == N, timeout=20.0), (
            [m.data for m in acks.messages[-3:]], out.read_text())
        # A simulator that matches the recorder only after an ack went out still gets it
        # (transient_local): a lost first ack held a simulator for its whole start timeout.
        late = tn.subscribe(ACK, UInt64, RECORD_ACK)
        assert tn.spin_until(lambda: len(late) and late.last.data == N, timeout=20.0), (
            [m.data for m in late.messages])
        rec.send_signal(signal.SIGINT)
        assert rec.wait(timeout=10.0) == 0, out.read_text()
    finally:
        if rec.poll() is None:
            rec.kill()
            rec.wait()
    text = out.read_text()
    assert re.search(r'recorded \{.*"/vessel_0/odom": %d' % N, text), text

    data = read_bag(bag)
    v = data.vessels[NS]
    steps = np.arange(1, N + 1)
    np.testing.assert_array_equal(v.t, steps * STEP_NS / 1e9)
    np.testing.assert_array_equal(v.x, 0.5 * steps)
    np.testing.assert_array_equal(v.rudder.v, 0.001 * steps)
    # sim-time log stamps: /clock and rudder are separate subscriptions, so at most one step apart
    assert np.max(np.abs(v.rudder.t - v.t)) <= STEP_NS / 1e9 + 1e-9
    assert v.route is not None and list(v.route.x) == [0.0, 100.0, 250.0]

    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    topics = {t['topic_metadata']['name']: t for t in meta['topics_with_message_count']}
    assert topics[f'{NS}/odom']['message_count'] == N
    assert topics['/clock']['message_count'] == N
    assert topics[f'{NS}/route']['message_count'] == 1
    assert topics[f'{NS}/route']['topic_metadata']['offered_qos_profiles'][0]['durability'] == 'transient_local'
    assert '/rosout' not in topics
    assert topics['/tf']['message_count'] == N
    assert topics['/tf']['topic_metadata']['type'] == 'tf2_msgs/msg/TFMessage'

    check = cross_check(bag)
    assert check['problems'] == [] and check['compressions'] == {'zstd'}
    assert check['metadata'][f'{NS}/fix'] == N - FIX_LAG
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.topic in (f'{NS}/fix', '/tf')]
        logged = {'/tf': [], f'{NS}/fix': []}
        for conn, t_ns, raw in reader.messages(connections=conns):
            logged[conn.topic].append((t_ns, reader.deserialize(raw, conn.msgtype)))
    # the lagging display topic is logged at its own stamps, not at the recorder's /clock
    assert [t for t, _ in logged[f'{NS}/fix']] == [k * STEP_NS for k in range(1, N - FIX_LAG + 1)]
    tf = [(t, m.transforms[0]) for t, m in logged['/tf']]
    assert [t for t, _ in tf] == list(steps * STEP_NS)
    assert all((x.header.frame_id, x.child_frame_id) == ('map', 'vessel_0/base_link') for _, x in tf)
    np.testing.assert_array_equal([x.transform.translation.x for _, x in tf], 0.5 * steps)
