"""visualization_msgs/MarkerArray of a collision-avoidance decision (RViz, Foxglove), in ENU.

Namespaces: ``safe_distance`` (a flat cylinder of radius d_safe around each target: one
radius for all, or one per target, widened by its uncertainty: ColavParams.safe_distance),
``cpa`` (spheres at the own ship's and each target's position at TCPA, straight lines),
``course`` (an arrow from the own ship along the commanded course, one minute of travel).
The first marker is a DELETEALL, so targets that left do not linger.
"""
import math

from visualization_msgs.msg import Marker, MarkerArray

from ship_sim.frames import psi_to_yaw
from ship_sim.ros.conversions import time_to_msg, yaw_to_quaternion

ARROW_S = 60.0   # the course arrow's length in seconds of travel


def _marker(ns, i, kind, stamp, rgba):
    m = Marker(ns=ns, id=i, type=kind, action=Marker.ADD)
    m.header.frame_id = 'map'
    m.header.stamp = stamp
    m.color.r, m.color.g, m.color.b, m.color.a = rgba
    m.pose.orientation.w = 1.0
    return m


def colav_markers(t, own, targets, decision, d_safe):
    """MarkerArray for own ship / targets (NED states) and the Decision taken at ``t`` (s)."""
    stamp = time_to_msg(t)
    out = [Marker(action=Marker.DELETEALL)]
    radii = list(d_safe) if hasattr(d_safe, '__len__') else [d_safe] * len(targets)
    for i, (tg, a) in enumerate(zip(targets, decision.targets)):
        red = a.threat
        c = _marker('safe_distance', i, Marker.CYLINDER, stamp,
                    (1.0, 0.2, 0.2, 0.3) if red else (0.2, 0.6, 1.0, 0.2))
        c.pose.position.x, c.pose.position.y = tg.east, tg.north
        c.scale.x = c.scale.y = 2.0 * radii[i]
        c.scale.z = 1.0
        out.append(c)
        tc = max(a.tcpa_s, 0.0)
        for j, ship in enumerate((own, tg)):
            s = _marker('cpa', 2 * i + j, Marker.SPHERE, stamp, (1.0, 0.8, 0.0, 0.9))
            s.pose.position.x = ship.east + ship.speed * math.sin(ship.course) * tc
            s.pose.position.y = ship.north + ship.speed * math.cos(ship.course) * tc
            s.scale.x = s.scale.y = s.scale.z = 50.0
            out.append(s)
    arrow = _marker('course', 0, Marker.ARROW, stamp,
                    (0.1, 0.9, 0.1, 1.0) if decision.mode == 'nominal' else (1.0, 0.5, 0.0, 1.0))
    arrow.pose.position.x, arrow.pose.position.y = own.east, own.north
    q = yaw_to_quaternion(float(psi_to_yaw(decision.course)))
    o = arrow.pose.orientation
    o.x, o.y, o.z, o.w = q
    arrow.scale.x = max(own.speed, 1.0) * ARROW_S
    arrow.scale.y = arrow.scale.z = 20.0
    out.append(arrow)
    return MarkerArray(markers=out)
