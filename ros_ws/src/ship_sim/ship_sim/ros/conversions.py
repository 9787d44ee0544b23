"""Message conversion, the one place where simulator numbers become ROS messages and back.

Frames (doc/design.md, REP-103/105; the arithmetic lives in ship_sim.frames):
- ``nav_msgs/Odometry``: pose in ENU, ``header.frame_id = 'map'``,
  ``child_frame_id = '<ns>/base_link'``; the twist is in the body frame FLU (REP-105: the twist
  of an Odometry is expressed in the child frame), velocities over ground.
- Inside our pure modules: NED pose (north, east, psi clockwise from north) and FRD body
  velocities (u surge, v sway to starboard, r yaw rate clockwise).

Units: m, m/s, rad, rad/s; time in seconds (float) <-> builtin_interfaces/Time (sec, nanosec).

The fill_* functions write into an existing message, so a node publishing every step can reuse
one message object instead of building a new tree of Python objects each time.

``odometry_to_ned`` also reads a serialized Odometry (``bytes``, what a subscription created
with ``raw=True`` hands over) straight from its CDR bytes: the nodes that follow odom every
step skip rclpy's conversion into nested Python message objects, the largest per-step cost
of the guidance and autopilot nodes otherwise (doc/results/performance.md).
The byte layout is in ``odometry_cdr`` (shared with the bag reader); any encoding other than
XCDR1 little endian is deserialised by rclpy.
"""
import math
import struct
from collections import namedtuple

import numpy as np
from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry

from ship_sim.frames import (enu_to_ned_xy, flu_to_frd_twist, frd_to_flu_twist, ned_to_enu_xy, psi_to_yaw,
                             yaw_to_psi)
from ship_sim.ros import odometry_cdr as cdr

#: A vessel's state read from (or written to) Odometry, in our science frames (NED / FRD).
NedOdometry = namedtuple('NedOdometry', 't north east psi u v r')

MAP_FRAME = 'map'
_NS_PER_S = 1_000_000_000


# -- yaw <-> quaternion (rotation about z only) -----------------------------------------------

def yaw_to_quaternion(yaw):
    """ENU yaw (rad) -> quaternion (x, y, z, w) of a pure rotation about z."""
    half = 0.5 * yaw
    return 0.0, 0.0, math.sin(half), math.cos(half)


def quaternion_to_yaw(q):
    """Quaternion (a geometry_msgs/Quaternion or an (x, y, z, w) tuple) -> yaw (rad), [-pi, pi].

    The general ZYX formula, so a quaternion with some roll/pitch still gives its heading.
    An (x, y, z, w) tuple of numpy arrays gives an array of yaws.
    """
    if hasattr(q, 'w'):
        x, y, z, w = q.x, q.y, q.z, q.w
    else:
        x, y, z, w = q
    if isinstance(x, np.ndarray):   # components as arrays: one yaw per quaternion
        return np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


# -- time ---------------------------------------------------------------------------------------

def time_to_msg(t, msg=None):
    """Seconds (float, >= 0) -> builtin_interfaces/Time, rounded to the nanosecond.

    Rounds the total in integer nanoseconds first so that e.g. 0.3 s gives (0, 300000000) and
    never (0, 299999999) or nanosec = 10**9.
    """
    ns = int(round(t * _NS_PER_S))
    if msg is None:
        msg = Time()
    msg.sec, msg.nanosec = divmod(ns, _NS_PER_S)
    return msg


def msg_to_time(msg):
    """builtin_interfaces/Time -> seconds (float)."""
    return msg.sec + msg.nanosec * 1e-9


def msg_to_nanoseconds(msg):
    """builtin_interfaces/Time -> integer nanoseconds (exact, for comparing stamps)."""
    return msg.sec * _NS_PER_S + msg.nanosec


# -- odometry -------------------------------------------------------------------------------------

def base_link_frame(namespace):
    """The body frame of the vessel in ``namespace``: '/vessel_0' -> 'vessel_0/base_link'.

    tf2 frame ids carry no leading slash; the root namespace gives plain 'base_link'.
    """
    ns = namespace.strip('/')
    return f'{ns}/base_link' if ns else 'base_link'


def fill_odometry(msg, t, north, east, psi, u, v, r):
    """Write a NED pose and FRD body velocities over ground into an existing Odometry (ENU/FLU).

    Leaves frame ids and covariances untouched (set them once when the message is made).
    """
    time_to_msg(t, msg.header.stamp)
    p = msg.pose.pose.position
    p.x, p.y = ned_to_enu_xy(float(north), float(east))
    p.z = 0.0
    o = msg.pose.pose.orientation
    o.x, o.y, o.z, o.w = yaw_to_quaternion(float(psi_to_yaw(psi)))
    u_flu, v_flu, r_flu = frd_to_flu_twist(float(u), float(v), float(r))
    tw = msg.twist.twist
    tw.linear.x, tw.linear.y, tw.linear.z = u_flu, v_flu, 0.0
    tw.angular.x, tw.angular.y, tw.angular.z = 0.0, 0.0, r_flu
    return msg


def make_odometry(t, north, east, psi, u, v, r, child_frame_id, frame_id=MAP_FRAME):
    """A new Odometry (ENU, FLU twist) from a NED pose and FRD body velocities over ground."""
    msg = Odometry()
    msg.header.frame_id = frame_id
    msg.child_frame_id = child_frame_id
    return fill_odometry(msg, t, north, east, psi, u, v, r)


def odometry_to_ned(msg):
    """Odometry (ENU pose, FLU twist) -> NedOdometry(t, north, east, psi, u, v, r) (NED/FRD).

    ``msg``: a nav_msgs/Odometry or its serialized bytes (a ``raw=True`` subscription).
    psi is wrapped to [-pi, pi); u, v, r are the body velocities the message carries (over
    ground when it comes from our simulator).
    """
    if isinstance(msg, bytes):
        fields = _odometry_cdr_fields(msg)
        if fields is None:
            from rclpy.serialization import deserialize_message
            return odometry_to_ned(deserialize_message(msg, Odometry))
        sec, nanosec, x, y, qx, qy, qz, qw, vx, vy, wz = fields
        return NedOdometry(sec + nanosec * 1e-9, *enu_to_ned_xy(x, y),
                           float(yaw_to_psi(quaternion_to_yaw((qx, qy, qz, qw)))),
                           *flu_to_frd_twist(vx, vy, wz))
    p = msg.pose.pose.position
    tw = msg.twist.twist
    yaw = quaternion_to_yaw(msg.pose.pose.orientation)
    return NedOdometry(msg_to_time(msg.header.stamp), *enu_to_ned_xy(p.x, p.y), float(yaw_to_psi(yaw)),
                       *flu_to_frd_twist(tw.linear.x, tw.linear.y, tw.angular.z))


_STAMP = struct.Struct('<iI')            # builtin_interfaces/Time: int32 sec, uint32 nanosec
_LENGTH = struct.Struct('<I')            # string length, NUL included
_POSE = struct.Struct('<7d')             # position x y z, orientation x y z w
_TWIST = struct.Struct('<6d')            # linear x y z, angular x y z


def _odometry_cdr_fields(data):
    """(sec, nanosec, x, y, qx, qy, qz, qw, vx, vy, wz) of a serialized Odometry, or None if
    it is not XCDR1 little endian or too short (layout: ``odometry_cdr``)."""
    if data[:2] != cdr.XCDR1_LE:
        return None
    h = cdr.HEADER_BYTES
    try:
        sec, nanosec = _STAMP.unpack_from(data, h)
        child = cdr.child_frame_at(_LENGTH.unpack_from(data, h + cdr.FRAME_ID_AT)[0])
        pose = cdr.pose_at(child, _LENGTH.unpack_from(data, h + child)[0])
        if len(data) < h + pose + cdr.END_FROM_POSE:
            return None
        x, y, _, qx, qy, qz, qw = _POSE.unpack_from(data, h + pose)
        vx, vy, _, _, _, wz = _TWIST.unpack_from(data, h + pose + cdr.TWIST_FROM_POSE)
    except struct.error:
        return None
    return sec, nanosec, x, y, qx, qy, qz, qw, vx, vy, wz
