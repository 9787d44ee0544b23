"""nav_msgs/Path <-> ship_guidance.path.Route (the route contract between planner and guidance).

The Path is in ENU, frame 'map'. Each pose's orientation is the start tangent of the leg that
begins at that pose (the last pose: the end tangent of the last leg). A leg is a straight line
when the first pose's yaw points along the chord to the next pose, otherwise it is the circular
arc leaving the first pose tangent to its yaw and passing through the next pose. Straight legs
contribute only their end points; arcs are split into sub-arcs of at most ``max_arc_step``.
This carries lines and arcs exactly, and any consumer that treats the Path as a polyline still
sees a faithful sampling of it (e.g. RViz, Foxglove).

What a receiver accepts (``path_msg_to_route``; anything else is refused with the reason and
the node keeps its previous route): frame 'map' (or empty), 2 to MAX_ROUTE_POSES poses, finite
coordinates within ship_guidance.path.MAX_COORDINATE_M of the origin. The nodes subscribe the
route raw: the pose count is read from the serialized bytes before anything else, so an
oversized Path costs microseconds, and the poses of an accepted one are read with numpy
straight from the bytes (rclpy's conversion builds one Python object per pose, far slower;
doc/results/performance.md).
"""
import struct

import numpy as np
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Path

from ship_sim.frames import psi_to_yaw, yaw_to_psi
from ship_sim.ros import odometry_cdr as cdr
from ship_sim.ros.conversions import MAP_FRAME, quaternion_to_yaw, yaw_to_quaternion

from ..path import MAX_COORDINATE_M, Route

#: Most poses a route Path may have. 20,000 poses are 500 km of arcs at the 25 m sampling, far
#: more than any route; decoding that many takes well under a second, while 200,000 held a
#: guidance node for 6.7 s, longer than the 5 s lockstep timeout.
MAX_ROUTE_POSES = 20_000

_U32 = struct.Struct('<I')


def route_to_path_msg(route, stamp, max_arc_step=25.0, frame_id=MAP_FRAME):
    """Encode a Route (NED) as a nav_msgs/Path (ENU) stamped with ``stamp`` (builtin Time)."""
    north, east, psi = route.to_poses(max_arc_step)
    yaw = psi_to_yaw(np.asarray(psi))
    msg = Path()
    msg.header.frame_id = frame_id
    msg.header.stamp = stamp
    for n, e, y in zip(north.tolist(), east.tolist(), yaw.tolist()):
        pose = PoseStamped()
        pose.header = msg.header
        pose.pose.position.x = e
        pose.pose.position.y = n
        q = pose.pose.orientation
        q.x, q.y, q.z, q.w = yaw_to_quaternion(y)
        msg.poses.append(pose)
    return msg


def path_msg_to_route(msg):
    """Decode a nav_msgs/Path (ENU; a message or its serialized bytes) into a Route (NED);
    ValueError if it is not a valid route (see the module docstring)."""
    if isinstance(msg, bytes):
        sizes = _path_sizes(msg)
        if sizes is not None:   # frame and count first: an oversized Path costs nothing
            _check_frame(sizes[0])
            _check_count(_U32.unpack_from(msg, cdr.HEADER_BYTES + sizes[1])[0])
        fields = _cdr_path_fields(msg)
        if fields is None:
            from rclpy.serialization import deserialize_message
            return path_msg_to_route(deserialize_message(msg, Path))
        _, east, north, q = fields
    else:
        _check_frame(msg.header.frame_id)
        _check_count(len(msg.poses))
        east = np.array([p.pose.position.x for p in msg.poses])
        north = np.array([p.pose.position.y for p in msg.poses])
        q = tuple(np.array([getattr(p.pose.orientation, c) for p in msg.poses])
                  for c in 'xyzw')
    yaw = quaternion_to_yaw(q)
    if not (np.all(np.isfinite(east)) and np.all(np.isfinite(north))
            and np.all(np.isfinite(yaw))):
        raise ValueError('route has non-finite poses')
    far = max(float(np.max(np.abs(east))), float(np.max(np.abs(north))))
    if far > MAX_COORDINATE_M:
        raise ValueError(f'route has a pose {far:.3g} m from the origin; at most '
                         f'{MAX_COORDINATE_M:.0e} m is physical')
    return Route.from_poses(north, east, yaw_to_psi(yaw))


def _check_frame(frame_id):
    if frame_id and frame_id != MAP_FRAME:
        raise ValueError(f"route frame_id is '{frame_id}', expected '{MAP_FRAME}'")


def _check_count(n):
    if n < 2:
        raise ValueError(f'route has {n} poses; at least 2 are needed')
    if n > MAX_ROUTE_POSES:
        raise ValueError(f'route has {n} poses; at most {MAX_ROUTE_POSES} are accepted')


def _path_sizes(data):
    """(frame_id, offset of the pose count word) of a serialized Path, offsets from the end of
    the encapsulation header; None if not XCDR1 little endian or too short."""
    if data[:2] != cdr.XCDR1_LE:
        return None
    h = cdr.HEADER_BYTES
    try:
        n = _U32.unpack_from(data, h + cdr.FRAME_ID_AT)[0]
        start = h + cdr.FRAME_ID_AT + 4
        if start + n > len(data) or n == 0:
            return None
        frame_id = data[start:start + n - 1].decode('utf-8', 'replace')
        at = cdr.align(cdr.FRAME_ID_AT + 4 + n, 4)
        _U32.unpack_from(data, h + at)
    except struct.error:
        return None
    return frame_id, at


def _cdr_path_fields(data):
    """(frame_id, east, north, (qx, qy, qz, qw)) of a serialized Path, read with numpy when
    every pose header has the same frame_id length (the poses then lie at a fixed stride);
    None otherwise (the caller lets rclpy deserialise). Each pose: stamp (8 bytes), frame_id
    (uint32 length + chars), aligned to 8: position x y z, orientation x y z w (float64)."""
    sizes = _path_sizes(data)
    if sizes is None:
        return None
    frame_id, at = sizes
    h = cdr.HEADER_BYTES
    count = _U32.unpack_from(data, h + at)[0]
    first = at + 4                       # first PoseStamped
    try:
        length = _U32.unpack_from(data, h + first + 8)[0]
    except struct.error:
        return None
    pose0 = cdr.align(first + 12 + length, 8)
    stride = cdr.align(12 + length, 8) + cdr.POSE_BYTES   # from pose 1 on, 8-aligned starts
    if count == 0 or h + pose0 + (count - 1) * stride + cdr.POSE_BYTES > len(data):
        return None
    if count > 1:
        lengths = np.ndarray((count - 1,), dtype='<u4', buffer=data,
                             offset=h + pose0 + cdr.POSE_BYTES + 8, strides=(stride,))
        if np.any(lengths != length):
            return None
    poses = np.ndarray((count, 7), dtype='<f8', buffer=data, offset=h + pose0,
                       strides=(stride, 8)).copy()
    return frame_id, poses[:, 0], poses[:, 1], (poses[:, 3], poses[:, 4], poses[:, 5],
                                                poses[:, 6])


def accept_route(msg, logger):
    """The Route of a received Path (a message or its serialized bytes), or None after logging
    one line why it was refused (the node keeps following its previous route)."""
    try:
        return path_msg_to_route(msg)
    except ValueError as exc:
        logger.error(f'route refused: {exc}; keeping the previous route')
        return None
