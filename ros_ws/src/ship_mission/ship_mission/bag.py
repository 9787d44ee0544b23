"""Read a mission bag (rosbag2, MCAP or sqlite3) back into numpy arrays, one set per vessel.

A vessel is a namespace with an ``odom`` topic of type nav_msgs/Odometry (``/vessel_0/odom`` ->
namespace ``/vessel_0``); its other topics are found by their relative names (``DEFAULT_TOPICS``,
overridable). Frames and units are those of the topics (doc/design.md): ENU position (m) and yaw
(rad, counter-clockwise from east), FLU body velocities (m/s, rad/s), rudder angles (rad,
positive turns to port), cross-track error (m, positive = vessel to starboard of the path).

Times (s): Odometry and Path use their header stamps (exact sim time). Unstamped topics
(std_msgs/Float64, the progress array) carry no time, so:

- with ``pair_by_sequence`` (default) a topic with exactly as many messages as the vessel's
  odom is paired with it message by message, as the graph itself pairs them (doc/design.md: in
  lockstep every producer publishes exactly one message per step; the simulator's ``rudder``
  goes out with each odom, the guidance answers each odom once, the autopilot each pair):
  the n-th message gets the n-th odom stamp, exactly (ship_sim.pacing.paired_record, the
  rule the nodes pair by);
- otherwise (a count differs: a recorder that started late, a lost message) the bag's log
  time: the latest ``/clock`` the recorder had seen (``mission.time_source: sim``), which can
  lag or lead by a few steps when the recorder falls behind the graph; for a wall-clock bag
  the log times are mapped to sim time through the recorded ``/clock`` messages.
  ``VesselData.timing`` says which, per topic.

Speed: the messages are read once with rosbags, then Float64 and Odometry are decoded straight
from their CDR bytes with vectorised numpy (no per-message deserialisation; the offsets of the
variable-length frame-id strings are computed for all messages at once). Path (only the latest
message) and the progress topic (any type) go through the rosbags typestore.
"""
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numpy as np
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore
from ship_sim.pacing import paired_record
from ship_sim.ros import odometry_cdr as cdr

from ship_mission import bag_recovery

NS_PER_S = 1e9

#: relative topic names of one vessel (see doc/design.md); 'progress' is the guidance's progress topic
DEFAULT_TOPICS = {
    'odom': 'odom',
    'rudder': 'rudder',
    'rudder_cmd': 'rudder_cmd',
    'heading_cmd': 'heading_cmd',
    'cross_track_error': 'cross_track_error',
    'route': 'route',
    'progress': 'progress',
}
FLOAT64 = 'std_msgs/msg/Float64'
ODOMETRY = 'nav_msgs/msg/Odometry'
PATH = 'nav_msgs/msg/Path'


class BagError(RuntimeError):
    """The path is not a readable bag, or it lacks what the analysis needs."""


class Series(NamedTuple):
    """Samples of one topic: ``t`` (s) and ``v`` (one row per message; 1-D for scalars).

    A tuple, so ``t, v = series`` works and the pure ``ship_mission.metrics`` takes it as is.
    """
    t: np.ndarray
    v: np.ndarray

    @classmethod
    def empty(cls):
        return cls(np.zeros(0), np.zeros(0))


@dataclass
class Route:
    """The latest nav_msgs/Path: waypoints in ENU (m) and the tangent yaw each pose carries."""
    t: float
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    frame_id: str = 'map'


@dataclass
class VesselData:
    """Everything recorded for one vessel namespace. Odometry arrays share the time ``t``."""
    namespace: str
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    u: np.ndarray
    v: np.ndarray
    r: np.ndarray
    rudder: Series
    rudder_cmd: Series
    heading_cmd: Series
    cross_track_error: Series
    progress: Series  # one row per message (Float64MultiArray data, or the numeric fields)
    route: Route | None
    missing: list = field(default_factory=list)  # relative topic names not found in the bag
    progress_labels: list = field(default_factory=list)  # column names, from the array's layout
    timing: dict = field(default_factory=dict)  # relative topic -> 'odom sequence' or 'log time'


@dataclass
class BagData:
    path: Path
    topics: dict  # topic -> (type, message count)
    time_source: str
    vessels: dict  # namespace -> VesselData
    custom_data: dict = field(default_factory=dict)  # metadata.yaml custom_data (str -> str)
    clock: np.ndarray | None = None  # the /clock values (sim s) in recording order, if recorded
    recovered: str | None = None     # the recovery's report when the recording was interrupted
    #                                  (custom_data mission.recovered of a recovered bag)


# -- vectorised CDR decoding -------------------------------------------------------------------

def _concat(datas):
    """Messages -> one uint8 buffer and the start offset of each message."""
    lengths = np.fromiter((len(d) for d in datas), dtype=np.int64, count=len(datas))
    starts = np.zeros(len(datas), dtype=np.int64)
    np.cumsum(lengths[:-1], out=starts[1:])
    return np.frombuffer(b''.join(datas), dtype=np.uint8), starts, lengths


def _gather(buf, offsets, nbytes, dtype):
    """Read ``nbytes`` at each of ``offsets`` and view them as little-endian ``dtype`` -> (N, k)."""
    idx = offsets[:, None] + np.arange(nbytes)
    return buf[idx].view(dtype)


def _little_endian(buf, starts):
    return bool(np.all(buf[starts + 1] == 1))  # CDR encapsulation byte 1: 1 = CDR_LE


def decode_float64(datas, typestore=None):
    """Serialized std_msgs/Float64 messages -> float64 array. CDR: 4-byte header, double at 4."""
    if not datas:
        return np.zeros(0)
    buf, starts, lengths = _concat(datas)
    if _little_endian(buf, starts) and np.all(lengths >= 12):
        return _gather(buf, starts + 4, 8, '<f8')[:, 0].copy()
    ts = typestore or get_typestore(Stores.ROS2_JAZZY)
    return np.array([ts.deserialize_cdr(d, FLOAT64).data for d in datas], dtype=float)


def decode_odometry(datas, typestore=None):
    """Serialized nav_msgs/Odometry -> dict of arrays: t (s), x, y, z, qx, qy, qz, qw, u, v, w, p, q, r.

    The byte layout (shared with the nodes' single-message reader) is ship_sim.ros.odometry_cdr.
    """
    if not datas:
        return {k: np.zeros(0) for k in ('t', 'x', 'y', 'z', 'qx', 'qy', 'qz', 'qw', 'u', 'v', 'w', 'p', 'q', 'r')}
    buf, starts, lengths = _concat(datas)
    if not _little_endian(buf, starts):
        return _decode_odometry_slow(datas, typestore)
    base = starts + cdr.HEADER_BYTES
    stamp = _gather(buf, base, 8, '<u4').astype(np.int64)
    sec = np.where(stamp[:, 0] >= 2**31, stamp[:, 0] - 2**32, stamp[:, 0])  # int32
    child = cdr.child_frame_at(_gather(buf, base + cdr.FRAME_ID_AT, 4, '<u4')[:, 0].astype(np.int64))
    pose = cdr.pose_at(child, _gather(buf, base + child, 4, '<u4')[:, 0].astype(np.int64))
    if np.any(base + pose + cdr.END_FROM_POSE > starts + lengths):
        raise BagError('malformed nav_msgs/Odometry message (shorter than its layout)')
    p7 = _gather(buf, base + pose, cdr.POSE_BYTES, '<f8')
    tw = _gather(buf, base + pose + cdr.TWIST_FROM_POSE, cdr.TWIST_BYTES, '<f8')
    out = {'t': (sec * 1_000_000_000 + stamp[:, 1]) / NS_PER_S}  # via integer ns, like log times
    for i, k in enumerate(('x', 'y', 'z', 'qx', 'qy', 'qz', 'qw')):
        out[k] = p7[:, i].copy()
    for i, k in enumerate(('u', 'v', 'w', 'p', 'q', 'r')):
        out[k] = tw[:, i].copy()
    return out


def _decode_odometry_slow(datas, typestore=None):
    ts = typestore or get_typestore(Stores.ROS2_JAZZY)
    rows = []
    for d in datas:
        m = ts.deserialize_cdr(d, ODOMETRY)
        pp, tt = m.pose.pose, m.twist.twist
        rows.append(((m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec) / NS_PER_S,
                     pp.position.x, pp.position.y,
                     pp.position.z, pp.orientation.x, pp.orientation.y, pp.orientation.z, pp.orientation.w,
                     tt.linear.x, tt.linear.y, tt.linear.z, tt.angular.x, tt.angular.y, tt.angular.z))
    cols = np.array(rows, dtype=float).T
    return dict(zip(('t', 'x', 'y', 'z', 'qx', 'qy', 'qz', 'qw', 'u', 'v', 'w', 'p', 'q', 'r'), cols))


def quaternion_yaw(qx, qy, qz, qw):
    """Yaw (rad, about z, ZYX convention) of quaternions; numpy arrays or floats."""
    return np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


def path_to_route(msg, t=None):
    """A deserialised nav_msgs/Path (rosbags or rclpy object) -> Route."""
    poses = msg.poses
    x = np.array([p.pose.position.x for p in poses], dtype=float)
    y = np.array([p.pose.position.y for p in poses], dtype=float)
    q = np.array([(p.pose.orientation.x, p.pose.orientation.y, p.pose.orientation.z, p.pose.orientation.w)
                  for p in poses], dtype=float).reshape(-1, 4)
    stamp = msg.header.stamp
    return Route(t=stamp.sec + stamp.nanosec / NS_PER_S if t is None else t, x=x, y=y,
                 yaw=quaternion_yaw(*q.T), frame_id=msg.header.frame_id)


def _numeric_row(msg):
    """Any message -> 1-D float array: its ``data`` array if it has one, else its numeric fields."""
    data = getattr(msg, 'data', None)
    if data is not None:
        return np.atleast_1d(np.asarray(data, dtype=float)).ravel()
    values = [getattr(msg, k) for k in getattr(msg, '__dataclass_fields__', {}) if not k.startswith('__')]
    return np.array([float(v) for v in values if isinstance(v, (int, float, bool, np.number))], dtype=float)


def _array_labels(msg):
    """Column names of a *MultiArray whose first dimension's label lists them comma-separated
    (ship_guidance's progress: 's_m,remaining_m,leg,finished,path_yaw_rad,curvature_1pm')."""
    dims = getattr(getattr(msg, 'layout', None), 'dim', None)
    if not dims:
        return []
    labels = [x.strip() for x in dims[0].label.split(',')]
    return labels if len(labels) > 1 else []


# -- reading -------------------------------------------------------------------------------------

def open_bag(path):
    """An open rosbags reader of the bag folder ``path``; BagError (one line) if it is not a
    readable rosbag2 bag."""
    path = Path(path)
    if not path.exists():
        raise BagError(f'{path}: no such file or directory')
    if not path.is_dir() or not (path / 'metadata.yaml').is_file():
        raise BagError(f'{path} is not a rosbag2 bag (a directory with metadata.yaml); '
                       'an interrupted recording may lack it')
    try:
        reader = AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY))
        reader.open()
    except Exception as err:  # rosbags raises AnyReaderError, ReaderError, ... : name the bag either way
        raise BagError(f'{path}: cannot open bag: {err}') from err
    return reader


def recover_if_needed(path):
    """Rebuild a bag whose recorder was killed (ship_mission.bag_recovery); its one-line report or None."""
    if not bag_recovery.needs_recovery(path):
        return None
    try:
        return bag_recovery.recover_bag(path)
    except (bag_recovery.RecoveryError, OSError) as err:
        raise BagError(f'{path}: interrupted recording, not recoverable: {err}') from err


def read_custom_data(path):
    """The ``custom_data`` of a bag's metadata.yaml ({} when absent)."""
    from ship_sim.safe_load import load_yaml_file
    meta = load_yaml_file(Path(path) / 'metadata.yaml') or {}
    return dict((meta.get('rosbag2_bagfile_information') or {}).get('custom_data') or {})


def read_bag(path, topics=None, namespaces=None, pair_by_sequence=True):
    """Read a mission bag -> BagData with one VesselData per namespace.

    ``topics``: relative names overriding ``DEFAULT_TOPICS`` entries (e.g. {'progress': 'guidance/progress'}).
    ``namespaces``: restrict to these (e.g. ['/vessel_0']); default: every namespace with an odom.
    ``pair_by_sequence``: time unstamped topics by the odom stamps when their counts match.
    Raises BagError when the path is not a bag or no vessel (Odometry topic) is in it.
    """
    names = {**DEFAULT_TOPICS, **(topics or {})}
    recovered = recover_if_needed(path)
    reader = open_bag(path)
    try:
        conns = {c.topic: c for c in reader.connections}
        info = {c.topic: (c.msgtype, c.msgcount) for c in reader.connections}
        suffix = '/' + names['odom']
        found = sorted(t[:-len(suffix)] for t, c in conns.items() if t.endswith(suffix) and c.msgtype == ODOMETRY)
        if namespaces is not None:
            wanted = {('/' + n.strip('/')) if n.strip('/') else '' for n in namespaces}
            found = [n for n in found if n in wanted]
        if not found:
            raise BagError(f'{path}: no nav_msgs/Odometry topic named */{names["odom"]} '
                           f'(topics: {", ".join(sorted(conns)) or "none"})')
        selected = {}  # topic -> (namespace, key)
        for ns in found:
            for key, rel in names.items():
                if f'{ns}/{rel}' in conns:
                    selected[f'{ns}/{rel}'] = (ns, key)
        if '/clock' in conns:
            selected['/clock'] = (None, 'clock')
        datas = {t: [] for t in selected}
        stamps = {t: [] for t in selected}
        by_id = {conns[t].id: t for t in selected}
        # one pass over the bag; the only per-message Python work is two appends
        for conn, t_ns, raw in reader.messages(connections=[conns[t] for t in selected]):
            topic = by_id[conn.id]
            datas[topic].append(raw)
            stamps[topic].append(t_ns)
        custom = read_custom_data(path)
        # a recovered bag says so every time it is read, not only when it is recovered
        recovered = custom.get(bag_recovery.RECOVERED, recovered)
        source = custom.get('mission.time_source', 'sim')
        lockstep = custom.get('mission.lockstep') == 'true'   # written by the recorder with acks
        to_sim = _wall_to_sim(datas.get('/clock'), stamps.get('/clock')) if source == 'wall' else None
        clock = _clock_values(datas['/clock']) if datas.get('/clock') else None
        vessels = {}
        for ns in found:
            vessels[ns or '/'] = _vessel(ns, names, conns, datas, stamps, reader, to_sim, pair_by_sequence,
                                         lockstep)
    finally:
        reader.close()
    return BagData(path=Path(path), topics=info, time_source=source, vessels=vessels, custom_data=custom,
                   clock=clock, recovered=recovered)


def _clock_values(clock_datas):
    """Serialized rosgraph_msgs/Clock messages -> sim time (s) of each."""
    buf, starts, _ = _concat(clock_datas)
    st = _gather(buf, starts + 4, 8, '<u4').astype(np.int64)
    return st[:, 0] + st[:, 1] / NS_PER_S


def _wall_to_sim(clock_datas, clock_stamps):
    """For a wall-clock bag: a function mapping log times (ns) to sim time (s) via /clock."""
    if not clock_datas:
        return None
    wall = np.asarray(clock_stamps, dtype=np.int64)
    sim = _clock_values(clock_datas)
    # relative to the first /clock in integer ns: epoch ns as float64 would lose ~256 ns
    return lambda t_ns: np.interp((np.asarray(t_ns, dtype=np.int64) - wall[0]).astype(float),
                                  (wall - wall[0]).astype(float), sim)


def _log_times(stamps, to_sim):
    ns = np.asarray(stamps, dtype=np.int64)
    return to_sim(ns) if to_sim is not None else ns / NS_PER_S


def _vessel(ns, names, conns, datas, stamps, reader, to_sim, pair_by_sequence, lockstep=False):
    topic = {key: f'{ns}/{rel}' for key, rel in names.items()}
    missing = [names[k] for k, t in topic.items() if t not in datas or not datas[t]]
    odom = decode_odometry(datas[topic['odom']])
    order = np.argsort(odom['t'], kind='stable')  # stamps are monotonic unless a publisher raced
    odom = {k: v[order] for k, v in odom.items()}

    timing = {}

    def times(key):
        t = topic[key]
        paired = (paired_record(odom['t'], len(datas[t]), cut_at_end=lockstep)
                  if pair_by_sequence else None)
        if paired is not None:
            timing[names[key]] = 'odom sequence'
            return paired
        timing[names[key]] = 'log time'
        return _log_times(stamps[t], to_sim)

    def scalar(key):
        t = topic[key]
        if t not in datas or not datas[t]:
            return Series.empty()
        if conns[t].msgtype == FLOAT64:
            return Series(times(key), decode_float64(datas[t]))
        rows = [_numeric_row(reader.deserialize(d, conns[t].msgtype)) for d in datas[t]]
        return Series(times(key), np.array([r[0] if len(r) else np.nan for r in rows]))

    progress, labels = Series.empty(), []
    t = topic['progress']
    if t in datas and datas[t]:
        msgs = [reader.deserialize(d, conns[t].msgtype) for d in datas[t]]
        labels = _array_labels(msgs[-1])
        rows = [_numeric_row(m) for m in msgs]
        width = max(len(r) for r in rows)
        arr = np.full((len(rows), width), np.nan)
        for i, r in enumerate(rows):
            arr[i, :len(r)] = r
        progress = Series(times('progress'), arr)

    route = None
    t = topic['route']
    if t in datas and datas[t] and conns[t].msgtype == PATH:
        route = path_to_route(reader.deserialize(datas[t][-1], PATH))

    return VesselData(
        namespace=ns or '/', t=odom['t'], x=odom['x'], y=odom['y'],
        yaw=quaternion_yaw(odom['qx'], odom['qy'], odom['qz'], odom['qw']),
        u=odom['u'], v=odom['v'], r=odom['r'],
        rudder=scalar('rudder'), rudder_cmd=scalar('rudder_cmd'), heading_cmd=scalar('heading_cmd'),
        cross_track_error=scalar('cross_track_error'), progress=progress, route=route, missing=missing,
        progress_labels=labels, timing=timing)
