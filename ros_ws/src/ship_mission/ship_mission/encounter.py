"""Two-ship encounter figures from a run's bag: closest approach, the side it was passed on and
the own ship's alteration (what the collision-avoidance test and doc/results/encounters.md report).

- ``min_distance``: the smallest range between the two odometry tracks, at the own stamps (in
  lockstep both step on the same stamps; otherwise the target is interpolated), its time, and
  the relative bearing of the target
  from the own bow there (clockwise, deg): 180..360 means the target was on the own port side.
- ``alteration``: from the own vessel's ``colav_decision`` rows (ship_guidance.colav_io
  DECISION_COLUMNS): the first time the mode left 'nominal' and the largest course offset.
- ``colav_messages``: the raw CDR bytes of the colav topics, to compare runs bit for bit.
- ``target_tracks``: the tracks of a many-target topic (ais_node's ``/targets``), one per
  child_frame_id, in the shape ``min_distance`` takes.
"""
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np

COLAV_TOPICS = ('heading_cmd', 'heading_ref', 'colav_targets', 'colav_decision', 'speed_factor_cmd')


def min_distance(own, target):
    """dict: min_distance_m, t_min_s, bearing_at_min_deg (target from own bow, clockwise), side;
    None when the tracks share no time. At the own stamps within the target's time span, the
    target's position interpolated linearly (exactly its samples where the stamps are shared, as
    in lockstep)."""
    sel, dx, dy = relative_positions(own, target)
    if not sel.size:
        return None
    t = np.asarray(own.t)[sel]
    d = np.hypot(dx, dy)
    k = int(np.argmin(d))
    # ENU: bearing of the target (anticlockwise from east) minus the own yaw, turned clockwise.
    rel = math.degrees(np.asarray(own.yaw)[sel][k] - math.atan2(dy[k], dx[k])) % 360.0
    return {'min_distance_m': float(d[k]), 't_min_s': float(t[k]),
            'bearing_at_min_deg': rel, 'side': 'port' if rel > 180.0 else 'starboard'}


def relative_positions(own, target):
    """(indices of the own stamps within the target's time span, dx, dy): the target's ENU
    position relative to the own ship there, the target interpolated linearly (exactly its
    samples where the stamps are shared)."""
    t_own = np.asarray(own.t)
    if not len(target.t):
        return np.zeros(0, dtype=int), np.zeros(0), np.zeros(0)
    sel = np.flatnonzero((t_own >= target.t[0]) & (t_own <= target.t[-1]))
    t = t_own[sel]
    return (sel, np.interp(t, target.t, target.x) - np.asarray(own.x)[sel],
            np.interp(t, target.t, target.y) - np.asarray(own.y)[sel])


def alteration(decisions):
    """dict from colav_decision rows [t, mode, offset, multiplier, threat, n]: first_avoid_s
    (None if never), max_offset_deg (+ starboard), first_offset_deg."""
    rows = np.asarray(decisions, dtype=float).reshape(-1, 6)
    acting = rows[rows[:, 1] >= 2]     # avoid or last resort
    if not len(acting):
        return {'first_avoid_s': None, 'first_offset_deg': 0.0, 'max_offset_deg': 0.0,
                'last_resort': False}
    off = np.degrees(acting[:, 2])
    return {'first_avoid_s': float(acting[0, 0]), 'first_offset_deg': float(off[0]),
            'max_offset_deg': float(off[np.argmax(np.abs(off))]),
            'last_resort': bool((rows[:, 1] == 3).any())}


def colav_messages(bag_dir, namespace):
    """{relative topic: [raw CDR bytes, ...]} of COLAV_TOPICS in ``namespace``."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
    topics = {f'/{namespace}/{t}': t for t in COLAV_TOPICS}
    out = {t: [] for t in COLAV_TOPICS}
    with AnyReader([Path(bag_dir)], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        conns = [c for c in reader.connections if c.topic in topics]
        for conn, _t, raw in reader.messages(connections=conns):
            out[topics[conn.topic]].append(bytes(raw))
    return out


def decision_rows(bag_dir, namespace):
    """The colav_decision rows of ``namespace`` (N x 6)."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
    rows = []
    with AnyReader([Path(bag_dir)], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        conns = [c for c in reader.connections if c.topic == f'/{namespace}/colav_decision']
        for conn, _t, raw in reader.messages(connections=conns):
            rows.append(list(reader.deserialize(raw, conn.msgtype).data))
    return np.array(rows).reshape(-1, 6)


def encounter_report(bag_dir, own_ns, target_ns):
    """min_distance and alteration of one run, as one dict."""
    from ship_mission.bag import read_bag
    data = read_bag(bag_dir, namespaces=[f'/{own_ns}', f'/{target_ns}'])
    out = min_distance(data.vessels[f'/{own_ns}'], data.vessels[f'/{target_ns}'])
    out.update(alteration(decision_rows(bag_dir, own_ns)))
    return out


def target_tracks(bag_dir, topic='/targets'):
    """{child_frame_id: track (t, x, y, yaw, u arrays, stamp order)} of the nav_msgs/Odometry
    messages on ``topic`` ({} when the bag has none)."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
    from ship_mission.bag import decode_odometry, quaternion_yaw
    raws = {}
    with AnyReader([Path(bag_dir)], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        for conn, _t, raw in reader.messages(connections=conns):
            name = reader.deserialize(raw, conn.msgtype).child_frame_id
            raws.setdefault(name, []).append(bytes(raw))
    out = {}
    for name in sorted(raws):
        o = decode_odometry(raws[name])
        k = np.argsort(o['t'], kind='stable')
        out[name] = SimpleNamespace(t=o['t'][k], x=o['x'][k], y=o['y'][k], u=o['u'][k],
                                    yaw=quaternion_yaw(o['qx'], o['qy'], o['qz'], o['qw'])[k])
    return out
