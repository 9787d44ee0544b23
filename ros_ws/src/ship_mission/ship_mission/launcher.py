"""Run a scenario as a graph of node processes (no `ros2 launch`): start, watch, stop, analyse.

Which nodes run, with which parameters, is ship_mission.graph (data); this module starts them,
each as its own process or, with the scenario's ``compose`` (run_mission --compose), several in
one container process (ship_mission.composition: same start order, same waits).

For each vessel namespace: route_node, guidance_node, autopilot_node and, last, vessel_node
(in lockstep it publishes step 0 only once its odom subscribers are all there). In a platoon
(ship_mission.platoon) a follower runs follower_node in place of guidance_node, steering at its
predecessor's odom; every vessel_node is started after all the other nodes and waits for its
own subscribers, which include the followers of that vessel; in lockstep the traffic vessels'
simulators start first and a colav vessel's only once every target has published step 0
(simulator_start_plan). Light targets get one
traffic_node, a scenario's `ais:` section one graph-wide ais_node (both started before the
simulators and, in lockstep, waited for until they follow /clock). In realtime a simulator waits
for no one, so the launcher starts each only once its vessel's odom followers are there. A
recorder process writes every topic to an MCAP bag. The launcher's own rclpy node follows /clock,
cross-track errors and route completion to print progress and to decide when the run is over:
every vessel has completed its route, or the simulators reached duration_s. A node that exits
early fails the run: everything is stopped and the exit code is non-zero. Ctrl-C or SIGTERM
stops everything too (exit 130; ``install_stop_handlers``, as run_mission.py does).
Afterwards the bag is turned into metrics.json and PNG plots.

Run folder: runs/<scenario>-<timestamp>/ with params/ (one ROS parameter file per node),
logs/ (one log per process), bag/ (rosbag2 MCAP), metrics.json, *.png, report.html (all of it on
one self-contained page: ship_mission.html_report); runs/latest points at it.
"""
import math
import os
import signal
import sys
import time
from datetime import datetime
from pathlib import Path

import yaml

from ship_mission.composition import Starter, member_ros_args
from ship_mission.console import progress_line
from ship_mission.domain import LeaseError, lease_domain_id
from ship_mission.graph import (  # noqa: F401 (the launcher's API: the graph as it starts it)
    AIS_NODE, AIS_SYNC, AIS_TARGETS, COLAV_NODE, COLAV_REMAP, DISPLAY_NODE, FOLLOWER_NODES,
    LIVE_VIEW, NODES, RECORD_ACK, RECORDER, ais_parameters, display_every, display_parameters,
    light_odom_topics, mission_graph, node_parameters, node_remaps, record_ack_arg,
    record_ack_args, simulator_start_plan, traffic_parameters, vessel_nodes)
from ship_mission.processes import REPO, ProcessGroup, install_env
from ship_mission.ready_wait import wait_for_announced, wait_for_subscribers
from ship_mission.scenario_checks import check_scenario  # noqa: F401 (the launcher's API)
from ship_mission.node_checks import RCLPY_PARAMETERS, node_parameter_names  # noqa: F401 (the launcher's API)
from ship_mission.scenario import scenario_origin, scenario_text

LAYOUT = REPO / 'scripts' / 'live_view_layout.json'   # the Foxglove layout of a run


class MissionFailed(RuntimeError):
    """A node process died or the graph never came up; the message says which and why."""


_stop_signals = []


def _on_stop_signal(signum, frame):
    _stop_signals.append(signal.Signals(signum).name)


def install_stop_handlers():
    """SIGINT (Ctrl-C) and SIGTERM (kill, timeout, CI cancel) end a run at its next check.

    The handler only takes note: an exception raised inside an rclpy call (where a signal
    usually lands) comes out as a RuntimeError from pybind11, not a KeyboardInterrupt. The
    nodes run in their own sessions, so without a SIGTERM handler they would be orphaned."""
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, _on_stop_signal)


def make_run_dir(scenario, root):
    root = Path(root)
    stamp = datetime.now().strftime('%Y%m%d-%H%M%S')
    run = root / f'{scenario.name}-{stamp}'
    n = 1
    while run.exists():
        n += 1
        run = root / f'{scenario.name}-{stamp}-{n}'
    try:
        (run / 'params').mkdir(parents=True)
        latest = root / 'latest'
        if latest.is_symlink() or latest.exists():
            latest.unlink()
        latest.symlink_to(run.name)
    except OSError as exc:
        raise MissionFailed(f'cannot create the run folder {exc.filename or run}: '
                            f'{exc.strerror or exc}') from None
    return run


def write_run_json(run, summary):
    """Write run.json whole or not at all (a temporary file renamed into place): a full or
    read-only disk leaves no truncated file. MissionFailed names the path and the OS error."""
    path = run / 'run.json'
    tmp = run / '.run.json.tmp'
    try:
        with open(tmp, 'w') as f:
            f.write(yaml.safe_dump(summary, sort_keys=False))
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        try:
            tmp.unlink()
        except OSError:
            pass
        raise MissionFailed(f'cannot write {path}: {exc.strerror or exc}') from None


def _wait_for_clock_subscriber(monitor, node, group, timeout_s=30.0):
    """Wait until graph ``node`` subscribes /clock: the simulators start after it, so it hears
    step 0 (colav_node waits for its samples from step 0 on)."""
    if wait_for_subscribers(monitor, '/clock', [node.full_name], lambda: _raise_if_failed(group),
                            timeout_s):
        raise MissionFailed(f'{node.full_name} did not subscribe /clock within {timeout_s:.0f} s')


def _raise_if_failed(group):
    """MissionFailed naming the first process of ``group`` that has exited, if any."""
    dead = group.failed()
    if dead:
        p = dead[0]
        raise MissionFailed(f'{p.label} exited with {_exit_status(p.returncode)}, its last '
                            f'line: {_last_line(p)} (log: {p.log_path})')


def wait_for_odom_subscribers(monitor, spec, group, progress, timeout_s=30.0):
    """Realtime: wait until the nodes of ``spec``'s namespace that follow its odom (guidance or
    follower, which subscribe only once they hold the route, the autopilot, colav_node) have
    subscribed, so its simulator, which does not wait for anyone in realtime, starts into a
    graph that answers step 0. Without this, a node still starting (the last vessel's, on a
    loaded machine) misses the first seconds of odom, which the record then counts as missing
    answers. Gives up with a warning after ``timeout_s``."""
    ns = f'/{spec.namespace}'
    wanted = [f'{ns}/{exe}' for exe, _ in vessel_nodes(spec) if exe != 'route_node']
    # a dead process ends the wait: the run loop reports it
    late = wait_for_subscribers(monitor, f'{ns}/odom', wanted, group.failed, timeout_s)
    if late:
        progress(f'  warning: {", ".join(late)} not following {ns}/odom after {timeout_s:.0f} s; '
                 'starting its simulator anyway (its first steps go unanswered)')


def _wait_until_ready(monitor, nodes, group, timeout_s=60.0):
    """Wait until every graph node of ``nodes`` has announced that it is ready (ship_sim.ros.ready:
    each of its target topics serves the recorder and every colav_node, by name), so that no
    one misses step 0 of a lockstep run."""
    late = wait_for_announced(monitor, [n.full_name for n in nodes],
                              lambda: _raise_if_failed(group), timeout_s)
    if late:
        raise MissionFailed(f'never ready within {timeout_s:.0f} s: {", ".join(late)} (their '
                            'logs name the readers they waited for)')


def write_params(run, namespace, node, params):
    path = run / 'params' / f'{namespace}.{node}.yaml'
    path.write_text(yaml.safe_dump({'/**': {'ros__parameters': params}}, sort_keys=True))
    return path


def params_file(run, node):
    """Write the parameter file of one node spec: params/<namespace or label>.<executable>.yaml."""
    return write_params(run, node.namespace or node.label.split('/')[0], node.executable,
                        node.parameters)


def start_node(run, group, node):
    """Start one node spec of ship_mission.graph: a script by its argv, a node with its
    parameter file in its namespace."""
    if node.package is None:
        return group.start_argv(node.label, node.argv)
    return group.start(node.label, node.package, node.executable,
                       member_ros_args(node, params_file(run, node)))


def _start_live_view(run, group, node, progress):
    """Start the live view (scripts/live_view.py, ship_mission.live_bridge) and wait until it
    serves on 127.0.0.1, before step 0: a viewer sees the whole run."""
    view = start_node(run, group, node)
    end = time.monotonic() + 30.0
    while 'live view: ws://' not in view.output():
        if view.returncode is not None or time.monotonic() > end:
            raise MissionFailed(f'live view did not start, its last line: '
                                f'{_last_line(view)} (log: {view.log_path})')
        time.sleep(0.05)
    url = view.output().split('live view: ', 1)[1].split()[0]   # the port, also when 0
    progress(f'live view: {url} (Foxglove or Lichtblick: Open connection -> Foxglove '
             f'WebSocket; layout: {LAYOUT.relative_to(REPO)})')


class Monitor:
    """In-process rclpy node: sim time, cross-track error and completion of every vessel."""

    def __init__(self, namespaces):
        import rclpy
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from rosgraph_msgs.msg import Clock
        from std_msgs.msg import Bool, Float64
        from ship_sim.ros.qos import LATCHED
        self.rclpy = rclpy
        self.context = rclpy.context.Context()
        from rclpy.signals import SignalHandlerOptions
        # No rclpy signal handlers: the launcher's own (install_stop_handlers) end the run.
        rclpy.init(context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        self.node = rclpy.create_node('mission_monitor', context=self.context)
        from rclpy.executors import SingleThreadedExecutor
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.t = 0.0
        self.xte = {ns: math.nan for ns in namespaces}
        self.complete = {ns: False for ns in namespaces}
        self.ready = {ns: False for ns in namespaces}   # the vessel_node has published step 0
        self.node.create_subscription(Clock, '/clock', self._on_clock,
                                      QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
        # Display only: the latest value is enough, and a reliable queue of every step of every
        # vessel would keep this executor busy (a platoon publishes thousands per second).
        latest = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)
        for ns in namespaces:
            self.node.create_subscription(Float64, f'/{ns}/cross_track_error',
                                          lambda m, ns=ns: self.xte.__setitem__(ns, m.data), latest)
            self.node.create_subscription(Bool, f'/{ns}/route_complete',
                                          lambda m, ns=ns: self.complete.__setitem__(ns, m.data),
                                          LATCHED)
            self.node.create_subscription(Bool, f'/{ns}/ready',
                                          lambda m, ns=ns: self.ready.__setitem__(ns, m.data),
                                          LATCHED)

    def _on_clock(self, msg):
        self.t = msg.clock.sec + 1e-9 * msg.clock.nanosec

    def load_publisher(self):
        """``Starter.publish_load`` on this node: a publisher per container on its ``~/_load``,
        with the container's own QoS (kept for a container subscription that matches late)."""
        from std_msgs.msg import String
        from ship_mission.container import LOAD_QOS
        pubs = {}

        def publish(topic, label):
            if topic not in pubs:
                pubs[topic] = self.node.create_publisher(String, topic, LOAD_QOS)
            pubs[topic].publish(String(data=label))
        return publish

    def spin(self, seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=max(0.0, end - time.monotonic()))

    def close(self):
        self.executor.shutdown()
        self.node.destroy_node()
        self.rclpy.try_shutdown(context=self.context)


def wait_for_ready(proc, namespace, vparams, monitor, group):
    """Wait until the lockstep simulator ``proc`` of ``namespace`` has published its step 0
    (its latched ``ready`` topic says so), so that a follower started next never waits for a
    predecessor that has not begun: its first wait would run out and the run would no longer
    be deterministic. Returns early if ``proc`` has exited or another process has failed (the
    run loop reports it); a simulator that has finished its run (exit 0) is not a failure: a
    leader can finish before a slow-starting follower has begun, and that follower's own
    followers must still wait for it."""
    limit = float(vparams.get('lockstep_start_timeout', 30.0)) + 15.0
    deadline = time.monotonic() + limit
    while not monitor.ready[namespace]:
        if any(p is proc or p.returncode != 0 for p in group.failed()):
            return
        if _stop_signals:
            raise KeyboardInterrupt(_stop_signals[0])
        if time.monotonic() > deadline:
            raise MissionFailed(f'{proc.label} did not publish step 0 (/{namespace}/ready) '
                                f'within {limit:.0f} s; its log ({proc.log_path}) ends with:\n'
                                f'{_tail(proc)}')
        monitor.spin(0.05)


def _last_line(proc):
    """The last line a process printed: a node's or the recorder's one-line reason for failing
    (the whole log is in its file)."""
    lines = [ln.strip() for ln in proc.output().splitlines() if ln.strip()]
    return lines[-1] if lines else 'it printed nothing'


def _exit_status(code):
    """'code 1', or 'SIGKILL' for a process a signal ended (Popen gives -signum)."""
    if code is not None and code < 0:
        try:
            return signal.Signals(-code).name
        except ValueError:
            pass
    return f'code {code}'


def _tail(proc, n=8):
    lines = proc.output().strip().splitlines()
    return '\n'.join('    ' + ln for ln in lines[-n:])


def run_scenario(scenario, runs_root=REPO / 'runs', domain_id=None, record=None, progress=print,
                 progress_period_s=2.0, analyse=True, wall_timeout_s=None, loopback_only=False):
    """Run ``scenario``; returns (run_dir, metrics or None). Raises MissionFailed on failure.
    ``loopback_only``: Fast DDS on 127.0.0.1 only (ship_mission.processes.install_env)."""
    record = scenario.record if record is None else record
    run = make_run_dir(scenario, runs_root)
    if domain_id is None:
        try:
            domain_id = lease_domain_id()   # a run never shares its domain (ship_mission.domain)
        except LeaseError as exc:   # none free, or an unsafe lock directory: one line
            raise MissionFailed(str(exc)) from None
    env = install_env(domain_id=domain_id, loopback_only=loopback_only)
    for var in ('ROS_DOMAIN_ID', 'ROS_AUTOMATIC_DISCOVERY_RANGE', 'FASTRTPS_DEFAULT_PROFILES_FILE'):
        if var in env:   # this process's own nodes (monitor, recorder) join the same way
            os.environ[var] = env[var]
    namespaces = [v.namespace for v in scenario.vessels]
    (run / 'scenario.yaml').write_text(scenario_text(scenario))   # a matrix run: its own
    progress(f'run folder {run} (ROS_DOMAIN_ID={domain_id}, {scenario.stepping})')
    if scenario.platoon is not None:
        chain = ', '.join(f'{s.namespace} <- {s.predecessor}' for s in scenario.vessels
                          if s.predecessor)
        progress(f'platoon of {len(namespaces)}: {chain}')
        for w in scenario.platoon.warnings:
            progress(f'  warning: {w}')

    group = ProcessGroup(env, run / 'logs')
    monitor = starter = None
    t_wall0 = time.monotonic()
    outcome = 'failed'
    try:
        graph = mission_graph(scenario, record, run)
        if scenario.display is not None and scenario_origin(scenario) is None:
            from ship_guidance.nav_display import DEFAULT_ORIGIN_DEG
            progress(f'display: no geodetic origin in the scenario or its routes; the fix uses '
                     f'the default sea area {DEFAULT_ORIGIN_DEG[0]:g} N {DEFAULT_ORIGIN_DEG[1]:g} E '
                     f'(Norwegian Sea; `display: origin` sets one)')
        # compose: several nodes per process (ship_mission.composition); none: one each
        starter = Starter(graph, scenario.compose, run, group,
                          lambda node: start_node(run, group, node),
                          lambda node: params_file(run, node))
        sims = {}
        for node in graph.nodes:   # all but the simulators, in the graph's order
            if node.executable == 'vessel_node':
                sims[node.namespace] = node
            elif node.label == 'live_view':
                _start_live_view(run, group, node, progress)
            else:
                starter.start(node)
        monitor = Monitor(namespaces)
        starter.publish_load = monitor.load_publisher()
        monitor.spin(1.0)
        on_clock = ([graph.node('traffic/traffic_node')] if scenario.light else []) + (
            [graph.node('ais/ais_node')] if scenario.ais is not None
            and scenario.stepping == 'lockstep' else [])
        for node in on_clock:
            _wait_for_clock_subscriber(monitor, node, group)
        if scenario.stepping == 'lockstep':
            _wait_until_ready(monitor, on_clock, group)
        simulators = {}
        for ns, awaited in simulator_start_plan(scenario):
            for other in awaited:
                wait_for_ready(simulators[other], other, sims[other].parameters, monitor, group)
            if scenario.stepping == 'realtime':
                wait_for_odom_subscribers(monitor, next(s for s in scenario.vessels
                                                        if s.namespace == ns), group, progress)
            simulators[ns] = starter.start(sims[ns])
        last_print = 0.0
        while True:
            monitor.spin(0.2)
            if _stop_signals:
                raise KeyboardInterrupt(_stop_signals[0])
            dead = group.failed()
            vessels_done = [p for p in dead if starter.simulators_in(p) and p.returncode == 0]
            crashed = [p for p in dead if p not in vessels_done]
            if crashed:
                p = crashed[0]
                raise MissionFailed(f'{p.label} exited with {_exit_status(p.returncode)}, its last '
                                    f'line: {_last_line(p)} (log: {p.log_path})')
            if all(monitor.complete.values()):
                outcome = 'completed'
                break
            if sum(map(starter.simulators_in, vessels_done)) == len(namespaces):
                outcome = 'duration reached'
                break
            now = time.monotonic()
            if wall_timeout_s and now - t_wall0 > wall_timeout_s:
                raise MissionFailed(f'wall-clock limit {wall_timeout_s:.0f} s reached at sim '
                                    f'time {monitor.t:.1f} s')
            if now - last_print >= progress_period_s:
                last_print = now
                rtf = monitor.t / max(now - t_wall0, 1e-9)
                eta = (scenario.duration_s - monitor.t) / rtf if rtf > 0 else None
                progress(progress_line(monitor.t, scenario.duration_s,
                                       {ns: monitor.xte[ns] for ns in namespaces}, rtf, eta))
    except KeyboardInterrupt:
        outcome = 'interrupted'
        raise
    finally:
        sim_t = monitor.t if monitor else 0.0
        if monitor is not None:
            monitor.close()
        # Simulators first (nothing new is published), then give the nodes outside the lockstep
        # loop that write every sample (the recorder, AIVDM out) time to take what they still
        # have queued, then everything else.
        drains = record or scenario.aivdm_out is not None
        codes = group.stop(first=lambda p: starter is not None and starter.simulators_in(p) > 0,
                           settle=1.0 if drains else 0.0)
        wall = time.monotonic() - t_wall0
        summary = {'scenario': str(scenario.file), 'name': scenario.name, 'outcome': outcome,
                   'sim_time_s': sim_t,
                   'wall_time_s': wall, 'real_time_factor': sim_t / wall if wall > 0 else None,
                   'domain_id': domain_id, 'exit_codes': codes}
        in_flight = sys.exc_info()[1]   # the run's own failure, if it is on its way out
        try:
            write_run_json(run, summary)
        except MissionFailed as exc:
            if in_flight is None:
                raise               # nothing else went wrong: this is the run's failure
            progress(f'  {exc}')    # the run's own failure says more; it goes on
        progress(f'{outcome}: sim {sim_t:.1f} s in {wall:.1f} s wall '
                 f'(x{sim_t / max(wall, 1e-9):.1f} real time)')
        if in_flight is not None and analyse and record:
            # A failed or interrupted run still gets metrics and plots of what was recorded.
            try:
                _analyse(scenario, run, summary, progress, partial=True)
            except Exception as exc:  # noqa: BLE001 - the run's own failure is what is reported
                progress(f'  no metrics for this run ({type(exc).__name__}: {exc}); '
                         f'try: scripts/replay_bag.py {run / "bag"}')
    metrics = _analyse(scenario, run, summary, progress) if analyse and record else None
    return run, metrics


def _analyse(scenario, run, summary, progress, partial=False):
    """metrics.json and the plots of a run's bag; prints whether the record is complete."""
    from ship_mission.integrity import summary_line
    from ship_mission.report import analyse_bag
    platoon = None
    if scenario.platoon is not None:
        platoon = {f'/{s.namespace}': f'/{s.predecessor}' if s.predecessor else None
                   for s in scenario.vessels}
    metrics = analyse_bag(run / 'bag', run, settle_s=scenario.settle_s, platoon=platoon,
                          extra={'run': summary})
    if metrics.get('recovered'):
        progress(metrics['recovered'])
    progress(summary_line(metrics['record']))
    progress(f'metrics and plots {"of what was recorded " if partial else ""}written to {run}')
    progress(f'report (opens in any browser, offline): {run / "report.html"}')
    return metrics
