"""Run a scenario as a graph of node processes (no `ros2 launch`): start, watch, stop, analyse.

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
import json
import math
import os
import signal
import sys
import time
from datetime import datetime
from pathlib import Path

import yaml

from ship_mission.console import progress_line
from ship_mission.domain import LeaseError, lease_domain_id
from ship_mission.processes import REPO, ProcessGroup, install_env
from ship_mission.node_checks import RCLPY_PARAMETERS, node_parameter_names  # noqa: F401 (the launcher's API)
from ship_mission.scenario import (TARGETS_KEY, ScenarioError, route_plan, scenario_origin,
                                   scenario_text, start_pose, target_record)
from ship_mission.waves import wave_filter_parameters
from ship_mission.wind_block import wind_meta, wind_parameters
from ship_guidance.nav_display import DEFAULT_DISPLAY_RATE_HZ

RECORDER = Path(__file__).resolve().parent / 'recorder.py'
NODES = (('route_node', 'ship_planner'), ('guidance_node', 'ship_guidance'),
         ('autopilot_node', 'ship_autopilot'))
FOLLOWER_NODES = (('route_node', 'ship_planner'), ('follower_node', 'ship_guidance'),
                  ('autopilot_node', 'ship_autopilot'))
COLAV_NODE = ('colav_node', 'ship_guidance')
#: guidance_node's output is colav_node's nominal input on a vessel with collision avoidance.
COLAV_REMAP = ['-r', 'heading_cmd:=heading_ref']
DISPLAY_NODE = ('nav_display_node', 'ship_guidance')
LIVE_VIEW = REPO / 'scripts' / 'live_view.py'
LAYOUT = REPO / 'scripts' / 'live_view_layout.json'   # the Foxglove layout of a run


RECORD_ACK = 'record_ack'  # per vessel namespace: the recorder's lockstep acknowledgement


def record_ack_arg(namespace, clock_master, extra=()):
    """The recorder's --ack argument for one vessel: the topics it publishes or gets every step
    (``extra``: more per-step topics acknowledged with it, e.g. the light targets' odom)."""
    ns = f'/{namespace}'
    # the guidance's (or follower's) outputs too: every vessel publishes them once per step, and
    # the recorder's first ack waits until it is subscribed to every covered topic, so it cannot
    # join them after step 0 (seen under load: a recorder that subscribed them 126 s late)
    per_step = ('odom', 'rudder', 'rudder_cmd', 'heading_cmd', 'cross_track_error', 'progress')
    topics = (['/clock'] if clock_master else []) + [f'{ns}/{t}' for t in per_step]
    return ['--ack', f'{ns}/{RECORD_ACK}=' + ','.join(topics + list(extra))]


def light_odom_topics(scenario):
    """The odom topics traffic_node publishes, one per light target of the scenario."""
    return [f"/{t['name']}/odom" for t in scenario.light]


AIS_NODE = ('ais_node', 'ship_guidance')
#: ais_node runs graph-wide (no namespace): its topics as every colav vessel sees them.
AIS_TARGETS, AIS_SYNC = '/targets', '/targets_sync'


def record_ack_args(scenario):
    """The recorder's --ack arguments for every vessel (the first is the clock master, whose
    acknowledgement also covers the light targets and the AIS targets' per-step announcement:
    traffic_node and ais_node publish them on its /clock)."""
    light = light_odom_topics(scenario) + ([AIS_SYNC] if scenario.ais else [])
    return [a for i, spec in enumerate(scenario.vessels)
            for a in record_ack_arg(spec.namespace, i == 0, light if i == 0 else ())]


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


def check_scenario(scenario):
    """What load_scenario cannot check without the packages: model names, route files, start
    points within their route, the number of steps (ship_mission.scenario.MAX_STEPS), node
    parameter names (node_parameter_names; an unknown one is named with the closest valid
    one), and for a platoon the stability of every look-ahead (ship_mission.platoon.check_stability;
    its warnings go to scenario.platoon.warnings).

    Raises ScenarioError (one line naming the file and the key) before anything starts."""
    import difflib
    from ship_mission.node_checks import check_vessel_sections
    from ship_mission.scenario import MAX_STEPS
    from ship_planner.route_loader import RouteError
    from ship_sim.models import MODEL_NAMES
    platoon = scenario.platoon
    for key, v in (('duration_s', scenario.duration_s), ('dt_s', scenario.dt_s)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0.0):
            raise ScenarioError(f'{scenario.file}: {key}: must be a positive number, got {v!r}')
    if not scenario.duration_s / scenario.dt_s <= MAX_STEPS:
        raise ScenarioError(f'{scenario.file}: duration_s: {scenario.duration_s:g} s is '
                            f'{scenario.duration_s / scenario.dt_s:.3g} steps of dt_s '
                            f'{scenario.dt_s:g} s; at most {MAX_STEPS:.0e} steps '
                            f'({MAX_STEPS * scenario.dt_s:.3g} s)')
    for i, spec in enumerate(scenario.vessels):
        section = 'traffic' if spec.traffic else 'vessels'
        where = (f'{scenario.file}: {section}.{spec.namespace}.' if platoon is None
                 else f'{scenario.file}: platoon.vessels[{i}] ({spec.namespace}).')
        if spec.model not in MODEL_NAMES:
            raise ScenarioError(f'{where}model: unknown model {spec.model!r}; one of '
                                f'{", ".join(MODEL_NAMES)}')
        try:
            plan = route_plan(scenario, spec)
        except RouteError as exc:
            key = f'{where}route' if platoon is None else f'{scenario.file}: platoon.route'
            raise ScenarioError(f'{key}: {exc}') from None
        along = spec.start.get('along_m')
        if along is not None and not 0.0 <= along < plan.route.length:
            raise ScenarioError(f'{where}start.along_m: {along:g} m is not on the route '
                                f'({spec.route_file}, {plan.route.length:.1f} m long); give '
                                f'0 <= along_m < {plan.route.length:.1f}')
        guidance = vessel_nodes(spec)[1]
        blocks = [('vessel', spec.vessel_params, ('vessel_node', 'ship_sim')),
                  ('guidance', spec.guidance_params, guidance),
                  ('autopilot', spec.autopilot_params, NODES[2])]
        if spec.colav_params is not None:
            blocks.append(('colav', spec.colav_params, COLAV_NODE))
        for block, params, (exe, pkg) in blocks:
            names = node_parameter_names(pkg, exe)
            for key in params:
                if key not in names:
                    near = difflib.get_close_matches(str(key), sorted(names), n=1)
                    hint = f' (did you mean "{near[0]}"?)' if near else ''
                    raise ScenarioError(f'{where}{block}.{key}: {exe} has no parameter '
                                        f'{key!r}{hint}')
        check_vessel_sections(spec, where)   # values, by the nodes' own rules
    if scenario.ais is not None:
        names = node_parameter_names(*reversed(AIS_NODE))
        for key in scenario.ais:
            if key not in names:
                near = difflib.get_close_matches(str(key), sorted(names), n=1)
                hint = f' (did you mean "{near[0]}"?)' if near else ''
                raise ScenarioError(f'{scenario.file}: ais.{key}: ais_node has no parameter '
                                    f'{key!r}{hint}')
    if scenario.aivdm_out is not None:
        from ship_mission.aivdm_block import aivdm_parameters
        aivdm_parameters(scenario, Path('.'))
    if platoon is not None:
        from ship_mission.platoon import check_lead, check_stability
        check_lead(scenario)
        check_stability(scenario)


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


def vessel_nodes(spec):
    """(executable, package) of the nodes started before a vessel's vessel_node."""
    nodes = NODES if spec.predecessor is None else FOLLOWER_NODES
    return nodes + (COLAV_NODE,) if spec.colav_params is not None else nodes


def node_remaps(spec, exe):
    """Extra ROS remapping arguments of one node: guidance's heading_cmd becomes heading_ref
    on a vessel with colav_node."""
    return COLAV_REMAP if spec.colav_params is not None and exe == 'guidance_node' else []


def odom_subscribers(scenario, spec, record):
    """Subscribers of a (non-platoon) vessel's odom a lockstep vessel_node waits for: its
    guidance and autopilot, the recorder, its own colav_node, every other vessel's colav_node
    (all other vessels are its targets), and for a colav vessel the simulators of the traffic
    vessels (each keeps within lockstep_follower_window steps of it)."""
    colav = [s for s in scenario.vessels if s.colav_params is not None]
    n = 2 + int(bool(record)) + sum(1 for s in colav if s is not spec)
    if spec.colav_params is not None:
        n += 1 + sum(1 for s in scenario.vessels if s.traffic)
    return n


def node_parameters(scenario, spec, index, record):
    """{node executable: parameters} for one vessel, scenario values first, then the glue.

    A platoon follower gets 'follower_node' (ship_mission.platoon.follower_parameters) instead of
    'guidance_node'; every platoon vessel_node also waits for the followers of its vessel."""
    plan = route_plan(scenario, spec)
    x, y, yaw = start_pose(spec, plan.route)
    lockstep = scenario.stepping == 'lockstep'
    steps = int(round(scenario.duration_s / scenario.dt_s))
    vessel = {
        'model': spec.model, 'initial_x': x, 'initial_y': y,
        'initial_yaw_deg': math.degrees(yaw), 'dt': scenario.dt_s,
        'publish_rate': 1.0 / scenario.dt_s, 'stepping_mode': scenario.stepping,
        'speedup': scenario.speedup, 'clock_master': index == 0, 'max_steps': steps,
        'lockstep_timeout': scenario.lockstep_timeout_s,
        # The recorder acknowledges each step it holds; the simulator never runs far enough
        # ahead of it for a publisher's queue to overwrite an unrecorded message.
        'lockstep_record_topic': RECORD_ACK if lockstep and record else '',
        # guidance + autopilot (+ the recorder) (+ the followers) must all hear step 0.
        'lockstep_odom_subscribers': (odom_subscribers(scenario, spec, record)
        if scenario.platoon is None else scenario.platoon.odom_subscribers(spec.namespace, record))
        + int(lockstep and scenario.live_port is not None)    # the live view's (start_viewers)
        + int(lockstep and scenario.aivdm_out is not None),   # aivdm_out_node's (every vessel)
    }
    if spec.traffic and lockstep:
        # A target never runs so far ahead that its odom queue overwrites a sample a colav_node
        # has not taken (the platoon predecessor's gate, on every colav vessel's odom).
        gated = [f'/{s.namespace}/odom' for s in scenario.vessels if s.colav_params is not None]
        if gated:
            vessel['lockstep_follower_odom_topics'] = ','.join(gated)
    if scenario.platoon is not None:
        # A predecessor never runs so far ahead (lockstep) that its odom queue overwrites a
        # sample its followers have not taken.
        followers = scenario.platoon.followers_of(spec.namespace)
        vessel['lockstep_follower_odom_topics'] = ','.join(f'/{f}/odom' for f in followers)
    if spec.speed is not None:
        vessel['initial_speed'] = spec.speed
    cur = spec.current
    for key, param in (('speed_mps', 'current_speed'), ('direction_deg', 'current_direction_deg'),
                       ('speed_sd_mps', 'current_speed_sd'),
                       ('direction_sd_deg', 'current_direction_sd_deg'),
                       ('time_constant_s', 'current_time_constant'), ('seed', 'current_seed')):
        if key in cur:
            vessel[param] = cur[key]
    vessel.update(spec.wave_params)
    if spec.colav_params is not None:   # colav_node's speed factor acts on the shaft
        vessel['speed_factor_input'] = True
    vessel.update(wind_parameters(spec.wind))
    vessel.update(spec.vessel_params)
    sim_time = {'use_sim_time': True}
    params = {
        'vessel_node': {**vessel, 'use_sim_time': False},
        'route_node': {**sim_time, 'route_file': str(spec.route_file)},
        'autopilot_node': {**sim_time, 'vessel_model': spec.model,
                           'pairing': 'sequence' if lockstep else 'latest',
                           **wave_filter_parameters(spec.wave_params, spec.autopilot_params),
                           **spec.autopilot_params},
    }
    if spec.colav_params is not None:
        others = [f'/{s.namespace}/odom' for s in scenario.vessels if s is not spec] + \
            light_odom_topics(scenario)
        # No node executes speed_factor_cmd yet: plan with course changes only unless asked.
        ais = {}
        if scenario.ais is not None:   # the graph-wide ais_node's targets, waited for in lockstep
            ais = {'targets_topic': AIS_TARGETS, 'targets_sync_topic': AIS_SYNC if lockstep else ''}
        # vessel_node executes speed_factor_cmd on a shaft (tanker, container); the Mariner has
        # none, so colav plans with course changes only there.
        from ship_sim.models import make_model
        params['colav_node'] = {**sim_time, 'target_topics': others or [''],
                                'has_shaft': bool(make_model(spec.model).has_shaft),
                                'pairing': 'sequence' if lockstep else 'latest', **ais,
                                **spec.colav_params}
    if spec.predecessor is None:
        params['guidance_node'] = {**sim_time, **spec.guidance_params}
    else:
        from ship_mission.platoon import follower_parameters
        params['follower_node'] = follower_parameters(scenario, spec)
    return params, plan


def target_subscribers(scenario, record):
    """Lockstep: the subscribers of every target topic of traffic_node and ais_node (the recorder,
    each colav vessel's colav_node) they wait for before ~/ready (ship_sim.ros.ready); 0 in
    realtime (nobody waits)."""
    if scenario.stepping != 'lockstep':
        return 0
    return int(bool(record)) + sum(1 for s in scenario.vessels if s.colav_params is not None)


def display_every(scenario):
    """vessel_node's ``display_every``: the steps between two odom_display messages, one per
    display frame (0 without a display). The display reads only those (one callback per frame,
    not per step), picked by the simulator and kept for it (qos DISPLAY), so its frames are the
    same on every lockstep run; a lockstep simulator need not wait for it before step 0."""
    if scenario.display is None:
        return 0
    rate = scenario.display.get('display_rate_hz', DEFAULT_DISPLAY_RATE_HZ)
    return max(1, int(round(1.0 / (scenario.dt_s * rate))))


def display_parameters(scenario, spec):
    """nav_display_node's parameters of one vessel: its model, the scenario's `display:` keys,
    and the NavSatFix origin (ship_mission.scenario.scenario_origin) if the scenario has one."""
    # Stamped from odom only: no /clock subscription (a callback per step) is needed.
    params = {'use_sim_time': False, 'model': spec.model, **scenario.display}
    origin = scenario_origin(scenario)
    if origin is not None:
        params['origin_lat_deg'], params['origin_lon_deg'] = origin
    return params


def start_viewers(scenario, run, group, progress):
    """Start every vessel's nav_display_node (unless `display: false`) and, with --live, the
    live view (scripts/live_view.py, ship_mission.live_bridge) serving the graph on 127.0.0.1."""
    if scenario.display is not None:
        if scenario_origin(scenario) is None:
            from ship_guidance.nav_display import DEFAULT_ORIGIN_DEG
            progress(f'display: no geodetic origin in the scenario or its routes; the fix uses '
                     f'the default sea area {DEFAULT_ORIGIN_DEG[0]:g} N {DEFAULT_ORIGIN_DEG[1]:g} E '
                     f'(Norwegian Sea; `display: origin` sets one)')
        exe, pkg = DISPLAY_NODE
        for spec in scenario.vessels:
            f = write_params(run, spec.namespace, exe, display_parameters(scenario, spec))
            group.start(f'{spec.namespace}/{exe}', pkg, exe,
                        ['--ros-args', '-r', f'__ns:=/{spec.namespace}', '--params-file', f])
    if scenario.live_port is not None:
        ready = [f'/{spec.namespace}/ready' for spec in scenario.vessels]
        # Lockstep: each simulator also waits for the view on its odom (node_parameters), so a
        # viewer connected before the run gets it from step 0.
        early = [f'/{spec.namespace}/odom' for spec in scenario.vessels
                 if scenario.stepping == 'lockstep']
        view = group.start_argv('live_view', [sys.executable, LIVE_VIEW, '--port',
                                              str(scenario.live_port), '--nice',
                                              str(scenario.live_nice), '--wait-ready', *ready,
                                              '--early', *early])
        end = time.monotonic() + 30.0   # serving before step 0: a viewer sees the whole run
        while 'live view: ws://' not in view.output():
            if view.returncode is not None or time.monotonic() > end:
                raise MissionFailed(f'live view did not start, its last line: '
                                    f'{_last_line(view)} (log: {view.log_path})')
            time.sleep(0.05)
        url = view.output().split('live view: ', 1)[1].split()[0]   # the port, also when 0
        progress(f'live view: {url} (Foxglove or Lichtblick: Open connection -> Foxglove '
                 f'WebSocket; layout: {LAYOUT.relative_to(REPO)})')


def traffic_parameters(scenario, record=True):
    """traffic_node's parameters: the light targets as JSON text (ship_sim.light_traffic)."""
    # aivdm_out_node subscribes every light target too: counted, or the count could be met by
    # it before the recorder or a colav_node has matched (publisher counts carry no names)
    aivdm = int(scenario.stepping == 'lockstep' and scenario.aivdm_out is not None)
    return {'use_sim_time': True, 'targets': json.dumps(scenario.light),
            'wait_subscribers': target_subscribers(scenario, record) + aivdm}


def ais_parameters(scenario, record=True):
    """ais_node's parameters: the scenario's `ais:` section on sim time; in lockstep it
    publishes at every /clock step, each followed by targets_sync (ais_node)."""
    lockstep = scenario.stepping == 'lockstep'
    return {'use_sim_time': True, 'publish_on_clock': lockstep,
            **({'wait_subscribers': target_subscribers(scenario, record)} if lockstep else {}),
            **scenario.ais}


def _wait_for_clock_subscriber(monitor, node_name, group, timeout_s=30.0):
    """Wait until ``node_name`` subscribes /clock: the simulators start after it, so it hears
    step 0 (colav_node waits for its samples from step 0 on)."""
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        infos = monitor.node.get_subscriptions_info_by_topic('/clock')
        if any(i.node_name == node_name for i in infos):
            return
        _raise_if_failed(group)
        monitor.spin(0.1)
    raise MissionFailed(f'{node_name} did not subscribe /clock within {timeout_s:.0f} s')


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
    wanted = {exe for exe, _ in vessel_nodes(spec) if exe != 'route_node'}
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        infos = monitor.node.get_subscriptions_info_by_topic(f'{ns}/odom')
        if wanted <= {i.node_name for i in infos if i.node_namespace == ns}:
            return
        if group.failed():
            return                  # the run loop reports the dead process
        monitor.spin(0.1)
    infos = monitor.node.get_subscriptions_info_by_topic(f'{ns}/odom')
    late = sorted(wanted - {i.node_name for i in infos if i.node_namespace == ns})
    progress(f'  warning: {", ".join(late)} of {ns} not following {ns}/odom after '
             f'{timeout_s:.0f} s; starting its simulator anyway (its first steps go unanswered)')


def _wait_for_ready_topic(monitor, node_name, group, timeout_s=60.0):
    """Wait until ``node_name``'s latched ``/<node_name>/ready`` is true (ship_sim.ros.ready:
    every target topic has its recorder and colav_node subscribers, as the publisher counts
    them), so that no one misses step 0 of a lockstep run."""
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import Bool
    got = []
    qos = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
    sub = monitor.node.create_subscription(Bool, f'/{node_name}/ready',
                                           lambda m: got.append(m.data), qos)
    try:
        end = time.monotonic() + timeout_s
        while not any(got):
            _raise_if_failed(group)
            if time.monotonic() > end:
                raise MissionFailed(f'{node_name}: its target topics did not get their '
                                    f'subscribers (recorder, colav_node) within {timeout_s:.0f} s')
            monitor.spin(0.1)
    finally:
        monitor.node.destroy_subscription(sub)


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

    def spin(self, seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=max(0.0, end - time.monotonic()))

    def close(self):
        self.executor.shutdown()
        self.node.destroy_node()
        self.rclpy.try_shutdown(context=self.context)


def simulator_start_plan(scenario):
    """[(namespace, namespaces whose step 0 must be out first)]: the order in which the launcher
    starts the simulators. In lockstep, whoever others wait for comes first and is waited for:
    every platoon predecessor before its followers (ship_mission.platoon.start_order), and every
    traffic vessel before the colav vessels, whose colav_node waits for each target's sample at
    every decision from step 0 on and, after lockstep_target_timeout_s, decides without a
    silent one (the run then does not repeat). Once a target has published step 0 its recorder
    and colav_node subscriptions are there, and its follower gate holds it within
    lockstep_follower_window steps of the own ship. In realtime nobody waits (predecessors
    still start first)."""
    specs = list(scenario.vessels)
    if scenario.platoon is not None:
        from ship_mission.platoon import start_order
        rank = {ns: i for i, ns in enumerate(start_order(scenario.platoon))}
        specs.sort(key=lambda s: rank[s.namespace])
    if scenario.stepping != 'lockstep':
        return [(s.namespace, ()) for s in specs]
    traffic = tuple(s.namespace for s in specs if s.traffic)
    specs.sort(key=lambda s: not s.traffic)     # stable: the order above within each kind
    plan = []
    for s in specs:
        awaited = () if s.predecessor is None else (s.predecessor,)
        if s.colav_params is not None:
            awaited += traffic
        plan.append((s.namespace, awaited))
    return plan


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
    monitor = None
    t_wall0 = time.monotonic()
    outcome = 'failed'
    try:
        vessel_params = []
        for i, spec in enumerate(scenario.vessels):
            params, plan = node_parameters(scenario, spec, i, record)
            params['vessel_node']['display_every'] = display_every(scenario)
            for exe, pkg in vessel_nodes(spec):
                f = write_params(run, spec.namespace, exe, params[exe])
                group.start(f'{spec.namespace}/{exe}', pkg, exe,
                            ['--ros-args', '-r', f'__ns:=/{spec.namespace}', '--params-file', f,
                             *node_remaps(spec, exe)])
            vessel_params.append((spec, params['vessel_node'], plan))
        if scenario.light:
            f = write_params(run, 'traffic', 'traffic_node', traffic_parameters(scenario, record))
            group.start('traffic/traffic_node', 'ship_sim', 'traffic_node',
                        ['--ros-args', '--params-file', f])
        if scenario.ais is not None:
            f = write_params(run, 'ais', 'ais_node', ais_parameters(scenario, record))
            group.start('ais/ais_node', AIS_NODE[1], AIS_NODE[0],
                        ['--ros-args', '--params-file', f])
        # AIVDM/AIVDO to chart plotters. In lockstep the simulators and traffic_node count its
        # odom subscriptions among those they wait for (node_parameters, traffic_parameters)
        if scenario.aivdm_out is not None:
            from ship_mission.aivdm_block import NODE, aivdm_parameters
            f = write_params(run, 'aivdm', NODE[0], aivdm_parameters(scenario, run))
            group.start(f'aivdm/{NODE[0]}', NODE[1], NODE[0], ['--ros-args', '--params-file', f])
        if record:
            from ship_sim.models import make_model
            # Each vessel's limit for ship_mission.report (the instance's: some models set it in
            # __init__), as a plain float so that repr gives a number, not 'np.float64(...)'.
            meta = []
            for spec in scenario.vessels:
                limit = float(make_model(spec.model).rudder_max)
                meta += ['--meta', f'mission.rudder_limit_rad/{spec.namespace}={limit!r}']
            meta += wind_meta(scenario.vessels)
            meta += ['--meta', f'{TARGETS_KEY}={target_record(scenario)}']
            # A platoon's followers run behind the master's /clock: wall log times, which
            # ship_mission.report maps onto each vessel's own odometry stamps.
            source = 'sim' if scenario.platoon is None else 'wall'
            acks = record_ack_args(scenario) if scenario.stepping == 'lockstep' else []
            group.start_argv('recorder', [sys.executable, RECORDER, run / 'bag', '--time-source',
                                          source, '--exclude', r'^/(rosout|parameter_events)$',
                                          '--compression', scenario.bag_compression,
                                          *meta, *acks])
        start_viewers(scenario, run, group, progress)
        monitor = Monitor(namespaces)
        monitor.spin(1.0)
        if scenario.light:
            _wait_for_clock_subscriber(monitor, 'traffic_node', group)
            if scenario.stepping == 'lockstep':
                _wait_for_ready_topic(monitor, 'traffic_node', group)
        if scenario.ais is not None and scenario.stepping == 'lockstep':
            _wait_for_clock_subscriber(monitor, 'ais_node', group)
            _wait_for_ready_topic(monitor, 'ais_node', group)
        simulators = {}
        by_ns = {spec.namespace: (spec, vparams) for spec, vparams, _plan in vessel_params}
        for ns, awaited in simulator_start_plan(scenario):
            spec, vparams = by_ns[ns]
            for other in awaited:
                wait_for_ready(simulators[other], other, by_ns[other][1], monitor, group)
            if scenario.stepping == 'realtime':
                wait_for_odom_subscribers(monitor, spec, group, progress)
            f = write_params(run, spec.namespace, 'vessel_node', vparams)
            simulators[spec.namespace] = group.start(
                f'{spec.namespace}/vessel_node', 'ship_sim', 'vessel_node',
                ['--ros-args', '-r', f'__ns:=/{spec.namespace}', '--params-file', f])
        last_print = 0.0
        while True:
            monitor.spin(0.2)
            if _stop_signals:
                raise KeyboardInterrupt(_stop_signals[0])
            dead = group.failed()
            vessels_done = [p for p in dead if p.label.endswith('/vessel_node') and p.returncode == 0]
            crashed = [p for p in dead if p not in vessels_done]
            if crashed:
                p = crashed[0]
                raise MissionFailed(f'{p.label} exited with {_exit_status(p.returncode)}, its last '
                                    f'line: {_last_line(p)} (log: {p.log_path})')
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
        # Simulators first (nothing new is published), then give the recorder time to write
        # what it still has queued, then everything else.
        codes = group.stop(first=lambda p: p.label.endswith('/vessel_node'),
                           settle=1.0 if record else 0.0)
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
