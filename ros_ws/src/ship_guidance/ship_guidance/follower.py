"""Platoon follower guidance (pure): steer at the predecessor, keep the gap, fall back to the route.

The law is Angelopoulos 2011, eq. 31 (Sec. II.E.2, Fig. 8): the aim point is the predecessor,
d = clip(gap, d_min, d_max) ahead along the path at the predecessor's cross-track; on a straight
leg psi_c = alpha - atan((e_f - e_p) / d). The look-ahead must exceed U / (2 zeta omega_n)
(Angelopoulos 2011 eqs. 34, 41); ``no_amplification_spacing`` is the spacing above which
cross-track errors do not grow down the string. Ours, off by default: arc length extended past
the route's ends, integral action (Borhaug et al. 2008), aim at the path instead of the
predecessor, a turn-rate lead; always: a PI spacing law on the speed and a route fallback when
the predecessor's odometry is stale.

Units m, s, rad, m/s, rpm; positions and headings NED (psi clockwise from north); cross-track e
positive to STARBOARD of the path (path.py). No ROS here: follower_node.py wraps it.

Derivation, stability and string-gain bounds, the extensions and the fallback rules:
ros_ws/src/ship_guidance/doc/follower.md.
"""
import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from ship_sim.frames import wrap_angle

from .guidance import Guidance, GuidanceOutput
from .path import Route
from .string_stability import check_platoon, follower_loops

MODES = ('follow', 'route_fallback')
FOLLOW, FALLBACK = MODES

#: Default PI gains of the spacing law: k_p (1/s), k_i = k_p^2 / 4 (1/s^2, critically damped).
SPACING_KP = 0.005
SPACING_KI = SPACING_KP ** 2 / 4.0
#: Default bound of the speed correction around the feedforward (m/s).
MAX_SPEED_CORRECTION = 1.0
#: Default bound on the predecessor samples kept (the follower lagging that many in time).
TRACK_MAX_SAMPLES = 20000
#: What a follower steers at (doc/follower.md): Angelopoulos's law, or ILOS toward the path.
AIMS = ('predecessor', 'path')


# ---------------------------------------------------------------- the law (Angelopoulos 2011 eq. 31)

def follower_heading_straight(path_angle, cross_track, pred_cross_track, lookahead):
    """Angelopoulos 2011 eq. 31, nonlinear: psi_c = alpha - atan((e_f - e_p) / d) (rad, wrapped; broadcasts).

    path_angle alpha (rad), cross_track e_f of the follower and e_p of its predecessor (m,
    + starboard), lookahead d > 0 (m, the along-path distance to the predecessor)."""
    return wrap_angle(path_angle - np.arctan((np.asarray(cross_track) - pred_cross_track)
                                             / lookahead))


def aim_point(route, s, lookahead, offset):
    """Point at arc length s + lookahead on ``route``, ``offset`` metres to starboard of it.

    Beyond the route's end (before its start) the path continues along the end (start)
    tangent. Returns (north, east, path_angle) at that arc length (m, m, rad)."""
    target = float(s) + float(lookahead)
    n, e, a = route.point_at(target)
    n, e, a = float(n), float(e), float(a)
    extra = target - min(max(target, 0.0), route.length)
    ca, sa = math.cos(a), math.sin(a)
    # tangent (ca, sa); starboard normal (-sa, ca) in (north, east)
    return n + extra * ca - offset * sa, e + extra * sa + offset * ca, a


def extended_arc_length(route, out, north, east):
    """Arc length (m) of (north, east) with the route continued along its end (start) tangent:
    s + t . (p - P(s)) for a guidance.GuidanceOutput ``out`` (its s, path_angle). Equals out.s
    where the reference point is the foot of the normal; beyond a clamped end it adds the
    distance along the tangent there (negative before the start). Returns (s_x, along) (m)."""
    pn, pe, _ = route.point_at(out.s)
    a = out.path_angle
    along = math.cos(a) * (north - float(pn)) + math.sin(a) * (east - float(pe))
    return out.s + along, along


def no_amplification_spacing(zeta, omega_n, speed=1.0):
    """Smallest look-ahead d (m) with sup_nu |G(i nu)| <= 1 for the follower transfer function
    G = a0 / (s^3 + 2 zeta w s^2 + w^2 s + a0), a0 = U w^2 / d (doc/follower.md):
    4 zeta U / w for zeta >= 1/sqrt 2, else U / (w zeta (1 - zeta^2)).
    zeta > 0, omega_n > 0 (rad/s), speed U > 0 (m/s)."""
    z, w, u = float(zeta), float(omega_n), float(speed)
    if not (z > 0.0 and w > 0.0 and u > 0.0):
        raise ValueError(f'no_amplification_spacing needs zeta, omega_n, speed > 0; '
                         f'got {zeta}, {omega_n}, {speed}')
    if 2.0 * z * z >= 1.0:
        return 4.0 * z * u / w
    return u / (w * z * (1.0 - z * z))


def follower_gain(zeta, omega_n, lookahead, speed, frequency):
    """|G(i nu)| of the follower transfer function at angular frequencies nu (rad/s)."""
    w, d, u = float(omega_n), float(lookahead), float(speed)
    nu = np.asarray(frequency, dtype=float)
    a0 = u * w * w / d
    den = a0 - 2.0 * zeta * w * nu * nu + 1j * nu * (w * w - nu * nu)
    return np.abs(a0 / den)


# ---------------------------------------------------------------- spacing

def speed_to_shaft(speed_cmd, speed_nominal, shaft_nominal, shaft_min=None, shaft_max=None):
    """Shaft speed (rpm) for a speed command (m/s): n_nom U_c / U_nom, clipped to the limits."""
    n = float(shaft_nominal) * float(speed_cmd) / float(speed_nominal)
    if shaft_min is not None:
        n = max(n, float(shaft_min))
    if shaft_max is not None:
        n = min(n, float(shaft_max))
    return n


class SpacingController:
    """Speed command keeping the along-path gap at ``spacing`` (m); see doc/follower.md.

    kp (1/s) >= 0, ki (1/s^2) >= 0, max_correction (m/s) >= 0: bound of the PI part."""

    def __init__(self, spacing, kp=SPACING_KP, ki=SPACING_KI, max_correction=MAX_SPEED_CORRECTION):
        _check('spacing', spacing, positive=True)
        _check('spacing kp', kp)
        _check('spacing ki', ki)
        _check('max_speed_correction', max_correction)
        self.spacing = float(spacing)
        self.kp, self.ki, self.max_correction = float(kp), float(ki), float(max_correction)
        self.reset()

    def reset(self):
        self.integral = 0.0   # m s

    def update(self, gap, feedforward, dt):
        """gap (m), predecessor speed along the path (m/s), dt (s) -> (speed_cmd, gap_error)."""
        err = float(gap) - self.spacing
        trial = self.integral + err * max(float(dt), 0.0)
        raw = self.kp * err + self.ki * trial
        if abs(raw) > self.max_correction and raw * err > 0.0:
            raw = self.kp * err + self.ki * self.integral   # saturated: do not wind up
        else:
            self.integral = trial
        corr = min(max(raw, -self.max_correction), self.max_correction)
        return max(0.0, float(feedforward) + corr), err


# ---------------------------------------------------------------- predecessor samples

@dataclass(frozen=True, slots=True)
class TrackSample:
    """The predecessor at a queried time: NED position (m), velocity over ground (m/s), and the
    age (s) of the newest sample used (0 when the track reaches the query time)."""
    north: float
    east: float
    v_north: float
    v_east: float
    age: float


class PredecessorTrack:
    """Time-ordered predecessor odometry, evaluated at the follower's time (doc/follower.md)."""

    def __init__(self, max_samples=TRACK_MAX_SAMPLES):
        self._s = deque(maxlen=int(max_samples))
        self.n_restarts = 0
        # Samples missing from a stream stamped every `step` s (the smallest stamp difference
        # seen): a gap means the transport dropped some, and the interpolation between the
        # samples either side of it is no longer what it would have been.
        self.step = None
        self.n_missing = 0
        self._last_t = None

    def __len__(self):
        return len(self._s)

    @property
    def latest_t(self):
        """Stamp (s) of the newest sample, None if empty."""
        return self._s[-1][0] if self._s else None

    def clear(self):
        self._s.clear()

    def add(self, t, north, east, psi, u, v):
        """Add a sample: sim time t (s), NED pose (m, rad), body velocity over ground u, v (m/s).

        Returns True if the stamp went backwards (the track was cleared first). ValueError on
        non-finite input (the track is left as it was). ``n_missing`` counts the samples missing
        between consecutive stamps, on the stream's step (the smallest difference seen)."""
        vals = (float(t), float(north), float(east), float(psi), float(u), float(v))
        if not all(math.isfinite(x) for x in vals):
            raise ValueError(f'predecessor odometry is not finite: t={t}, north={north}, '
                             f'east={east}, psi={psi}, u={u}, v={v}')
        t, n, e, psi, u, v = vals
        self._count_missing(t)
        c, s = math.cos(psi), math.sin(psi)
        sample = (t, n, e, u * c - v * s, u * s + v * c)
        restarted = False
        if self._s and t < self._s[-1][0]:
            self._s.clear()
            self.n_restarts += 1
            restarted = True
        if self._s and t == self._s[-1][0]:
            self._s[-1] = sample
        else:
            self._s.append(sample)
        return restarted

    def _count_missing(self, t):
        last, self._last_t = self._last_t, t
        if last is None or t <= last:
            return
        gap = t - last
        if self.step is None or gap < self.step:
            self.step = gap
        # Stamps are k * dt in floating point: round the ratio, count a step only beyond 1.5.
        if gap > 1.5 * self.step:
            self.n_missing += round(gap / self.step) - 1

    def at(self, t):
        """TrackSample at sim time t, None if there is no sample. Samples older than the one
        at or before t are dropped (queries must not go back in time)."""
        s = self._s
        if not s:
            return None
        while len(s) >= 2 and s[1][0] <= t:
            s.popleft()
        t0, n0, e0, vn0, ve0 = s[0]
        if len(s) == 1 or t <= t0:
            dt = t - t0   # constant-velocity extrapolation (backwards if the track is ahead)
            return TrackSample(n0 + vn0 * dt, e0 + ve0 * dt, vn0, ve0, max(dt, 0.0))
        t1, n1, e1, vn1, ve1 = s[1]
        w = (t - t0) / (t1 - t0)
        return TrackSample(n0 + w * (n1 - n0), e0 + w * (e1 - e0),
                           vn0 + w * (vn1 - vn0), ve0 + w * (ve1 - ve0), 0.0)


# ---------------------------------------------------------------- the follower

@dataclass(frozen=True, slots=True)
class FollowerOutput:
    """One follower step. heading_cmd: NED heading command (rad, wrapped); route: the own
    vessel's progress on the route (guidance.GuidanceOutput; its heading_cmd is the fallback LOS
    command); mode: 'follow' | 'route_fallback'; mode_changed: differs from the previous step;
    reason: why the mode is route_fallback ('' when following); gap: s_p - s_f (m); gap_error:
    gap - spacing (m, > 0 too far behind); lookahead: the d used (m); speed_cmd: commanded speed
    (m/s); pred_cross_track: e_p (m); pred_age: age of the predecessor data (s); integral:
    e_int (s, 0 without integral action); s: the follower's arc length extended past the
    route's ends (m, ``extended_arc_length``). Quantities not defined in the current mode are
    NaN."""
    heading_cmd: float
    route: GuidanceOutput
    mode: str
    mode_changed: bool
    reason: str
    gap: float
    gap_error: float
    lookahead: float
    speed_cmd: float
    pred_cross_track: float
    pred_age: float
    integral: float = 0.0
    s: float = math.nan


class FollowerGuidance:
    """Follow the predecessor along ``route`` (Angelopoulos 2011 eq. 31), with spacing and stale fallback.

    Parameters (SI): spacing g_ref (m, > 0); min_lookahead d_min (m, > 0); max_lookahead d_max
    (m, >= d_min, None = no cap); fallback_lookahead (m, > 0: route LOS look-ahead when the
    predecessor is stale); predecessor_timeout (s of sim time, > 0); acceptance_radius (m, >= 0,
    corner switching as guidance.Guidance); spacing_kp, spacing_ki, max_speed_correction (see
    SpacingController); zeta, omega_n (rad/s), speed (m/s): the paired autopilot and speed for
    the stability check (all three or none); allow_unstable: accept d_min or the fallback
    look-ahead at or below U / (2 zeta omega_n); track: a PredecessorTrack to use (kept across
    route changes by the node), default a new one; aim 'predecessor' | 'path', integral_gain
    sigma (m/s, >= 0, 0 = none), curvature_lead (needs zeta, omega_n, speed): the extensions of
    doc/follower.md (defaults: Angelopoulos's law). Raises ValueError naming the parameter.
    """

    def __init__(self, route, spacing, *, min_lookahead, fallback_lookahead, max_lookahead=None,
                 predecessor_timeout=5.0, acceptance_radius=0.0, spacing_kp=SPACING_KP,
                 spacing_ki=SPACING_KI, max_speed_correction=MAX_SPEED_CORRECTION,
                 zeta=None, omega_n=None, speed=None, allow_unstable=False, track=None,
                 aim='predecessor', integral_gain=0.0, curvature_lead=False):
        if not isinstance(route, Route):
            raise ValueError('route must be a ship_guidance.path.Route, '
                             f'got {type(route).__name__}')
        if aim not in AIMS:
            raise ValueError(f'aim must be one of {AIMS}, got {aim!r}')
        _check('integral_gain', integral_gain)
        self.aim = aim
        self.integral_gain = float(integral_gain)
        _check('min_lookahead', min_lookahead, positive=True)
        _check('fallback_lookahead', fallback_lookahead, positive=True)
        _check('predecessor_timeout', predecessor_timeout, positive=True)
        if max_lookahead is not None:
            _check('max_lookahead', max_lookahead, positive=True)
            if max_lookahead < min_lookahead:
                raise ValueError(f'max_lookahead {max_lookahead} m must be >= min_lookahead '
                                 f'{min_lookahead} m')
        self.route = route
        self.spacing = SpacingController(spacing, spacing_kp, spacing_ki, max_speed_correction)
        self.min_lookahead = float(min_lookahead)
        self.max_lookahead = None if max_lookahead is None else float(max_lookahead)
        self.fallback_lookahead = float(fallback_lookahead)
        self.timeout = float(predecessor_timeout)
        self.track = PredecessorTrack() if track is None else track
        self.critical_lookahead = None
        self.no_amplification_spacing = None
        self.warnings = []
        given = [x is not None for x in (zeta, omega_n, speed)]
        if any(given) and not all(given):
            raise ValueError('the stability check needs zeta, omega_n and speed together, got '
                             f'zeta={zeta}, omega_n={omega_n}, speed={speed}')
        if all(given):
            self._check_stability(zeta, omega_n, speed, allow_unstable)
        self.curvature_lead = bool(curvature_lead)
        if self.curvature_lead and not all(given):
            raise ValueError('curvature_lead needs the paired autopilot: give zeta, omega_n and '
                             'speed')
        # Turn-rate lead (s), as guidance.Guidance: the heading loop's lag behind a command
        # turning at U kappa is 2 zeta U kappa / omega_n.
        self._lead = 2.0 * zeta * speed / omega_n if self.curvature_lead else 0.0
        if self.spacing.spacing < self.min_lookahead:
            self.warnings.append(
                f'spacing {self.spacing.spacing:.1f} m is below min_lookahead '
                f'{self.min_lookahead:.1f} m: at the set gap the follower aims beyond its '
                'predecessor (Angelopoulos 2011 eq. 31 then holds with d = min_lookahead, not the gap)')
        # Own progress and the fallback LOS; the predecessor's projection (its own progress
        # state, so neither jumps to another branch of the route).
        self._own = Guidance(route, 'los', self.fallback_lookahead, acceptance_radius)
        self._pred = Guidance(route, 'los', self.fallback_lookahead, acceptance_radius)
        self.reset()

    def _check_stability(self, zeta, omega_n, speed, allow_unstable):
        # With integral action the limit is ILOS's (U + 4 zeta^2 sigma) / (2 zeta omega_n)
        # (los.critical_lookahead), i.e. the LOS limit at the speed U + 4 zeta^2 sigma; the
        # fallback is plain LOS.
        loops = follower_loops(zeta, omega_n, speed, self.min_lookahead,
                               self.fallback_lookahead, self.integral_gain)
        checks = check_platoon(loops)
        self.critical_lookahead = checks[0].critical
        self.no_amplification_spacing = no_amplification_spacing(zeta, omega_n, speed)
        bad = [c for c in checks if not c.ok]
        if bad and not allow_unstable:
            raise ValueError('; '.join(c.message() for c in bad)
                             + f' (U / (2 zeta omega_n) with zeta={zeta}, omega_n={omega_n} '
                             f'rad/s, speed={speed} m/s; Angelopoulos 2011 eqs. 34, 41). Increase it or '
                             'pass allow_unstable=True.')
        if self.spacing.spacing < self.no_amplification_spacing:
            self.warnings.append(
                f'spacing {self.spacing.spacing:.1f} m is below '
                f'{self.no_amplification_spacing:.1f} m: cross-track disturbances can grow '
                'from vessel to vessel before they decay (follower gain |G(i nu)| > 1)')

    def reset(self):
        """Forget progress, the spacing integral and the mode (the track is kept)."""
        self._own.reset()
        self._pred.reset()
        self.spacing.reset()
        self.integral = 0.0   # e_int (s)
        self._t_prev = None
        self.mode = None
        self.speed_cmd = math.nan

    def add_predecessor(self, t, north, east, psi, u, v):
        """Predecessor odometry (sim time s, NED pose, body velocity over ground). Returns True
        if its time went backwards (track restarted). ValueError on non-finite input."""
        return self.track.add(t, north, east, psi, u, v)

    def update(self, t, north, east, psi=0.0):
        """One step at the follower's sim time t (s), NED position (m) and heading (rad).
        -> FollowerOutput. ValueError on non-finite input (the state is not changed)."""
        t, n, e = float(t), float(north), float(east)
        if not math.isfinite(t):
            raise ValueError(f'follower update needs a finite time, got t={t}')
        if self._t_prev is not None and t < self._t_prev:
            self.reset()   # own simulator restarted
        dt = 0.0 if self._t_prev is None else t - self._t_prev
        own = self._own.update(n, e, psi, dt)   # raises on bad input before any state change
        self._t_prev = t
        sample = self.track.at(t)
        nan = math.nan
        if sample is None:
            mode, reason = FALLBACK, 'no predecessor odometry yet'
        elif sample.age > self.timeout:
            mode, reason = FALLBACK, (f'predecessor odometry is {sample.age:.1f} s old '
                                      f'(timeout {self.timeout:g} s)')
        else:
            mode, reason = FOLLOW, ''
        changed = mode != self.mode
        self.mode = mode
        s_f, beyond = extended_arc_length(self.route, own, n, e)
        if mode == FALLBACK:
            return FollowerOutput(own.heading_cmd, own, mode, changed, reason, nan, nan,
                                  self.fallback_lookahead, self.speed_cmd, nan,
                                  nan if sample is None else sample.age, self.integral, s_f)
        p = self._pred.update(sample.north, sample.east, 0.0, dt)
        s_p, _ = extended_arc_length(self.route, p, sample.north, sample.east)
        gap = s_p - s_f
        d = max(gap, self.min_lookahead)
        if self.max_lookahead is not None:
            d = min(d, self.max_lookahead)
        ef, sigma = own.cross_track, self.integral_gain
        if self.aim == 'predecessor':
            offset = p.cross_track - sigma * self.integral
            an, ae, _ = aim_point(self.route, s_f, d, offset)
            psi_c = math.atan2(ae - e, an - n)
        else:
            offset = -sigma * self.integral
            psi_c = own.path_angle - math.atan((ef - offset) / d)
        if sigma > 0.0:
            self.integral += dt * d * ef / ((ef - offset) ** 2 + d * d)
        # Beyond a clamped end the reference is the (straight) tangent line.
        kappa = own.curvature if abs(beyond) <= self.route.s_tol else 0.0
        psi_c = float(wrap_angle(psi_c + self._lead * kappa))
        along = sample.v_north * math.cos(p.path_angle) + sample.v_east * math.sin(p.path_angle)
        self.speed_cmd, gap_error = self.spacing.update(gap, along, dt)
        return FollowerOutput(psi_c, own, mode, changed, reason, gap, gap_error, d,
                              self.speed_cmd, p.cross_track, sample.age, self.integral, s_f)


def _check(name, value, positive=False):
    v = float(value)
    if not math.isfinite(v) or v < 0.0 or (positive and v == 0.0):
        raise ValueError(f'{name} must be a finite number {"> 0" if positive else ">= 0"}, '
                         f'got {value}')
