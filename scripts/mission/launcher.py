"""Run a scenario as a graph of node processes (no `ros2 launch`): start, watch, stop, analyse.

For each vessel namespace: route_node, guidance_node, autopilot_node and, last, vessel_node
(in lockstep it publishes step 0 only once its odom subscribers are all there). A recorder
process writes every topic to an MCAP bag. The launcher's own rclpy node follows /clock,
cross-track errors and route completion to print progress and to decide when the run is over:
every vessel has completed its route, or the simulators reached duration_s. A node that exits
early fails the run: everything is stopped and the exit code is non-zero. Ctrl-C stops
everything too (exit 130). Afterwards the bag is turned into metrics.json and PNG plots.

Run folder: runs/<scenario>-<timestamp>/ with params/ (one ROS parameter file per node),
logs/ (one log per process), bag/ (rosbag2 MCAP), metrics.json, *.png; runs/latest points at it.
"""
import math
import os
import sys
import time
from datetime import datetime
from pathlib import Path

import yaml

from mission.processes import INSTALL, PY_SITE, REPO, ProcessGroup, install_env
from mission.scenario import start_pose

RECORDER = Path(__file__).resolve().parent / 'recorder.py'
NODES = (('route_node', 'ship_planner'), ('guidance_node', 'ship_guidance'),
         ('autopilot_node', 'ship_autopilot'))


class MissionFailed(RuntimeError):
    """A node process died or the graph never came up; the message says which and why."""


def use_install_tree():
    """Make the installed packages importable in this process (as sourcing setup.bash would)."""
    for pkg in sorted(INSTALL.glob('*/' + PY_SITE)):
        if str(pkg) not in sys.path:
            sys.path.insert(0, str(pkg))


def make_run_dir(scenario, root):
    root = Path(root)
    stamp = datetime.now().strftime('%Y%m%d-%H%M%S')
    run = root / f'{scenario.name}-{stamp}'
    n = 1
    while run.exists():
        n += 1
        run = root / f'{scenario.name}-{stamp}-{n}'
    (run / 'params').mkdir(parents=True)
    latest = root / 'latest'
    if latest.is_symlink() or latest.exists():
        latest.unlink()
    latest.symlink_to(run.name)
    return run


def node_parameters(scenario, spec, index, record):
    """{node executable: parameters} for one vessel, scenario values first, then the glue."""
    from ship_planner.route_files import load_route
    plan = load_route(spec.route_file)
    x, y, yaw = start_pose(spec, plan.route)
    lockstep = scenario.stepping == 'lockstep'
    steps = int(round(scenario.duration_s / scenario.dt_s))
    vessel = {
        'model': spec.model, 'initial_x': x, 'initial_y': y,
        'initial_yaw_deg': math.degrees(yaw), 'dt': scenario.dt_s,
        'publish_rate': 1.0 / scenario.dt_s, 'stepping_mode': scenario.stepping,
        'speedup': scenario.speedup, 'clock_master': index == 0, 'max_steps': steps,
        'lockstep_timeout': scenario.lockstep_timeout_s,
        # guidance + autopilot (+ the recorder) must all hear step 0.
        'lockstep_odom_subscribers': 2 + int(record),
    }
    if spec.speed is not None:
        vessel['initial_speed'] = spec.speed
    cur = spec.current
    for key, param in (('speed_mps', 'current_speed'), ('direction_deg', 'current_direction_deg'),
                       ('speed_sd_mps', 'current_speed_sd'),
                       ('direction_sd_deg', 'current_direction_sd_deg'),
                       ('time_constant_s', 'current_time_constant'), ('seed', 'current_seed')):
        if key in cur:
            vessel[param] = cur[key]
    vessel.update(spec.vessel_params)
    sim_time = {'use_sim_time': True}
    return {
        'vessel_node': {**vessel, 'use_sim_time': False},
        'route_node': {**sim_time, 'route_file': str(spec.route_file)},
        'guidance_node': {**sim_time, **spec.guidance_params},
        'autopilot_node': {**sim_time, 'vessel_model': spec.model,
                           'pairing': 'sequence' if lockstep else 'latest',
                           **spec.autopilot_params},
    }, plan


def write_params(run, namespace, node, params):
    path = run / 'params' / f'{namespace}.{node}.yaml'
    path.write_text(yaml.safe_dump({'/**': {'ros__parameters': params}}, sort_keys=True))
    return path


class Monitor:
    """In-process rclpy node: sim time, cross-track error and completion of every vessel."""

    def __init__(self, namespaces):
        import rclpy
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from rosgraph_msgs.msg import Clock
        from std_msgs.msg import Bool, Float64
        from ship_sim.ros.qos import LATCHED, STREAM
        self.rclpy = rclpy
        self.context = rclpy.context.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node('mission_monitor', context=self.context)
        from rclpy.executors import SingleThreadedExecutor
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.t = 0.0
        self.xte = {ns: math.nan for ns in namespaces}
        self.complete = {ns: False for ns in namespaces}
        self.node.create_subscription(Clock, '/clock', self._on_clock,
                                      QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
        for ns in namespaces:
            self.node.create_subscription(Float64, f'/{ns}/cross_track_error',
                                          lambda m, ns=ns: self.xte.__setitem__(ns, m.data), STREAM)
            self.node.create_subscription(Bool, f'/{ns}/route_complete',
                                          lambda m, ns=ns: self.complete.__setitem__(ns, m.data),
                                          LATCHED)

    def _on_clock(self, msg):
        self.t = msg.clock.sec + 1e-9 * msg.clock.nanosec

    def spin(self, seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=max(0.0, end - time.monotonic()))

    def close(self):
        self.executor.shutdown()
        self.node.destroy_node()
        self.rclpy.try_shutdown(context=self.context)


def _tail(proc, n=8):
    lines = proc.output().strip().splitlines()
    return '\n'.join('    ' + ln for ln in lines[-n:])


def run_scenario(scenario, runs_root=REPO / 'runs', domain_id=None, record=None, progress=print,
                 progress_period_s=2.0, analyse=True, wall_timeout_s=None):
    """Run ``scenario``; returns (run_dir, metrics or None). Raises MissionFailed on failure."""
    use_install_tree()
    record = scenario.record if record is None else record
    run = make_run_dir(scenario, runs_root)
    domain_id = domain_id if domain_id is not None else 1 + os.getpid() % 100
    env = install_env(domain_id=domain_id)
    os.environ['ROS_DOMAIN_ID'] = str(domain_id)
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    namespaces = [v.namespace for v in scenario.vessels]
    (run / 'scenario.yaml').write_text(scenario.file.read_text())
    progress(f'run folder {run} (ROS_DOMAIN_ID={domain_id}, {scenario.stepping})')

    group = ProcessGroup(env, run / 'logs')
    monitor = None
    t_wall0 = time.monotonic()
    outcome = 'failed'
    try:
        vessel_params = []
        for i, spec in enumerate(scenario.vessels):
            params, plan = node_parameters(scenario, spec, i, record)
            for exe, pkg in NODES:
                f = write_params(run, spec.namespace, exe, params[exe])
                group.start(f'{spec.namespace}/{exe}', pkg, exe,
                            ['--ros-args', '-r', f'__ns:=/{spec.namespace}', '--params-file', f])
            vessel_params.append((spec, params['vessel_node'], plan))
        if record:
            from ship_sim.models import model_class
            limit = model_class(scenario.vessels[0].model).rudder_max
            group.start_argv('recorder', [sys.executable, RECORDER, run / 'bag', '--time-source',
                                          'sim', '--exclude', r'^/(rosout|parameter_events)$',
                                          '--meta', f'mission.rudder_limit_rad={limit!r}'])
        monitor = Monitor(namespaces)
        monitor.spin(1.0)
        for spec, vparams, _plan in vessel_params:
            f = write_params(run, spec.namespace, 'vessel_node', vparams)
            group.start(f'{spec.namespace}/vessel_node', 'ship_sim', 'vessel_node',
                        ['--ros-args', '-r', f'__ns:=/{spec.namespace}', '--params-file', f])
        last_print = 0.0
        while True:
            monitor.spin(0.2)
            dead = group.failed()
            vessels_done = [p for p in dead if p.label.endswith('/vessel_node') and p.returncode == 0]
            crashed = [p for p in dead if p not in vessels_done]
            if crashed:
                p = crashed[0]
                raise MissionFailed(f'{p.label} exited with code {p.returncode}; its log '
                                    f'({p.log_path}) ends with:\n{_tail(p)}')
            if all(monitor.complete.values()):
                outcome = 'completed'
                break
            if len(vessels_done) == len(namespaces):
                outcome = 'duration reached'
                break
            now = time.monotonic()
            if wall_timeout_s and now - t_wall0 > wall_timeout_s:
                raise MissionFailed(f'wall-clock limit {wall_timeout_s:.0f} s reached at sim '
                                    f'time {monitor.t:.1f} s')
            if now - last_print >= progress_period_s:
                last_print = now
                rtf = monitor.t / max(now - t_wall0, 1e-9)
                eta = (scenario.duration_s - monitor.t) / rtf if rtf > 0 else math.inf
                xte = '  '.join(f'{ns} xte {monitor.xte[ns]:+8.1f} m' for ns in namespaces)
                progress(f'  t = {monitor.t:7.1f} / {scenario.duration_s:.0f} s  {xte}  '
                         f'x{rtf:5.1f} real time, at most {eta:4.0f} s left')
    except KeyboardInterrupt:
        outcome = 'interrupted'
        raise
    finally:
        sim_t = monitor.t if monitor else 0.0
        if monitor is not None:
            monitor.close()
        codes = group.stop()
        wall = time.monotonic() - t_wall0
        summary = {'scenario': str(scenario.file), 'outcome': outcome, 'sim_time_s': sim_t,
                   'wall_time_s': wall, 'real_time_factor': sim_t / wall if wall > 0 else None,
                   'domain_id': domain_id, 'exit_codes': codes}
        (run / 'run.json').write_text(yaml.safe_dump(summary, sort_keys=False))
        progress(f'{outcome}: sim {sim_t:.1f} s in {wall:.1f} s wall '
                 f'(x{sim_t / max(wall, 1e-9):.1f} real time)')
    metrics = None
    if analyse and record:
        from mission.report import analyse_bag
        metrics = analyse_bag(run / 'bag', run, settle_s=scenario.settle_s)
        metrics['run'] = summary
        progress(f'metrics and plots written to {run}')
    return run, metrics
