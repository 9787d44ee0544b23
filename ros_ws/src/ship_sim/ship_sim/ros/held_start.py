"""A publisher that holds its first messages until every subscriber it can know of will get them.

Lockstep pairs commands with steps by sequence: a consumer takes the k-th message it receives
as the answer to step k. A volatile reader gets nothing a writer sent before the two matched,
and a reader matching a writer is not yet the writer matching the reader (discovery is per
endpoint), so under load the very first answer could be sent before the consumer's reader was
matched: it was lost, every later answer was taken for the step before it and the run stalled.
``HeldStart`` queues what is published until the readers are there by name
(ship_sim.ros.readiness: each node of ``names`` listed on the topic, and the writer's own count
of matched subscriptions reaching every subscription listed; without names, at least
``min_readers``), then sends the queue in order and from then on publishes directly. A count
alone could be met by a reader that pairs nothing (an echo, a display) while the one that pairs
was not yet discovered at all. The values are the same; only the first sends are later. After
``timeout_s`` of wall time it opens anyway, with a warning naming the nodes still missing.
"""
import copy
import time

from rclpy.clock import Clock, ClockType

from ship_sim.ros.readiness import PeerWait

POLL_S = 0.02


class HeldStart:
    """Wraps ``publisher`` of ``node``; ``publish(msg)`` queues a copy until open."""

    def __init__(self, node, publisher, min_readers=1, timeout_s=30.0, names=()):
        self.node, self.publisher = node, publisher
        self.wait = PeerWait(node, publisher, names, min_readers)
        self.timeout_s = float(timeout_s)
        self.open = False
        self.queue = []
        self._since = None
        self._timer = None

    def ready(self):
        return self.wait.ready()

    def publish(self, msg):
        if self.open:
            self.publisher.publish(msg)
            return
        self.queue.append(copy.deepcopy(msg))
        if self._since is None:
            self._since = time.monotonic()
            self._timer = self.node.create_timer(POLL_S, self._poll,
                                                 clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._poll()

    def _poll(self):
        if self.open:
            return
        waited = time.monotonic() - self._since
        if not self.ready():
            if waited < self.timeout_s:
                return
            self.node.get_logger().warning(
                f'{self.wait.describe()}; sending after {waited:.1f} s: a reader that matches '
                'later misses the first messages')
        self.open = True
        self.node.destroy_timer(self._timer)
        for msg in self.queue:
            self.publisher.publish(msg)
        self.queue.clear()


def held_publisher(node, publisher, names, **kw):
    """``publisher`` held by name (HeldStart) when ``names`` (a ``<topic>_readers`` parameter,
    ship_sim.param_schema.readers_param) names any node, else ``publisher`` itself."""
    from ship_sim.ros.readiness import names_param
    names = names_param(names)
    return HeldStart(node, publisher, names=names, **kw) if names else publisher
