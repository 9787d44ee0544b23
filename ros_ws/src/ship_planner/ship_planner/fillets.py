"""Round the corners of a waypoint route with circular fillets (line - arc - line, tangent).

Source: Lee 2004, sec. 4 (Figs. 4.4-4.6, eqs. 4.21-4.24): between two
straight legs WP1-WP2 and WP2-WP3 the ship follows a turning circle of radius R (the ship's
turning radius at a chosen rudder angle, Fig. 4.5) that it enters at P_in on the first leg and
leaves at P_out on the second; its LOS point then moves on that circle (eq. 4.24). The OCR of
those equations is unreadable, so the construction below is the standard tangent-circle
geometry, which is what Fig. 4.6 draws. NED frame (x north, y east), metres, radians.

For a corner P with incoming course chi_in, outgoing course chi_out and course change
Delta = wrap(chi_out - chi_in) (> 0: starboard turn, < 0: port turn):

    t       = R tan(|Delta| / 2)              distance from P to each tangent point
    P_in    = P - t u_in,   P_out = P + t u_out
    centre  = P_in + R n,   n = unit normal of u_in towards the turn (starboard if Delta > 0)
    sweep   = |Delta|                          the arc turns the course by exactly Delta

The radius may be given, or taken from the vessel itself as Lee 2004 does (Fig. 4.5: the
turning circle for a constant rudder angle): ``rudder_turn_radius`` runs the chosen plant
model's steady turn at that rudder (ship_sim.maneuvers.steady_turn) and returns U/|r|, for a
starboard or a port turn separately (the MSS hulls are not symmetric). The LOS point on the
circle (eq. 4.24) is ship_guidance.los.circle_los_point, steered at by the guidance's
``arc_los_point`` option.

A fillet must fit: on every straight leg the tangent lengths taken from both of its ends must
not exceed the leg's length; otherwise FilletError names the corner and the largest radius
that would fit. A straight-through corner (Delta = 0) needs no arc; a reversal (|Delta| = pi)
cannot be filleted.
"""
import functools
import math
from dataclasses import dataclass

import numpy as np

from ship_guidance.path import Arc, Line, Route
from ship_sim.frames import wrap_angle

_STRAIGHT_RAD = 1e-9        # below this course change a corner is straight
_REVERSAL_RAD = 1e-6        # closer than this to pi the tangent length is unbounded
_LENGTH_EPS_M = 1e-6        # straight pieces shorter than this after trimming are dropped


class FilletError(ValueError):
    """A fillet does not fit or cannot be built; ``corner`` is the index of the junction
    (junction i joins segment i and segment i + 1)."""

    def __init__(self, message, corner):
        self.corner = corner
        super().__init__(message)


@dataclass(frozen=True)
class LineSpec:
    """A straight leg from start to end, (north, east) m; label names it in messages."""
    start: tuple
    end: tuple
    label: str = ''

    @property
    def length(self):
        return float(np.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1]))


@dataclass(frozen=True)
class ArcSpec:
    """A circular leg about centre; clockwise seen from above = starboard turn (NED)."""
    start: tuple
    end: tuple
    center: tuple
    clockwise: bool
    label: str = ''


@dataclass(frozen=True)
class Fillet:
    """One rounded corner: tangent points, centre, direction, course change (rad), tangent length."""
    entry: tuple
    exit: tuple
    center: tuple
    clockwise: bool
    course_change: float
    tangent_length: float


def suggest_fillet_radius(turning_diameter_m, rudder_fraction=0.5):
    """Fillet radius (m) for a vessel whose steady turning circle has this diameter at full rudder.

    A path bent at exactly the minimum turning radius needs full rudder for the whole turn and
    leaves nothing to correct errors. In the linear Nomoto steady state r = K delta the turn
    radius U / r scales as 1 / delta, so a turn that needs only a fraction f of full rudder has
    radius (D / 2) / f. The default f = 0.5 gives R = D; for the MSS Mariner (steady radius
    556 m, tactical diameter 1029 m at 35 deg, tests/data/mss_golden/maneuvers.json) that is ~1000-1100 m.
    A tactical diameter may be passed instead of the steady diameter (it is ~ 5-10 % larger).
    """
    d = float(turning_diameter_m)
    f = float(rudder_fraction)
    if not np.isfinite(d) or d <= 0.0:
        raise ValueError(f'turning_diameter_m must be a positive finite number of metres, got {turning_diameter_m}')
    if not np.isfinite(f) or not 0.0 < f <= 1.0:
        raise ValueError(f'rudder_fraction must be in (0, 1], got {rudder_fraction}')
    return 0.5 * d / f


@functools.lru_cache(maxsize=64)
def rudder_turn_radius(model_name, rudder_deg, starboard):
    """Steady turning radius (m) of plant model ``model_name`` (ship_sim.models, default
    parameters) holding |rudder_deg| of rudder to starboard (starboard=True) or to port.

    Lee 2004, Ch. 4 (Fig. 4.5): the circle between two legs is the ship's own turning circle
    at a chosen rudder angle, so the turn needs that rudder and leaves the rest of the range to
    correct errors. ValueError for an unknown model or a rudder outside (0, rudder_max].
    """
    from ship_sim.maneuvers import steady_turn
    from ship_sim.models import make_model
    model = make_model(model_name)
    a = float(rudder_deg)
    limit = math.degrees(model.rudder_max)
    if not math.isfinite(a) or not 0.0 < a <= limit + 1e-9:
        raise ValueError(f'turn rudder angle must be in (0, {limit:g}] deg for model {model_name}, got {rudder_deg}')
    # unified rudder sign: positive turns to port
    return steady_turn(model, math.radians(-a if starboard else a)).radius_m


def fillet_corner(p_prev, p_corner, p_next, radius):
    """The fillet of the given radius at p_corner between legs p_prev->p_corner->p_next.

    Returns None for a straight-through corner. Raises ValueError for a reversal or a bad radius.
    Does not check that the fillet fits on the legs (see fillet_segments).
    """
    r = float(radius)
    if not np.isfinite(r) or r <= 0.0:
        raise ValueError(f'fillet radius must be a positive finite number of metres, got {radius}')
    p_prev, p_corner, p_next = (np.asarray(p, dtype=float) for p in (p_prev, p_corner, p_next))
    d_in, d_out = p_corner - p_prev, p_next - p_corner
    u_in = d_in / np.hypot(*d_in)
    u_out = d_out / np.hypot(*d_out)
    delta = float(wrap_angle(np.arctan2(u_out[1], u_out[0]) - np.arctan2(u_in[1], u_in[0])))
    if abs(delta) < _STRAIGHT_RAD:
        return None
    if abs(delta) > np.pi - _REVERSAL_RAD:
        raise ValueError('the route reverses its course here (180 deg turn); a fillet cannot round it')
    t = r * np.tan(0.5 * abs(delta))
    entry = p_corner - t * u_in
    exit_ = p_corner + t * u_out
    starboard = np.array([-u_in[1], u_in[0]])   # right-hand normal in NED (north, east)
    center = entry + (r if delta > 0.0 else -r) * starboard
    return Fillet(tuple(entry), tuple(exit_), tuple(center), delta > 0.0, delta, float(t))


def fillet_segments(segments, radii, corner_labels=None):
    """Round every junction between two straight segments whose radius is > 0.

    segments       list of LineSpec / ArcSpec, each starting where the previous one ends
    radii          one radius (m) per junction (len(segments) - 1); 0 or None: keep the corner
    corner_labels  optional names of the junctions for messages (e.g. "waypoint 3 (line 12)")
    Returns a new list of LineSpec / ArcSpec. Junctions next to an arc are never rounded.
    """
    n_junction = len(segments) - 1
    if len(radii) != n_junction:
        raise ValueError(f'need one radius per junction ({n_junction}), got {len(radii)}')
    labels = list(corner_labels) if corner_labels is not None else [f'corner {i + 1}' for i in range(n_junction)]
    fillets = [None] * n_junction
    for j, radius in enumerate(radii):
        if radius is None or radius == 0.0:
            continue
        a, b = segments[j], segments[j + 1]
        if not (isinstance(a, LineSpec) and isinstance(b, LineSpec)):
            continue
        try:
            fillets[j] = fillet_corner(a.start, a.end, b.end, radius)
        except ValueError as exc:
            raise FilletError(f'cannot round {labels[j]}: {exc}', j) from None

    def taken(j):
        return fillets[j].tangent_length if 0 <= j < n_junction and fillets[j] is not None else 0.0

    # Every straight leg must hold the tangent lengths of both of its ends.
    for i, seg in enumerate(segments):
        if not isinstance(seg, LineSpec):
            continue
        t_start, t_end = taken(i - 1), taken(i)
        length = seg.length
        if t_start + t_end > length + _LENGTH_EPS_M:
            j = i if t_end > 0.0 else i - 1           # blame the corner at the far end when it has a fillet
            t_other = t_start if j == i else t_end
            f = fillets[j]
            r = float(radii[j])
            tan_j = np.tan(0.5 * abs(f.course_change))
            r_alone = max(length - t_other, 0.0) / tan_j
            if t_other > 0.0:
                k = i - 1 if j == i else i
                other_label = labels[k]
                tan_k = np.tan(0.5 * abs(fillets[k].course_change))
                hint = (f' (the fillet at {other_label} already takes {t_other:.1f} m of it); the largest radius '
                        f'that fits both corners is {length / (tan_j + tan_k):.1f} m')
                if r_alone > 0.0:
                    hint += f', or {r_alone:.1f} m at {labels[j]} alone'
            else:
                hint = f'; the largest radius that fits there is {r_alone:.1f} m'
            raise FilletError(
                f'fillet of radius {r:g} m at {labels[j]} does not fit: a course change of '
                f'{np.degrees(abs(f.course_change)):.1f} deg needs {f.tangent_length:.1f} m of straight leg '
                f'before and after the corner, but {seg.label or f"segment {i + 1}"} is {length:.1f} m long'
                f'{hint}', j)

    out = []
    for i, seg in enumerate(segments):
        if isinstance(seg, LineSpec):
            start = fillets[i - 1].exit if i > 0 and fillets[i - 1] is not None else seg.start
            end = fillets[i].entry if i < n_junction and fillets[i] is not None else seg.end
            if np.hypot(end[0] - start[0], end[1] - start[1]) > _LENGTH_EPS_M:
                out.append(LineSpec(tuple(start), tuple(end), seg.label))
        else:
            out.append(seg)
        if i < n_junction and fillets[i] is not None:
            f = fillets[i]
            out.append(ArcSpec(f.entry, f.exit, f.center, f.clockwise, f'fillet at {labels[i]}'))
    return out


def polyline_segments(points, labels=None):
    """Straight segments through points ((N, 2) north, east). labels name the legs."""
    pts = np.asarray(points, dtype=float)
    return [LineSpec(tuple(pts[i]), tuple(pts[i + 1]), labels[i] if labels else f'leg {i + 1}')
            for i in range(len(pts) - 1)]


def fillet_polyline(points, radius, corner_labels=None):
    """Straight legs through points ((N, 2) north, east, m) with every inner corner rounded.

    radius is one number (m) for all corners or a sequence of N - 2 (0 keeps a corner).
    Returns a list of LineSpec / ArcSpec; build a Route with segments_to_route.
    """
    pts = np.asarray(points, dtype=float)
    n_corner = max(len(pts) - 2, 0)
    radii = [radius] * n_corner if np.ndim(radius) == 0 else list(radius)
    if corner_labels is None:
        corner_labels = [f'waypoint {i + 1}' for i in range(1, len(pts) - 1)]
    return fillet_segments(polyline_segments(pts), radii, corner_labels)


def segments_to_route(segments):
    """LineSpec / ArcSpec list -> ship_guidance.path.Route (NED)."""
    legs = []
    for seg in segments:
        if isinstance(seg, LineSpec):
            legs.append(Line(seg.start, seg.end))
        else:
            legs.append(Arc(seg.start, seg.end, seg.center, seg.clockwise))
    return Route(legs)
