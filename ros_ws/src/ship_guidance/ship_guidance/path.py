"""Path geometry every package shares: straight lines, circular arcs and routes made of them.

Frame and units: NED world (north, east) in metres, angles in radians, headings clockwise from
north (Fossen). Nothing here knows about ROS; the node converts NED <-> ENU via ship_sim.frames.

Sources:
- Closest-point path frame of Martinsen and Lekkas 2018 (curved path following), eqs. 1-3: the path
  angle is the tangent direction at the closest point, and the cross-track error is
      e = -sin(gamma_p) (n - n_p) + cos(gamma_p) (e - e_p)           (Martinsen and Lekkas 2018 eq. 2)
  i.e. positive when the vessel is to STARBOARD of the path direction (the project convention).
  For an interior closest point this is the signed distance to the path; when the closest
  point is clamped to the start/end of the searched stretch it is the offset from the tangent
  line there (the classic waypoint-LOS "extended leg").
- Straight legs and circular arcs (both turning directions) as the route primitives of Simakis 1992
  (Papoulias et al., Chapter IV) and waypoint routes of Lee 2004.

Conventions of this module:
- An arc is ``clockwise`` when it turns to starboard seen from above: the path angle increases
  along it and its centre lies to starboard. Signed curvature kappa = d(path_angle)/ds is
  +1/R for clockwise arcs, -1/R for counter-clockwise arcs, 0 for lines.
- Arc length s runs from 0 at the route start to ``Route.length``; a leg's local arc length t
  runs from 0 to its own length.
- Polar angles about an arc centre are measured like headings (from north, clockwise), so a
  point at polar angle theta is centre + R (cos theta, sin theta) in (north, east); moving
  clockwise increases theta and the tangent heading is theta + pi/2 (theta - pi/2 if ccw).

nav_msgs/Path encoding (``Route.to_poses`` / ``Route.from_poses``): each pose carries the START
tangent of the leg that begins there (the last pose carries the end tangent of the last leg).
The leg from pose i to pose i+1 is a straight line when psi_i equals the chord bearing, else the
unique circular arc leaving pose i with heading psi_i and passing through pose i+1: for such an
arc the chord bearing is psi_i + (turn angle)/2, so with delta = wrap(bearing - psi_i) the turn
is 2 delta, the radius is chord / (2 |sin delta|) and the arc is clockwise when delta > 0.
"""
import bisect
import math
from dataclasses import dataclass

import numpy as np

from ship_sim import bounds
from ship_sim.frames import wrap_angle

TWO_PI = 2.0 * math.pi
HALF_PI = 0.5 * math.pi

#: Largest coordinate (m, |north| and |east| from the map origin) a route or a vessel position
#: may have (ship_sim.bounds, with the reason). The nodes refuse routes and odometry beyond it
#: (ship_guidance.ros.path_msgs, ship_guidance.ros.odom_gate).
MAX_COORDINATE_M = bounds.MAX_COORDINATE_M
#: Longest route (m) a route file may describe or a curve generate (ship_guidance.curves).
MAX_ROUTE_LENGTH_M = 1e6
#: Most legs a route may have (= samples of a generated curve).
MAX_ROUTE_SAMPLES = 100_000

#: Default half-width (m) of the arc-length search window when ``project`` gets an ``s_hint``
#: but no ``window``. The guidance passes its own (2 look-ahead distances and more).
DEFAULT_WINDOW = 500.0
#: ``Route.project`` searches up to this many legs on Python floats, more with numpy: the
#: float loop's cost grows with the legs, the vectorised search has a fixed overhead that
#: dominates for few legs (crossover measured, doc/results/performance.md).
FEW_LEGS = 16


def _point(p, name):
    a = np.asarray(p, dtype=float).reshape(-1)
    if a.shape != (2,):
        raise ValueError(f'{name} must be a (north, east) pair, got {p!r}')
    if not np.all(np.isfinite(a)):
        raise ValueError(f'{name} must be finite, got {p!r}')
    a.setflags(write=False)
    return a


class Line:
    """Straight leg from ``start`` to ``end`` ((north, east) pairs, m)."""

    kind = 'line'
    clockwise = None
    curvature = 0.0

    def __init__(self, start, end):
        self.start = _point(start, 'Line start')
        self.end = _point(end, 'Line end')
        d = self.end - self.start
        self.length = float(math.hypot(d[0], d[1]))
        if not self.length > 0.0:
            raise ValueError(f'Line has zero length (start = end = {self.start.tolist()})')
        self.unit = d / self.length
        self.unit.setflags(write=False)
        #: Path angle (NED heading of the direction start -> end), rad.
        self.angle = float(wrap_angle(math.atan2(d[1], d[0])))
        self.start_angle = self.end_angle = self.angle

    def point_at(self, t):
        """Point and path angle at local arc length t (clipped to the leg): (north, east, angle)."""
        t = np.clip(t, 0.0, self.length)
        return (self.start[0] + t * self.unit[0], self.start[1] + t * self.unit[1],
                np.full(np.shape(t), self.angle)[()])

    def along(self, north, east):
        """Unclamped local arc length of the foot of the perpendicular (m); >= length means the
        point has passed the end normal."""
        return (north - self.start[0]) * self.unit[0] + (east - self.start[1]) * self.unit[1]

    def __repr__(self):
        return f'Line(start={self.start.tolist()}, end={self.end.tolist()})'


class Arc:
    """Circular arc from ``start`` to ``end`` around ``center``, turning ``clockwise`` (starboard)
    or counter-clockwise (port), seen from above. Sweeps less than a full turn (a full circle
    must be given as two arcs).

    Raises ValueError when start and end are not on one circle about the centre (relative
    tolerance ``rtol`` on the two radii), when start and end coincide, or on non-finite input.
    The radius is the start radius; ``end`` is stored as given.
    """

    kind = 'arc'

    def __init__(self, start, end, center, clockwise, rtol=1e-6):
        self.start = _point(start, 'Arc start')
        self.end = _point(end, 'Arc end')
        self.center = _point(center, 'Arc center')
        if not isinstance(clockwise, (bool, np.bool_)):
            raise ValueError(f'Arc clockwise must be a bool, got {clockwise!r}')
        self.clockwise = bool(clockwise)
        #: +1 for clockwise (starboard) turns, -1 for counter-clockwise.
        self.direction = 1.0 if self.clockwise else -1.0
        r0 = float(math.hypot(*(self.start - self.center)))
        r1 = float(math.hypot(*(self.end - self.center)))
        if not (r0 > 0.0 and r1 > 0.0):
            raise ValueError('Arc start or end lies on the centre (zero radius)')
        if abs(r0 - r1) > rtol * max(r0, r1):
            raise ValueError(f'Arc start and end are not on one circle about '
                             f'{self.center.tolist()}: radii {r0:.6g} m and {r1:.6g} m '
                             f'(rtol {rtol:g})')
        chord = float(math.hypot(*(self.end - self.start)))
        if chord <= 1e-12 * max(1.0, r0):
            raise ValueError('Arc start and end coincide (zero length; '
                             'give a full circle as two arcs)')
        self.radius = r0
        #: Polar angle of the start about the centre (from north, clockwise), rad.
        self.theta0 = float(math.atan2(self.start[1] - self.center[1],
                                       self.start[0] - self.center[0]))
        theta1 = math.atan2(self.end[1] - self.center[1], self.end[0] - self.center[0])
        #: Unsigned swept angle in (0, 2 pi), rad.
        self.sweep = float((self.direction * (theta1 - self.theta0)) % TWO_PI)
        if not 0.0 < self.sweep < TWO_PI:
            raise ValueError('Arc start and end coincide (zero length)')
        self.length = self.radius * self.sweep
        self.curvature = self.direction / self.radius
        self.start_angle = float(wrap_angle(self.theta0 + self.direction * HALF_PI))
        self.end_angle = float(wrap_angle(self.theta0 + self.direction * (self.sweep + HALF_PI)))

    def point_at(self, t):
        """Point and path angle at local arc length t (clipped to the leg): (north, east, angle)."""
        theta = self.theta0 + self.direction * np.clip(t, 0.0, self.length) / self.radius
        return (self.center[0] + self.radius * np.cos(theta),
                self.center[1] + self.radius * np.sin(theta),
                wrap_angle(theta + self.direction * HALF_PI))

    def along(self, north, east):
        """Unclamped local arc length of the radial foot point (m), the angle about the centre
        cut at the antipode of the arc's midpoint: < 0 before the start normal, > length past
        the end normal."""
        phi = np.arctan2(east - self.center[1], north - self.center[0])
        cut = math.pi - 0.5 * self.sweep
        rel = (self.direction * (phi - self.theta0) + cut) % TWO_PI - cut
        return rel * self.radius

    def frame(self, north, east):
        """Guidance frame about the full circle, valid at every position around the centre:
        (path_angle, cross_track) with the tangent heading at the radial foot point and the
        signed radial offset e = direction * (R - distance to centre) (positive to starboard).
        Undefined at the centre itself (returns the start tangent there)."""
        dn, de = north - self.center[0], east - self.center[1]
        phi = np.arctan2(de, dn)
        return (wrap_angle(phi + self.direction * HALF_PI),
                self.direction * (self.radius - np.hypot(dn, de)))

    def __repr__(self):
        return (f'Arc(start={self.start.tolist()}, end={self.end.tolist()}, '
                f'center={self.center.tolist()}, clockwise={self.clockwise})')


@dataclass(frozen=True, slots=True)
class Projection:
    """Closest point of a route to a position (``Route.project``). Units m, rad.

    s: arc length of the closest point; leg_index: its leg; north, east: the closest point;
    path_angle: NED heading of the path tangent there; cross_track: Martinsen and Lekkas 2018 eq. 2, positive when the
    vessel is to starboard of the path direction; curvature: signed, +1/R on clockwise
    (starboard) arcs, -1/R on counter-clockwise arcs, 0 on lines; distance: Euclidean distance
    to the closest point; at_start / at_end: the closest point is the route's start / end.
    """
    s: float
    leg_index: int
    north: float
    east: float
    path_angle: float
    cross_track: float
    curvature: float
    distance: float
    at_start: bool
    at_end: bool


class Route:
    """A connected sequence of Line and Arc legs.

    Raises ValueError if the sequence is empty, a leg is not a Line/Arc, or consecutive legs do
    not join (end of leg i within ``join_tol`` m of the start of leg i+1; default
    max(1e-6 m, 1e-9 x the coordinate scale)). Legs themselves refuse zero length and
    non-finite numbers.

    Arrays (one entry per leg): ``leg_lengths``, ``leg_starts`` (arc length at each leg start);
    ``cumulative`` has one more entry (0 ... length).
    """

    def __init__(self, legs, join_tol=None):
        legs = tuple(legs)
        if not legs:
            raise ValueError('Route needs at least one leg')
        for i, leg in enumerate(legs):
            if not isinstance(leg, (Line, Arc)):
                raise ValueError(f'Route leg {i} is not a Line or Arc: {leg!r}')
        pts = np.array([[leg.start, leg.end] for leg in legs]).reshape(-1, 2)
        scale = max(float(np.max(np.abs(pts))), max(leg.length for leg in legs))
        tol = max(1e-6, 1e-9 * scale) if join_tol is None else float(join_tol)
        for i in range(len(legs) - 1):
            gap = float(np.hypot(*(legs[i].end - legs[i + 1].start)))
            if not gap <= tol:
                raise ValueError(f'Route legs {i} and {i + 1} do not join: end '
                                 f'{legs[i].end.tolist()} vs start {legs[i + 1].start.tolist()} '
                                 f'(gap {gap:.3g} m > {tol:.3g} m)')
        self.legs = legs
        m = len(legs)
        self.leg_lengths = np.array([leg.length for leg in legs])
        self.cumulative = np.concatenate(([0.0], np.cumsum(self.leg_lengths)))
        self.leg_starts = self.cumulative[:-1]
        self.length = float(self.cumulative[-1])
        # Per-leg arrays for the vectorised closest-point search; unused entries stay 0.
        self._is_arc = np.array([leg.kind == 'arc' for leg in legs])
        self._has_arcs = bool(self._is_arc.any())
        self._p0 = np.array([leg.start for leg in legs])
        self._unit = np.zeros((m, 2))
        self._center = np.zeros((m, 2))
        self._radius = np.zeros(m)
        self._theta0 = np.zeros(m)
        self._dir = np.zeros(m)
        self._angle = np.zeros(m)  # line path angle
        for i, leg in enumerate(legs):
            if leg.kind == 'arc':
                self._center[i] = leg.center
                self._radius[i] = leg.radius
                self._theta0[i] = leg.theta0
                self._dir[i] = leg.direction
            else:
                self._unit[i] = leg.unit
                self._angle[i] = leg.angle
        self.curvatures = np.array([leg.curvature for leg in legs])
        self.start_angles = np.array([leg.start_angle for leg in legs])
        self.end_angles = np.array([leg.end_angle for leg in legs])
        #: Arc-length tolerance (m) for "at the start/end".
        self.s_tol = 1e-9 * max(1.0, self.length)
        # The same per-leg numbers as Python floats for ``_closest_on_few_legs`` (a guidance
        # step searches 1-3 legs, where numpy's per-call overhead exceeds the arithmetic).
        self._cum_list = self.cumulative.tolist()
        self._curv_list = self.curvatures.tolist()
        self._leg_floats = [
            (bool(a), *p0, *u, *c, r, th, d, ang, ln) for a, p0, u, c, r, th, d, ang, ln in zip(
                self._is_arc.tolist(), self._p0.tolist(), self._unit.tolist(),
                self._center.tolist(), self._radius.tolist(), self._theta0.tolist(),
                self._dir.tolist(), self._angle.tolist(), self.leg_lengths.tolist())]

    # ---------------------------------------------------------------- construction helpers

    @classmethod
    def polyline(cls, points):
        """Straight legs through ``points`` ((n, 2) array-like of (north, east), at least 2)."""
        p = np.asarray(points, dtype=float)
        if p.ndim != 2 or p.shape[1] != 2 or len(p) < 2:
            raise ValueError('polyline needs at least two (north, east) points')
        return cls([Line(p[i], p[i + 1]) for i in range(len(p) - 1)])

    @classmethod
    def from_poses(cls, north, east, psi, angle_tol=1e-6, merge_arcs=True):
        """Decode the pose encoding (see module docstring): arrays of north, east (m) and NED
        heading psi (rad), at least two poses.

        A leg is a line when |wrap(chord bearing - psi_i)| <= angle_tol (rad); a sub-arc whose
        half turn is below angle_tol therefore decodes as a line, a lateral difference of at
        most chord * angle_tol / 4. With ``merge_arcs`` consecutive arcs on the same circle
        (centre and radius equal to 1e-7 R, same direction, total sweep < 2 pi) are merged, so
        arcs that ``to_poses`` split into sub-arcs come back as one leg. Raises ValueError on
        repeated points or when a pose points directly away from the next point.
        """
        n, e, h = (np.asarray(a, dtype=float).reshape(-1) for a in (north, east, psi))
        if not (len(n) == len(e) == len(h)) or len(n) < 2:
            raise ValueError('from_poses needs equally long north, east, psi arrays '
                             'with >= 2 poses')
        if not (np.all(np.isfinite(n)) and np.all(np.isfinite(e)) and np.all(np.isfinite(h))):
            raise ValueError('from_poses: poses must be finite')
        legs = []
        for i in range(len(n) - 1):
            p0, p1 = (n[i], e[i]), (n[i + 1], e[i + 1])
            dn, de = n[i + 1] - n[i], e[i + 1] - e[i]
            chord = math.hypot(dn, de)
            if chord == 0.0:
                raise ValueError(f'from_poses: poses {i} and {i + 1} coincide')
            delta = float(wrap_angle(math.atan2(de, dn) - h[i]))
            if abs(delta) <= angle_tol:
                legs.append(Line(p0, p1))
                continue
            if math.pi - abs(delta) <= angle_tol:
                raise ValueError(f'from_poses: pose {i} points directly away from pose {i + 1}; '
                                 'no circular arc leaves it tangentially through the next point')
            direction = 1.0 if delta > 0.0 else -1.0
            radius = chord / (2.0 * abs(math.sin(delta)))
            normal = h[i] + direction * HALF_PI  # towards the centre
            center = (n[i] + radius * math.cos(normal), e[i] + radius * math.sin(normal))
            arc = Arc(p0, p1, center, clockwise=delta > 0.0)
            prev = legs[-1] if legs else None
            if (merge_arcs and prev is not None and prev.kind == 'arc'
                    and prev.clockwise == arc.clockwise
                    and abs(prev.radius - arc.radius) <= 1e-7 * arc.radius
                    and math.hypot(*(prev.center - arc.center)) <= 1e-7 * arc.radius
                    and prev.sweep + arc.sweep < TWO_PI - 1e-9):
                legs[-1] = Arc(prev.start, arc.end, prev.center, prev.clockwise)
            else:
                legs.append(arc)
        return cls(legs)

    @classmethod
    def from_curve(cls, north, east, psi=None, angle_tol=1e-6):
        """Route through a densely sampled smooth curve as a sequence of tangent arcs: leg i
        leaves sample i with the curve tangent psi_i and passes through sample i+1.

        ``psi`` (rad, NED) are the curve's tangents at the samples; when omitted they are
        estimated: interior samples from the circle through three neighbours (bearings of the
        two chords weighted by chord length, exact for equally spaced points on a circle), end
        samples so that the first/last arc is that circle.

        Accuracy (derived for a curve with linearly varying curvature, tested on a sine): the
        arcs deviate from the curve by at most (2/81) |kappa'| c^3 with exact tangents and
        (1/(9 sqrt 3)) |kappa'| c^3 = 0.064 |kappa'| c^3 with estimated ones (c the chord
        between samples, kappa' = d(curvature)/ds), so the closest-point cross-track error is
        that accurate: about 1 mm resp. 3 mm for 25 m samples of a sine with 300 m amplitude
        and 3 km wavelength.
        """
        n = np.asarray(north, dtype=float).reshape(-1)
        e = np.asarray(east, dtype=float).reshape(-1)
        if len(n) != len(e) or len(n) < 2:
            raise ValueError('from_curve needs equally long north, east arrays with >= 2 samples')
        if psi is None:
            psi = estimate_tangents(n, e)
        return cls.from_poses(n, e, psi, angle_tol=angle_tol, merge_arcs=True)

    # ---------------------------------------------------------------- queries

    @property
    def start(self):
        return self.legs[0].start

    @property
    def end(self):
        return self.legs[-1].end

    def leg_at(self, s):
        """Index of the leg containing arc length s (clipped to the route)."""
        i = np.searchsorted(self.cumulative, np.clip(s, 0.0, self.length), side='right') - 1
        return np.clip(i, 0, len(self.legs) - 1)[()]

    def point_at(self, s):
        """(north, east, path_angle) at arc length s (scalar or array; clipped to [0, length])."""
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        i = np.clip(np.searchsorted(self.cumulative, s, side='right') - 1, 0, len(self.legs) - 1)
        n, e, a = self._eval(i, s - self.leg_starts[i])
        return n[()], e[()], a[()]

    def _eval(self, i, t):
        """Points and path angles of legs i at local arc lengths t (arrays of equal shape)."""
        arc = self._is_arc[i]
        theta = self._theta0[i] + self._dir[i] * t / np.where(arc, self._radius[i], 1.0)
        n = np.where(arc, self._center[i, 0] + self._radius[i] * np.cos(theta),
                     self._p0[i, 0] + t * self._unit[i, 0])
        e = np.where(arc, self._center[i, 1] + self._radius[i] * np.sin(theta),
                     self._p0[i, 1] + t * self._unit[i, 1])
        a = np.where(arc, wrap_angle(theta + self._dir[i] * HALF_PI), self._angle[i])
        return n, e, a

    def project(self, north, east, s_hint=None, window=None, bounds=None):
        """Closest point of the route to (north, east) (Martinsen and Lekkas 2018 eqs. 1-3), as a Projection.

        Without ``s_hint`` the whole route (or ``bounds``) is searched. With ``s_hint`` (the
        previous arc length) only arc lengths in [s_hint - back, s_hint + ahead] are searched,
        ``window`` being a half-width (m) or a (back, ahead) pair (default DEFAULT_WINDOW), so the
        progress cannot jump to another branch of a self-approaching path (figure-eight
        crossings, hairpins). ``bounds`` = (s_lo, s_hi) further restricts the search (the
        guidance uses it to stop at corners). Where the closest point is clamped at the route's
        start or end, at_start / at_end is set and cross_track is the offset from the tangent
        line there. Up to FEW_LEGS legs in the search interval are searched one by one on
        Python floats, more all at once with numpy (same arithmetic, same result to rounding).
        """
        pn, pe = float(north), float(east)
        if not (math.isfinite(pn) and math.isfinite(pe)):
            raise ValueError(f'project: position must be finite, got ({north}, {east})')
        lo, hi = 0.0, self.length
        if bounds is not None:
            lo, hi = max(lo, float(bounds[0])), min(hi, float(bounds[1]))
            if lo > hi:
                raise ValueError(f'project: empty bounds {bounds} '
                                 f'for a route of length {self.length}')
        if s_hint is not None:
            w = DEFAULT_WINDOW if window is None else window
            back, ahead = (w, w) if np.ndim(w) == 0 else w
            sh = min(max(float(s_hint), lo), hi)
            lo, hi = max(lo, sh - float(back)), min(hi, sh + float(ahead))
        # Legs overlapping (lo, hi) with positive length; a point interval takes its leg.
        cl = self._cum_list
        i0 = bisect.bisect_right(cl, lo, 1) - 1   # = searchsorted(c[1:], lo, 'right')
        i1 = bisect.bisect_left(cl, hi, 0, len(cl) - 1) - 1
        i0 = min(i0, len(self.legs) - 1)
        if i1 < i0:
            i1 = i0
        if i1 - i0 < FEW_LEGS:
            leg, s, t, fn, fe, gamma, dist = self._closest_on_few_legs(pn, pe, lo, hi, i0, i1)
        else:
            leg, s, t, fn, fe, gamma, dist = self._closest_vectorised(pn, pe, lo, hi, i0, i1)
        cross = -math.sin(gamma) * (pn - fn) + math.cos(gamma) * (pe - fe)  # Martinsen and Lekkas 2018 eq. 2
        return Projection(s=s, leg_index=leg, north=fn, east=fe, path_angle=gamma,
                          cross_track=cross, curvature=self._curv_list[leg],
                          distance=dist, at_start=s <= self.s_tol,
                          at_end=s >= self.length - self.s_tol)

    def _closest_on_few_legs(self, pn, pe, lo, hi, i0, i1):
        """``_closest_vectorised`` on Python floats, leg by leg, with the same arithmetic."""
        cl, legs = self._cum_list, self._leg_floats
        best = None
        for i in range(i0, i1 + 1):
            arc, p0n, p0e, un, ue, cn, ce, radius, theta0, d, angle, length = legs[i]
            c0 = cl[i]
            ta = min(max(lo - c0, 0.0), length)
            tb = min(max(hi - c0, 0.0), length)
            if arc:
                phi = math.atan2(pe - ce, pn - cn)
                t = ((d * (phi - theta0)) % TWO_PI) * radius
                if not ta <= t <= tb:
                    ga = abs(wrap_angle((ta - t) / radius))
                    gb = abs(wrap_angle((tb - t) / radius))
                    t = ta if ga <= gb else tb
                theta = theta0 + d * t / radius
                fn = cn + radius * math.cos(theta)
                fe = ce + radius * math.sin(theta)
                fa = wrap_angle(theta + d * HALF_PI)
            else:
                t = min(max((pn - p0n) * un + (pe - p0e) * ue, ta), tb)
                fn, fe, fa = p0n + t * un, p0e + t * ue, angle
            dist = math.hypot(fn - pn, fe - pe)
            if best is None or dist < best[-1]:  # first minimum, as argmin
                best = (i, c0 + t, t, fn, fe, fa, dist)
        return best

    def _closest_vectorised(self, pn, pe, lo, hi, i0, i1):
        """Closest point on legs i0..i1 restricted to arc lengths [lo, hi], all legs at once:
        (leg, s, t, north, east, path_angle, distance)."""
        sl = slice(i0, i1 + 1)  # contiguous legs: views, no copies
        c0 = self.cumulative[sl]
        t, fn, fe, fa, dist = self.closest_on_legs(sl, pn, pe, lo - c0, hi - c0)
        k = int(np.argmin(dist))
        return (i0 + k, float(c0[k] + t[k]), float(t[k]), float(fn[k]), float(fe[k]),
                float(fa[k]), float(dist[k]))

    def closest_on_legs(self, i, pn, pe, lo_local, hi_local):
        """Closest points of (pn, pe) on legs ``i`` (a slice or an index array), each leg
        searched over its local arc lengths [lo_local, hi_local] (clamped to the leg):
        arrays (t, north, east, path_angle, distance) of the shape of ``i`` broadcast with the
        inputs. The one closest-point kernel of ``project`` (many legs) and of the batched
        guidance (ship_guidance.batch_guidance: one leg per point, 1-D arrays, where lines
        and arcs are computed apart; the same arithmetic per element)."""
        lengths = self.leg_lengths[i]
        ta = np.minimum(np.maximum(lo_local, 0.0), lengths)
        tb = np.minimum(np.maximum(hi_local, 0.0), lengths)
        if not self._has_arcs:
            return self._line_foot(i, pn, pe, ta, tb)
        arc = self._is_arc[i]
        if np.ndim(i) == 1 and np.ndim(pn) == 1:   # one leg per point: each kind apart
            if arc.all():
                return self._arc_foot(i, pn, pe, ta, tb)
            if not arc.any():
                return self._line_foot(i, pn, pe, ta, tb)
            out = [np.empty(len(i)) for _ in range(5)]
            for rows, foot in ((np.flatnonzero(~arc), self._line_foot),
                               (np.flatnonzero(arc), self._arc_foot)):
                for o, v in zip(out, foot(i[rows], pn[rows], pe[rows], ta[rows], tb[rows])):
                    o[rows] = v
            return tuple(out)
        # Lines: perpendicular foot clamped to the searched part.
        p0, unit = self._p0[i], self._unit[i]
        t_line = np.minimum(np.maximum(
            (pn - p0[..., 0]) * unit[..., 0] + (pe - p0[..., 1]) * unit[..., 1], ta), tb)
        t_arc = self._arc_t(i, pn, pe, ta, tb, np.where(arc, self._radius[i], 1.0))
        t = np.where(arc, t_arc, t_line)
        fn, fe, fa = self._eval(i, t)
        return t, fn, fe, fa, np.hypot(fn - pn, fe - pe)

    def _arc_t(self, i, pn, pe, ta, tb, radius):
        """Arcs: radial foot if it lies in the searched part [ta, tb], else the nearer end of
        that part (distance to a circle point grows with the wrapped angle from the foot)."""
        center = self._center[i]
        phi = np.arctan2(pe - center[..., 1], pn - center[..., 0])
        t_free = ((self._dir[i] * (phi - self._theta0[i])) % TWO_PI) * radius
        # wrapped angles from the radial foot to the two ends of the searched part
        ga = np.abs(wrap_angle((ta - t_free) / radius))
        gb = np.abs(wrap_angle((tb - t_free) / radius))
        t_end = np.where(ga <= gb, ta, tb)
        return np.where((t_free >= ta) & (t_free <= tb), t_free, t_end)

    def _line_foot(self, i, pn, pe, ta, tb):
        """closest_on_legs for lines i only: perpendicular foot clamped to [ta, tb]."""
        p0, unit = self._p0[i], self._unit[i]
        t = np.minimum(np.maximum(
            (pn - p0[..., 0]) * unit[..., 0] + (pe - p0[..., 1]) * unit[..., 1], ta), tb)
        fn, fe = p0[..., 0] + t * unit[..., 0], p0[..., 1] + t * unit[..., 1]
        return t, fn, fe, self._angle[i], np.hypot(fn - pn, fe - pe)

    def _arc_foot(self, i, pn, pe, ta, tb):
        """closest_on_legs for arcs i only (``_eval``'s arc branch)."""
        radius = self._radius[i]
        t = self._arc_t(i, pn, pe, ta, tb, radius)
        d = self._dir[i]
        theta = self._theta0[i] + d * t / radius
        center = self._center[i]
        fn = center[..., 0] + radius * np.cos(theta)
        fe = center[..., 1] + radius * np.sin(theta)
        return t, fn, fe, wrap_angle(theta + d * HALF_PI), np.hypot(fn - pn, fe - pe)

    def along(self, leg_index, north, east):
        """Unclamped local arc length of a position on leg ``leg_index`` (see Line/Arc.along)."""
        leg = self.legs[leg_index]
        if leg.kind == 'line':  # Line.along on floats (the guidance calls this every step)
            _, p0n, p0e, un, ue = self._leg_floats[leg_index][:5]
            return (float(north) - p0n) * un + (float(east) - p0e) * ue
        return float(leg.along(float(north), float(east)))

    # ---------------------------------------------------------------- pose encoding

    def to_poses(self, max_arc_step):
        """Encode as poses (north, east, psi arrays): one pose at the start of every leg with
        that leg's start tangent, arcs split into equal sub-arcs no longer than ``max_arc_step``
        (m), and a last pose at the route end with the end tangent of the last leg."""
        max_arc_step = float(max_arc_step)
        if not (math.isfinite(max_arc_step) and max_arc_step > 0.0):
            raise ValueError(f'max_arc_step must be a positive number of metres, '
                             f'got {max_arc_step}')
        n, e, h = [], [], []
        for leg in self.legs:
            if leg.kind == 'arc':
                k = max(1, math.ceil(leg.length / max_arc_step - 1e-9))
                pn, pe, pa = leg.point_at(leg.length * np.arange(k) / k)
                pn[0], pe[0] = leg.start  # exact start, not the recomputed circle point
                n.extend(pn)
                e.extend(pe)
                h.extend(pa)
            else:
                n.append(leg.start[0])
                e.append(leg.start[1])
                h.append(leg.angle)
        n.append(self.end[0])
        e.append(self.end[1])
        h.append(self.legs[-1].end_angle)
        return np.array(n), np.array(e), np.array(h)

    def __len__(self):
        return len(self.legs)

    def __repr__(self):
        return f'Route({len(self.legs)} legs, length {self.length:.1f} m)'


def estimate_tangents(north, east):
    """Tangent headings (rad, NED) of a smooth curve at its samples: at interior samples the
    bearing of the chord before plus the chord-length-weighted share of the turn to the chord
    after (the tangent of the circle through the three samples, exact for equal spacing on a
    circle, O(h^2) otherwise); at the ends the tangent of the circle through the first/last
    three samples (2 chord bearing - neighbour tangent)."""
    n = np.asarray(north, dtype=float)
    e = np.asarray(east, dtype=float)
    dn, de = np.diff(n), np.diff(e)
    chord = np.hypot(dn, de)
    if np.any(chord == 0.0):
        raise ValueError('estimate_tangents: consecutive samples coincide')
    bearing = np.arctan2(de, dn)
    if len(n) == 2:
        return np.array([bearing[0], bearing[0]])
    turn = wrap_angle(bearing[1:] - bearing[:-1])
    psi = np.empty(len(n))
    psi[1:-1] = bearing[:-1] + turn * chord[:-1] / (chord[:-1] + chord[1:])
    psi[0] = 2.0 * bearing[0] - psi[1]
    psi[-1] = 2.0 * bearing[-1] - psi[-2]
    return wrap_angle(psi)
