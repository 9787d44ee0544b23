"""Serve a running ROS 2 graph over the Foxglove WebSocket protocol (foxglove-sdk), natively.

Every topic found by discovery (``get_topic_names_and_types``, every DISCOVERY_PERIOD_S) is
advertised as a channel with message encoding ``cdr`` and a ``ros2msg`` schema: the message
definition text with its dependencies (mission.recorder.message_definition, the text rosbag2
puts in its MCAP files), so Foxglove and Lichtblick decode the messages as they decode a bag.
Messages are forwarded as received: raw subscriptions, the CDR bytes untouched.

Never in the graph's way:
- a ROS topic is subscribed only while some client is subscribed to its channel (the sdk's
  ``has_sinks``; checked every UPDATE_PERIOD_S), as foxglove_bridge does: with no client the
  bridge costs the graph nothing but discovery;
- subscriptions are best effort, keep-last ``depth`` (a latched topic, all of whose publishers
  are transient_local, is reliable + transient_local, so a client joining late still gets the
  route); a slow bridge loses messages, it never holds a publisher back;
- the sdk queues at most ``backlog`` messages per client and drops the oldest when a client
  reads too slowly (its control queue overflowing disconnects that client);
- messages lost before the bridge (its DDS queue overflowing) are counted per topic from the
  publishers' sequence numbers (topics with one publisher) and reported with the forwarded
  counts.
``wait_ready``: latched std_msgs/Bool topics (the launcher's ``<ns>/ready``); nothing is
subscribed before all of them are true, so the bridge never counts as an odom subscriber that a
lockstep simulator waits for before its step 0.

Message log time: the graph's sim time (latest ``/clock``, subscribed while anything is;
messages before its first value are not forwarded) else, in a graph without /clock, wall time;
the server also broadcasts that time (the protocol's ``time`` capability), so a client's clock
and plots follow sim time.
"""
import re
import time
from collections import Counter

from mission.recorder import DEFAULT_EXCLUDE, _clock_ns, _message_class, message_definition

CLOCK_TOPIC = '/clock'
UPDATE_PERIOD_S = 0.1
DISCOVERY_PERIOD_S = 0.5


class LiveBridge:
    """Topics of the graph ``node`` sees -> channels of a foxglove ``context``.

    The caller starts the server on the same context and spins ``node`` with an executor that
    passes message info (rclpy's SingleThreadedExecutor: the drop count needs the sequence
    numbers; Jazzy's EventsExecutor does not hand them over)."""

    def __init__(self, node, context, topics=None, exclude=DEFAULT_EXCLUDE, depth=10,
                 wait_ready=()):
        from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
        from rosbags.typesys import Stores, get_typestore
        from std_msgs.msg import Bool
        from ship_sim.ros.qos import LATCHED
        self.node = node
        self.context = context
        self.wanted = None if topics is None else set(topics)
        self.exclude = re.compile(exclude) if exclude else None
        self.typestore = get_typestore(Stores.ROS2_JAZZY)
        self._stream_qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth,
                                      reliability=ReliabilityPolicy.BEST_EFFORT)
        self._latched_qos = LATCHED
        self._transient = DurabilityPolicy.TRANSIENT_LOCAL
        self.channels = {}     # topic -> (foxglove Channel, msgtype)
        self.subs = {}         # topic -> rclpy Subscription (while a client listens)
        self.refused = {}      # topic -> reason it is not served
        self.forwarded = Counter()
        self.dropped = Counter()
        self._last_seq = {}
        self._sim_ns = None
        self._clock_sub = None
        self._last_discovery = -1e9
        self._last_broadcast = None
        self.server = None     # set by the caller once started (time broadcasts)
        self.ready = {t: False for t in wait_ready}
        for t in wait_ready:
            node.create_subscription(Bool, t, lambda m, t=t: self.ready.__setitem__(t, m.data),
                                     LATCHED)
        node.create_timer(UPDATE_PERIOD_S, self.update)

    def _serves(self, topic):
        if self.wanted is not None:
            return topic in self.wanted
        return not (self.exclude and self.exclude.search(topic))

    def discover(self):
        """Advertise every served topic that has appeared since the last call."""
        import foxglove
        for topic, types in self.node.get_topic_names_and_types():
            if topic in self.channels or topic in self.refused or not self._serves(topic):
                continue
            msgtype = types[0]
            try:
                schema = foxglove.Schema(name=msgtype, encoding='ros2msg',
                                         data=message_definition(self.typestore, msgtype).encode())
                _message_class(msgtype)   # the raw subscription needs the type support
            except Exception as err:  # noqa: BLE001 (one unknown type must not stop the others)
                self.refused[topic] = str(err)
                self.node.get_logger().warning(f'not serving {topic} [{msgtype}]: {err}')
                continue
            channel = foxglove.Channel(topic, schema=schema, message_encoding='cdr',
                                       context=self.context)
            self.channels[topic] = (channel, msgtype)

    def update(self):
        """Discovery (every DISCOVERY_PERIOD_S), then subscribe exactly the ROS topics some
        client listens to; broadcast the sim time."""
        now = time.monotonic()
        if now - self._last_discovery >= DISCOVERY_PERIOD_S:
            self._last_discovery = now
            self.discover()
        open_ = all(self.ready.values())
        for topic, (channel, msgtype) in self.channels.items():
            listening = open_ and channel.has_sinks()
            if listening and topic not in self.subs:
                self._subscribe(topic, channel, msgtype)
            elif not listening and topic in self.subs:
                self.node.destroy_subscription(self.subs.pop(topic))
                self._last_seq.pop(topic, None)
        self._follow_clock(bool(self.subs))
        if self.server is not None and self._sim_ns is not None \
                and self._sim_ns != self._last_broadcast:
            self._last_broadcast = self._sim_ns
            self.server.broadcast_time(self._sim_ns)

    def _follow_clock(self, on):
        if on and self._clock_sub is None and CLOCK_TOPIC in self.channels:
            from rosgraph_msgs.msg import Clock
            self._clock_sub = self.node.create_subscription(
                Clock, CLOCK_TOPIC, self._on_clock, self._stream_qos, raw=True)
        elif not on and self._clock_sub is not None and CLOCK_TOPIC not in self.subs:
            self.node.destroy_subscription(self._clock_sub)
            self._clock_sub = None

    def _on_clock(self, data):
        self._sim_ns = _clock_ns(data)

    def _subscribe(self, topic, channel, msgtype):
        pubs = self.node.get_publishers_info_by_topic(topic)
        latched = bool(pubs) and all(p.qos_profile.durability == self._transient for p in pubs)
        qos = self._latched_qos if latched else self._stream_qos
        count_drops = len(pubs) == 1
        log, forwarded, dropped, last = channel.log, self.forwarded, self.dropped, self._last_seq

        def callback(data, info):
            seq = info.get('publication_sequence_number')
            if count_drops and seq is not None:
                prev = last.get(topic)
                if prev is not None and seq > prev + 1:
                    dropped[topic] += seq - prev - 1
                last[topic] = seq
            if topic == CLOCK_TOPIC:
                self._sim_ns = _clock_ns(data)
            if self._sim_ns is not None:
                log(data, log_time=self._sim_ns)
            elif self._clock_sub is None:   # a graph without /clock: wall time
                log(data, log_time=time.time_ns())
            else:                           # the first /clock is on its way: no time to give
                return
            forwarded[topic] += 1

        self.subs[topic] = self.node.create_subscription(_message_class(msgtype), topic,
                                                         callback, qos, raw=True)

    def summary(self):
        """One line: topics advertised and listened to, messages forwarded and lost."""
        lost = sum(self.dropped.values())
        worst = ', '.join(f'{t} {n}' for t, n in self.dropped.most_common(3))
        return (f'{len(self.channels)} topics advertised, {len(self.subs)} listened to; '
                f'{sum(self.forwarded.values())} messages forwarded, {lost} lost before the '
                f'bridge' + (f' ({worst})' if lost else ''))
