"""nav_msgs/Path <-> ship_guidance.path.Route (the route contract between planner and guidance).

The Path is in ENU, frame 'map'. Each pose's orientation is the start tangent of the leg that
begins at that pose (the last pose: the end tangent of the last leg). A leg is a straight line
when the first pose's yaw points along the chord to the next pose, otherwise it is the circular
arc leaving the first pose tangent to its yaw and passing through the next pose. Straight legs
contribute only their end points; arcs are split into sub-arcs of at most ``max_arc_step``.
This carries lines and arcs exactly, and any consumer that treats the Path as a polyline still
sees a faithful sampling of it (e.g. RViz, Foxglove).
"""
import numpy as np
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Path

from ship_sim.frames import psi_to_yaw, yaw_to_psi
from ship_sim.ros.conversions import MAP_FRAME, quaternion_to_yaw, yaw_to_quaternion

from ..path import Route


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
    """Decode a nav_msgs/Path (ENU) into a Route (NED); ValueError if it is not a valid route."""
    if msg.header.frame_id and msg.header.frame_id != MAP_FRAME:
        raise ValueError(f"route frame_id is '{msg.header.frame_id}', expected '{MAP_FRAME}'")
    if len(msg.poses) < 2:
        raise ValueError(f'route has {len(msg.poses)} poses; at least 2 are needed')
    east = np.array([p.pose.position.x for p in msg.poses])
    north = np.array([p.pose.position.y for p in msg.poses])
    yaw = np.array([quaternion_to_yaw(p.pose.orientation) for p in msg.poses])
    return Route.from_poses(north, east, yaw_to_psi(yaw))


def accept_route(msg, logger):
    """The Route of a received Path, or None after logging why it was refused (the node keeps
    following its previous route)."""
    try:
        return path_msg_to_route(msg)
    except ValueError as exc:
        logger.error(f'route refused: {exc}; keeping the previous route')
        return None
