"""A held publisher opens for its readers by name, in real processes (ship_sim.ros.held_start,
ship_sim.ros.readiness): autopilot_node in sequence pairing with `rudder_cmd_readers` naming one
node. A subscriber of another name does not open it (a count would have: one reader listed, one
matched); the named one, joining late, does, and both then get every answer from the first on,
in order."""
import time

import pytest
from nav_msgs.msg import Odometry
from std_msgs.msg import Float64

from harness import TestNode
from ship_sim.frames import psi_to_yaw
from ship_sim.ros.conversions import make_odometry

NS = '/vessel_0'
NAMED = 'named_reader'
N_STEPS = 3


@pytest.mark.timeout(120)
def test_rudder_cmd_is_held_for_the_named_reader_not_for_any_reader(ros_graph, request):
    proc = ros_graph.start('ship_autopilot', 'autopilot_node', namespace=NS,
                           params={'vessel_model': 'mariner', 'pairing': 'sequence',
                                   'rudder_cmd_readers': [f'/{NAMED}']})
    tn = ros_graph.test_node()          # /test_node: a reader of rudder_cmd, not the named one
    odom = tn.publisher(f'{NS}/odom', Odometry)
    cmd = tn.publisher(f'{NS}/heading_cmd', Float64)
    early = tn.subscribe(f'{NS}/rudder_cmd', Float64)
    assert tn.wait_for_subscribers(odom, timeout=15.0), proc.report()
    assert tn.wait_for_subscribers(cmd, timeout=10.0), proc.report()
    assert tn.wait_for_publishers(early, timeout=10.0), proc.report()
    for k in range(N_STEPS):
        cmd.publish(Float64(data=psi_to_yaw(0.3)))
        odom.publish(make_odometry(0.1 * k, 0.0, 0.0, 0.0, 7.7, 0.0, 0.0, 'vessel_0/base_link'))
    tn.spin_for(3.0)                    # the answers are computed and held
    assert proc.returncode is None, proc.report()
    assert len(early) == 0, 'a reader of another name opened the held rudder_cmd'

    named = TestNode(ros_graph.domain_id, NAMED)
    request.addfinalizer(named.close)
    late = named.subscribe(f'{NS}/rudder_cmd', Float64)
    deadline = time.monotonic() + 20.0
    while (len(early) < N_STEPS or len(late) < N_STEPS) and time.monotonic() < deadline:
        tn.spin_once(0.02)
        named.spin_once(0.02)
    tn.spin_for(0.3)
    named.spin_for(0.3)
    got_early, got_late = [m.data for m in early.messages], [m.data for m in late.messages]
    assert len(got_late) == N_STEPS and got_early == got_late, (got_early, got_late)
    # the ramp as answered live: to starboard at the rate limit, never letting up
    assert all(v < 0.0 for v in got_late[1:]) and got_late[2] < got_late[1], got_late
    assert 'sending after' not in proc.output(), proc.report()
    assert ros_graph.stop(proc) == 0
