"""sensor_msgs/NavSatFix and the visualization_msgs/MarkerArray of one vessel (nav_display_node).

Marker namespaces (frame ``map``, ENU, one marker each, fixed ids so each update replaces the
last): ``hull`` (closed LINE_STRIP outline at the true length and heading), ``label`` (the
vessel's name above the hull), ``route`` (LINE_STRIP through the route Path's poses, which
sample arcs every 25 m), ``trail`` (LINE_STRIP of the past positions). Targets and CPA points
are colav_node's ``colav_markers``, not repeated here.
"""
from geometry_msgs.msg import Point
from sensor_msgs.msg import NavSatFix, NavSatStatus
from visualization_msgs.msg import Marker, MarkerArray

from ship_guidance.nav_display import enu_to_geodetic, hull_outline
from ship_sim.ros.conversions import MAP_FRAME

HULL_RGBA = (0.95, 0.95, 0.2, 1.0)
ROUTE_RGBA = (0.3, 0.7, 1.0, 0.9)
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
    """Line width (m) of a vessel's markers: visible at chart scale, thin beside the hull."""
    return max(1.0, length / 60.0)


def route_marker(stamp, route_xy, length):
    """The ``route`` LINE_STRIP (built once per route: a route has hundreds of poses)."""
    return _strip('route', stamp, ROUTE_RGBA, line_width(length), route_xy)


def display_markers(stamp, name, x, y, yaw, length, route, trail_xy):
    """MarkerArray: hull at (x, y, yaw) of ``length`` m, its label, the ``route`` marker
    (route_marker, or None) and the trail through ``trail_xy`` (ENU)."""
    width = line_width(length)
    out = [_strip('hull', stamp, HULL_RGBA, width, hull_outline(x, y, yaw, length))]
    label = Marker(ns='label', id=0, type=Marker.TEXT_VIEW_FACING, action=Marker.ADD, text=name)
    label.header.frame_id = MAP_FRAME
    label.header.stamp = stamp
    label.pose.position.x, label.pose.position.y = float(x), float(y)
    label.pose.position.z = length / 2.0
    label.pose.orientation.w = 1.0
    label.scale.z = length / 3.0
    label.color.r = label.color.g = label.color.b = label.color.a = 1.0
    out.append(label)
    if route is not None and len(route.points) >= 2:
        out.append(route)
    if len(trail_xy) >= 2:
        out.append(_strip('trail', stamp, TRAIL_RGBA, width, trail_xy))
    return MarkerArray(markers=out)
