"""A node's readiness announcement (ship_sim.ros.readiness.READY_TOPIC) once every given
publisher serves every named subscriber (ship_sim.ros.readiness: listed by name, and matched as
the publisher itself counts them).

For nodes that publish on the simulator's /clock (traffic_node, ais_node with publish_on_clock):
they cannot hold the simulator back, so in lockstep the launcher starts the simulators only
after they have announced that the recorder and every colav_node will get step 0.
"""
from rclpy.clock import Clock, ClockType

from ship_sim.ros.readiness import PeerWait, ReadyAnnouncer, describe_waits

POLL_S = 0.05
WARN_EVERY_S = 10.0


class ReadyWhenMatched:
    """Announce readiness once ``publishers()`` (a callable giving the publishers to check) all
    serve the nodes ``names`` (full names); no names: at once."""

    def __init__(self, node, publishers, names):
        self.node, self.publishers, self.names = node, publishers, tuple(names)
        self.announcer = ReadyAnnouncer(node)
        self.ready = False
        self._polls = 0
        self.timer = node.create_timer(POLL_S, self._check,
                                       clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._check()

    def waits(self):
        return [PeerWait(self.node, p, self.names) for p in self.publishers()] if self.names else []

    def _check(self):
        if self.ready:
            return
        waits = self.waits()
        if all(w.ready() for w in waits):
            self.ready = True
            self.announcer.announce(sorted({w.topic for w in waits}))
            self.node.destroy_timer(self.timer)
            self.node.get_logger().info(
                'ready: ' + (f"every target topic serves {', '.join(self.names)}" if self.names
                             else 'nobody to wait for'))
            return
        self._polls += 1
        if self._polls % int(WARN_EVERY_S / POLL_S) == 0:
            self.node.get_logger().warning(describe_waits(waits))
