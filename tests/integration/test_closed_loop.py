"""The whole graph of one vessel as real processes, in lockstep: route, guidance, autopilot, sim.

Vessel: the NPS AUV II (ship_sim.models.nps_auv2, 2.2 m, 1 m/s) on a 121 m route with two
filleted 90 deg corners (data/routes/auv_two_corners.yaml), starting 5 m to starboard of the
first leg, plain LOS + PD autopilot (data/auv_closed_loop.yaml). Its closed loop is fast compared
with its length (omega_n 1.35 rad/s), so the start offset dies out within ~20 m and both
corners fit in ~1250 lockstep steps: seconds of wall time, yet the same loop as the Mariner's.
The test node starts the four executables as ``ros2 run`` would (params from the scenario
file, with the glue written out here, not taken from the launcher) and listens to every topic.

1. The route is completed (``route_complete`` arrives) with a bounded cross-track error:
   - bound: on straight legs plain LOS settles at e = 0; on an arc of radius R the PD autopilot's
     heading lags the command by 2 zeta r / omega_n (r = U / (R + e)) and the hull's course
     lags its heading by the steady sideslip beta(R), so LOS settles outside the arc at
         e_arc = d tan(2 zeta U / (omega_n (R + e_arc)) + |beta(R)|)
     (ship_guidance.los.pd_arc_offset's fixed point with the sideslip added; beta(R) from the
     pure simulator turning steadily on radius R). The worst steady error of the route is thus
     e_arc; the RMS error after settling must stay below it (a loop that oscillates, lags or
     saturates does worse);
   - settling: the approach from the start offset is nonlinear (the LOS intercept angle
     saturates at atan(e/d)) until |e| <= d; from there the linearised loop
     (ship_guidance.los.linear_loop_matrix) decays within 4 / |Re lambda_slowest|;
   - the corners were turned: at the middle of each straight leg the heading is the leg's
     course within atan(e_arc / d), the largest deviation LOS commands while |e| <= e_arc.
2. Determinism: the same graph twice gives bit-identical odom, heading_cmd and rudder_cmd
   streams, message by message (lockstep pairs by sequence, so wall-clock load cannot matter).
"""
import math

import numpy as np
import pytest
from nav_msgs.msg import Odometry
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Bool, Float64, Float64MultiArray

from mission.scenario import load_scenario, start_pose
from ship_autopilot.gains import autopilot_gains
from ship_guidance.los import linear_loop_matrix
from ship_planner.route_files import load_route
from ship_sim.frames import wrap_angle
from ship_sim.ros.conversions import quaternion_to_yaw
from ship_sim.ros.qos import LATCHED
from ship_sim.simulator import VesselSimulator

from harness import REPO_ROOT

SCENARIO = REPO_ROOT / 'tests' / 'integration' / 'data' / 'auv_closed_loop.yaml'
# The test node keeps every message of a run (the graph's own QoS keeps 100; a test process that
# is descheduled for a moment must not lose any, the graph runs at hundreds of steps/s).
DEEP = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10000,
                  reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
FINISHED = 3  # index of the 'finished' flag in guidance_node's progress array


def _odom_fields(msg):
    """Every number of an Odometry from the simulator (exact compares)."""
    p, o = msg.pose.pose.position, msg.pose.pose.orientation
    lin, ang = msg.twist.twist.linear, msg.twist.twist.angular
    return (msg.header.stamp.sec, msg.header.stamp.nanosec, p.x, p.y, p.z, o.x, o.y, o.z, o.w,
            lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)


def _start_graph(ros_graph, scenario, max_steps, tag=''):
    """Start the four nodes of vessel 0 of ``scenario`` in lockstep; the test node listens.

    Returns (test node, {name: NodeProcess}, {topic: Inbox}). The simulator publishes step 0
    once guidance, autopilot and the test node all subscribe odom (lockstep_odom_subscribers =
    3), and it is started only when the test node hears the other nodes' publishers."""
    spec = scenario.vessels[0]
    ns = f'/{spec.namespace}'
    tn = ros_graph.test_node()
    inbox = {name: tn.subscribe(f'{ns}/{name}', typ, DEEP) for name, typ in (
        ('odom', Odometry), ('heading_cmd', Float64), ('rudder_cmd', Float64),
        ('cross_track_error', Float64), ('progress', Float64MultiArray))}
    inbox['route_complete'] = tn.subscribe(f'{ns}/route_complete', Bool, LATCHED)
    x, y, yaw = start_pose(spec, load_route(spec.route_file).route)
    sim_time = {'use_sim_time': True}
    procs = {
        'route': ros_graph.start('ship_planner', 'route_node', namespace=ns, label='route' + tag,
                                 params={**sim_time, 'route_file': str(spec.route_file),
                                         'watch_period_s': 0.0}),
        'guidance': ros_graph.start('ship_guidance', 'guidance_node', namespace=ns,
                                    label='guidance' + tag,
                                    params={**sim_time, **spec.guidance_params}),
        'autopilot': ros_graph.start('ship_autopilot', 'autopilot_node', namespace=ns,
                                     label='autopilot' + tag,
                                     params={**sim_time, 'vessel_model': spec.model,
                                             'pairing': 'sequence', **spec.autopilot_params}),
    }
    # The simulator only waits for ITS subscribers; the test node must also have matched the
    # guidance's and the autopilot's publishers before step 0, or it misses the first steps.
    for name in ('heading_cmd', 'rudder_cmd', 'cross_track_error', 'progress', 'route_complete'):
        matched = tn.wait_for_publishers(inbox[name], timeout=20.0)
        assert matched and not _dead(procs), f'no publisher of {name}:\n' + ros_graph.report()
    # A second publisher means another graph on this ROS_DOMAIN_ID (e.g. a launcher run that
    # chose the same id without the harness's lock): the run would mix two vessels.
    assert inbox['route_complete'].subscription.get_publisher_count() == 1, (
        f'another graph publishes on domain {ros_graph.domain_id}')
    procs['vessel'] = ros_graph.start(
        'ship_sim', 'vessel_node', namespace=ns, label='vessel' + tag,
        params={'model': spec.model, 'initial_x': float(x), 'initial_y': float(y),
                'initial_yaw_deg': math.degrees(yaw), 'dt': scenario.dt_s,
                'publish_rate': 1.0 / scenario.dt_s, 'stepping_mode': 'lockstep',
                'clock_master': True, 'max_steps': max_steps,
                'lockstep_timeout': scenario.lockstep_timeout_s, 'lockstep_odom_subscribers': 3})
    return tn, procs, inbox


def _dead(procs, allow=()):
    return [p for name, p in procs.items() if name not in allow and p.returncode is not None]


def _steady_sideslip(model, radius, dt):
    """|sideslip| (rad) of ``model`` turning steadily on ``radius`` (m), pure simulator.

    The rudder for that radius is found by rescaling (radius ~ 1 / rudder for a steady turn,
    Nomoto) and repeating until the radius is within 1 %; each turn is held 60 s (the AUV's
    turn settles in a few seconds: Nomoto T ~ L/U ~ 2 s)."""
    delta = 0.1
    for _ in range(8):
        sim = VesselSimulator(model, dt=dt)
        sim.run(delta, int(round(60.0 / dt)))
        u, v, r = sim.velocity_ground()
        got = math.hypot(u, v) / abs(r)
        if abs(got / radius - 1.0) < 0.01:
            return abs(math.atan2(v, u))
        delta *= got / radius
    raise AssertionError(f'no steady turn of radius {radius} m found (last {got:.2f} m)')


def _arc_offset_bound(lookahead, radius, speed, zeta, omega_n, sideslip):
    """Steady LOS cross-track error (m) outside an arc: d tan(2 zeta r / omega_n + |beta|)."""
    e = 0.0
    for _ in range(100):
        e = lookahead * math.tan(2.0 * zeta * speed / (omega_n * (radius + e)) + sideslip)
    return e


# -- 1. route completed, cross-track error bounded, corners turned ------------------------------

@pytest.mark.timeout(120)
def test_graph_completes_the_route_with_bounded_cross_track_error(ros_graph):
    scenario = load_scenario(SCENARIO)
    spec = scenario.vessels[0]
    max_steps = int(round(scenario.duration_s / scenario.dt_s))
    tn, procs, inbox = _start_graph(ros_graph, scenario, max_steps)
    done = tn.spin_until(lambda: (inbox['route_complete'].last is not None
                                  and inbox['route_complete'].last.data) or _dead(procs),
                         timeout=90.0, poll=0.2)
    xte_last = inbox['cross_track_error'].last
    assert done and not _dead(procs), (
        f'route not complete: {len(inbox["odom"])} steps (max_steps {max_steps}), last '
        f'cross-track error {xte_last.data if xte_last else None} m; processes:\n'
        + ros_graph.report())
    tn.spin_for(0.3)
    codes = ros_graph.stop_all()
    assert all(c == 0 for c in codes.values()), codes
    assert '0 lockstep timeouts' in procs['vessel'].stderr(), procs['vessel'].stderr()

    # One guidance output per odom, in order (lockstep pairs them by sequence); the graph ran on
    # for a moment after the route's end, so the streams are compared up to that step.
    progress = [m.data for m in inbox['progress']]
    k_end = next(k for k, p in enumerate(progress) if p[FINISHED] == 1.0)
    counts = {name: len(inbox[name]) for name in ('odom', 'cross_track_error', 'heading_cmd',
                                                  'rudder_cmd')}
    assert min(counts.values()) > k_end, counts
    odom = inbox['odom'].messages
    xte = np.array([m.data for m in inbox['cross_track_error'].messages[:k_end + 1]])
    dt = scenario.dt_s
    t = np.array([m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in odom[:k_end + 1]])
    np.testing.assert_allclose(t, dt * np.arange(k_end + 1), atol=1e-9)
    # Started where the scenario says: cross_m to starboard (+).
    assert xte[0] == pytest.approx(spec.start['cross_m'], abs=1e-6)

    plan = load_route(spec.route_file)
    route = plan.route
    speed = float(np.mean([math.hypot(m.twist.twist.linear.x, m.twist.twist.linear.y)
                           for m in odom[:k_end + 1]]))
    gains = autopilot_gains(spec.model)
    zeta, omega_n = gains['zeta'], gains['omega_n']
    d = float(spec.guidance_params['lookahead_m'])
    radii = [leg.radius for leg in route.legs if leg.kind == 'arc']
    assert radii, 'the test route needs arcs'
    e_arc = max(_arc_offset_bound(d, R, speed, zeta, omega_n,
                                  _steady_sideslip(spec.model, R, dt)) for R in radii)
    eig = np.linalg.eigvals(linear_loop_matrix(zeta, omega_n, speed, d))
    assert np.all(eig.real < 0.0)
    k_linear = int(np.argmax(np.abs(xte) <= d))
    assert abs(xte[k_linear]) <= d, 'never came within the look-ahead of the path'
    k_settled = k_linear + int(math.ceil(4.0 / np.min(-eig.real) / dt))
    settled = xte[k_settled:]
    rms = float(np.sqrt(np.mean(settled ** 2)))
    print(f'route complete at step {k_end} (t = {k_end * dt:.1f} s, route {route.length:.1f} m); '
          f'|e| <= d at t = {k_linear * dt:.1f} s, settled at t = {k_settled * dt:.1f} s; '
          f'RMS xte after settling {rms:.3f} m, max {np.max(np.abs(settled)):.3f} m; '
          f'bound e_arc {e_arc:.3f} m (U {speed:.3f} m/s, R {min(radii):.1f} m)')
    assert len(settled) > 0.5 * len(xte), 'settling took most of the route'
    assert rms < e_arc

    # Corners turned: heading at the middle of each straight leg = the leg's course.
    north = np.array([m.pose.pose.position.y for m in odom[:k_end + 1]])
    east = np.array([m.pose.pose.position.x for m in odom[:k_end + 1]])
    yaw = np.array([quaternion_to_yaw(m.pose.pose.orientation) for m in odom[:k_end + 1]])
    tol = math.atan(e_arc / d)
    lines = [leg for leg in route.legs if leg.kind == 'line']
    assert len(lines) >= 3
    for leg in lines:
        mid = leg.point_at(0.5 * leg.length)  # NED
        k = int(np.argmin(np.hypot(north - mid[0], east - mid[1])))
        course = math.pi / 2 - leg.angle      # NED path angle -> ENU yaw
        print(f'middle of {leg}: heading {math.degrees(yaw[k]):.2f} deg, course '
              f'{math.degrees(course):.2f} deg (tolerance {math.degrees(tol):.1f} deg)')
        assert abs(float(wrap_angle(yaw[k] - course))) < tol, (
            f'heading {math.degrees(yaw[k]):.1f} deg at the middle of leg {leg}, course '
            f'{math.degrees(course):.1f} deg')
    # The last odom of the route lies at its end (within the acceptance/normal criterion).
    assert math.hypot(north[-1] - route.end[0], east[-1] - route.end[1]) < e_arc + speed * dt


# -- 2. determinism -----------------------------------------------------------------------------

DETERMINISM_STEPS = 600  # 60 s: the approach from the start offset and the first corner


def _run_to_max_steps(ros_graph, scenario, tag):
    tn, procs, inbox = _start_graph(ros_graph, scenario, DETERMINISM_STEPS, tag)
    n = DETERMINISM_STEPS + 1  # steps 0..max_steps
    assert tn.spin_until(lambda: len(inbox['odom']) >= n or _dead(procs), timeout=60.0,
                         poll=0.2), ros_graph.report()
    assert procs['vessel'].wait(10.0) == 0, 'vessel_node did not end after max_steps'
    assert not _dead(procs, allow=('vessel',)), ros_graph.report()
    # The answers to the last step come after the simulator has ended.
    assert tn.spin_until(lambda: len(inbox['rudder_cmd']) >= n, timeout=10.0), (
        {name: len(box) for name, box in inbox.items()})
    tn.spin_for(0.2)
    for p in procs.values():
        assert ros_graph.stop(p) == 0, p.report()
    assert '0 lockstep timeouts' in procs['vessel'].stderr()
    out = {'odom': [_odom_fields(m) for m in inbox['odom']],
           'heading_cmd': [m.data for m in inbox['heading_cmd']],
           'rudder_cmd': [m.data for m in inbox['rudder_cmd']]}
    for name, box in inbox.items():
        tn.unsubscribe(box)
    for name in ('odom', 'heading_cmd', 'rudder_cmd'):
        assert len(out[name]) == n, f'{tag}: {len(out[name])} {name} messages for {n} steps'
    return out


@pytest.mark.timeout(150)
def test_graph_in_lockstep_is_bit_identical_on_repeat(ros_graph):
    scenario = load_scenario(SCENARIO)
    first = _run_to_max_steps(ros_graph, scenario, '_run1')
    second = _run_to_max_steps(ros_graph, scenario, '_run2')
    for name in ('odom', 'heading_cmd', 'rudder_cmd'):
        assert first[name] == second[name], (
            f'{name}: first difference at message '
            f'{next(k for k, (a, b) in enumerate(zip(first[name], second[name])) if a != b)}')
    # Not a trivial equality: the vessel steered (rudder moved both ways) and moved.
    rudder = np.array(first['rudder_cmd'])
    assert rudder.max() > 0.0 > rudder.min()
    assert first['odom'][-1][2:4] != first['odom'][0][2:4]
