"""Route-following guidance (pure): progress along a Route, waypoint switching, LOS / ILOS /
course schedule.

The guidance node wraps one ``Guidance`` per vessel; Monte Carlo and learning code use it
in-process. Units m, s, rad; positions and headings NED (see path.py, los.py for the laws and
their sources).

How the route is followed:
- The first update (and the first after ``reset()``) takes the closest point of the whole
  route, so a restarted node resumes mid-route; ``reset(s=0.0)`` starts from the beginning.
- The route is cut at CORNERS, joins where the tangent jumps by more than ``corner_angle``
  (default 1 deg), into smooth stretches. Within a stretch the reference is the closest point
  of the path (Martinsen and Lekkas 2018, eqs. 1-3, ``Route.project``), searched only within
  ``window`` of arc length around the previous one so progress never jumps to another branch
  of a self-crossing or hairpin path. Tangent joins (line -> tangent arc, sampled curves) are
  thus followed without switching logic.
- At the end of a stretch the guidance switches to the next one when the vessel is within the
  acceptance circle (radius ``acceptance_radius``, Simakis 1992 "TURN = circle", Lee 2004) of the
  corner, or has passed the normal to the path at the corner, whichever comes first (the
  normal catches vessels that miss the circle, e.g. with R = 0). Until then the reference is
  the stretch's last leg extended along its end tangent; right after a switch, while the vessel
  has not reached the next stretch's start normal, it is the next leg extended backwards (the
  classic waypoint-LOS legs). The acceptance circle is not applied at tangent joins: there is
  no corner to anticipate and on a densely sampled curve it would skip many short legs.
- The route is finished when the vessel enters the acceptance circle of the route's end point
  or passes its end normal. Afterwards the command keeps the vessel on the extension of the
  last leg's end tangent (a defined behaviour; the node decides what to do next).
- Law: 'los' psi_c = alpha - atan(e/d); 'ilos' psi_c = alpha - atan((e + sigma e_int)/d) with
  the integrator of Borhaug et al. (2008), frozen once finished. The integrator is kept across
  switches (a steady current needs a similar correction on the next leg) unless
  ``reset_integral_at_corners``. 'course' (course-change experiments, Lee 2004, sec. 5.2,
  Figs. 5.7-5.11): psi_c follows a time schedule (``course_schedule``, see
  ``parse_course_schedule``; course_i from t_i on, course0 before t0; needs the sim time ``t``
  in ``update``) and ignores the route's geometry; cross-track and progress still refer to the
  route, followed as with LOS, but the law never reports the route complete
  (``reports_completion``): a course experiment ends at its duration.
- Optional turn-rate lead (``curvature_lead``, needs the autopilot's zeta, omega_n and the
  speed; LOS / ILOS): psi_c += (2 zeta U / omega_n) kappa(s). On an arc the heading loop lags
  a turning command by 2 zeta r / omega_n (its velocity error); the lead cancels it (its effect
  on the flagship route: doc/results/flagship.md).

- Optional LOS point on turning circles (``arc_los_point``, law 'los' only; Lee 2004, Ch. 4,
  eq. 4.24): on an arc leg the command is the bearing of the point of the circle one
  look-ahead of arc ahead of the vessel (los.circle_los_point), instead of the tangent law.
  On the circle that leads the tangent by d / (2R), a lead fixed by the geometry rather than by
  the autopilot (the turn-rate lead's alternative; the two are not combined).

Stability check: given the paired PD autopilot's zeta and omega_n (rad/s) and the speed U (m/s)
the constructor refuses a look-ahead at or below U / (2 zeta omega_n) for LOS, or
(U + 4 zeta^2 sigma) / (2 zeta omega_n) for ILOS, unless ``allow_unstable=True``.
Angelopoulos 2011 (eq. 34) and Simakis 1992 (eq. 3.5) write d > 1 / (2 zeta omega_n) in
non-dimensional units (d in ship lengths, omega_n in units of U/L); convert with
los.omega_n_from_nondim and los.ship_lengths_to_metres. See los.py for the derivation.
"""
import bisect
import math
from dataclasses import dataclass

import numpy as np

from ship_sim.frames import wrap_angle

from .los import circle_los_point, critical_lookahead
from .path import Arc, Route

LAWS = ('los', 'ilos', 'course')
COURSE_LAW = 'course'


def parse_course_schedule(values):
    """[t0, c0_deg, t1, c1_deg, ...] -> (times (s), NED courses (rad)); ValueError says why not."""
    values = list(values or [])
    if not values or len(values) % 2:
        raise ValueError('needs pairs [t0, course0_deg, t1, course1_deg, ...], got '
                         f'{len(values)} values')
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
               for v in values):
        raise ValueError(f'needs finite numbers, got {values}')
    times = [float(t) for t in values[0::2]]
    if any(b <= a for a, b in zip(times, times[1:])):
        raise ValueError(f'times must increase strictly, got {times}')
    return times, [math.radians(c) for c in values[1::2]]


def course_schedule_for(law, values):
    """The course schedule ``law`` takes from [t0, c0_deg, ...]: parsed for the course law, None
    for the others (whose ``values`` must be empty); ValueError says why not."""
    if law != COURSE_LAW:
        if values:
            raise ValueError(f'empty unless law is {COURSE_LAW!r} (law is {law!r})')
        return None
    return parse_course_schedule(values)


def course_at(times, courses, t):
    """The scheduled course (rad) at sim time t: the last course whose time is <= t, else the first."""
    return courses[max(bisect.bisect_right(times, t) - 1, 0)]


@dataclass(frozen=True, slots=True)
class GuidanceOutput:
    """One guidance step. heading_cmd: NED heading command psi_c (rad, wrapped; the course law's
    as scheduled); cross_track: e
    (m, positive to starboard of the path); s: arc length of the reference point (m); leg_index:
    its leg; distance_remaining: route length - s (m); finished: end reached (latched);
    path_angle: alpha (rad); curvature: signed curvature of the path there (1/m, + clockwise);
    integral: ILOS state e_int (s, 0 for LOS); heading_error: wrap(psi_c - psi) (rad)."""
    heading_cmd: float
    cross_track: float
    s: float
    leg_index: int
    distance_remaining: float
    finished: bool
    path_angle: float
    curvature: float
    integral: float
    heading_error: float


class Guidance:
    """Follow ``route`` (path.Route) with LOS, ILOS or a course schedule (module docstring).

    Parameters (SI): law 'los' | 'ilos' | 'course'; lookahead d (m, > 0); acceptance_radius
    (m, >= 0);
    integral_gain sigma (m/s, > 0, ILOS only); corner_angle (rad, tangent jump that makes a
    corner); window (m, half-width of the progress search, default 2 d, widened to 3x the
    distance moved since the previous update); zeta, omega_n (rad/s), speed (m/s): the paired
    autopilot and speed for the stability check (all three or none); allow_unstable: skip the
    refusal; course_schedule: (times (s), NED courses (rad)) of the course law
    (``parse_course_schedule``). Raises ValueError naming the offending parameter.
    """

    def __init__(self, route, law='los', lookahead=100.0, acceptance_radius=0.0, *,
                 integral_gain=0.5, corner_angle=math.radians(1.0), window=None,
                 zeta=None, omega_n=None, speed=None, allow_unstable=False,
                 reset_integral_at_corners=False, curvature_lead=False, course_schedule=None,
                 arc_los_point=False):
        if not isinstance(route, Route):
            raise ValueError('route must be a ship_guidance.path.Route, '
                             f'got {type(route).__name__}')
        if law not in LAWS:
            raise ValueError(f"law must be one of {LAWS}, got {law!r}")
        _check_positive('lookahead', lookahead)
        _check_positive('acceptance_radius', acceptance_radius, allow_zero=True)
        if law == 'ilos':
            _check_positive('integral_gain', integral_gain)
        if (law == COURSE_LAW) != (course_schedule is not None):
            raise ValueError(f'course_schedule is given for law {COURSE_LAW!r} and only for it '
                             f'(law {law!r}, course_schedule {course_schedule!r})')
        if not 0.0 <= float(corner_angle) <= math.pi:
            raise ValueError(f'corner_angle must be in [0, pi] rad, got {corner_angle}')
        if window is not None:
            _check_positive('window', window)
        self.route = route
        self.law = law
        self.lookahead = float(lookahead)
        self.acceptance_radius = float(acceptance_radius)
        self.integral_gain = float(integral_gain) if law == 'ilos' else 0.0
        self.window = 2.0 * self.lookahead if window is None else float(window)
        self.reset_integral_at_corners = bool(reset_integral_at_corners)
        self.course_schedule = course_schedule
        #: False for the course law: its run ends at its duration, not at the route's end.
        self.reports_completion = law != COURSE_LAW
        self.critical_lookahead = None
        given = [x is not None for x in (zeta, omega_n, speed)]
        if any(given):
            if not all(given):
                raise ValueError('the stability check needs zeta, omega_n and speed together, got '
                                 f'zeta={zeta}, omega_n={omega_n}, speed={speed}')
            self.critical_lookahead = critical_lookahead(zeta, omega_n, speed, self.integral_gain)
            if not self.lookahead > self.critical_lookahead and not allow_unstable:
                limit = ('(U + 4 zeta^2 sigma) / (2 zeta omega_n)' if law == 'ilos'
                         else 'U / (2 zeta omega_n)')
                raise ValueError(
                    f'lookahead {self.lookahead:.2f} m is not above the stability limit '
                    f'{self.critical_lookahead:.2f} m = {limit} of the paired autopilot '
                    f'(zeta={zeta}, omega_n={omega_n} rad/s, speed={speed} m/s'
                    + (f', sigma={self.integral_gain} m/s' if law == 'ilos' else '')
                    + '; Angelopoulos 2011 eq. 34 / Simakis 1992 eq. 3.5 in metres). Increase '
                    'lookahead or pass '
                    'allow_unstable=True.')
        # Turn-rate lead (s): a heading loop of damping zeta and frequency omega_n follows a
        # heading ramp of rate r_d with a steady lag 2 zeta r_d / omega_n; on a path of
        # curvature kappa at speed U, r_d = U kappa, so leading the command by that much removes
        # the autopilot's share of the cross-track offset on arcs and curves.
        self.curvature_lead = bool(curvature_lead)
        if self.curvature_lead and self.critical_lookahead is None:
            raise ValueError('curvature_lead needs the paired autopilot: give zeta, omega_n and '
                             'speed')
        self._lead = 2.0 * zeta * speed / omega_n if self.curvature_lead else 0.0
        self.arc_los_point = bool(arc_los_point)
        if self.arc_los_point and (law != 'los' or self.curvature_lead):
            raise ValueError(f"arc_los_point is a variant of law 'los' without curvature_lead "
                             f'(law {law!r}, curvature_lead {self.curvature_lead})')
        # Smooth stretches between corners: first leg index of each.
        turn = np.abs(wrap_angle(route.start_angles[1:] - route.end_angles[:-1]))
        self._first = np.concatenate(([0], np.nonzero(turn > float(corner_angle))[0] + 1))
        self._last = np.concatenate((self._first[1:] - 1, [len(route.legs) - 1]))
        self.corner_legs = tuple(int(i) for i in self._first[1:])  # legs that start at a corner
        # Per stretch, as Python floats for the per-step work: (start s, end s) and
        # (last leg, its end north, its end east).
        c = route.cumulative.tolist()
        self._stretch_s = [(c[first], c[last + 1]) for first, last in zip(self._first.tolist(),
                                                                        self._last.tolist())]
        self._stretch_end = [(last, *route.legs[last].end.tolist()) for last in self._last.tolist()]
        self.reset()

    def reset(self, s=None):
        """Forget progress (next update searches the whole route), or restart at arc length s."""
        self._s = None if s is None else float(np.clip(s, 0.0, self.route.length))
        self._k = 0 if s is None else self._stretch_of(int(self.route.leg_at(self._s)))
        self._prev = None
        self.integral = 0.0
        self.finished = False

    @property
    def s(self):
        """Arc length of the current reference point (m), None before the first update.
        To change parameters mid-route build a new Guidance and call ``reset(s=old.s)``."""
        return self._s

    def _stretch_of(self, leg):
        return int(np.searchsorted(self._first, leg, side='right') - 1)

    def _bounds(self, k):
        return self._stretch_s[k]

    def _reached_end(self, k, proj, north, east):
        """Acceptance circle of the stretch's end point, or past the normal there. Both only
        count once the reference point has progressed close to the end (within pi R_acc of
        arc length, which any approach inside the circle satisfies, resp. clamped at the end),
        so a long arc whose end lies near its start does not switch at once."""
        leg, end_n, end_e = self._stretch_end[k]
        hi = self._stretch_s[k][1]
        if (math.hypot(north - end_n, east - end_e) <= self.acceptance_radius
                and hi - proj.s <= math.pi * self.acceptance_radius):
            return True
        return (proj.s >= hi - self.route.s_tol
                and self.route.along(leg, north, east) >= self.route.leg_lengths[leg])

    def update(self, north, east, psi=0.0, dt=0.0, t=None):
        """One guidance step at NED position (m) and heading psi (rad; only used for
        heading_error), dt (s) since the previous step (integrates ILOS), sim time t (s; the
        course law's schedule). -> GuidanceOutput."""
        if self.course_schedule is not None and t is None:
            raise ValueError('the course law needs the sim time t')
        n, e, psi, dt = float(north), float(east), float(psi), float(dt)
        isfinite = math.isfinite
        if not (isfinite(n) and isfinite(e) and isfinite(psi) and isfinite(dt)):
            raise ValueError(f'guidance update needs finite inputs, got north={north}, '
                             f'east={east}, psi={psi}, dt={dt}')
        if dt < 0.0:
            raise ValueError(f'dt must be >= 0 s, got {dt}')
        route = self.route
        if self._s is None:
            proj = route.project(n, e)
            self._k = self._stretch_of(proj.leg_index)
            # A start exactly on a corner belongs to the stretch that leaves it.
            if proj.s >= self._bounds(self._k)[1] and self._k < len(self._first) - 1:
                self._k += 1
        step = 0.0 if self._prev is None else math.hypot(n - self._prev[0], e - self._prev[1])
        w = max(self.window, 3.0 * step)
        hint = self._s
        while True:
            lo, hi = self._bounds(self._k)
            if hint is not None:
                proj = route.project(n, e, s_hint=hint, window=(w, w), bounds=(lo, hi))
            elif self._k != self._stretch_of(proj.leg_index):
                proj = route.project(n, e, bounds=(lo, hi))
            if self._k == len(self._first) - 1 or not self._reached_end(self._k, proj, n, e):
                break
            self._k += 1  # switch at the corner (acceptance circle or end normal)
            hint = self._bounds(self._k)[0]
            if self.reset_integral_at_corners:
                self.integral = 0.0
        if not self.finished and self._k == len(self._first) - 1:
            self.finished = bool(self._reached_end(self._k, proj, n, e))
        self._s, self._prev = proj.s, (n, e)

        alpha, err, d = proj.path_angle, proj.cross_track, self.lookahead
        leg = route.legs[proj.leg_index] if self.arc_los_point else None
        if isinstance(leg, Arc):
            pn, pe = circle_los_point(leg.center, leg.radius, leg.clockwise, n, e, d)
            psi_c = float(wrap_angle(math.atan2(pe - e, pn - n)))
        elif self.law == 'los':
            psi_c = float(wrap_angle(alpha - math.atan(err / d) + self._lead * proj.curvature))
        elif self.law == 'ilos':
            sigma = self.integral_gain
            psi_c = alpha - math.atan((err + sigma * self.integral) / d)
            if not self.finished:
                self.integral += dt * d * err / ((err + sigma * self.integral) ** 2 + d * d)
            psi_c = float(wrap_angle(psi_c + self._lead * proj.curvature))
        else:   # course: the schedule, as given (not wrapped)
            psi_c = course_at(*self.course_schedule, float(t))
        return GuidanceOutput(
            heading_cmd=psi_c, cross_track=err, s=proj.s, leg_index=proj.leg_index,
            distance_remaining=max(0.0, route.length - proj.s), finished=self.finished,
            path_angle=alpha, curvature=proj.curvature, integral=self.integral,
            heading_error=float(wrap_angle(psi_c - psi)))


def _check_positive(name, value, allow_zero=False):
    v = float(value)
    if not math.isfinite(v) or v < 0.0 or (v == 0.0 and not allow_zero):
        bound = '>= 0' if allow_zero else '> 0'
        raise ValueError(f'{name} must be a finite number {bound}, got {value}')
