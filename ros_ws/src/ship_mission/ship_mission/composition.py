"""Several nodes of a graph in one process: which specs share a container, and how the launcher
starts them.

``compose`` (scenario key, or run_mission ``--compose``):

- ``none``: every node its own process (the default);
- ``vessel``: one container process per vessel, holding its route, guidance (or follower),
  autopilot, colav, display and simulator nodes;
- ``all``: one container holding every node of the graph (every vessel's, traffic_node,
  ais_node, aivdm_out_node).

Scripts (the recorder, the live view) stay processes of their own. A member keeps its own name,
namespace, parameter file and remappings (ship_mission.container builds it with those as its
own ROS arguments), so ``ros2 node list``, ``ros2 param`` and the bag see the same graph.

The start order stays the launcher's: a container starts, with every member but its
simulators, where the graph lists its first such member; a simulator is loaded into its running
container where the launcher would start its process (after the waits of
ship_mission.graph.simulator_start_plan), by a message on the container's latched
``~/_load`` topic naming the member (hidden: the bag holds the same topics as without
composition). A container ends by itself (exit 0) once all of its
simulators have ended by themselves; a member that ends with an error code ends it with that
code, as that node's own process would end.
"""
import json
from dataclasses import dataclass, field

from ship_mission.graph import SIMULATOR
from ship_mission.scenario import COMPOSE
CONTAINER = 'component_container'   # the console script and the container's own node name
#: private and hidden (a leading '_': not recorded, not listed): .../component_container/_load
LOAD_TOPIC = '_load'
#: Load messages a container's ~/_load keeps (transient local): more than any graph's simulators.
LOAD_DEPTH = 1000


@dataclass
class Container:
    """One container process: ``members`` (NodeSpecs of the graph, in its start order)."""
    label: str
    namespace: str = None
    members: list = field(default_factory=list)

    @property
    def node_name(self):
        """The fully qualified name of the container's own node."""
        return f'/{self.namespace}/{CONTAINER}' if self.namespace else f'/{CONTAINER}'

    @property
    def load_topic(self):
        return f'{self.node_name}/{LOAD_TOPIC}'

    def deferred(self):
        """The members the launcher loads later (the simulators)."""
        return [m for m in self.members if is_deferred(m)]


def is_deferred(node):
    return node.executable == SIMULATOR[0]


def containers(graph, mode):
    """The containers of ``graph`` for ``compose`` ``mode`` (``[]`` for none). Only package
    nodes are composed; every spec belongs to at most one container."""
    if mode not in COMPOSE:
        raise ValueError(f"compose {mode!r} is not allowed: one of {', '.join(COMPOSE)}")
    nodes = [n for n in graph.nodes if n.package is not None]
    if mode == 'none':
        return []
    if mode == 'all':
        return [Container(CONTAINER, None, nodes)] if nodes else []
    out = []
    for sim in graph.simulators():
        members = [n for n in nodes if n.namespace == sim.namespace]
        out.append(Container(f'{sim.namespace}/{CONTAINER}', sim.namespace, members))
    return out


def container_spec(container, params_file, defer=True):
    """The JSON the container process reads: its own name and every member with the ROS
    arguments its own process would get (``params_file(node)``: the member's parameter file),
    whether it waits to be loaded (``deferred``: the simulators, unless ``defer`` is false) and
    whether the container ends once it and the other such members have ended (``final``: the
    simulators)."""
    return json.dumps({
        'namespace': container.namespace,
        'members': [{'label': m.label, 'package': m.package, 'executable': m.executable,
                     'ros_args': member_ros_args(m, params_file(m)),
                     'deferred': defer and is_deferred(m), 'final': is_deferred(m)}
                    for m in container.members],
    }, indent=1)


def member_ros_args(node, params_file):
    """The ROS arguments of one node, the same in its own process and in a container."""
    ns = ['-r', f'__ns:=/{node.namespace}'] if node.namespace else []
    return ['--ros-args', *ns, '--params-file', str(params_file), *node.remaps]


class Starter:
    """Starts the graph's specs for the launcher: a spec of no container as its own process
    (``start_process(node)``), a spec of a container by starting that container (in ``group``,
    its spec file in ``run``/params/, each member's parameter file ``params_file(node)``) or,
    for a simulator, by loading it into its container (``publish_load(topic, label)``, set by the
    launcher once its monitor node is up: ``launcher.Monitor.load_publisher``)."""

    def __init__(self, graph, mode, run, group, start_process, params_file):
        self.containers = containers(graph, mode)
        self.of = {m.label: c for c in self.containers for m in c.members}
        self.run, self.group = run, group
        self._start_process = start_process
        self._params_file = params_file
        self.procs = {}         # container label -> its NodeProcess
        self.publish_load = None

    def start(self, node):
        """The process that runs ``node`` (its own, or its container's)."""
        c = self.of.get(node.label)
        if c is None:
            return self._start_process(node)
        if c.label not in self.procs:
            path = self.run / 'params' / f"{c.label.replace('/', '.')}.json"
            path.write_text(container_spec(c, self._params_file))
            self.procs[c.label] = self.group.start(c.label, 'ship_mission', CONTAINER, [path])
        if is_deferred(node):
            self.publish_load(c.load_topic, node.label)
        return self.procs[c.label]

    def simulators_in(self, proc):
        """How many simulators end with ``proc`` (a vessel_node process: 1)."""
        for c in self.containers:
            if self.procs.get(c.label) is proc:
                return len(c.deferred())
        return 1 if proc.label.endswith('/' + SIMULATOR[0]) else 0

