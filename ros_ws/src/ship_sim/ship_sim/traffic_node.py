"""traffic_node: light target ships on the graph (thin plumbing around ship_sim.light_traffic).

Subscribes /clock (rosgraph_msgs/Clock, reliable + transient_local, ship_sim.ros.qos.CLOCK_STEPS:
step 0 reaches it even when the simulator's publisher matches it late) and for every /clock message publishes one
nav_msgs/Odometry per light target on ``/<name>/odom`` (QoS ship_sim.ros.qos.STREAM), stamped
with exactly that clock time: pose ENU (frame ``map``), child ``<name>/base_link``, twist in
body FLU with the body along the course (surge = speed, no sway, no yaw rate). colav_node can
list these topics in its ``target_topics`` and stays deterministic in lockstep: one sample per
simulator step, stamped at the step, computed in closed form from the clock time alone.

Parameter ``wait_readers``: in lockstep, the full names of the nodes every target topic must
serve (the recorder, the colav_nodes); once each is listed and matched, the node announces that
it is ready on /graph_ready (ship_sim.ros.ready, ship_sim.ros.readiness), and the launcher starts
the simulators only then, so nobody misses step 0.

Parameter ``targets``: the targets as JSON text (ROS 2 parameters carry no list of mappings),
schema in ship_sim.light_traffic.parse_targets; a bad list is refused at start (exit 2, one
line naming the target and the problem). A target's ``behaviour`` may be ``straight`` or
``no_alteration`` (both the closed-form motion); the behaviours that react to other ships
(``reciprocal``, ``turns_to_port``, ship_guidance.reacting_traffic) are refused there: this node
moves targets from the clock alone, and a reacting target would need every other ship's state
at each step, in lockstep a per-step wait on their odometry that the node graph does not have.
"""
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rosgraph_msgs.msg import Clock as ClockMsg

from ship_sim.light_traffic import parse_targets
from ship_sim.ros.conversions import MAP_FRAME, base_link_frame, fill_odometry
from ship_sim.ros.params import NodeParameters
from ship_sim.ros.qos import CLOCK_STEPS, STREAM
from ship_sim.ros.readiness import names_param
from ship_sim.ros.ready import ReadyWhenMatched
from ship_sim.ros.run import run_node
from ship_sim.schema import TRAFFIC_NODE

_NS_PER_S = 1_000_000_000


class TrafficNode(Node):
    def __init__(self):
        super().__init__('traffic_node')
        p = self.params = NodeParameters(self, TRAFFIC_NODE)
        text = p.param('targets')
        wait = names_param(p.param('wait_readers'))
        self.traffic = parse_targets(text)
        # /clock first: once the odom publishers are visible, the clock subscription exists.
        self._clock_sub = self.create_subscription(ClockMsg, '/clock', self._on_clock,
                                                   CLOCK_STEPS)
        self._pubs, self._msgs = [], []
        for name in self.traffic.names:
            self._pubs.append(self.create_publisher(Odometry, f'/{name}/odom', STREAM))
            msg = Odometry()
            msg.header.frame_id = MAP_FRAME
            msg.child_frame_id = base_link_frame(name)
            self._msgs.append(msg)
        self.steps = 0
        self.ready = ReadyWhenMatched(self, lambda: self._pubs, wait)
        self.get_logger().info(f'{len(self.traffic)} light targets: '
                               f"{', '.join(self.traffic.names) or '(none)'}")

    def _on_clock(self, msg):
        stamp = msg.clock
        t = (stamp.sec * _NS_PER_S + stamp.nanosec) / _NS_PER_S
        north, east, course, speed = self.traffic.state(t)
        for i, (pub, odom) in enumerate(zip(self._pubs, self._msgs)):
            fill_odometry(odom, t, north[i], east[i], course[i], speed[i], 0.0, 0.0)
            odom.header.stamp.sec, odom.header.stamp.nanosec = stamp.sec, stamp.nanosec
            pub.publish(odom)
        self.steps += 1


def main(args=None):
    return run_node(TrafficNode, args=args)
