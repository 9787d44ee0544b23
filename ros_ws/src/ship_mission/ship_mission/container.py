"""component_container: several of the project's nodes in one process, spun by one executor.

    component_container SPEC.json     (written by the launcher: ship_mission.composition)

Each member is the class its own executable runs (the one rclpy Node subclass of the module its
console script names), built with that executable's ROS arguments as the node's own arguments
(namespace, --params-file, remappings), so it has the same name, parameters and topics as in a
process of its own, and the same checks (ship_sim.ros.run: an unknown parameter ends the
container with exit 2 and one line naming the member). The container also has a node of its
own, ``component_container`` (in the vessel's namespace with compose: vessel), whose latched
``~/_load`` topic (std_msgs/String, a member's label) tells it to build a deferred member: the
launcher loads each simulator when its start plan says so.

One executor (ship_sim.ros.run.make_executor, EventsExecutor by default) spins every member:
no node's callback waits for another node's callback (the lockstep waits are all message-driven,
subscriber counts are the middleware's), so one thread is enough and the messages between
members never leave the process's DDS participant.

A member that ends itself (ship_sim.ros.run.finish) is taken out of the executor and destroyed
alone; the container ends once every ``final`` member (every simulator) has ended with 0, or
at once with the first non-zero code. SIGINT / SIGTERM end it as they end a node (run_node).
"""
import importlib
import inspect
import json
import sys
from importlib.metadata import entry_points
from pathlib import Path

import rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from ship_mission.composition import CONTAINER, LOAD_DEPTH, LOAD_TOPIC
from ship_sim.ros import run as node_run

#: ~/_load, on both ends (the launcher's Monitor.load_publisher publishes with it).
LOAD_QOS = QoSProfile(depth=LOAD_DEPTH, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL)


def node_class(package, executable):
    """The rclpy Node subclass that ``ros2 run package executable`` runs: the one Node subclass
    defined in the module of its console script."""
    module = f'{package}.{executable}'
    for ep in entry_points(group='console_scripts', name=executable):
        if ep.value.startswith(f'{package}.'):
            module = ep.value.split(':')[0]
            break
    mod = importlib.import_module(module)
    classes = [c for _, c in inspect.getmembers(mod, inspect.isclass)
               if issubclass(c, Node) and c is not Node and c.__module__ == mod.__name__]
    if len(classes) != 1:
        raise ValueError(f'{module}: {len(classes)} Node classes, cannot compose it')
    return classes[0]


def with_args(cls, ros_args):
    """A subclass of node class ``cls`` whose node is built with ``ros_args`` as its own ROS
    arguments. The nodes call ``super().__init__(name)``; the class put between them and Node
    adds the arguments there, so the node classes need no constructor arguments."""
    class _OwnArgs(Node):
        def __init__(self, node_name, **kwargs):
            super().__init__(node_name, cli_args=list(ros_args), **kwargs)
    return type(cls.__name__, (cls, _OwnArgs), {})


class Container:
    """The members of one container and their executor."""

    def __init__(self, spec, executor):
        self.members = {m['label']: m for m in spec['members']}
        self.pending = [m['label'] for m in spec['members'] if m['deferred']]
        self.to_build = [m['label'] for m in spec['members'] if not m['deferred']]
        self.executor = executor
        self.running = {}       # label -> node
        self.ended = []         # nodes that called finish
        self.code = None        # the container's exit code once decided
        ns = spec.get('namespace')
        self.node = Node(CONTAINER, namespace=f'/{ns}' if ns else '/')
        self.node.create_subscription(String, '~/' + LOAD_TOPIC, self._on_load, LOAD_QOS)
        executor.add_node(self.node)

    def _on_load(self, msg):
        label = msg.data
        if label not in self.pending:
            self.node.get_logger().warning(f'load {label!r}: not a deferred member (ignored)')
            return
        self.pending.remove(label)
        self.to_build.append(label)   # built between two callbacks (build_pending)

    def build_pending(self):
        """Build the members waiting to be built (ParameterError: refused, as run_node does)."""
        while self.to_build:
            m = self.members[self.to_build.pop(0)]
            cls = with_args(node_class(m['package'], m['executable']), m['ros_args'])
            node = node_run.build_node(cls)
            node.end_alone = lambda code, node=node, label=m['label']: \
                self.ended.append((label, node, code))
            self.running[m['label']] = node
            self.executor.add_node(node)
            self.node.get_logger().info(f"loaded {m['label']} "
                                        f'({node.get_namespace().rstrip("/")}/{node.get_name()})')

    def reap(self):
        """Take out the members that ended themselves; decide the exit code when it is due."""
        if not self.ended:      # after every callback: nothing to do but this test
            return
        while self.ended:
            label, node, code = self.ended.pop(0)
            self.executor.remove_node(node)
            node.destroy_node()
            self.running.pop(label, None)
            self.members[label]['ended'] = code
            if code:
                self.code = code
                return
        final = [m for m in self.members.values() if m['final']]
        if final and all(m.get('ended') == 0 for m in final):
            self.code = 0

    def destroy(self):
        for node in self.running.values():
            node.destroy_node()
        self.node.destroy_node()


def spin(container):
    """spin_once in a loop (see ship_sim.ros.run.spin for why not spin()); between two
    callbacks: build what was loaded, take out what ended."""
    ok = rclpy.ok
    spin_once = container.executor.spin_once
    with node_run.spinning():
        while ok() and not node_run.stop_signalled() and container.code is None:
            container.build_pending()
            try:
                spin_once(timeout_sec=node_run.SPIN_TIMEOUT_S)
            except rclpy._rclpy_pybind11.RCLError:
                if ok():
                    raise
            container.reap()


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    prog = CONTAINER
    if len(argv) != 1:
        print(f'usage: {prog} SPEC.json', file=sys.stderr)
        return 2
    try:
        spec = json.loads(Path(argv[0]).read_text())
    except (OSError, ValueError) as exc:
        print(f'{prog}: cannot read the container spec {argv[0]}: {exc}', file=sys.stderr)
        return 2
    return node_run.run_process(lambda: Container(spec, node_run.make_executor()), spin,
                                lambda container: container.destroy(),
                                lambda container: container.code, prog=prog)


if __name__ == '__main__':
    sys.exit(main())
