"""The graph a scenario makes, as data: which nodes run, with which parameters and remappings,
and which of them follow which topic. Nothing is started here and nothing is written; the
launcher (ship_mission.launcher) turns the node specs into processes.

``mission_graph`` lists, in start order: per vessel route_node, guidance_node (follower_node
for a platoon follower), autopilot_node and colav_node where the scenario has colav; then the
graph-wide traffic_node (light targets), ais_node (`ais:`), aivdm_out_node (`aivdm_out:`), the
recorder (record on), every vessel's nav_display_node (unless `display: false`), the live view
(--live), and last every vessel_node (started in ship_mission.launcher.simulator_start_plan
order). Each spec names the topics on which a lockstep publisher waits for it before step 0
(``counted``) and, in lockstep, the per-step topics it takes message by message whose publisher
holds its first messages until it has matched (``paired``: commands paired with steps by
sequence). The nodes the simulators, traffic_node, ais_node and the held publishers wait for
are read off those by name (``Graph.names``, ship_sim.ros.readiness), so a new subscriber node
is one more spec, not more arithmetic.
"""
import json
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

from ship_guidance.nav_display import DEFAULT_DISPLAY_RATE_HZ
from ship_mission.processes import REPO
from ship_mission.scenario import TARGETS_KEY, route_plan, scenario_origin, start_pose, target_record
from ship_mission.waves import wave_filter_parameters
from ship_mission.wind_block import wind_meta, wind_parameters
from ship_sim.ros.readiness import READY_TOPIC, full_name

RECORDER = Path(__file__).resolve().parent / 'recorder.py'
NODES = (('route_node', 'ship_planner'), ('guidance_node', 'ship_guidance'),
         ('autopilot_node', 'ship_autopilot'))
FOLLOWER_NODES = (('route_node', 'ship_planner'), ('follower_node', 'ship_guidance'),
                  ('autopilot_node', 'ship_autopilot'))
COLAV_NODE = ('colav_node', 'ship_guidance')
#: guidance_node's output is colav_node's nominal input on a vessel with collision avoidance.
COLAV_REMAP = ['-r', 'heading_cmd:=heading_ref']
DISPLAY_NODE = ('nav_display_node', 'ship_guidance')
SIMULATOR = ('vessel_node', 'ship_sim')
LIVE_VIEW = REPO / 'scripts' / 'live_view.py'
AIS_NODE = ('ais_node', 'ship_guidance')
#: ais_node runs graph-wide (no namespace): its topics as every colav vessel sees them.
AIS_TARGETS, AIS_SYNC = '/targets', '/targets_sync'
RECORD_ACK = 'record_ack'  # per vessel namespace: the recorder's lockstep acknowledgement
#: Not recorded: ROS's own logging and parameter events, and the start-up announcements (graph
#: plumbing, not the run: a record with them would differ from one made before they existed).
EXCLUDED = r'^/(rosout|parameter_events|' + READY_TOPIC.lstrip('/') + r')$'
RECORDER_NAME = 'mission_recorder'   # the recorder's ROS node name (ship_mission.recorder)
#: The parameter of a held publisher (ship_sim.ros.held_start) naming the readers of its topic.
HELD_PARAMETER = '{}_readers'


@dataclass
class NodeSpec:
    """One process of the graph. ``package`` None: a script started as ``argv`` (the recorder,
    the live view). ``counted``: the topics on which a lockstep publisher waits for this node
    (by name) before step 0; ``paired``: the per-step topics whose held publisher waits for it
    (lockstep); ``ros_name``: the ROS node name when it is not the executable's."""
    label: str
    package: str
    executable: str
    namespace: str = None
    parameters: dict = field(default_factory=dict)
    remaps: list = field(default_factory=list)
    argv: list = field(default_factory=list)
    counted: tuple = ()
    paired: tuple = ()
    ros_name: str = None

    @property
    def name(self):
        """The ROS node name (each executable names its node after itself)."""
        return self.ros_name or self.executable

    @property
    def full_name(self):
        """'/<namespace>/<name>', as the ROS graph lists the node."""
        return full_name(self.namespace, self.name)


@dataclass
class Graph:
    """The node specs of a run in start order (the simulators last)."""
    nodes: list

    def subscribers(self, topic):
        """How many node specs a lockstep publisher of ``topic`` counts."""
        return sum(1 for n in self.nodes if topic in n.counted)

    def names(self, topic):
        """Full names of the nodes a publisher of ``topic`` waits for (counted or paired), in
        start order."""
        return [n.full_name for n in self.nodes if topic in n.counted or topic in n.paired]

    def topics(self):
        """{topic: [labels of the nodes counted on it]}: the wiring the waits rest on."""
        wiring = {}
        for n in self.nodes:
            for t in n.counted:
                wiring.setdefault(t, []).append(n.label)
        return wiring

    def node(self, label):
        return next(n for n in self.nodes if n.label == label)

    def simulators(self):
        return [n for n in self.nodes if n.executable == SIMULATOR[0]]


def odom(namespace):
    return f'/{namespace}/odom'


def light_odom_topics(scenario):
    """The odom topics traffic_node publishes, one per light target of the scenario."""
    return [odom(t['name']) for t in scenario.light]


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


def record_ack_args(scenario):
    """The recorder's --ack arguments for every vessel (the first is the clock master, whose
    acknowledgement also covers the light targets and the AIS targets' per-step announcement:
    traffic_node and ais_node publish them on its /clock)."""
    light = light_odom_topics(scenario) + ([AIS_SYNC] if scenario.ais else [])
    return [a for i, spec in enumerate(scenario.vessels)
            for a in record_ack_arg(spec.namespace, i == 0, light if i == 0 else ())]


def vessel_nodes(spec):
    """(executable, package) of the nodes started before a vessel's vessel_node."""
    nodes = NODES if spec.predecessor is None else FOLLOWER_NODES
    return nodes + (COLAV_NODE,) if spec.colav_params is not None else nodes


def node_remaps(spec, exe):
    """Extra ROS remapping arguments of one node: guidance's heading_cmd becomes heading_ref
    on a vessel with colav_node."""
    return COLAV_REMAP if spec.colav_params is not None and exe == 'guidance_node' else []


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


def _gated_topics(scenario, spec):
    """The odom topics a vessel_node keeps within lockstep_follower_window steps of: a
    platoon predecessor its followers', a traffic vessel every colav vessel's (whose colav_node
    must take each of its samples)."""
    if scenario.platoon is not None:
        return [odom(f) for f in scenario.platoon.followers_of(spec.namespace)]
    if spec.traffic:
        return [odom(s.namespace) for s in scenario.vessels if s.colav_params is not None]
    return []


def _vessel_parameters(scenario, spec, index, record):
    """{node executable: parameters} for one vessel, scenario values first, then the glue;
    vessel_node's subscriber count is filled in by mission_graph."""
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
    }
    gated = _gated_topics(scenario, spec)
    # A predecessor (lockstep or not) or, in lockstep, a target never runs so far ahead that its
    # odom queue overwrites a sample a follower or colav_node has not taken.
    if scenario.platoon is not None or (lockstep and gated):
        vessel['lockstep_follower_odom_topics'] = ','.join(gated)
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
        others = [odom(s.namespace) for s in scenario.vessels if s is not spec] + \
            light_odom_topics(scenario)
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


def _counted_topics(scenario, spec, exe):
    """The topics a vessel's node (not its simulator) is counted on before step 0."""
    own = odom(spec.namespace)
    if exe == 'route_node':
        return ()
    if exe == 'follower_node':
        return (own, odom(spec.predecessor))
    if exe == 'colav_node':     # every other vessel and light target is one of its targets
        others = [odom(s.namespace) for s in scenario.vessels if s is not spec]
        return ((own, *others, *light_odom_topics(scenario))
                + ((AIS_TARGETS,) if scenario.ais is not None else ()))
    return (own,)       # guidance_node, autopilot_node


def _paired_topics(scenario, spec, exe):
    """The per-step topics of a vessel that ``exe`` takes by sequence in lockstep (the n-th
    message as step n's), so that their publishers hold the first ones until it has matched."""
    if scenario.stepping != 'lockstep':
        return ()
    ns = f'/{spec.namespace}'
    if exe == 'vessel_node':
        return (f'{ns}/rudder_cmd',) + ((f'{ns}/speed_factor_cmd',)
                                        if spec.colav_params is not None else ())
    if exe == 'autopilot_node':   # a policy steers by path_state, which no one holds
        policy = spec.autopilot_params.get('controller') == 'policy'
        return () if policy else (f'{ns}/heading_cmd',)
    if exe == 'colav_node':
        return (f'{ns}/heading_ref',)
    return ()


def _recorded_paired(scenario):
    """The held per-step topics of every vessel: the recorder takes each of them from the first
    message on (its bag pairs the unstamped ones with odom by sequence)."""
    return tuple(t for spec in scenario.vessels
                 for exe in ('vessel_node', 'autopilot_node', 'colav_node')
                 for t in _paired_topics(scenario, spec, exe)) + tuple(
        f'/{spec.namespace}/heading_cmd' for spec in scenario.vessels
        if scenario.stepping == 'lockstep' and
        spec.autopilot_params.get('controller') == 'policy')


def _held_publishers(scenario, spec):
    """{executable: {held topic parameter: topic}} of a vessel's publishers that hold their
    first messages in lockstep (ship_sim.ros.held_start) until the topic's readers matched."""
    ns = f'/{spec.namespace}'
    guide = 'guidance_node' if spec.predecessor is None else 'follower_node'
    held = {'autopilot_node': {'rudder_cmd': f'{ns}/rudder_cmd'}}
    if spec.colav_params is None:
        held[guide] = {'heading_cmd': f'{ns}/heading_cmd'}
    else:   # guidance's heading_cmd is remapped to colav_node's heading_ref
        held[guide] = {'heading_cmd': f'{ns}/heading_ref'}
        held['colav_node'] = {'heading_cmd': f'{ns}/heading_cmd',
                              'speed_factor_cmd': f'{ns}/speed_factor_cmd'}
    return held


def traffic_parameters(scenario, record=True):
    """traffic_node's parameters: the light targets as JSON text (ship_sim.light_traffic), and
    in lockstep the subscribers it waits for on each target topic (0 in realtime)."""
    graph = mission_graph(scenario, record)
    return graph.node('traffic/traffic_node').parameters if scenario.light else {
        'use_sim_time': True, 'targets': json.dumps(scenario.light), 'wait_readers': ['']}


def ais_parameters(scenario, record=True):
    """ais_node's parameters: the scenario's `ais:` section on sim time; in lockstep it
    publishes at every /clock step, each followed by targets_sync (ais_node)."""
    return mission_graph(scenario, record).node('ais/ais_node').parameters


def node_parameters(scenario, spec, index, record):
    """({node executable: parameters}, route plan) of one vessel as mission_graph makes them
    (without display_every, which the launcher's graph adds for the display)."""
    graph = mission_graph(scenario, record)
    params = {n.executable: dict(n.parameters) for n in graph.nodes
              if n.namespace == spec.namespace}
    params['vessel_node'].pop('display_every')
    params['vessel_node']['clock_master'] = index == 0
    return params, route_plan(scenario, spec)


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



def _recorder_argv(scenario, run_dir):
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
    return [sys.executable, RECORDER, Path(run_dir) / 'bag', '--time-source', source,
            '--exclude', EXCLUDED, '--compression',
            scenario.bag_compression, *meta, *acks]


def mission_graph(scenario, record=None, run_dir=Path('.')):
    """The Graph of ``scenario`` as the launcher starts it. Run options come with the scenario
    (``stepping``: lockstep or realtime, ``live_port``: the live view or None) and ``record``
    (None: the scenario's own). ``run_dir`` only names files in it (the bag, a relative
    aivdm_out file); nothing is written."""
    record = scenario.record if record is None else record
    lockstep = scenario.stepping == 'lockstep'
    vessel_odom = [odom(s.namespace) for s in scenario.vessels]
    light = light_odom_topics(scenario)
    nodes, simulators = [], []
    for i, spec in enumerate(scenario.vessels):
        params, _plan = _vessel_parameters(scenario, spec, i, record)
        params['vessel_node']['display_every'] = display_every(scenario)
        for exe, pkg in vessel_nodes(spec):
            nodes.append(NodeSpec(f'{spec.namespace}/{exe}', pkg, exe, spec.namespace,
                                  params[exe], list(node_remaps(spec, exe)),
                                  counted=_counted_topics(scenario, spec, exe),
                                  paired=_paired_topics(scenario, spec, exe)))
        simulators.append(NodeSpec(f'{spec.namespace}/vessel_node', SIMULATOR[1], SIMULATOR[0],
                                   spec.namespace, params['vessel_node'],
                                   counted=tuple(_gated_topics(scenario, spec)),
                                   paired=_paired_topics(scenario, spec, 'vessel_node')))
    if scenario.light:
        nodes.append(NodeSpec('traffic/traffic_node', 'ship_sim', 'traffic_node', None,
                              {'use_sim_time': True, 'targets': json.dumps(scenario.light)}))
    if scenario.ais is not None:
        nodes.append(NodeSpec('ais/ais_node', AIS_NODE[1], AIS_NODE[0], None,
                              {'use_sim_time': True, 'publish_on_clock': lockstep}))
    if scenario.aivdm_out is not None:
        from ship_mission.aivdm_block import NODE, aivdm_parameters
        # counted in lockstep by the simulators and traffic_node: publisher counts carry no
        # names, so an uncounted subscriber could meet a count before the recorder has matched
        nodes.append(NodeSpec(f'aivdm/{NODE[0]}', NODE[1], NODE[0], None,
                              aivdm_parameters(scenario, Path(run_dir)),
                              counted=tuple(vessel_odom + light) if lockstep else ()))
    if record:
        nodes.append(NodeSpec('recorder', None, 'recorder', None,
                              argv=_recorder_argv(scenario, run_dir),
                              counted=tuple(vessel_odom + light) +
                              ((AIS_TARGETS,) if scenario.ais is not None else ()),
                              paired=_recorded_paired(scenario), ros_name=RECORDER_NAME))
    if scenario.display is not None:
        exe, pkg = DISPLAY_NODE
        for spec in scenario.vessels:
            nodes.append(NodeSpec(f'{spec.namespace}/{exe}', pkg, exe, spec.namespace,
                                  display_parameters(scenario, spec)))
    if scenario.live_port is not None:
        ready = [f'/{s.namespace}/ready' for s in scenario.vessels]
        # Lockstep: each simulator also waits for the view on its odom, so a viewer connected
        # before the run gets it from step 0.
        early = vessel_odom if lockstep else []
        nodes.append(NodeSpec('live_view', None, 'live_view', None,
                              argv=[sys.executable, LIVE_VIEW, '--port', str(scenario.live_port),
                                    '--nice', str(scenario.live_nice), '--wait-ready', *ready,
                                    '--early', *early],
                              counted=tuple(early)))
    graph = Graph(nodes + simulators)
    for sim in simulators:   # guidance + autopilot (+ recorder, colav, followers) hear step 0
        sim.parameters['lockstep_odom_readers'] = graph.names(odom(sim.namespace)) or ['']
    if lockstep:
        for spec in scenario.vessels:
            for exe, held in _held_publishers(scenario, spec).items():
                node = graph.node(f'{spec.namespace}/{exe}')
                for out, topic in held.items():
                    node.parameters[HELD_PARAMETER.format(out)] = graph.names(topic) or ['']
    if scenario.light:
        # every light target has the same subscribers: the recorder, each colav_node (aivdm)
        graph.node('traffic/traffic_node').parameters['wait_readers'] = (
            graph.names(light[0]) if lockstep else []) or ['']
    if scenario.ais is not None:
        ais = graph.node('ais/ais_node').parameters
        if lockstep:
            ais['wait_readers'] = graph.names(AIS_TARGETS) or ['']
        ais.update(scenario.ais)
    return graph
