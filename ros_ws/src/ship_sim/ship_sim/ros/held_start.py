"""A publisher that holds its first messages until every subscriber it can know of will get them.

Lockstep pairs commands with steps by sequence: a consumer takes the k-th message it receives
as the answer to step k. A volatile reader gets nothing a writer sent before the two matched,
and a reader matching a writer is not yet the writer matching the reader (discovery is per
endpoint), so under load the very first answer could be sent before the consumer's reader was
matched: it was lost, every later answer was taken for the step before it and the run stalled.
``HeldStart`` queues what is published until the writer's own count of matched subscriptions
reaches every subscription the ROS graph lists on the topic (and at least ``min_readers``),
then sends the queue in order and from then on publishes directly. The values are the same;
only the first sends are later. After ``timeout_s`` of wall time it opens anyway, with a
warning naming the counts.
"""
import copy
import time

from rclpy.clock import Clock, ClockType

POLL_S = 0.02


class HeldStart:
    """Wraps ``publisher`` of ``node``; ``publish(msg)`` queues a copy until open."""

    def __init__(self, node, publisher, min_readers=1, timeout_s=30.0):
        self.node, self.publisher = node, publisher
        self.min_readers, self.timeout_s = int(min_readers), float(timeout_s)
        self.open = False
        self.queue = []
        self._since = None
        self._timer = None

    def readers(self):
        """(matched by the writer, listed by the graph) for the topic."""
        return (self.publisher.get_subscription_count(),
                self.node.count_subscribers(self.publisher.topic_name))

    def ready(self):
        matched, listed = self.readers()
        return matched >= max(self.min_readers, listed)

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
            matched, listed = self.readers()
            self.node.get_logger().warning(
                f'{self.publisher.topic_name}: sending after {waited:.1f} s with {matched} matched '
                f'of {max(self.min_readers, listed)} subscribers; a reader that matches later '
                'misses the first messages')
        self.open = True
        self.node.destroy_timer(self._timer)
        for msg in self.queue:
            self.publisher.publish(msg)
        self.queue.clear()
