"""A latched `~/ready` (std_msgs/Bool) that turns true once every given publisher has matched
at least `n` subscribers, as the publisher itself counts them.

For nodes that publish on the simulator's /clock (traffic_node, ais_node with publish_on_clock):
they cannot hold the simulator back, so in lockstep the launcher starts the simulators only
after this says that the recorder and every colav_node will get step 0. A subscriber that has
discovered a publisher is not yet one the publisher sends to; only the publisher's own count
says so (vessel_node's lockstep start waits on the same count).
"""
from rclpy.clock import Clock, ClockType
from std_msgs.msg import Bool

from ship_sim.ros.qos import LATCHED

POLL_S = 0.05


class ReadyWhenMatched:
    """Publish True on `~/ready` once ``publishers()`` (a callable giving the publishers to
    check) all have at least ``n`` subscriptions; n = 0: at once."""

    def __init__(self, node, publishers, n):
        self.node, self.publishers, self.n = node, publishers, int(n)
        self.pub = node.create_publisher(Bool, '~/ready', LATCHED)
        self.ready = False
        self.timer = node.create_timer(POLL_S, self._check,
                                       clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._check()

    def _check(self):
        if self.ready:
            return
        if all(p.get_subscription_count() >= self.n for p in self.publishers()):
            self.ready = True
            self.pub.publish(Bool(data=True))
            self.node.destroy_timer(self.timer)
            self.node.get_logger().info(f'ready: every target topic has {self.n} subscribers')
