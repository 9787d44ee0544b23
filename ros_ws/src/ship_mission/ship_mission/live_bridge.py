"""Serve a running ROS 2 graph over the Foxglove WebSocket protocol (foxglove-sdk), natively.

Every topic found by discovery (``get_topic_names_and_types``, every DISCOVERY_PERIOD_S) is
advertised as a channel with message encoding ``cdr`` and a ``ros2msg`` schema: the message
definition text with its dependencies (ship_mission.recorder.message_definition, the text rosbag2
puts in its MCAP files), so Foxglove and Lichtblick decode the messages as they decode a bag.
Messages are forwarded as received: raw subscriptions, the CDR bytes untouched.

Never in the graph's way:
- a ROS topic is subscribed only while some client is subscribed to its channel (the sdk's
  ``has_sinks``; checked every UPDATE_PERIOD_S), as foxglove_bridge does: with no client the
  bridge costs the graph nothing but discovery;
- subscriptions are best effort, keep-last ``depth`` (a latched topic, all of whose publishers
  are transient_local, is reliable + transient_local, so a client joining late still gets the
  route); a slow bridge loses messages, it never holds a publisher back. A topic is subscribed
  only once it has a publisher (discovery also lists topics only subscribers have named, and a
  volatile subscription made then would never get a route latched before it), and is subscribed
  again with the other QoS when its publishers change between latched and not;
- the sdk queues at most ``backlog`` messages per client and drops the oldest when a client
  reads too slowly (its control queue overflowing disconnects that client);
- messages lost before the bridge (its DDS queue overflowing) are counted per topic from the
  publishers' sequence numbers (topics with one publisher) and reported with the forwarded
  counts.
``wait_ready``: latched std_msgs/Bool topics (the launcher: every vessel's ``<ns>/ready``, true
once its step 0 is out); nothing is subscribed before all of them are true, so the bridge is
never one of the subscribers a lockstep simulator or a ``ReadyWhenMatched`` waits for before
step 0 (a subscriber it does not know of would let step 0 go out before the real ones matched)
- except the ``early`` topics (the launcher: every vessel's odom, whose simulator then waits for
one more odom subscriber): those the bridge subscribes as soon as a client listens to the
channel or to ``/tf``, else EARLY_GRACE_S after their advertisement (a run nobody watches must
still start), so a viewer connected before the run gets it from step 0.

Message log time: the message's own header stamp (the sim time it describes; any type whose
first field is a ``std_msgs/Header`` or a ``builtin_interfaces/Time``), else the graph's sim time
(latest ``/clock``; such messages before its first value are not forwarded) else, in a graph
without /clock, wall time; never earlier than the channel's previous log time (a viewer's
timeline and plots never go backwards). The server also broadcasts the sim time (the protocol's
``time`` capability), so a client's clock and plots follow sim time.

``/tf``: while a client listens to it, every vessel odom topic (``/<ns>/odom``) becomes a
``foxglove.FrameTransforms`` message (the sdk's FrameTransformsChannel, protobuf; what
Foxglove's and Lichtblick's 3D panels read for frames) from the odom's ``header.frame_id``
(``map``) to its ``child_frame_id`` (``<ns>/base_link``), at the odom's stamp.
"""
import re
import time
from collections import Counter

from ship_mission.recorder import DEFAULT_EXCLUDE, clock_ns, message_class, message_definition

CLOCK_TOPIC = '/clock'
TF_TOPIC = '/tf'
TF_SOURCES = re.compile(r'^/[^/]+/odom$')   # a vessel's odom: map -> <ns>/base_link
UPDATE_PERIOD_S = 0.1
DISCOVERY_PERIOD_S = 0.5
EARLY_GRACE_S = 1.0
_STAMPED_FIRST = ('std_msgs/msg/Header', 'builtin_interfaces/msg/Time')


class LiveBridge:
    """Topics of the graph ``node`` sees -> channels of a foxglove ``context``.

    The caller starts the server on the same context and spins ``node`` with an executor that
    passes message info (rclpy's SingleThreadedExecutor: the drop count needs the sequence
    numbers; Jazzy's EventsExecutor does not hand them over)."""

    def __init__(self, node, context, topics=None, exclude=DEFAULT_EXCLUDE, depth=10,
                 wait_ready=(), early=()):
        from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
        from foxglove.channels import FrameTransformsChannel
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
        self.advertised_at = {}   # topic -> time.monotonic() of its advertisement
        self.early = set(early)
        self.tf = FrameTransformsChannel(TF_TOPIC, context=context)
        self._tf_sources = set()  # odom topics that feed /tf
        self._last_log = {}    # channel topic -> last log time (ns)
        self._early_seen = set()   # early topics that have delivered a message
        self.subs = {}         # topic -> rclpy Subscription (while a client listens)
        self._latched = {}     # topic -> whether its subscription is the latched QoS
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
        if topic == TF_TOPIC:   # ours (a graph's own /tf would be a second channel of the name)
            return False
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
                message_class(msgtype)   # the raw subscription needs the type support
            except Exception as err:  # noqa: BLE001 (one unknown type must not stop the others)
                self.refused[topic] = str(err)
                self.node.get_logger().warning(f'not serving {topic} [{msgtype}]: {err}')
                continue
            channel = foxglove.Channel(topic, schema=schema, message_encoding='cdr',
                                       context=self.context)
            self.channels[topic] = (channel, msgtype)
            self.advertised_at[topic] = time.monotonic()
            if msgtype == 'nav_msgs/msg/Odometry' and TF_SOURCES.match(topic):
                self._tf_sources.add(topic)

    def update(self):
        """Discovery (every DISCOVERY_PERIOD_S), then subscribe exactly the ROS topics some
        client listens to; broadcast the sim time."""
        now = time.monotonic()
        if now - self._last_discovery >= DISCOVERY_PERIOD_S:
            self._last_discovery = now
            self.discover()
            self._requalify()
        # Step 0 is out once the ready topics say so, or once every early topic (every
        # vessel's odom) has delivered: on a busy machine the latched ready can come seconds
        # after the odom the bridge itself receives.
        open_ = all(self.ready.values()) or bool(self.early) and self.early <= self._early_seen
        tf_wanted = self.tf.has_sinks()
        for topic, (channel, msgtype) in self.channels.items():
            wanted = channel.has_sinks() or (tf_wanted and topic in self._tf_sources)
            if open_:
                listening = wanted
            elif topic in self.early:
                # Held from the first subscription until step 0 is out: the simulator counts
                # it among the odom subscribers it waits for.
                listening = topic in self.subs or wanted \
                    or now - self.advertised_at[topic] >= EARLY_GRACE_S
            else:
                listening = False
            if listening and topic not in self.subs:
                self._subscribe(topic, channel, msgtype)
            elif not listening and topic in self.subs:
                self._unsubscribe(topic)
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
        self._sim_ns = clock_ns(data)

    def _stamped(self, msgtype):
        """Whether ``msgtype``'s serialized form starts with a stamp (a Header or a Time)."""
        try:
            first = self.typestore.get_msgdef(msgtype).fields[0][1]
        except Exception:  # noqa: BLE001 (a type only the .msg files know: no stamp assumed)
            return False
        return first[1] in _STAMPED_FIRST

    def _is_latched(self, pubs):
        return all(p.qos_profile.durability == self._transient for p in pubs)

    def _requalify(self):
        """Drop the subscriptions whose QoS no longer fits their publishers (the next update
        subscribes them again with the right one)."""
        for topic in list(self.subs):
            pubs = self.node.get_publishers_info_by_topic(topic)
            if pubs and self._is_latched(pubs) != self._latched[topic]:
                self._unsubscribe(topic)

    def _unsubscribe(self, topic):
        self.node.destroy_subscription(self.subs.pop(topic))
        self._latched.pop(topic, None)
        self._last_seq.pop(topic, None)

    def _subscribe(self, topic, channel, msgtype):
        pubs = self.node.get_publishers_info_by_topic(topic)
        if not pubs:   # named by subscribers only so far: nothing to receive, QoS unknown
            return
        latched = self._is_latched(pubs)
        qos = self._latched_qos if latched else self._stream_qos
        count_drops = len(pubs) == 1
        stamped = self._stamped(msgtype)
        to_tf = self._tf_to(topic) if topic in self._tf_sources else None
        early, early_seen = topic in self.early, self._early_seen
        log, forwarded, dropped, last = channel.log, self.forwarded, self.dropped, self._last_seq
        last_log = self._last_log

        def callback(data, info):
            seq = info.get('publication_sequence_number')
            if count_drops and seq is not None:
                prev = last.get(topic)
                if prev is not None and seq > prev + 1:
                    dropped[topic] += seq - prev - 1
                last[topic] = seq
            if topic == CLOCK_TOPIC:
                self._sim_ns = clock_ns(data)
            if stamped:
                t = clock_ns(data)   # the same layout: encapsulation, int32 sec, uint32 nanosec
            elif self._sim_ns is not None:
                t = self._sim_ns
            elif self._clock_sub is None:   # a graph without /clock: wall time
                t = time.time_ns()
            else:                           # the first /clock is on its way: no time to give
                return
            t = max(t, last_log.get(topic, 0))
            last_log[topic] = t
            if early:
                early_seen.add(topic)
            if channel.has_sinks():
                log(data, log_time=t)
                forwarded[topic] += 1
            if to_tf is not None:
                to_tf(data)

        self.subs[topic] = self.node.create_subscription(message_class(msgtype), topic,
                                                         callback, qos, raw=True)
        self._latched[topic] = latched

    def _tf_to(self, topic):
        """A function serialized Odometry -> one transform on /tf (while anyone listens)."""
        from foxglove.messages import (FrameTransform, FrameTransforms, Quaternion, Timestamp,
                                       Vector3)
        from nav_msgs.msg import Odometry
        from rclpy.serialization import deserialize_message
        tf, last_log, forwarded = self.tf, self._last_log, self.forwarded

        def to_tf(data):
            if not tf.has_sinks():
                return
            m = deserialize_message(data, Odometry)
            stamp, p, q = m.header.stamp, m.pose.pose.position, m.pose.pose.orientation
            t = max(stamp.sec * 1_000_000_000 + stamp.nanosec, last_log.get(TF_TOPIC, 0))
            last_log[TF_TOPIC] = t
            tf.log(FrameTransforms(transforms=[FrameTransform(
                timestamp=Timestamp(stamp.sec, stamp.nanosec), parent_frame_id=m.header.frame_id,
                child_frame_id=m.child_frame_id, translation=Vector3(x=p.x, y=p.y, z=p.z),
                rotation=Quaternion(x=q.x, y=q.y, z=q.z, w=q.w))]), log_time=t)
            forwarded[TF_TOPIC] += 1
        return to_tf

    def summary(self):
        """One line: topics advertised and listened to, messages forwarded and lost."""
        lost = sum(self.dropped.values())
        worst = ', '.join(f'{t} {n}' for t, n in self.dropped.most_common(3))
        return (f'{len(self.channels)} topics advertised, {len(self.subs)} listened to; '
                f'{sum(self.forwarded.values())} messages forwarded, {lost} lost before the '
                f'bridge' + (f' ({worst})' if lost else ''))
