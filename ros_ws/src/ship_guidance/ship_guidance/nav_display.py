"""What a map or 3D viewer needs of a vessel, without ROS: hull outline, geodetic fix, trail.

nav_display_node (thin) turns these into sensor_msgs/NavSatFix and a visualization_msgs
MarkerArray. Everything here is ENU (x east, y north, yaw counter-clockwise from east), the
frame of the topics (REP-103), and sim time in seconds.

- ``hull_outline``: a closed plan-view polygon of a ship of length L (bow to stern, the model's
  length between perpendiculars) and beam B, a pointed bow over the last ``B`` of the length:
  the outline people read as "a ship pointing that way" on a chart. B defaults to L / 7, a
  typical length-to-beam ratio of merchant ships (the Mariner's 160.93 m / 23.17 m is 6.9).
- ``enu_to_geodetic``: a local ENU point -> latitude/longitude on WGS-84 through the tangent
  plane at the scenario's origin (ship_sim.geodetic, the inverse of what route files use).
- ``Throttle``: publish at most ``rate_hz`` per second of sim time, on the stamps themselves
  (a run in lockstep goes many times faster than real time; wall-time throttling would show a
  different number of frames per simulated minute at every load).
- ``Trail``: the last positions at the display rate, bounded (a long run never grows it).
"""
from collections import deque

import numpy as np

from ship_sim.geodetic import ned_to_geodetic

#: Frames per second of sim time unless told (nav_display_node's display_rate_hz; the launcher
#: sets the simulator's odom_display to it).
DEFAULT_DISPLAY_RATE_HZ = 2.0

#: Geodetic origin (latitude, longitude in deg) of the ENU frame when a scenario, its routes and
#: its AIS block give none: open deep water in the Norwegian Sea, about 450 km west of the
#: Norwegian coast, so that a ship is at sea on any map (never silently at 0 N 0 E, the Gulf of
#: Guinea).
DEFAULT_ORIGIN_DEG = (66.0, 2.0)

#: Beam as a fraction of length when a model gives none (merchant ships: L/B about 6 to 7.5).
DEFAULT_BEAM_RATIO = 1.0 / 7.0


def hull_outline(x, y, yaw, length, beam=None):
    """Closed ENU polygon (6 x 2 array, last point = first) of a hull centred at (x, y) with
    heading ``yaw`` (ENU, rad): stern corners, shoulders, bow point. Bow to stern is
    ``length``; the widest part is ``beam`` (default length * DEFAULT_BEAM_RATIO)."""
    if not (np.isfinite(length) and length > 0.0):
        raise ValueError(f'hull length must be a positive number, got {length!r}')
    half_l = 0.5 * length
    b = length * DEFAULT_BEAM_RATIO if beam is None else beam
    half_b = 0.5 * b
    shoulder = half_l - min(b, length / 2.0)
    body = np.array([[-half_l, -half_b], [shoulder, -half_b], [half_l, 0.0],
                     [shoulder, half_b], [-half_l, half_b], [-half_l, -half_b]])  # FLU x fwd, y left
    c, s = np.cos(yaw), np.sin(yaw)
    rot = np.array([[c, -s], [s, c]])
    return body @ rot.T + np.array([x, y])


def enu_to_geodetic(x, y, lat0_deg, lon0_deg):
    """ENU metres (east ``x``, north ``y``) from the origin -> (latitude, longitude) in deg."""
    return ned_to_geodetic(y, x, lat0_deg, lon0_deg)


class Throttle:
    """True for the first stamp at or after each multiple of the period (sim time), and for the
    first stamp of all; a stamp going backwards (a restarted simulator) starts over."""

    def __init__(self, rate_hz):
        if not rate_hz > 0.0:
            raise ValueError(f'display rate must be positive, got {rate_hz!r}')
        self.period = 1.0 / rate_hz
        self.next_t = None

    def due(self, t):
        if self.next_t is not None and self.next_t - self.period <= t < self.next_t:
            return False
        self.next_t = (np.floor(t / self.period) + 1.0) * self.period
        return True


class Trail:
    """The last ``max_points`` positions (ENU), oldest first."""

    def __init__(self, max_points):
        if max_points < 2:
            raise ValueError(f'a trail needs at least 2 points, got {max_points!r}')
        self.points = deque(maxlen=int(max_points))

    def add(self, x, y):
        self.points.append((float(x), float(y)))

    def __len__(self):
        return len(self.points)
