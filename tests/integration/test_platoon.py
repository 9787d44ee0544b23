"""A platoon of three as real processes in lockstep: the followers converge, and when the leader's
simulator dies its follower falls back to the route.

Vessels: three NPS AUV IIs (2.2 m, 1 m/s, PD zeta 0.8, omega_n 1.348 rad/s from the gain table:
a fast loop, so the whole run takes seconds) on the two-corner test route
(data/routes/auv_two_corners.yaml, 50 m north, 90 deg starboard, 40 m east, 90 deg port, R 10 m).
The scenario is written here as a `platoon:` section and every node parameter comes from the
launcher's own code (ship_mission.platoon, ship_mission.launcher.node_parameters), so this tests the glue
too: follower_node steering at /vessel_<i-1>/odom, lockstep waits, the odom subscriber counts
(the test node takes the recorder's place). Spacing 5 m with min_lookahead_m 4 m: above the
no-amplification look-ahead 4 zeta U / omega_n = 2.37 m of ship_guidance.follower (x 1.2 for the
AUV's sway, Simakis 1992 Sec. III.B), far above the stability limit 0.46 m.

1. Convergence (before anything falls back): the followers start 3 m to either side of the
   route (the leader on it), 5 m apart. The slowest mode of a follower's linearised loop (seed
   Angelopoulos 2011 eq. 30 with d = 5 m, the diagonal block of eq. 37) has time constant
   tau = 1 / |Re lambda|; each follower's RMS
   cross-track error in a late window (from 5 tau, before the first corner) must be below
   e^-2 of its RMS in the first two seconds: a loose check that the errors decay (the linear
   chain of two such blocks is at (1 + 5) e^-5 = 0.04 of its start by then).
2. Fallback: SIGKILL of the leader's vessel_node once the leader is 40 s into the run (in
   lockstep a leader runs up to lockstep_follower_window steps ahead of its follower). Its follower goes
   on with the leader's recorded samples, waits predecessor_wait_s once when they end, then
   runs on; at the first step where the leader's newest sample is more than
   predecessor_timeout_s (sim) old its `mode` topic says 'route_fallback' (follower_node's
   documented behaviour) and it follows the route with plain LOS. The second follower keeps
   following the first ('follow': its predecessor still runs). Both complete the route
   (route_complete) through both corners, staying within their look-ahead of the path
   (|e| < d: the LOS law's linear regime, where it is in control).
Cross-track errors are computed from the stamped odometry and the route (the same closest-point
projection the guidance uses), so a message the test node misses cannot shift a time.
"""
import math
import os
import re
import signal
import time

import numpy as np
import pytest
import yaml
from nav_msgs.msg import Odometry
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Bool, String

from ship_mission.launcher import check_scenario, node_parameters, vessel_nodes
from ship_mission.platoon import STEP0_LINE, start_order
from ship_mission.scenario import load_scenario
from ship_guidance.string_stability import single_vessel_matrix
from ship_planner.route_loader import load_route
from ship_sim.models import make_model
from ship_sim.ros.qos import LATCHED

from harness import REPO_ROOT, TestNode

ROUTE = REPO_ROOT / 'tests' / 'integration' / 'data' / 'routes' / 'auv_two_corners.yaml'
DEEP = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10000,
                  reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
LATEST = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                    reliability=ReliabilityPolicy.BEST_EFFORT, durability=DurabilityPolicy.VOLATILE)
SPACING = 5.0        # m
FALLBACK_D = 3.0     # m, route LOS look-ahead of a follower in route_fallback
TIMEOUT_S = 2.0      # sim s: predecessor data older than this -> route_fallback
DT_S = 0.1           # sim s: the scenario's step
KILL_LEADER_AT_S = 40.0   # the leader's own sim time when its simulator is killed
LATE_END_S = 28.0         # end of the late window: the leader reaches the first corner at 30 s


def platoon_file(tmp_path):
    follower = {'min_lookahead_m': 4.0, 'max_lookahead_m': 8.0, 'lookahead_m': FALLBACK_D,
                'predecessor_timeout_s': TIMEOUT_S}
    # The vehicle's own rudder limits (0.4 rad, 1 rad/s, set per instance) for the autopilot,
    # as the Simakis 1992 scenarios give them: autopilot_node reads the model CLASS's (35 deg, 5 deg/s).
    auv = make_model('nps_auv2')
    autopilot = {'controller': 'pd', 'rudder_max_deg': math.degrees(auv.rudder_max),
                 'rudder_rate_max_deg': math.degrees(auv.rudder_rate_max)}
    data = {
        'name': 'test_platoon', 'duration_s': 200.0, 'stepping': 'lockstep', 'dt_s': DT_S,
        'lockstep_timeout_s': 5.0,
        'platoon': {
            'route': str(ROUTE), 'spacing_m': SPACING, 'stability_margin': 1.2,
            'predecessor_wait_s': 1.0,
            'vessels': [
                {'namespace': 'vessel_0', 'model': 'nps_auv2',
                 'start': {'along_m': 10.0, 'cross_m': 0.0},
                 'guidance': {'law': 'los', 'lookahead_m': FALLBACK_D}, 'autopilot': autopilot},
                {'namespace': 'vessel_1', 'model': 'nps_auv2',
                 'start': {'along_m': 5.0, 'cross_m': 3.0}, 'guidance': follower,
                 'autopilot': autopilot},
                {'namespace': 'vessel_2', 'model': 'nps_auv2',
                 'start': {'along_m': 0.0, 'cross_m': -3.0}, 'guidance': follower,
                 'autopilot': autopilot},
            ]}}
    path = tmp_path / 'platoon.yaml'
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _stamp(msg):
    return msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec


def cross_track(route, odoms):
    """(t, s, e) from Odometry messages: time, arc length and cross-track error (+ = starboard)
    of the route's closest point."""
    t = np.array([_stamp(m) for m in odoms])
    proj = [route.project(m.pose.pose.position.y, m.pose.pose.position.x) for m in odoms]
    return t, np.array([p.s for p in proj]), np.array([p.cross_track for p in proj])


def rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


@pytest.mark.timeout(150)
def test_platoon_converges_and_falls_back_when_the_leader_dies(ros_graph, tmp_path, request):
    t_wall0 = time.monotonic()
    scenario = load_scenario(platoon_file(tmp_path))
    check_scenario(scenario)
    assert scenario.platoon.warnings == []
    route = load_route(ROUTE).route
    names = [s.namespace for s in scenario.vessels]
    tn = ros_graph.test_node()
    # The followers' odometry in full. The leader's (hundreds of steps per second) only the
    # latest, on a node of its own, so that the decision to kill it never waits behind the
    # followers' messages.
    watch = TestNode(ros_graph.domain_id, 'leader_watch')
    request.addfinalizer(watch.close)
    odom = {ns: (watch if ns == 'vessel_0' else tn).subscribe(
        f'/{ns}/odom', Odometry, LATEST if ns == 'vessel_0' else DEEP) for ns in names}
    mode = {ns: tn.subscribe(f'/{ns}/mode', String, LATCHED) for ns in names[1:]}
    done = {ns: tn.subscribe(f'/{ns}/route_complete', Bool, LATCHED) for ns in names}

    procs, sims = {}, {}
    for i, spec in enumerate(scenario.vessels):
        # no recorder: the test's nodes follow odom in its place, named as its readers
        params, _ = node_parameters(scenario, spec, i, record=False)
        watcher = '/leader_watch' if spec.namespace == 'vessel_0' else '/test_node'
        params['vessel_node']['lockstep_odom_readers'] = [
            *params['vessel_node']['lockstep_odom_readers'], watcher]
        for exe, pkg in vessel_nodes(spec):
            procs[f'{spec.namespace}/{exe}'] = ros_graph.start(
                pkg, exe, namespace=f'/{spec.namespace}', label=f'{spec.namespace}.{exe}',
                params=params[exe])
        # No recorder acknowledges steps here (the test node only subscribes in its place).
        sims[spec.namespace] = {**params['vessel_node'], 'lockstep_record_topic': ''}
    for ns in names:
        assert tn.wait_for_publishers(done[ns], timeout=30.0), ros_graph.report()
    for ns in names[1:]:
        assert tn.wait_for_publishers(mode[ns], timeout=30.0), ros_graph.report()
    def dead():
        # A simulator that reached max_steps ends with 0 by design (a follower in route
        # fallback no longer waits and can get there before the others finish): not a crash.
        return [k for k, p in procs.items() if p.returncode is not None
                and not (k.endswith('vessel_node') and p.returncode == 0)]

    def own_time(ns):
        last = odom[ns].last
        return _stamp(last) if last is not None else -1.0

    # As the launcher: the simulators after all other nodes, predecessors first, a follower's
    # once its predecessor's has published step 0; each waits for its own subscribers.
    # Meanwhile the leader runs ahead (in lockstep up to lockstep_follower_window steps ahead of
    # its follower, a few seconds of sim time): its simulator is killed as soon as it is past
    # KILL_LEADER_AT_S. Its followers go on with its recorded samples up to then, and fall back.
    waiting = list(start_order(scenario.platoon))
    leader_sim = None
    deadline = time.monotonic() + 60.0
    while waiting or leader_sim is None:
        assert time.monotonic() < deadline and not dead(), (
            waiting, {ns: own_time(ns) for ns in names}, ros_graph.report())
        if waiting:
            pred = scenario.platoon.predecessors[waiting[0]]
            if pred is None or STEP0_LINE in procs[f'{pred}/vessel_node'].output():
                ns = waiting.pop(0)
                procs[f'{ns}/vessel_node'] = ros_graph.start(
                    'ship_sim', 'vessel_node', namespace=f'/{ns}', label=f'{ns}.vessel_node',
                    params=sims[ns])
        if leader_sim is None and own_time('vessel_0') >= KILL_LEADER_AT_S:
            leader_sim = procs.pop('vessel_0/vessel_node')
            os.kill(leader_sim.pid, signal.SIGKILL)
        watch.spin_once(0.002)
    assert leader_sim.wait(10.0) == -signal.SIGKILL
    watch.spin_for(0.5)
    t_last = own_time('vessel_0')   # the leader's last step
    print(f'leader killed at its t = {t_last:.1f} s')

    # -- 1. convergence (before anything fell back) ------------------------------------------
    assert tn.spin_until(lambda: own_time(names[-1]) >= LATE_END_S or dead(), timeout=60.0,
                         poll=0.1), ({ns: own_time(ns) for ns in names}, ros_graph.report())
    assert not dead(), ros_graph.report()
    loop = scenario.platoon.loops['vessel_1']
    lam = np.linalg.eigvals(single_vessel_matrix(loop.zeta, loop.omega_n, SPACING, loop.speed))
    tau = 1.0 / float(np.min(-lam.real))
    late = (5.0 * tau, LATE_END_S)
    assert late[0] < late[1] < t_last
    for ns in names[1:]:
        t, _, e = cross_track(route, odom[ns].messages)
        early_rms = rms(e[t <= 2.0])
        late_rms = rms(e[(t >= late[0]) & (t <= late[1])])
        print(f'{ns}: RMS cross-track {early_rms:.3f} m in [0, 2] s, {late_rms:.4f} m in '
              f'[{late[0]:.1f}, {late[1]:.1f}] s (tau {tau:.2f} s)')
        assert early_rms > 2.0   # started 3 m off the route
        assert late_rms < math.exp(-2.0) * early_rms
    for ns in names[1:]:   # following since step 0; no wait ran out before the kill
        assert mode[ns].messages[0].data == 'follow', ns
        log = procs[f'{ns}/follower_node'].output()
        waits = [float(x) for x in re.findall(r'no predecessor sample for t = ([0-9.]+) s', log)]
        # >=: SIGKILL can land while the leader's last odom is on its way, so this test's
        # reader may hold it and vessel_1 not; a wait for any earlier step would be a fault.
        assert all(t >= t_last for t in waits), (ns, waits, t_last)

    # -- 2. the leader's simulator is dead: its follower falls back -----------------------------
    fell_back = tn.wait_for_message(mode['vessel_1'], timeout=30.0, count=2,
                                    predicate=lambda m: m.data == 'route_fallback')
    assert fell_back is not None and not dead(), (
        [m.data for m in mode['vessel_1'].messages], ros_graph.report())
    found = procs['vessel_1/follower_node'].wait_for_output(
        r'route_fallback at t = ([0-9.]+) s: predecessor odometry is', timeout=10.0)
    assert found, procs['vessel_1/follower_node'].output()[-2000:]
    t_fallback = float(found.group(1))
    print(f'vessel_1: route_fallback at its t = {t_fallback:.1f} s')
    # the first step at which the leader's newest sample is more than TIMEOUT_S old; as above,
    # vessel_1's newest sample is t_last or, when SIGKILL caught the last odom on its way to it
    # (its wait for t_last in the log says so), the step before
    log = procs['vessel_1/follower_node'].output()
    waited = [float(x) for x in re.findall(r'no predecessor sample for t = ([0-9.]+) s', log)]
    t_newest = t_last - DT_S if any(abs(t - t_last) < 1e-6 for t in waited) else t_last
    assert t_newest + TIMEOUT_S < t_fallback <= t_newest + TIMEOUT_S + 1.0
    # both followers go on to the end of the route, through both corners
    assert tn.spin_until(lambda: all(done[ns].last is not None and done[ns].last.data
                                     for ns in names[1:]) or dead(), timeout=60.0, poll=0.2), (
        {ns: own_time(ns) for ns in names}, ros_graph.report())
    assert not dead(), ros_graph.report()
    tn.spin_for(0.5)   # the odometry up to the finish
    assert [m.data for m in mode['vessel_1'].messages] == ['follow', 'route_fallback']
    assert [m.data for m in mode['vessel_2'].messages] == ['follow']
    d_follow = {'vessel_1': FALLBACK_D, 'vessel_2': SPACING}
    for ns in names[1:]:
        t, s, e = cross_track(route, odom[ns].messages)
        # from the fallback to the end of the route (past its end the route is not followed)
        after = e[(t > t_fallback) & (s < route.length)]
        print(f'{ns}: from t = {t_fallback:.1f} s to the end of the route, max |e| '
              f'{np.max(np.abs(after)):.3f} m over {after.size} steps; reached s = '
              f'{s.max():.1f} of {route.length:.1f} m')
        assert after.size > 0.5 * (route.length - 10.0 - t_fallback) / 0.1   # ~1 m/s
        assert np.max(np.abs(after)) < d_follow[ns]
        assert s.max() >= route.length - 1e-6
    codes = ros_graph.stop_all()
    codes.pop('vessel_0.vessel_node')
    assert all(c == 0 for c in codes.values()), codes
    print(f'wall time {time.monotonic() - t_wall0:.1f} s')
