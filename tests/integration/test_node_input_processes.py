"""Bad input to real node processes (colcon install tree): one line and exit 2 at start, or the
node staying up, answering, with its state intact.

1. invalid ROS arguments (empty value, missing value, unreadable or malformed params file, bad
   namespace, unknown flag) end every node with ONE line ``<exe>: invalid ROS arguments: ...``
   and exit code 2, no traceback;
2. an undeclared parameter ends the node with one line naming it and the closest declared one;
3. guidance_node: routes in the wrong frame or at 1e308 are refused (one line each) and the
   next good one is taken; NaN, 1e308 and 1e6 m jumps in odom are refused and still answered,
   one heading_cmd per odom, never NaN, cross-track unchanged, route_complete not latched by
   the outlier and still reported at the real end; a 200,000-pose route is refused without
   holding the node (odom answered throughout, well within the lockstep timeout);
4. follower_node: the same odom outliers, answered one for one, no NaN command;
5. autopilot_node (sequence pairing): a NaN heading_cmd is refused, counted, the previous
   command held, and its odom still answered;
6. traffic_node refuses a light target at 1e300 m/s or 1e300 m, ais_node an integer out of
   range (shown as an integer), each in one line with exit code 2.
"""
import math
import time

import pytest
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry, Path
from std_msgs.msg import Bool, Float64

from ship_guidance.path import Line, Route
from ship_guidance.ros.path_msgs import MAX_ROUTE_POSES, route_to_path_msg
from ship_sim.frames import psi_to_yaw
from ship_sim.ros.conversions import make_odometry
from ship_sim.ros.qos import LATCHED

NS = '/vessel_0'
NODES = [('ship_sim', 'vessel_node'), ('ship_guidance', 'guidance_node'),
         ('ship_guidance', 'follower_node'), ('ship_autopilot', 'autopilot_node'),
         ('ship_planner', 'route_node'), ('ship_planner', 'planner_node')]
#: The vessel node's lockstep timeout default (s).
LOCKSTEP_TIMEOUT_S = 5.0


def _lines(proc):
    return [line for line in proc.stderr().splitlines() if line.strip()]


def _assert_one_line_exit_2(proc, prefix, *needles):
    assert proc.wait(20.0) == 2, proc.report()
    lines = _lines(proc)
    assert len(lines) == 1, lines
    assert lines[0].startswith(prefix), lines[0]
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert 'Traceback' not in proc.output()


# -- 1, 2. start-up refusals ------------------------------------------------------------------------

@pytest.mark.timeout(120)
def test_vessel_node_refuses_invalid_ros_arguments_in_one_line(ros_graph, tmp_path):
    broken = tmp_path / 'broken.yaml'
    broken.write_text('/**:\n  ros__parameters:\n    dt: [0.1,\n')
    cases = [(['-p', 'model:='], "'-p model:='"),
             (['--params-file', '/nonexistent.yaml'], '/nonexistent.yaml'),
             (['--params-file', str(broken)], str(broken)),
             (['-p', 'dt'], "'-p dt'"),
             (['-r', '__ns:=bad ns'], '__ns'),
             (['--no-such-flag'], '--no-such-flag')]
    procs = [(ros_graph.start('ship_sim', 'vessel_node', extra_args=args), needle)
             for args, needle in cases]
    for proc, needle in procs:
        _assert_one_line_exit_2(proc, 'vessel_node: invalid ROS arguments: ', needle)
        assert '.c:' not in proc.stderr()   # rcl's C source locations are not for the user


@pytest.mark.timeout(120)
@pytest.mark.parametrize('package, name', NODES)
def test_every_node_refuses_an_empty_parameter_value_in_one_line(ros_graph, package, name):
    proc = ros_graph.start(package, name, extra_args=['-p', 'some_param:='])
    _assert_one_line_exit_2(proc, f'{name}: invalid ROS arguments: ', "'-p some_param:='")


@pytest.mark.timeout(120)
@pytest.mark.parametrize('package, name, typo, meant', [
    ('ship_sim', 'vessel_node', 'modle', 'model'),
    ('ship_guidance', 'guidance_node', 'lookahed_m', 'lookahead_m'),
    ('ship_guidance', 'follower_node', 'spacing', 'spacing_m'),
    ('ship_autopilot', 'autopilot_node', 'vessel_modl', 'vessel_model'),
    ('ship_planner', 'route_node', 'nonexistent_param', None),
])
def test_undeclared_parameter_is_refused_naming_the_closest(ros_graph, package, name, typo,
                                                            meant):
    proc = ros_graph.start(package, name, namespace=NS, params={typo: 'x'})
    needles = [f"'{typo}'"] + ([f"did you mean '{meant}'"] if meant else [])
    _assert_one_line_exit_2(proc, f'{name}: ', *needles)


@pytest.mark.timeout(60)
def test_guidance_refuses_arc_los_point_with_ilos_naming_it(ros_graph):
    """Lee 2004's LOS point on the turning circle is a variant of plain LOS only."""
    proc = ros_graph.start('ship_guidance', 'guidance_node', namespace=NS,
                           params={'law': 'ilos', 'arc_los_point': True})
    _assert_one_line_exit_2(proc, 'guidance_node: ', 'arc_los_point')


@pytest.mark.parametrize('target, needle', [
    ({'name': 't1', 'course_deg': 0.0, 'speed_mps': 1e300}, 'speed must be in [0, 50] m/s'),
    ({'name': 't1', 'x_m': 1e300, 'course_deg': 0.0, 'speed_mps': 1.0}, 'at most 1e+07 m'),
])
def test_traffic_node_refuses_a_target_no_ship_can_be_in_one_line(ros_graph, tmp_path, target,
                                                                  needle):
    import json

    import yaml
    params = tmp_path / 'traffic.yaml'       # JSON text in a parameter: a file, as the launcher
    params.write_text(yaml.safe_dump({'/**': {'ros__parameters': {'targets': json.dumps(
        [target])}}}))
    proc = ros_graph.start('ship_sim', 'traffic_node', params_file=params)
    _assert_one_line_exit_2(proc, 'traffic_node: ', "'targets'", 'light target t1', needle)


def test_ais_node_refuses_an_integer_out_of_range_naming_it_as_an_integer(ros_graph):
    proc = ros_graph.start('ship_guidance', 'ais_node', params={'udp_port': -1})
    _assert_one_line_exit_2(proc, 'ais_node: ', "'udp_port' = -1 is", '[0, 65535]')


def test_autopilot_refuses_a_partial_fuzzy_scaling_in_one_line(ros_graph):
    # Lee 2004's fuzzy scaling is all four gains or none (the gain table's)
    proc = ros_graph.start('ship_autopilot', 'autopilot_node', namespace=NS,
                           params={'controller': 'fuzzy_pid', 'fuzzy_ge': 2.75, 'fuzzy_gr': 50.0})
    _assert_one_line_exit_2(proc, 'autopilot_node: ', 'fuzzy_ge', 'all > 0')


@pytest.mark.timeout(120)
def test_wildcard_params_file_with_valid_keys_is_accepted(ros_graph, tmp_path):
    config = tmp_path / 'guidance.yaml'
    config.write_text('/**:\n  ros__parameters:\n    law: los\n    lookahead_m: 300.0\n'
                      '    max_plausible_speed: 20.0\n    use_sim_time: false\n')
    proc = ros_graph.start('ship_guidance', 'guidance_node', namespace=NS, params_file=config)
    # Constructed (its parameters are checked in the constructor; a refusal exits 2) once it
    # subscribes to its route; stopped only then, not while it may still be importing.
    route = ros_graph.test_node().publisher(f'{NS}/route', Path, LATCHED)
    assert ros_graph.test_node().wait_for_subscribers(route, timeout=90.0), proc.report()
    assert proc.returncode is None, proc.report()
    assert ros_graph.stop(proc) == 0


# -- 3. guidance_node -------------------------------------------------------------------------------

ROUTE_END_N = 1000.0
SPEED = 40.0          # m/s: 4 m per 0.1 s step, below the 50 m/s plausibility bound
OFFSET_E = 20.0       # m to starboard of the route (it runs north)
LOOKAHEAD = 100.0


def _route(frame_id='map'):
    from builtin_interfaces.msg import Time
    return route_to_path_msg(Route([Line((0.0, 0.0), (ROUTE_END_N, 0.0))]), Time(),
                             frame_id=frame_id)


def _odom(k, north=None, east=OFFSET_E, psi=0.0):
    t = 0.1 * k
    north = SPEED * t if north is None else north
    return make_odometry(t, north, east, psi, SPEED, 0.0, 0.0, 'vessel_0/base_link')


def _outlier(k):
    """The odom of step k: the straight run along the route, with outliers at fixed steps."""
    return {10: _odom(10, north=math.nan), 20: _odom(20, north=1e308),
            30: _odom(30, north=ROUTE_END_N + 1e6),       # far past the end: would finish
            40: _odom(40, psi=math.nan), 50: _odom(50, east=-1e308)}.get(k, _odom(k))


OUTLIERS = (10, 20, 30, 40, 50)


def _paced(tn, pub, inbox, msgs, timeout=5.0):
    """Publish each message once the previous one was answered on ``inbox``; the index of the
    first unanswered one (len(msgs) if all were)."""
    start = len(inbox)
    for i, m in enumerate(msgs):
        pub.publish(m)
        if not tn.spin_until(lambda: len(inbox) >= start + i + 1, timeout, poll=0.01):
            return i
    return len(msgs)


def _start_guidance(ros_graph, **params):
    proc = ros_graph.start('ship_guidance', 'guidance_node', namespace=NS,
                           params={'law': 'los', 'lookahead_m': LOOKAHEAD, **params})
    tn = ros_graph.test_node()
    route = tn.publisher(f'{NS}/route', Path, LATCHED)
    odom = tn.publisher(f'{NS}/odom', Odometry)
    heading = tn.subscribe(f'{NS}/heading_cmd', Float64)
    xte = tn.subscribe(f'{NS}/cross_track_error', Float64)
    complete = tn.subscribe(f'{NS}/route_complete', Bool, LATCHED)
    assert tn.wait_for_subscribers(route, timeout=15.0), proc.report()
    return proc, tn, route, odom, heading, xte, complete


@pytest.mark.timeout(120)
def test_guidance_refuses_bad_routes_and_outlier_odom_and_keeps_answering(ros_graph):
    proc, tn, route, odom, heading, xte, complete = _start_guidance(ros_graph)
    route.publish(_route('odom'))
    assert proc.wait_for_output(r"route refused: route frame_id is 'odom'", 10.0), proc.report()
    far = _route()
    far.poses[1].pose.position.y = 1e308
    route.publish(far)
    assert proc.wait_for_output(r'route refused: .*from the origin', 10.0), proc.report()
    assert proc.returncode is None
    route.publish(_route())
    assert proc.wait_for_output(r'route received: 1 legs, 1000.0 m', 10.0), proc.report()
    assert tn.wait_for_subscribers(odom, timeout=10.0)
    refusals = [line for line in proc.output().splitlines() if 'route refused' in line]
    assert len(refusals) == 2      # one line per refused route

    # Up to the outlier that would finish the route, then check it did not.
    k_end = int(math.ceil(ROUTE_END_N / (SPEED * 0.1)))   # first step at or past the end
    n_steps = k_end + 15
    assert _paced(tn, odom, heading, [_outlier(k) for k in range(31)]) == 31
    tn.spin_for(0.3)
    assert not any(m.data for m in complete.messages), 'an outlier completed the route'
    assert _paced(tn, odom, heading, [_outlier(k) for k in range(31, n_steps)]) == n_steps - 31
    tn.spin_for(0.3)
    assert proc.returncode is None, proc.report()
    # Exactly one answer per odom (lockstep pairing), never NaN, state intact: the guidance
    # answers the refused ones with the previous values, and the normal ones see the same
    # line, so every answer is the same LOS command and cross-track.
    assert len(heading) == n_steps and len(xte) == n_steps
    want_yaw = psi_to_yaw(-math.atan(OFFSET_E / LOOKAHEAD))
    assert all(m.data == pytest.approx(want_yaw, abs=1e-9) for m in heading.messages)
    assert all(m.data == pytest.approx(OFFSET_E, abs=1e-6) for m in xte.messages)
    # The real end of the route is still reported.
    assert tn.wait_for_message(complete, 5.0, predicate=lambda m: m.data) is not None
    out = proc.output()
    assert 'odom refused' in out and '1 so far' in out
    assert ros_graph.stop(proc) == 0


def _huge_path(n):
    msg = Path()
    msg.header.frame_id = 'map'
    poses = []
    for i in range(n):
        p = PoseStamped()
        p.header.frame_id = 'map'
        p.pose.position.y = 5.0 * i
        p.pose.orientation.z = math.sin(math.pi / 4)
        p.pose.orientation.w = math.cos(math.pi / 4)
        poses.append(p)
    msg.poses = poses
    return msg


@pytest.mark.timeout(180)
def test_guidance_refuses_a_huge_route_without_stalling(ros_graph):
    proc, tn, route, odom, heading, xte, complete = _start_guidance(ros_graph)
    route.publish(_route())
    assert proc.wait_for_output(r'route received', 10.0), proc.report()
    assert tn.wait_for_subscribers(odom, timeout=10.0)
    huge = _huge_path(10 * MAX_ROUTE_POSES)
    assert _paced(tn, odom, heading, [_odom(k) for k in range(5)]) == 5
    route.publish(huge)
    # Keep stepping as a lockstep simulator would: every odom must be answered within the
    # lockstep timeout while the huge route arrives and is refused.
    t0 = time.monotonic()
    k = 5
    worst = 0.0
    while time.monotonic() - t0 < 15.0 and not proc.wait_for_output(
            r'route refused: route has 200000 poses', 0.0):
        t = time.monotonic()
        assert _paced(tn, odom, heading, [_odom(k)], timeout=LOCKSTEP_TIMEOUT_S) == 1, \
            f'odom {k} not answered within {LOCKSTEP_TIMEOUT_S} s'
        worst = max(worst, time.monotonic() - t)
        k += 1
    assert proc.wait_for_output(r'route refused: route has 200000 poses; at most 20000', 1.0), \
        proc.report()
    assert _paced(tn, odom, heading, [_odom(k)]) == 1
    print(f'worst odom answer while the 200,000-pose route arrived: {worst:.3f} s')
    assert worst < 0.5 * LOCKSTEP_TIMEOUT_S
    # The previous route is kept: the answers are those of the good route.
    assert heading.last.data == pytest.approx(psi_to_yaw(-math.atan(OFFSET_E / LOOKAHEAD)))
    assert ros_graph.stop(proc) == 0


# -- 4. follower_node -------------------------------------------------------------------------------

@pytest.mark.timeout(120)
def test_follower_refuses_outlier_odom_and_answers_each(ros_graph):
    proc = ros_graph.start('ship_guidance', 'follower_node', namespace='/vessel_1',
                           params={'predecessor_odom_topic': '/vessel_0/odom',
                                   'lookahead_m': LOOKAHEAD, 'stepping_mode': 'realtime'})
    tn = ros_graph.test_node()
    route = tn.publisher('/vessel_1/route', Path, LATCHED)
    odom = tn.publisher('/vessel_1/odom', Odometry)
    pred = tn.publisher('/vessel_0/odom', Odometry)
    heading = tn.subscribe('/vessel_1/heading_cmd', Float64)
    xte = tn.subscribe('/vessel_1/cross_track_error', Float64)
    complete = tn.subscribe('/vessel_1/route_complete', Bool, LATCHED)
    assert tn.wait_for_subscribers(route, timeout=15.0), proc.report()
    route.publish(_route())
    assert proc.wait_for_output(r'route received', 10.0), proc.report()
    assert tn.wait_for_subscribers(odom, timeout=10.0)
    assert tn.wait_for_subscribers(pred, timeout=10.0)
    pred.publish(_odom(0, north=math.nan))        # a bad predecessor sample: dropped, counted
    n_steps = 60
    assert _paced(tn, odom, heading, [_outlier(k) for k in range(n_steps)]) == n_steps
    tn.spin_for(0.3)
    assert proc.returncode is None, proc.report()
    assert len(heading) == n_steps and len(xte) == n_steps
    assert all(math.isfinite(m.data) for m in heading.messages)
    assert all(m.data == pytest.approx(OFFSET_E, abs=1e-6) for m in xte.messages)
    assert not any(m.data for m in complete.messages), 'an outlier completed the route'
    out = proc.output()
    assert 'odom refused' in out and 'predecessor odom refused' in out
    assert ros_graph.stop(proc) == 0


# -- 5. autopilot_node ------------------------------------------------------------------------------

@pytest.mark.timeout(120)
def test_autopilot_holds_a_nan_heading_cmd_counts_it_and_answers(ros_graph):
    proc = ros_graph.start('ship_autopilot', 'autopilot_node', namespace=NS,
                           params={'vessel_model': 'mariner', 'pairing': 'sequence'})
    tn = ros_graph.test_node()
    odom = tn.publisher(f'{NS}/odom', Odometry)
    cmd = tn.publisher(f'{NS}/heading_cmd', Float64)
    rudder = tn.subscribe(f'{NS}/rudder_cmd', Float64)
    assert tn.wait_for_subscribers(odom, timeout=15.0), proc.report()
    assert tn.wait_for_subscribers(cmd, timeout=10.0)
    # Heading north, no yaw rate, command 0.3 rad to starboard: the rudder ramps to starboard
    # (negative) at the rate limit, monotonically while the command is held.
    want = psi_to_yaw(0.3)
    bad = {5: math.nan, 6: math.inf, 12: math.nan}
    n_steps = 20
    for k in range(n_steps):
        cmd.publish(Float64(data=bad.get(k, want)))
        odom.publish(make_odometry(0.1 * k, 0.0, 0.0, 0.0, 7.7, 0.0, 0.0, 'vessel_0/base_link'))
        assert tn.spin_until(lambda: len(rudder) >= k + 1, 5.0, poll=0.01), proc.report()
    tn.spin_for(0.3)
    assert proc.returncode is None and len(rudder) == n_steps
    values = [m.data for m in rudder.messages]
    assert all(math.isfinite(v) for v in values)
    assert all(v < 0.0 for v in values[1:]), values
    assert all(b <= a + 1e-12 for a, b in zip(values, values[1:])), values   # held: no let-up
    out = proc.output()
    assert 'heading_cmd nan refused' in out and '(1 so far)' in out
    assert ros_graph.stop(proc) == 0


@pytest.mark.timeout(120)
def test_autopilot_in_sequence_pairing_holds_its_first_answers_for_a_late_subscriber(ros_graph):
    """A simulator takes the n-th rudder_cmd it receives as step n's: an answer sent before its
    reader matched would be lost and shift every later one. The autopilot keeps its answers
    until a subscriber has matched, then sends them all, in order."""
    proc = ros_graph.start('ship_autopilot', 'autopilot_node', namespace=NS,
                           params={'vessel_model': 'mariner', 'pairing': 'sequence'})
    tn = ros_graph.test_node()
    odom = tn.publisher(f'{NS}/odom', Odometry)
    cmd = tn.publisher(f'{NS}/heading_cmd', Float64)
    assert tn.wait_for_subscribers(odom, timeout=15.0), proc.report()
    assert tn.wait_for_subscribers(cmd, timeout=10.0)
    n_steps = 3
    for k in range(n_steps):
        cmd.publish(Float64(data=psi_to_yaw(0.3)))
        odom.publish(make_odometry(0.1 * k, 0.0, 0.0, 0.0, 7.7, 0.0, 0.0, 'vessel_0/base_link'))
    tn.spin_for(1.0)   # the answers are computed; nobody subscribes to rudder_cmd yet
    assert proc.returncode is None, proc.report()
    rudder = tn.subscribe(f'{NS}/rudder_cmd', Float64)
    assert tn.spin_until(lambda: len(rudder) >= n_steps, 15.0, poll=0.01), proc.report()
    tn.spin_for(0.3)
    values = [m.data for m in rudder.messages]
    assert len(values) == n_steps, values
    # The same ramp as answered live: to starboard at the rate limit, never letting up.
    assert all(v < 0.0 for v in values[1:]) and values[2] < values[1], values
    assert ros_graph.stop(proc) == 0
