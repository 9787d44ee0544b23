"""Record a running graph into a rosbag2 (MCAP) bag, without a ROS install: rclpy + rosbags.

Two layers:

- ``BagWriter``: the bag file. A rosbags ``Writer`` (rosbag2 format version 9, MCAP storage,
  serialization 'cdr') with message definitions and RIHS01 type hashes from the rosbags Jazzy
  typestore (types it lacks are read from ``share/<pkg>/msg/*.msg`` under AMENT_PREFIX_PATH),
  the publishers' offered QoS profiles per topic, and a message count per topic. ``close()``
  writes the MCAP summary and ``metadata.yaml`` (what ``ros2 bag info``, Foxglove and
  PlotJuggler read). No rclpy here: tests and offline tools write bags through the same code.
- ``Recorder``: an rclpy node that discovers topics (``get_topic_names_and_types``, every
  ``discovery_period_s`` until it is closed) or takes an explicit list, subscribes with
  ``raw=True`` (the serialized CDR bytes go straight to the file, nothing is deserialised) and
  a QoS matched to the publishers: reliable when every publisher is reliable, transient_local
  when every publisher is transient_local (so a late recorder still gets the latched ``route``).
  A topic is subscribed only once it has a publisher, so its QoS is known.

Message time (the bag's log_time, ns): with ``time_source='sim'`` (default; our graph runs on
sim time) a message with a header stamp (Odometry, Path, NavSatFix; MarkerArray and TFMessage
by their first element's header: ``header_stamp_at``) is logged at that stamp, the sim time it
describes, and a message without one (std_msgs/Float64, the progress array, /clock itself) at
the latest ``/clock`` value the recorder has received (0 before the first
``/clock``). The display topics (``fix``, ``nav_markers``) come from a node that lags the
lockstep graph by seconds of sim time: logged at the recorder's ``/clock`` they trailed the
odometry on playback by hundreds of metres. Per topic the log times never decrease (a stamp
older than the topic's previous log time is logged at that time), so a reader that orders by
log time keeps each topic's messages in the order they were published. With ``'wall'`` every
message is logged at its wall-clock receive time, as ``ros2 bag record`` does without
``--use-sim-time`` (a platoon's followers run behind the master's /clock, so neither /clock
nor their stamps are a time base common to all vessels; ship_mission.report maps wall log times
onto each vessel's own odometry). An unstamped topic and ``/clock`` are separate
subscriptions, so such a message can be logged a step early or late, and several steps late
when the recorder falls behind a loaded graph (seen: 42 steps at x20 real time on a busy
machine); ``ship_mission.bag`` times the unstamped ones by pairing them with odom by sequence, and by
log time only when the counts differ. The bag's ``custom_data`` records the choice under
``mission.time_source``.

``/tf``: each ``*/odom`` Odometry message is also written as a tf2_msgs/TFMessage on ``/tf``
(header.frame_id -> child_frame_id, i.e. map -> <ns>/base_link, with the odom's pose, stamp
and log time), so RViz and Foxglove 3D panels place the hulls from the bag alone. Nothing in
the graph publishes tf (the ROS wheels have no tf2_msgs); rosbags' typestore knows the type.

Compression (``compression``, ``--compression``): MCAP chunks compressed with zstd (default,
as rosbag2's MCAP writer does), lz4, or none. It is the storage's own chunk compression, so
metadata.yaml says ``compression_format: ''`` and ``compression_mode: ''``, as rosbag2 Jazzy
writes it for MCAP chunk compression (its file and message modes are something else).

Executor: rclpy's EventsExecutor (several times the callback rate of SingleThreadedExecutor;
doc/results/performance.md), driven by ``spin_once`` because its ``spin()`` in this Jazzy wheel
never fires timers and ignores SIGINT.

Lockstep acknowledgements (``acks``, ``--ack``): the recorder can take part in the lockstep
handshake, so that a lockstep graph never runs ahead of it far enough for a publisher's queue
to overwrite a message the recorder has not taken (keep-last 100 per stream topic, 10 for
``/clock``). Each ack group names a topic on which the recorder publishes std_msgs/UInt64 and
the topics it covers; the value is the number of complete steps recorded, the smallest message
count over the covered topics. A group's first message (0) goes out once every covered topic is
subscribed and matched to a publisher, so no step 0 is missed; vessel_node's
``lockstep_record_topic`` waits for it and then stays at most ``lockstep_record_window`` steps
ahead (QoS ``ship_sim.ros.qos.RECORD_ACK``, transient_local: a simulator that matches the
recorder late still gets the first one). In realtime nobody waits: losses are counted by
``ship_mission.bag.record_integrity``.

Stopping: SIGINT/SIGTERM (the launcher's ``ProcessGroup.stop``) end the spin and ``close()``
finalises the bag, so an interrupted run still leaves a complete bag. SIGKILL leaves an MCAP
without summary and without metadata.yaml; the recorder closes its chunk and flushes the file
every FLUSH_PERIOD_S, and writes its custom data to ``recording.yaml`` at the start, so
``ship_mission.bag_recovery`` (run by ``ship_mission.bag`` whenever such a bag is opened) gets back all
but the last second. A write error (disk full) ends the recording with one line and exit 1.

CLI (one process of the launcher)::

    python ros_ws/src/ship_mission/ship_mission/recorder.py OUT_BAG_DIR [--topics T ...] [--exclude REGEX]
        [--time-source sim|wall] [--depth N] [--discovery-period S] [--executor events|single]
        [--meta KEY=VALUE ...] [--ack ACK_TOPIC=TOPIC,TOPIC,... ...]
        [--compression none|lz4|zstd] [--no-tf]

prints ``recording <topic> [<type>]`` once per subscribed topic (a readiness signal) and, at
exit, one line ``recorded {json: topic -> count}``.
"""
import argparse
import importlib
import json
import os
import re
import struct
import sys
import threading
import time
from io import BytesIO
from pathlib import Path

import yaml
from rosbags.interfaces import (Nodetype, Qos, QosDurability, QosHistory, QosLiveliness,
                                QosReliability, QosTime)
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer
from rosbags.rosbag2 import storage_mcap
from rosbags.typesys import Stores, TypesysError, get_types_from_msg, get_typestore
from ship_sim.ros import odometry_cdr as cdr

CLOCK_TOPIC = '/clock'
DEFAULT_EXCLUDE = r'^/(rosout|parameter_events)$'
BAG_VERSION = 9  # rosbag2 metadata version written by Jazzy
ROS_DISTRO = 'jazzy'
RECORDING_FILE = 'recording.yaml'  # custom data, written at open (ship_mission.bag_recovery reads it)
FLUSH_PERIOD_S = 1.0               # a killed recorder loses at most about this much
COMPRESSIONS = ('none', 'lz4', 'zstd')   # MCAP chunk compression
DEFAULT_COMPRESSION = 'zstd'             # what rosbag2's MCAP writer does by default
ODOMETRY = 'nav_msgs/msg/Odometry'
HEADER = 'std_msgs/msg/Header'
TF_TOPIC = '/tf'
TF_TYPE = 'tf2_msgs/msg/TFMessage'
TF_DEPTH = 100   # tf2_ros TransformBroadcaster's QoS: reliable, volatile, keep-last 100


# -- the bag file (no rclpy) -------------------------------------------------------------------

def reliable_qos(depth=10, transient_local=False):
    """A rosbags Qos record: reliable, keep-last ``depth``, volatile or transient_local.

    Deadline, lifespan and lease are infinite, written the way rosbag2 writes them.
    """
    inf = QosTime(*divmod(2**63 - 1, 1_000_000_000))
    return Qos(QosHistory.KEEP_LAST, depth, QosReliability.RELIABLE,
               QosDurability.TRANSIENT_LOCAL if transient_local else QosDurability.VOLATILE,
               inf, inf, QosLiveliness.AUTOMATIC, inf, False)


def _load_msg_type(typestore, msgtype, prefixes=None):
    """Register ``pkg/msg/Name`` (and the types it uses) from .msg files under the ament prefixes."""
    prefixes = prefixes if prefixes is not None else os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep)
    pending = [msgtype]
    for _ in range(64):  # a message tree is never this deep; guards against a loop
        if not pending:
            return
        name = pending.pop()
        pkg, _, short = name.split('/')
        for prefix in filter(None, prefixes):
            path = Path(prefix) / 'share' / pkg / 'msg' / f'{short}.msg'
            if path.is_file():
                typestore.register(get_types_from_msg(path.read_text(), name))
                break
        else:
            raise TypesysError(f'no definition of {name} in the typestore nor under AMENT_PREFIX_PATH')
        try:
            typestore.generate_msgdef(msgtype, ros_version=2)
        except TypesysError as err:  # a field type is still missing: load it next
            missing = re.search(r"'([\w]+/msg/[\w]+)'", str(err))
            if not missing:
                raise
            pending.append(missing.group(1))


def message_definition(typestore, msgtype):
    """The ROS 2 message definition text of ``msgtype`` ('pkg/msg/Name') with its dependencies
    (the ``ros2msg`` schema of rosbag2's MCAP files and of the Foxglove WebSocket protocol),
    from the typestore, else from the .msg files under AMENT_PREFIX_PATH (registered there)."""
    try:
        return typestore.generate_msgdef(msgtype, ros_version=2)[0]
    except TypesysError:
        _load_msg_type(typestore, msgtype)
        return typestore.generate_msgdef(msgtype, ros_version=2)[0]


def header_stamp_at(typestore, msgtype):
    """Byte offset of the header stamp in a serialized ``msgtype``, or None (no header in front).

    A message whose first field is a std_msgs/Header has its stamp right after the 4-byte CDR
    encapsulation (offset 4); one whose first field is a sequence of such messages
    (visualization_msgs/MarkerArray, tf2_msgs/TFMessage) has its first element's stamp after
    the sequence length (offset 8; an empty sequence has none). Headers deeper in a message are
    not looked for: which of several would be "the" stamp is not defined.
    """
    def first_is_header(name):
        fields = typestore.fielddefs[name][1]
        return bool(fields) and fields[0][1] == (Nodetype.NAME, HEADER)
    try:
        if first_is_header(msgtype):
            return 4
        fields = typestore.fielddefs[msgtype][1]
        if fields and fields[0][1][0] == Nodetype.SEQUENCE:
            element = fields[0][1][1][0]
            if element[0] == Nodetype.NAME and first_is_header(element[1]):
                return 8
    except KeyError:   # a type the typestore does not have: treated as unstamped
        pass
    return None


def stamp_ns(data, at):
    """The header stamp (ns) at byte offset ``at`` (``header_stamp_at``) of serialized ``data``;
    None when there is none: no offset, too short, an empty sequence, a negative stamp. (Zero is
    a stamp: the sim time of step 0.)"""
    if at is None or len(data) < at + 8:
        return None
    endian = '<' if data[1] == 1 else '>'
    if at == 8 and struct.unpack_from(endian + 'I', data, 4)[0] == 0:
        return None
    sec, nsec = struct.unpack_from(endian + 'iI', data, at)
    ns = sec * 1_000_000_000 + nsec
    return ns if ns >= 0 else None


def odometry_to_tf(typestore, data):
    """Serialized nav_msgs/Odometry -> serialized tf2_msgs/TFMessage with one transform
    header.frame_id -> child_frame_id: the odom's stamp and pose."""
    if bytes(data[:2]) == cdr.XCDR1_LE:   # the layout of ship_sim.ros.odometry_cdr
        base = cdr.HEADER_BYTES
        sec, nsec, n_frame = struct.unpack_from('<iII', data, base)
        child = cdr.child_frame_at(n_frame)
        (n_child,) = struct.unpack_from('<I', data, base + child)
        x, y, z, qx, qy, qz, qw = struct.unpack_from('<7d', data, base + cdr.pose_at(child, n_child))
        at = base + cdr.FRAME_ID_AT + 4
        frame = bytes(data[at:at + n_frame - 1]).decode()
        child_frame = bytes(data[base + child + 4:base + child + 3 + n_child]).decode()
    else:
        m = typestore.deserialize_cdr(bytes(data), ODOMETRY)
        sec, nsec, frame, child_frame = (m.header.stamp.sec, m.header.stamp.nanosec,
                                         m.header.frame_id, m.child_frame_id)
        p, q = m.pose.pose.position, m.pose.pose.orientation
        x, y, z, qx, qy, qz, qw = p.x, p.y, p.z, q.x, q.y, q.z, q.w
    T = typestore.types
    transform = T['geometry_msgs/msg/TransformStamped'](
        header=T[HEADER](stamp=T['builtin_interfaces/msg/Time'](sec=sec, nanosec=nsec),
                         frame_id=frame),
        child_frame_id=child_frame,
        transform=T['geometry_msgs/msg/Transform'](
            translation=T['geometry_msgs/msg/Vector3'](x=x, y=y, z=z),
            rotation=T['geometry_msgs/msg/Quaternion'](x=qx, y=qy, z=qz, w=qw)))
    return bytes(typestore.serialize_cdr(T[TF_TYPE](transforms=[transform]), TF_TYPE))


class BagWriter:
    """A rosbag2 bag being written: topics, CDR messages with ns timestamps, counts.

    ``path`` must not exist yet (rosbags never overwrites). Use as a context manager or call
    ``close()``; both are idempotent and safe from a ``finally`` block. ``compression``: the
    MCAP chunks' (one of COMPRESSIONS); sqlite3 bags are stored uncompressed.
    """

    def __init__(self, path, storage='mcap', typestore=None, custom_data=None, side_file=True,
                 compression=DEFAULT_COMPRESSION):
        plugin = {'mcap': StoragePlugin.MCAP, 'sqlite3': StoragePlugin.SQLITE3}[storage]
        if compression not in COMPRESSIONS:
            raise ValueError(f'compression must be one of {", ".join(COMPRESSIONS)}, '
                             f'got {compression!r}')
        self.path = Path(path)
        self.typestore = typestore or get_typestore(Stores.ROS2_JAZZY)
        self._writer = Writer(self.path, version=BAG_VERSION, storage_plugin=plugin)
        self._mcap = plugin == StoragePlugin.MCAP
        self.compression = compression if self._mcap else 'none'
        if self.compression == 'zstd':   # rosbags' own chunk compression (it has zstd only)
            self._writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
        for key, value in (custom_data or {}).items():
            self._writer.set_custom_data(str(key), str(value))
        self._writer.open()
        if self._mcap:
            _as_rosbag2_mcap(self._writer.storage, self.compression)
        if side_file:  # metadata.yaml comes only at close: what ship_mission.bag_recovery needs before
            (self.path / RECORDING_FILE).write_text(yaml.safe_dump(
                {'custom_data': {str(k): str(v) for k, v in (custom_data or {}).items()},
                 'compression': self.compression}))
        self._connections = {}
        self._lock = threading.Lock()
        self.closed = False
        self.error = None  # the first OSError (disk full, file system gone): writing stops there

    def add_topic(self, topic, msgtype, offered_qos=(), rihs01=None):
        """Declare a topic (``msgtype`` like 'nav_msgs/msg/Odometry'); returns its connection.

        ``offered_qos``: rosbags Qos records of the publishers (what rosbag2 stores).
        ``rihs01``: the type hash the graph advertises; defaults to the typestore's.
        """
        if topic in self._connections:
            return self._connections[topic]
        msgdef = message_definition(self.typestore, msgtype)
        rihs01 = rihs01 or self.typestore.hash_rihs01(msgtype)
        with self._lock:
            conn = self._writer.add_connection(topic, msgtype, msgdef=msgdef, rihs01=rihs01,
                                               serialization_format='cdr',
                                               offered_qos_profiles=list(offered_qos))
            self._connections[topic] = conn
        return conn

    def write(self, conn, t_ns, data):
        """Append one serialized CDR message at log time ``t_ns`` (ns). Ignored after close."""
        with self._lock:
            if not self.closed and self.error is None:
                try:
                    self._writer.write(conn, t_ns, data)
                except OSError as err:
                    self.error = err

    def flush(self):
        """Put what is pending on disk (MCAP: close the open chunk), so that a recorder killed
        now loses nothing before it (ship_mission.bag_recovery reads the rest back)."""
        with self._lock:
            if self.closed or self.error is not None or not self._mcap:
                return
            storage = self._writer.storage
            try:
                if storage.chunk.msgs:
                    storage.close_chunk()
                storage.bio.flush()
            except OSError as err:
                self.error = err

    @property
    def topics(self):
        return list(self._connections)

    def counts(self):
        """{topic: number of messages written}."""
        with self._lock:
            return {t: self._writer.counts[c.id] for t, c in self._connections.items()}

    def close(self):
        """Write the MCAP summary and metadata.yaml. Safe to call more than once."""
        with self._lock:
            if self.closed:
                return
            self.closed = True
            try:
                self._writer.close()
                meta = self.path / 'metadata.yaml'
                meta.write_text(_jazzy_distro(meta.read_text()))
            except OSError as err:  # what was written before stays readable (ship_mission.bag_recovery)
                self.error = self.error or err

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


def _jazzy_distro(metadata_text):
    """rosbags writes ``ros_distro: rosbags``; a bag of this Jazzy graph says ``jazzy``, as rosbag2 does."""
    return metadata_text.replace('ros_distro: rosbags', f'ros_distro: {ROS_DISTRO}', 1)


def _as_rosbag2_mcap(storage, compression=DEFAULT_COMPRESSION):
    """Make rosbags' MCAP storage write what Jazzy's rosbag2 MCAP plugin writes: each channel's
    metadata holds ``topic_type_hash`` (RIHS01) beside ``offered_qos_profiles``, and the
    embedded copy of the bag's metadata names the distribution. (rosbags 0.11.9 writes only
    the QoS; readers of either key, rosbags included, skip keys they do not know.)

    Chunk compression: rosbags 0.11.9 compresses chunks with zstd only (chosen before
    ``open``); lz4 (the LZ4 frame format, as the MCAP specification says) is set here."""
    if compression == 'lz4':
        import lz4.frame
        storage.compression, storage.compressor = 'lz4', lz4.frame.compress
    def add_connection(connection, offered_qos_profiles):
        meta = BytesIO()
        for key, value in (('offered_qos_profiles', offered_qos_profiles),
                           ('topic_type_hash', connection.digest)):
            storage_mcap.write_string(meta, key)
            storage_mcap.write_string(meta, value)
        storage.channels.append(storage_mcap.Channel(
            connection.id, connection.msgtype, connection.topic,
            connection.ext.serialization_format, meta.getvalue()))
        storage.channel_stats[connection.id] = 0
        storage_mcap.write_channel(storage.chunk.bio, storage.channels[-1], storage.schemas)

    close = storage.close

    def close_with_distro(version, metadata):
        close(version, _jazzy_distro(metadata))

    storage.add_connection = add_connection
    storage.close = close_with_distro


# -- the node (rclpy) -----------------------------------------------------------------------------

def _rclpy_qos_to_rosbags(profile):
    """rclpy QoSProfile -> rosbags Qos (enums matched by name; durations as sec/nsec)."""
    def duration(d):
        sec, nsec = divmod(int(d.nanoseconds), 1_000_000_000)
        return QosTime(sec, nsec)

    def enum(cls, value):
        return cls[value.name] if value.name in cls.__members__ else cls.UNKNOWN

    return Qos(enum(QosHistory, profile.history), int(profile.depth),
               enum(QosReliability, profile.reliability), enum(QosDurability, profile.durability),
               duration(profile.deadline), duration(profile.lifespan),
               enum(QosLiveliness, profile.liveliness), duration(profile.liveliness_lease_duration),
               bool(profile.avoid_ros_namespace_conventions))


def message_class(msgtype):
    """'pkg/msg/Name' -> the rclpy message class (needed for type support, even for raw)."""
    pkg, sub, name = msgtype.split('/')
    return getattr(importlib.import_module(f'{pkg}.{sub}'), name)


def clock_ns(data):
    """Serialized rosgraph_msgs/Clock -> ns. CDR: 4-byte encapsulation, int32 sec, uint32 nanosec."""
    sec, nsec = struct.unpack_from('<iI' if data[1] == 1 else '>iI', data, 4)
    return sec * 1_000_000_000 + nsec


class Recorder:
    """An rclpy node that records topics into a ``BagWriter``.

    ``topics``: explicit absolute topic names, or None for every topic that is not hidden (a
    name token starting with '_', e.g. a component container's ``~/_load``) and does not match
    ``exclude`` (a regex). ``/clock`` is always recorded (sim-time stamps and replay need it).
    ``tf``: also write ``/tf`` from every ``*/odom`` (module docstring); ``compression``: the
    MCAP chunks' (COMPRESSIONS).
    The caller spins ``recorder.node`` (any executor) and calls ``close()`` at the end.
    """

    def __init__(self, bag_path, topics=None, exclude=DEFAULT_EXCLUDE, time_source='sim',
                 depth=1000, discovery_period_s=0.2, node_name='mission_recorder', on_subscribe=None,
                 context=None, custom_data=None, acks=None, tf=True,
                 compression=DEFAULT_COMPRESSION):
        import rclpy.node  # rclpy only for the node layer
        from rclpy.qos import QoSProfile
        from std_msgs.msg import UInt64

        from ship_sim.ros.qos import RECORD_ACK   # the simulators' side of the acks
        if time_source not in ('sim', 'wall'):
            raise ValueError(f"time_source must be 'sim' or 'wall', got {time_source!r}")
        if depth < 1:
            raise ValueError(f'depth must be >= 1, got {depth}')
        self._QoSProfile = QoSProfile
        self.wanted = None if topics is None else set(topics) | {CLOCK_TOPIC}
        self.exclude = re.compile(exclude) if exclude else None
        self.time_source = time_source
        self.depth = int(depth)
        self.on_subscribe = on_subscribe or (lambda topic, msgtype: None)
        # mission.lockstep: the record loses nothing in its middle (the simulators wait for the
        # acks), so the analysis may pair a record cut off at its end (ship_sim.pacing.paired_record)
        lockstep = {'mission.lockstep': 'true'} if acks else {}
        self.writer = BagWriter(bag_path, custom_data={**(custom_data or {}), **lockstep,
                                                       'mission.time_source': time_source},
                                compression=compression)
        self.tf = bool(tf)
        self.node = rclpy.node.Node(node_name, context=context)
        self._subs = {}
        self._sim_ns = 0
        # Lockstep acks: ack topic -> covered topics; per covered topic, the groups it counts in.
        self.acks = {a: list(ts) for a, ts in (acks or {}).items()}
        self._ack_msg = UInt64
        self._ack_pubs = {a: self.node.create_publisher(UInt64, a, RECORD_ACK) for a in self.acks}
        self._ack_sent = {a: None for a in self.acks}   # last value sent (None: not ready yet)
        self._seen = {}                                  # covered topic -> messages received
        self._groups_of = {}
        for a, ts in self.acks.items():
            for t in ts:
                self._groups_of.setdefault(t, []).append(a)
                self._seen[t] = 0
        if self.wanted is not None:
            self.wanted |= set(self._seen)
        self._discovery = self.node.create_timer(discovery_period_s, self.discover)
        self._flush = self.node.create_timer(FLUSH_PERIOD_S, self.writer.flush)
        self.discover()

    # topics
    def _wanted(self, topic):
        if topic in self._ack_pubs:
            return False  # our own acknowledgements
        if topic in self._seen:
            return True
        if self.wanted is not None:
            return topic in self.wanted
        if any(token.startswith('_') for token in topic.split('/')):
            return False  # hidden (a name token starts with '_'), as `ros2 bag record -a` skips
        return not (self.exclude and self.exclude.search(topic))

    def discover(self):
        """Subscribe to every wanted topic that has appeared (and has a publisher) since last time."""
        if self.writer.closed:
            return
        for topic, types in self.node.get_topic_names_and_types():
            if topic in self._subs or not self._wanted(topic):
                continue
            pubs = self.node.get_publishers_info_by_topic(topic)
            if not pubs:
                continue  # only subscribers so far: the publishers' QoS is not known yet
            msgtype = types[0]
            try:
                self._subscribe(topic, msgtype, pubs)
            except Exception as err:  # noqa: BLE001 (one bad topic must not stop the recording)
                self.node.get_logger().warning(f'not recording {topic} [{msgtype}]: {err}')
                self._subs[topic] = None
        for ack, topics in self.acks.items():
            if self._ack_sent[ack] is None and all(
                    self._subs.get(t) is not None and self._subs[t].get_publisher_count() > 0
                    for t in topics):
                self._send_ack(ack)

    def _send_ack(self, ack):
        value = min(self._seen[t] for t in self.acks[ack])
        self._ack_sent[ack] = value
        msg = self._ack_msg()
        msg.data = value
        self._ack_pubs[ack].publish(msg)

    def _counted(self, topic, write):
        """``write`` followed by the acknowledgement of every group ``topic`` counts in."""
        groups = self._groups_of.get(topic)
        if not groups:
            return write
        seen, sent, acks = self._seen, self._ack_sent, self.acks

        def callback(data):
            write(data)
            seen[topic] += 1
            for ack in groups:
                last = sent[ack]
                if last is not None and min(seen[t] for t in acks[ack]) > last:
                    self._send_ack(ack)
        return callback

    def _subscribe(self, topic, msgtype, pubs):
        from rclpy.qos import DurabilityPolicy, HistoryPolicy, ReliabilityPolicy
        profiles = [p.qos_profile for p in pubs]
        reliable = all(p.reliability == ReliabilityPolicy.RELIABLE for p in profiles)
        latched = all(p.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in profiles)
        qos = self._QoSProfile(
            history=HistoryPolicy.KEEP_LAST, depth=max([self.depth] + [p.depth for p in profiles]),
            reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
            durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)
        rihs01 = _type_hash_string(pubs[0])
        conn = self.writer.add_topic(topic, msgtype, [_rclpy_qos_to_rosbags(p) for p in profiles], rihs01)
        write = self.writer.write
        if self.tf and msgtype == ODOMETRY and topic.endswith('/odom'):
            tf_conn = self.writer.add_topic(TF_TOPIC, TF_TYPE, [reliable_qos(TF_DEPTH)])
            typestore = self.writer.typestore

            def write(conn, t_ns, data, tf_conn=tf_conn):
                self.writer.write(conn, t_ns, data)
                self.writer.write(tf_conn, t_ns, odometry_to_tf(typestore, data))
        if topic == CLOCK_TOPIC:
            def callback(data, conn=conn):
                self._sim_ns = clock_ns(data)
                write(conn, self._sim_ns if self.time_source == 'sim' else time.time_ns(), data)
        elif self.time_source == 'sim':
            # The message's own stamp where it has one, else the latest /clock; never before
            # the topic's previous log time (module docstring: Message time).
            at = header_stamp_at(self.writer.typestore, msgtype)
            last = [0]

            def callback(data, conn=conn):
                stamp = stamp_ns(data, at)
                last[0] = max(self._sim_ns if stamp is None else stamp, last[0])
                write(conn, last[0], data)
        else:
            def callback(data, conn=conn):
                write(conn, time.time_ns(), data)
        callback = self._counted(topic, callback)
        self._subs[topic] = self.node.create_subscription(message_class(msgtype), topic, callback, qos, raw=True)
        self.on_subscribe(topic, msgtype)

    @property
    def subscribed(self):
        """Topics being recorded."""
        return sorted(t for t, s in self._subs.items() if s is not None)

    def counts(self):
        return self.writer.counts()

    def close(self):
        """Stop discovery, finalise the bag; returns the counts. Idempotent."""
        first = not self.writer.closed
        self.writer.close()
        counts = self.writer.counts()
        if first and self.time_source == 'sim' and not counts.get(CLOCK_TOPIC):
            self.node.get_logger().warning('no /clock message was received: every log time is 0 '
                                           '(record with --time-source wall when nothing publishes /clock)')
        return counts

    def destroy(self):
        self.close()
        self.node.destroy_node()


def _type_hash_string(endpoint):
    """The RIHS01 string of a publisher's advertised type hash, or None to use the typestore's."""
    text = str(getattr(endpoint, 'topic_type_hash', ''))  # rclpy TypeHash prints 'RIHS01_<hex>'
    return text if re.fullmatch(r'RIHS01_[0-9a-f]{64}', text) else None


def _make_executor(kind):
    if kind == 'events':
        from rclpy.experimental import EventsExecutor
        return EventsExecutor()
    from rclpy.executors import SingleThreadedExecutor
    return SingleThreadedExecutor()


# -- CLI --------------------------------------------------------------------------------------------

def main(argv=None):
    parser = argparse.ArgumentParser(description='Record topics into a rosbag2 MCAP bag (sim time).')
    parser.add_argument('bag', help='bag directory to create (must not exist)')
    parser.add_argument('--topics', nargs='*', default=None, help='absolute topic names (default: all)')
    parser.add_argument('--exclude', default=DEFAULT_EXCLUDE, help='regex of topics not to record when discovering')
    parser.add_argument('--time-source', choices=('sim', 'wall'), default='sim')
    parser.add_argument('--depth', type=int, default=1000, help='subscription queue depth')
    parser.add_argument('--discovery-period', type=float, default=0.2, help='s between topic discoveries')
    parser.add_argument('--executor', choices=('events', 'single'), default='events',
                        help='rclpy EventsExecutor (faster per callback) or SingleThreadedExecutor')
    parser.add_argument('--meta', action='append', default=[], metavar='KEY=VALUE',
                        help="stored in the bag's custom_data (e.g. mission.rudder_limit_rad=0.6981)")
    parser.add_argument('--compression', choices=COMPRESSIONS, default=DEFAULT_COMPRESSION,
                        help='MCAP chunk compression (default: %(default)s, as rosbag2 writes)')
    parser.add_argument('--no-tf', action='store_true',
                        help='do not write /tf (map -> <ns>/base_link) from the */odom topics')
    parser.add_argument('--ack', action='append', default=[], metavar='ACK_TOPIC=TOPIC,...',
                        help='lockstep: publish on ACK_TOPIC (std_msgs/UInt64) the number of '
                             'complete steps recorded of the listed topics (vessel_node '
                             'lockstep_record_topic)')
    args, ros_argv = parser.parse_known_args(argv)
    bad = [m for m in args.meta + args.ack if '=' not in m]
    if bad:
        parser.error(f'--meta and --ack need KEY=VALUE, got {bad}')
    meta = dict(m.split('=', 1) for m in args.meta)
    acks = {a: [t for t in ts.split(',') if t] for a, ts in (m.split('=', 1) for m in args.ack)}

    import rclpy
    from rclpy.executors import ExternalShutdownException

    rclpy.init(args=[sys.argv[0], *ros_argv])
    recorder = None
    try:
        recorder = Recorder(args.bag, topics=args.topics, exclude=args.exclude, time_source=args.time_source,
                            depth=args.depth, discovery_period_s=args.discovery_period, custom_data=meta,
                            acks=acks, tf=not args.no_tf, compression=args.compression,
                            on_subscribe=lambda t, m: print(f'recording {t} [{m}]', flush=True))
        executor = _make_executor(args.executor)
        executor.add_node(recorder.node)
        while rclpy.ok() and recorder.writer.error is None:  # spin_once: Jazzy's EventsExecutor.spin()
            executor.spin_once(timeout_sec=0.1)                # never fires our discovery timer
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if recorder is not None:
            counts = recorder.close()
            print('recorded ' + json.dumps(counts, sort_keys=True), flush=True)
            recorder.node.destroy_node()
        rclpy.try_shutdown()
    err = recorder.writer.error if recorder is not None else None
    if err is not None:
        print(f'recorder: cannot write {err.filename or args.bag}: {err.strerror or err}',
              file=sys.stderr, flush=True)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
