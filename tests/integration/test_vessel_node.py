"""vessel_node as a real process (colcon install tree), checked against the pure simulator.

1. realtime turn: a constant rudder_cmd of +-0.35 rad turns the Mariner to the commanded side
   (positive = port = ENU yaw increasing) on a circle whose radius (U/r from odom, and a circle
   fitted to the odom positions) matches VesselSimulator's within 2 % / 3 %;
2. lockstep: a test node answers every odom with a rudder_cmd that is a function of the step
   index (with NaN, inf and out-of-range values mixed in); two runs give bit-identical odom,
   equal to the pure simulator fed the same (held / saturated) commands, message by message;
3. bad input: an unknown model ends the node with exit code 2 and one line naming the
   parameter and the allowed names; NaN/inf rudder_cmd neither crash the node nor reach the
   rudder.
"""
import math

import numpy as np
import pytest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64

from ship_sim.models import MODEL_NAMES
from ship_sim.ros.conversions import make_odometry, msg_to_time, quaternion_to_yaw
from ship_sim.simulator import VesselSimulator

from harness import answer_each_odom

NS = '/vessel_0'


def _odom_fields(msg):
    """Every number an Odometry from the simulator carries, as a tuple (for exact compares)."""
    p, o = msg.pose.pose.position, msg.pose.pose.orientation
    lin, ang = msg.twist.twist.linear, msg.twist.twist.angular
    return (msg.header.stamp.sec, msg.header.stamp.nanosec, p.x, p.y, p.z, o.x, o.y, o.z, o.w,
            lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)


def _circle_radius(x, y):
    """Least-squares circle through points (algebraic fit): radius."""
    A = np.column_stack([x, y, np.ones_like(x)])
    b = x * x + y * y
    c, *_ = np.linalg.lstsq(A, b, rcond=None)
    xc, yc = c[0] / 2, c[1] / 2
    return math.sqrt(c[2] + xc * xc + yc * yc)


# -- 1. realtime turning circle -------------------------------------------------------------------

SETTLE_S = 300.0   # sim seconds after the rudder command: U/r is within 0.1 % of its final value


@pytest.mark.timeout(90)
@pytest.mark.parametrize('rudder', [0.35, -0.35])
def test_realtime_turn_matches_pure_simulator(ros_graph, rudder):
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS,
                          params={'model': 'mariner', 'stepping_mode': 'realtime',
                                  'speedup': 40.0, 'command_timeout_s': 0.0})  # hold it
    tn = ros_graph.test_node()
    odom = tn.subscribe(f'{NS}/odom', Odometry)
    rudder_in = tn.subscribe(f'{NS}/rudder', Float64)
    cmd = tn.publisher(f'{NS}/rudder_cmd', Float64)
    assert tn.wait_for_subscribers(cmd, timeout=15.0), 'vessel_node never subscribed rudder_cmd'
    assert tn.wait_for_message(odom, timeout=15.0) is not None, 'no odom'

    # The first step the rudder moves marks the execute time; then wait SETTLE_S of sim time.
    state = {'t_exec': None}

    def settled():
        cmd.publish(Float64(data=rudder))  # held by the node: repeating it is harmless
        if state['t_exec'] is None:
            for i, m in enumerate(rudder_in.messages):
                if m.data != 0.0:
                    # rudder and odom go out together per step; use the odom of that step
                    state['t_exec'] = msg_to_time(odom[min(i, len(odom) - 1)].header.stamp)
                    break
            return False
        return msg_to_time(odom.last.header.stamp) >= state['t_exec'] + SETTLE_S

    assert tn.spin_until(settled, timeout=60.0, poll=0.2), (
        f'not settled: t_exec {state["t_exec"]}, last odom t '
        f'{msg_to_time(odom.last.header.stamp):.1f} s')
    assert sim.returncode is None, 'vessel_node ended during the run'

    # The pure simulator, same command from trim, same time after execute.
    pure = VesselSimulator('mariner', dt=0.1)
    pure.run(rudder, int(round(SETTLE_S / 0.1)))
    u_p, v_p, r_p = pure.velocity_ground()
    radius_pure = math.hypot(u_p, v_p) / abs(r_p)

    last = odom.last.twist.twist
    r_node = last.angular.z   # FLU: positive = counter-clockwise = port turn
    radius_node = math.hypot(last.linear.x, last.linear.y) / abs(r_node)

    # Side: + rudder turns to port (ENU yaw increases), - to starboard.
    assert np.sign(r_node) == np.sign(rudder)
    assert np.sign(-r_p) == np.sign(rudder)   # pure sim is NED: r < 0 is a port turn
    t = np.array([msg_to_time(m.header.stamp) for m in odom.messages])
    yaw = np.unwrap([quaternion_to_yaw(m.pose.pose.orientation) for m in odom.messages])
    after = t >= state['t_exec']
    assert np.sign(yaw[-1] - yaw[after][0]) == np.sign(rudder)
    assert abs(yaw[-1] - yaw[after][0]) > math.pi  # well into the turn

    # Geometry too: a circle through the last 150 s of the track.
    late = t >= t[-1] - 150.0
    x = np.array([m.pose.pose.position.x for m in odom.messages])[late]
    y = np.array([m.pose.pose.position.y for m in odom.messages])[late]
    radius_fit = _circle_radius(x, y)
    print(f'rudder {rudder:+.2f} rad: turning radius pure {radius_pure:.2f} m, node U/r '
          f'{radius_node:.2f} m, node circle fit {radius_fit:.2f} m')
    assert radius_node == pytest.approx(radius_pure, rel=0.02)
    assert radius_fit == pytest.approx(radius_pure, rel=0.03)

    assert ros_graph.stop(sim) == 0
    assert 'realtime x40 pacing' in sim.stderr()


# -- 2. lockstep: deterministic, equal to the pure simulator -------------------------------------

N_STEPS = 400


def _command(k):
    """rudder_cmd for step k: a smooth manoeuvre with bad values mixed in."""
    if k == 100:
        return math.nan
    if k == 200:
        return math.inf
    if 250 <= k < 260:
        return 1.0   # beyond the Mariner's 40 deg: saturated
    return 0.35 * math.sin(0.05 * k)


def _expected_odoms(n_steps):
    """The odom of steps 0..n_steps from the pure simulator fed what the node must apply."""
    sim = VesselSimulator('mariner', dt=0.1)
    held = 0.0
    out = [_odom_fields(make_odometry(*sim.nav_state(), child_frame_id='vessel_0/base_link'))]
    for k in range(n_steps):
        c = _command(k)
        if math.isfinite(c):
            held = c
        sim.step(held)
        out.append(_odom_fields(make_odometry(*sim.nav_state(),
                                              child_frame_id='vessel_0/base_link')))
    return out


def _lockstep_run(ros_graph, label):
    tn = ros_graph.test_node()
    odom, cmd = answer_each_odom(tn, NS, _command)
    clock = tn.subscribe('/clock', Clock)
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS, label=label,
                          params={'model': 'mariner', 'stepping_mode': 'lockstep',
                                  'max_steps': N_STEPS, 'lockstep_timeout': 5.0})
    assert tn.spin_until(lambda: len(odom) > N_STEPS or sim.returncode is not None,
                         timeout=60.0, poll=0.5)
    tn.spin_for(0.2)
    assert sim.wait(10.0) == 0, 'vessel_node did not end cleanly after max_steps'
    wall = odom.times[-1] - odom.times[0]
    print(f'{label}: {len(odom) - 1} lockstep steps in {wall:.3f} s wall = '
          f'{(len(odom) - 1) / wall:.0f} steps/s (sim + Python echo)')
    assert len(odom) == N_STEPS + 1, f'{len(odom)} odom messages for steps 0..{N_STEPS}'
    assert 'timeouts' in sim.stderr() and '0 lockstep timeouts' in sim.stderr()
    assert '2 non-finite commands refused' in sim.stderr()
    stamps = [msg_to_time(m.clock) for m in clock.messages]
    assert stamps[-1] == pytest.approx(N_STEPS * 0.1)
    result = [_odom_fields(m) for m in odom.messages]
    tn.unsubscribe(odom)
    tn.unsubscribe(clock)
    tn.node.destroy_publisher(cmd)
    return result


@pytest.mark.timeout(150)
def test_lockstep_is_bit_identical_and_equals_pure_simulator(ros_graph):
    first = _lockstep_run(ros_graph, 'lockstep_run1')
    second = _lockstep_run(ros_graph, 'lockstep_run2')
    expected = _expected_odoms(N_STEPS)
    assert first == second                 # raw floats, every field, every step
    for k, (got, want) in enumerate(zip(first, expected)):
        assert got == want, f'step {k}: node {got} != pure simulator {want}'
    # Frames as documented.
    assert first[0][:2] == (0, 0)


@pytest.mark.timeout(60)
def test_lockstep_timeout_holds_the_previous_command_and_drops_the_late_one(ros_graph):
    n_steps, skipped = 30, 10
    tn = ros_graph.test_node()
    cmd = tn.publisher(f'{NS}/rudder_cmd', Float64)

    def answer(msg):
        k = len(odom) - 1
        if k == skipped:
            return                                    # step 10's command does not come ...
        if k == skipped + 1:
            cmd.publish(Float64(data=-0.3))           # ... until after its timeout: dropped
        cmd.publish(Float64(data=0.02 * k))

    odom = tn.subscribe(f'{NS}/odom', Odometry, callback=answer)
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS,
                          params={'model': 'nomoto1', 'stepping_mode': 'lockstep',
                                  'max_steps': n_steps, 'lockstep_timeout': 0.5})
    assert tn.spin_until(lambda: len(odom) > n_steps, timeout=30.0)
    assert sim.wait(10.0) == 0
    err = sim.stderr()
    assert f'no rudder_cmd for step {skipped}' in err
    assert '1 lockstep timeouts, 1 late commands dropped' in err

    pure = VesselSimulator('nomoto1', dt=0.1)
    want = [_odom_fields(make_odometry(*pure.nav_state(), child_frame_id='vessel_0/base_link'))]
    for k in range(n_steps):
        pure.step(0.02 * (k if k != skipped else k - 1))   # step 10 holds step 9's command
        want.append(_odom_fields(make_odometry(*pure.nav_state(),
                                               child_frame_id='vessel_0/base_link')))
    assert [_odom_fields(m) for m in odom.messages] == want


@pytest.mark.timeout(60)
def test_runtime_parameter_changes_are_validated(ros_graph):
    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient

    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS,
                          params={'model': 'mariner', 'speedup': 5.0})
    tn = ros_graph.test_node()
    client = AsyncParameterClient(tn.node, f'{NS}/vessel_node')
    assert tn.spin_until(lambda: client.services_are_ready(), timeout=15.0)

    def set_param(name, value):
        future = client.set_parameters([Parameter(name, value=value)])
        assert tn.spin_until(future.done, timeout=10.0)
        return future.result().results[0]

    assert not set_param('speedup', -1.0).successful
    assert not set_param('model', 'tanker').successful        # read-only
    assert not set_param('dt', 0.2).successful                # read-only
    odom = tn.subscribe(f'{NS}/odom', Odometry)
    assert set_param('speedup', 20.0).successful
    assert sim.wait_for_output(r'speedup now x20', timeout=5.0)
    # Still stepping, now at 200 steps per wall second.
    assert tn.spin_until(lambda: len(odom) >= 100, timeout=10.0)
    t_sim = msg_to_time(odom[-1].header.stamp) - msg_to_time(odom[0].header.stamp)
    t_wall = odom.times[-1] - odom.times[0]
    assert t_sim / t_wall == pytest.approx(20.0, rel=0.3)
    assert sim.returncode is None
    assert ros_graph.stop(sim) == 0
    assert 'realtime x20 pacing' in sim.stderr()


@pytest.mark.timeout(60)
def test_config_file_sets_every_declared_parameter(ros_graph):
    import yaml
    from rclpy.parameter import parameter_value_to_python
    from rclpy.parameter_client import AsyncParameterClient

    from harness import INSTALL

    config = INSTALL / 'ship_sim' / 'share' / 'ship_sim' / 'config' / 'vessel.yaml'
    values = yaml.safe_load(config.read_text())['/**']['ros__parameters']
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS, params_file=config)
    tn = ros_graph.test_node()
    client = AsyncParameterClient(tn.node, f'{NS}/vessel_node')
    assert tn.spin_until(lambda: client.services_are_ready(), timeout=15.0)
    future = client.list_parameters()
    assert tn.spin_until(future.done, timeout=10.0)
    declared = set(future.result().result.names) - {'use_sim_time',
                                                     'start_type_description_service'}
    assert declared == set(values)
    future = client.get_parameters(sorted(values))
    assert tn.spin_until(future.done, timeout=10.0)
    got = dict(zip(sorted(values), map(parameter_value_to_python, future.result().values)))
    assert got == values
    assert ros_graph.stop(sim) == 0


# -- 3. bad input ---------------------------------------------------------------------------------

@pytest.mark.timeout(30)
def test_unknown_model_exits_with_one_line(ros_graph):
    proc = ros_graph.start('ship_sim', 'vessel_node', namespace=NS,
                           params={'model': 'titanic'})
    code = proc.wait(20.0)
    assert code is not None and code != 0
    lines = [line for line in proc.stderr().splitlines() if line.strip()]
    assert len(lines) == 1, lines
    line = lines[0]
    assert "'model'" in line and 'titanic' in line
    for name in MODEL_NAMES:
        assert name in line


@pytest.mark.timeout(30)
def test_bad_publish_rate_exits_with_one_line(ros_graph):
    proc = ros_graph.start('ship_sim', 'vessel_node', namespace=NS,
                           params={'dt': 0.1, 'publish_rate': 3.0})
    assert proc.wait(20.0) == 2
    lines = [line for line in proc.stderr().splitlines() if line.strip()]
    assert len(lines) == 1 and "'publish_rate'" in lines[0] and '3.0' in lines[0], lines


@pytest.mark.timeout(60)
def test_nan_rudder_cmd_is_refused_and_not_applied(ros_graph):
    sim = ros_graph.start('ship_sim', 'vessel_node', namespace=NS,
                          params={'model': 'mariner', 'speedup': 10.0})
    tn = ros_graph.test_node()
    odom = tn.subscribe(f'{NS}/odom', Odometry)
    rudder = tn.subscribe(f'{NS}/rudder', Float64)
    cmd = tn.publisher(f'{NS}/rudder_cmd', Float64)
    assert tn.wait_for_subscribers(cmd, timeout=15.0)
    assert tn.wait_for_message(rudder, timeout=15.0) is not None
    for bad in (math.nan, math.inf, -math.inf, math.nan):
        cmd.publish(Float64(data=bad))
    n_before = len(odom)
    tn.spin_for(1.0)   # 10 sim seconds at x10
    assert sim.returncode is None, 'vessel_node died on a NaN command'
    assert len(odom) > n_before + 20, 'odom stopped after the NaN command'
    assert all(m.data == 0.0 for m in rudder.messages), 'a refused command moved the rudder'
    assert all(math.isfinite(v) for m in odom.messages for v in _odom_fields(m)[2:])

    # A valid command still works afterwards.
    cmd.publish(Float64(data=0.1))
    assert tn.wait_for_message(rudder, timeout=10.0, predicate=lambda m: m.data > 0.05)
    assert ros_graph.stop(sim) == 0
    err = sim.stderr()
    assert 'refused' in err
    assert '4 non-finite commands refused' in err


@pytest.mark.timeout(20)
def test_install_tree_has_the_executable():
    from harness import executable
    assert executable('ship_sim', 'vessel_node').name == 'vessel_node'
