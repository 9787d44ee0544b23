"""ship_sim.ros.conversions (hand-computed frames) and ship_sim.ros.params (in-process node).

Frames (doc/design.md): x_E = y_N, y_E = x_N, yaw_ENU = pi/2 - psi_NED, v_FLU = -v_FRD,
r_FLU = -r_FRD; Odometry pose in 'map' (ENU), twist in the body frame FLU.
"""
import math
import time

import pytest
from rclpy.parameter import Parameter

from ship_sim.ros.conversions import (base_link_frame, make_odometry, msg_to_nanoseconds,
                                      msg_to_time, odometry_to_ned, quaternion_to_yaw,
                                      time_to_msg, yaw_to_quaternion)
from ship_sim.ros.params import ParameterError


def test_odometry_from_ned_by_hand():
    # Heading east (psi = 90 deg) at north 100, east 50; surge 5, sway 1 to starboard, turning
    # to starboard at 0.1 rad/s.
    msg = make_odometry(12.5, 100.0, 50.0, math.pi / 2, 5.0, 1.0, 0.1, 'vessel_3/base_link')
    assert msg.header.frame_id == 'map' and msg.child_frame_id == 'vessel_3/base_link'
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (12, 500_000_000)
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    assert (p.x, p.y, p.z) == (50.0, 100.0, 0.0)
    # ENU yaw 0 (facing east): identity quaternion.
    assert (q.x, q.y, q.z, q.w) == pytest.approx((0.0, 0.0, 0.0, 1.0), abs=1e-15)
    tw = msg.twist.twist
    assert (tw.linear.x, tw.linear.y, tw.angular.z) == (5.0, -1.0, -0.1)


def test_odometry_heading_north_is_enu_yaw_90_deg():
    msg = make_odometry(0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 'base_link')
    q = msg.pose.pose.orientation
    assert (q.z, q.w) == pytest.approx((math.sin(math.pi / 4), math.cos(math.pi / 4)))
    assert quaternion_to_yaw(q) == pytest.approx(math.pi / 2)


@pytest.mark.parametrize('psi', [-3.0, -1.0, 0.0, 0.5, 2.0, 3.1])
def test_odometry_round_trip(psi):
    msg = make_odometry(3.25, -7.0, 11.0, psi, 4.0, -0.3, 0.02, 'base_link')
    o = odometry_to_ned(msg)
    assert (o.t, o.north, o.east, o.u, o.v, o.r) == (3.25, -7.0, 11.0, 4.0, -0.3, 0.02)
    assert o.psi == pytest.approx(psi, abs=1e-12)


def test_yaw_quaternion_round_trip_and_roll_pitch_ignored():
    for yaw in (-3.1, -1.0, 0.0, 1.0, 3.1):
        assert quaternion_to_yaw(yaw_to_quaternion(yaw)) == pytest.approx(yaw, abs=1e-12)
    # yaw 30 deg composed with a roll of 10 deg: the heading is still 30 deg.
    cy, sy = math.cos(math.radians(15)), math.sin(math.radians(15))
    cr, sr = math.cos(math.radians(5)), math.sin(math.radians(5))
    q = (sr * cy, sr * sy, cr * sy, cr * cy)   # q_yaw * q_roll (ZYX)
    assert quaternion_to_yaw(q) == pytest.approx(math.radians(30), abs=1e-12)


def test_time_conversion_rounds_to_whole_nanoseconds():
    m = time_to_msg(0.3)
    assert (m.sec, m.nanosec) == (0, 300_000_000)
    m = time_to_msg(1.9999999999)
    assert (m.sec, m.nanosec) == (2, 0)
    m = time_to_msg(7 * 0.1)                      # 0.7000000000000001
    assert (m.sec, m.nanosec) == (0, 700_000_000)
    assert msg_to_time(time_to_msg(123.456)) == pytest.approx(123.456, abs=1e-9)
    assert msg_to_nanoseconds(time_to_msg(5.000000001)) == 5_000_000_001


def test_base_link_frame():
    assert base_link_frame('/vessel_0') == 'vessel_0/base_link'
    assert base_link_frame('/fleet/vessel_2') == 'fleet/vessel_2/base_link'
    assert base_link_frame('/') == 'base_link'


# -- params ----------------------------------------------------------------------------------

def test_start_values_are_checked(make_node):
    node, p = make_node(dt=0.05)
    assert p.declare('dt', 0.1, 'step', lo=1e-3, hi=1.0, unit='s') == 0.05
    assert p.declare('mode', 'a', 'mode', choices=('a', 'b')) == 'a'
    d = node.describe_parameter('dt')
    assert d.floating_point_range[0].from_value == 1e-3
    assert d.floating_point_range[0].to_value == 1.0
    assert 'step' in d.description


@pytest.mark.parametrize('name, default, value, kw, needles', [
    ('dt', 0.1, 5.0, dict(lo=1e-3, hi=1.0), ("'dt'", '5.0', '[0.001, 1.0]')),
    ('dt', 0.1, math.nan, dict(lo=1e-3, hi=1.0), ("'dt'", 'nan')),
    ('gain', 0.1, math.inf, dict(), ("'gain'", 'inf', 'finite')),
    ('mode', 'a', 'c', dict(choices=('a', 'b')), ("'mode'", "'c'", "'a', 'b'")),
    ('steps', 5, -1, dict(lo=0), ("'steps'", '= -1 is', '>= 0')),     # an integer, not -1.0
    ('udp_port', 0, 70000, dict(lo=0, hi=65535), ("= 70000 is", '[0, 65535]')),
    ('rate', 10.0, 3.0, dict(check=lambda r: None if 10 % r == 0 else 'a divisor of 10'),
     ("'rate'", '3.0', 'a divisor of 10')),
    ('dt', 0.1, 1, dict(), ("'dt'", '1', 'DOUBLE')),          # static typing: write 1.0
])
def test_bad_start_value_raises_one_line(make_node, name, default, value, kw, needles):
    node, p = make_node(**{name: value})
    with pytest.raises(ParameterError) as err:
        p.declare(name, default, 'description', **kw)
    text = str(err.value)
    assert '\n' not in text
    for needle in needles:
        assert needle in text, text


def test_runtime_changes_are_validated(make_node):
    node, p = make_node()
    seen = []
    p.declare('speedup', 1.0, 'x', lo=0.01, hi=100.0, on_change=seen.append)
    p.declare('model', 'm', 'model', read_only=True)
    p.declare('mode', 'a', 'mode', choices=('a', 'b'))
    # Out of the descriptor's range: rclpy's own refusal (names parameter, value and range).
    bad = node.set_parameters([Parameter('speedup', value=-2.0)])[0]
    assert not bad.successful and 'speedup' in bad.reason and '-2.0' in bad.reason
    # Other checks: our on-set callback, same message as at start.
    bad = node.set_parameters([Parameter('mode', value='z')])[0]
    assert not bad.successful and "'mode'" in bad.reason and "'a', 'b'" in bad.reason
    assert node.get_parameter('mode').value == 'a'
    assert node.get_parameter('speedup').value == 1.0 and seen == []
    ok = node.set_parameters([Parameter('speedup', value=20.0)])[0]
    assert ok.successful and seen == [20.0] and p.value('speedup') == 20.0
    ro = node.set_parameters([Parameter('model', value='x')])[0]
    assert not ro.successful and node.get_parameter('model').value == 'm'
    # Parameters we did not declare (use_sim_time) are left to rclpy.
    assert node.set_parameters([Parameter('use_sim_time', value=True)])[0].successful


def test_a_bad_route_is_refused_with_the_reason_and_a_good_one_decoded():
    from nav_msgs.msg import Path
    from ship_guidance.path import Line, Route
    from ship_guidance.ros.path_msgs import accept_route, route_to_path_msg

    class Log:
        def __init__(self):
            self.lines = []

        def error(self, text):
            self.lines.append(text)

    log = Log()
    bad = Path()
    bad.header.frame_id = 'odom'
    assert accept_route(bad, log) is None
    assert log.lines == ["route refused: route frame_id is 'odom', expected 'map'; keeping the "
                         'previous route']
    from builtin_interfaces.msg import Time
    good = route_to_path_msg(Route([Line((0.0, 0.0), (100.0, 50.0))]), Time())
    route = accept_route(good, log)
    assert route.length == pytest.approx(math.hypot(100.0, 50.0)) and len(log.lines) == 1


# -- shutdown --------------------------------------------------------------------------------

def test_wait_for_acks_is_quiet_when_a_signal_has_shut_the_context_down(make_node):
    # vessel_node waits for reliable subscribers after its last step; a signal arriving then
    # made rcl refuse and the EventsExecutor log a FATAL callback exception.
    from rclpy._rclpy_pybind11 import RCLError
    from rclpy.duration import Duration
    from std_msgs.msg import Float64

    from ship_sim.ros.run import wait_for_acks
    node, _ = make_node()
    pub = node.create_publisher(Float64, 'acks_test', 10)
    wait_for_acks(node, (pub, None), timeout_s=0.1)      # context alive, nobody listening
    node.context.try_shutdown()
    with pytest.raises(RCLError, match='context is invalid'):
        pub.wait_for_all_acked(Duration(seconds=0.1))    # what rcl does without the guard
    wait_for_acks(node, (pub, None), timeout_s=0.1)


def test_a_stop_signal_ends_the_spin_between_callbacks_and_before_it_the_start(make_node,
                                                                               monkeypatch):
    # rclpy's own handlers shut the context down at any moment, also inside a busy callback,
    # whose next publish then failed (a FATAL traceback on Ctrl-C under load). run_node's only
    # take note while spinning: the running callback finishes and publishes, then spin ends.
    # After the spin (a lockstep simulator that ended itself at max_steps, tearing down when
    # the launcher's SIGINT came) a signal is only noted too: raised there, it killed the
    # process by the signal (exit -2) instead of letting it return its code.
    import signal

    from std_msgs.msg import Float64

    from ship_sim.ros import run
    node, _ = make_node()
    pub = node.create_publisher(Float64, 'stop_test', 10)
    published = []

    def busy():
        if not published:
            run._on_stop_signal(signal.SIGINT, None)     # the signal lands inside the callback
        pub.publish(Float64(data=1.0))                   # ... which still publishes
        published.append(True)

    node.create_timer(0.01, busy)
    t0 = time.monotonic()
    try:
        run.spin(node, 'single')
        assert published == [True]          # ended right after that callback, none after it
        assert node.context.ok()            # the context is shut down by run_node's finally
        assert time.monotonic() - t0 < 5.0
    finally:
        run._stop_signals.clear()
    run._on_stop_signal(signal.SIGINT, None)   # the spin is over: the teardown goes on
    assert run.stop_signalled()
    run._stop_signals.clear()
    monkeypatch.setattr(run, '_ending', False)   # as before any spin
    with pytest.raises(KeyboardInterrupt):  # not spinning (rclpy starting, node being built)
        run._on_stop_signal(signal.SIGTERM, None)
    run._stop_signals.clear()


def test_a_per_step_clock_subscriber_matched_after_step_0_still_hears_it(make_node):
    # traffic_node and ais_node act on every /clock step; in lockstep colav_node waits for
    # their step-0 samples. The simulator's /clock publisher may match them only after step 0
    # is out (discovery on a loaded machine), which the subscriptions created here after the
    # publish stand for: the transient_local pair delivers it, a volatile one could not.
    import rclpy
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock

    from ship_sim.ros.qos import CLOCK, CLOCK_STEPS
    sim, _ = make_node()
    listener, _ = make_node()
    pub = sim.create_publisher(Clock, '/clock_test', CLOCK)
    step0 = Clock()
    step0.clock.sec = 0
    pub.publish(step0)
    heard, missed = [], []
    listener.create_subscription(Clock, '/clock_test', heard.append, CLOCK_STEPS)
    listener.create_subscription(Clock, '/clock_test', missed.append,
                                 QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE))
    ex = rclpy.executors.SingleThreadedExecutor(context=sim.context)
    ex.add_node(listener)
    deadline = time.monotonic() + 10.0
    while not heard and time.monotonic() < deadline:
        ex.spin_once(timeout_sec=0.1)
    assert len(heard) == 1 and heard[0].clock.sec == 0
    assert missed == []


_RUN_PROCESS_THEN_SIGNAL = '''
import os, signal, sys
from ship_sim.ros import run
code = run.run_process(lambda: object(), lambda obj: None, lambda obj: None, lambda obj: 7,
                       args=['node'], prog='node')
print(signal.getsignal(signal.SIGINT) is signal.SIG_IGN,
      signal.getsignal(signal.SIGTERM) is signal.SIG_IGN, flush=True)
os.kill(os.getpid(), signal.SIGINT)       # as a launcher's stop landing while the process exits
os.kill(os.getpid(), signal.SIGTERM)
sys.exit(code)
'''


def test_a_process_that_returned_from_run_process_exits_with_its_code_whatever_signal_comes():
    # At interpreter exit Python puts back the default action of a signal with a Python handler,
    # and a stop landing then killed a node that had ended by itself (exit -2: a lockstep
    # simulator at max_steps, in test_platoon and test_closed_loop under load). Ignored signals
    # stay ignored through the exit.
    import subprocess
    import sys
    done = subprocess.run([sys.executable, '-c', _RUN_PROCESS_THEN_SIGNAL], capture_output=True,
                          text=True, timeout=60)
    assert done.stdout.split() == ['True', 'True'], done.stderr[-2000:]
    assert done.returncode == 7, done.stderr[-2000:]
