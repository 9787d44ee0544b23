"""sensor_msgs/NavSatFix and the visualization_msgs/MarkerArray of one vessel (nav_display_node).

Marker namespaces (frame ``map``, ENU, one marker each, fixed ids so each update replaces the
last): ``hull`` (closed LINE_STRIP outline at the true length and heading), ``hull_fill`` (the
same outline filled, a TRIANGLE_LIST fan: at chart scale a ship is a few pixels long, and only a
filled shape still reads as one), ``label`` (the vessel's name above the hull), ``route``
(LINE_STRIP through the route Path's poses, which sample arcs every 25 m), ``trail``
(LINE_STRIP of the past positions). Targets and CPA points are colav_node's ``colav_markers``,
not repeated here.
"""
from geometry_msgs.msg import Point
from sensor_msgs.msg import NavSatFix, NavSatStatus
from visualization_msgs.msg import Marker, MarkerArray

from ship_guidance.nav_display import enu_to_geodetic, hull_outline
from ship_sim.ros.conversions import MAP_FRAME

# Colours that read on a viewer's light and dark themes alike (Foxglove follows the system's).
HULL_RGBA = (0.85, 0.1, 0.75, 1.0)
ROUTE_RGBA = (0.2, 0.55, 1.0, 0.9)
TRAIL_RGBA = (1.0, 0.5, 0.1, 0.9)


def navsat_fix(stamp, frame_id, x, y, lat0_deg, lon0_deg):
    """NavSatFix of ENU point (x, y) (altitude 0, covariance unknown), a simulated GNSS fix."""
    msg = NavSatFix()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.status.status = NavSatStatus.STATUS_FIX
    msg.status.service = NavSatStatus.SERVICE_GPS
    msg.latitude, msg.longitude = enu_to_geodetic(x, y, lat0_deg, lon0_deg)
    msg.altitude = 0.0
    msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_UNKNOWN
    return msg


def _strip(ns, stamp, rgba, width, points):
    m = Marker(ns=ns, id=0, type=Marker.LINE_STRIP, action=Marker.ADD)
    m.header.frame_id = MAP_FRAME
    m.header.stamp = stamp
    m.pose.orientation.w = 1.0
    m.scale.x = width
    m.color.r, m.color.g, m.color.b, m.color.a = rgba
    m.points = [Point(x=float(px), y=float(py), z=0.0) for px, py in points]
    return m


def line_width(length):
    """Line width (m) of a vessel's route and trail: viewers draw marker lines in metres, so a
    line must be some 10 m wide to cover a pixel at the scale of a few kilometres across a
    panel; a fifteenth of the length is about half the beam."""
    return max(1.0, length / 15.0)


def outline_width(length):
    """Line width (m) of the hull outline: thin beside the hull, which the fill shows."""
    return max(0.5, length / 60.0)


def _hull_fill(stamp, outline):
    """TRIANGLE_LIST fan of the closed convex ``outline`` from its centroid."""
    m = Marker(ns='hull_fill', id=0, type=Marker.TRIANGLE_LIST, action=Marker.ADD)
    m.header.frame_id = MAP_FRAME
    m.header.stamp = stamp
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = 1.0
    m.color.r, m.color.g, m.color.b, m.color.a = HULL_RGBA
    corners = outline[:-1]
    cx, cy = (float(v) for v in corners.mean(axis=0))
    for (ax, ay), (bx, by) in zip(corners, [*corners[1:], corners[0]]):
        m.points += [Point(x=cx, y=cy, z=0.0), Point(x=float(ax), y=float(ay), z=0.0),
                     Point(x=float(bx), y=float(by), z=0.0)]
    return m


def route_marker(stamp, route_xy, length):
    """The ``route`` LINE_STRIP (built once per route: a route has hundreds of poses)."""
    return _strip('route', stamp, ROUTE_RGBA, line_width(length), route_xy)


def display_markers(stamp, name, x, y, yaw, length, route, trail_xy):
    """MarkerArray: hull at (x, y, yaw) of ``length`` m (outline and fill), its label, the
    ``route`` marker (route_marker; None: not in this frame) and the trail through ``trail_xy``
    (ENU; fewer than 2 points: not in this frame)."""
    width = line_width(length)
    outline = hull_outline(x, y, yaw, length)
    out = [_strip('hull', stamp, HULL_RGBA, outline_width(length), outline),
           _hull_fill(stamp, outline)]
    label = Marker(ns='label', id=0, type=Marker.TEXT_VIEW_FACING, action=Marker.ADD, text=name)
    label.header.frame_id = MAP_FRAME
    label.header.stamp = stamp
    label.pose.position.x, label.pose.position.y = float(x), float(y)
    label.pose.position.z = length / 2.0
    label.pose.orientation.w = 1.0
    label.scale.z = length / 3.0
    label.color.r, label.color.g, label.color.b, label.color.a = HULL_RGBA
    out.append(label)
    if route is not None and len(route.points) >= 2:
        out.append(route)
    if len(trail_xy) >= 2:
        out.append(_strip('trail', stamp, TRAIL_RGBA, width, trail_xy))
    return MarkerArray(markers=out)
