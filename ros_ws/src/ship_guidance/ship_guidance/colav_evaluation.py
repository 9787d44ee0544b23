"""Evaluation of a collision-avoidance run from its tracks (pure): safety, COLREGs compliance,
path deviation, time lost and the return to the route.

After the protocol of Woerner et al. 2018 ("Quantifying protocol evaluation for autonomous
collision avoidance", Autonomous Robots) with the parameter names and penalty weights the NTNU
COLAV simulator's evaluator publishes (config/evaluator.yaml: the 30 deg apparent course
change, the halved speed, the 10 deg starboard-manoeuvre limit, the gamma weights and the
COLREGs stage ranges), simplified to step penalties that can be checked by hand
(doc/colav_benchmark.md has every parameter, its source and the composition of the score).

The evaluator takes the ships' dimensions (``ShipDimensions``), never a collision-avoidance
method's parameters, so it judges a method against the ships rather than against the method's
own set-points.

Per target, from the own track, the target track (same sample times), the own ship's track in
the same run without traffic (the reference) and both ships' dimensions:

- safety:
    collision: the hull outlines touch at some sample. Each hull is approximated by the
      rectangle length x beam centred on the track point and turned to the heading (the
      rectangle contains the pointed hull nav_display draws, so this errs towards a collision);
    near miss: one ship's centre inside the other's ship domain, Fujii and Tanaka's ellipse
      (1971, "Traffic capacity", Journal of Navigation 24(4)) of semi-axes ``domain_along``
      ship lengths ahead / astern and ``domain_across`` lengths abeam, centred on the ship;
    below safe: the centre distance below ``r_min_m`` (a reported statistic of the passing
      distance, not a failure);
  safety score 1 - (gamma_min [below safe] + gamma_nm [near miss] + gamma_col [collision]);
- situation and role: classified at the first sample (ship_guidance.colregs);
- t_cpa: the time of the target's closest approach to the reference track (when it would have
  been closest had the own ship not manoeuvred; the own manoeuvre moves the actual closest
  approach, so the give-way window counts back from this one);
- own manoeuvre: the own course's departure from the reference's at the same time (rad, +
  starboard) and the speed ratio to the reference; the manoeuvre starts at the first sample
  where the departure reaches ``delta_course_md`` or the speed has dropped by
  ``delta_speed_md``;
- COLREGs stage (Woerner's stages by range, ``colregs_stage``): 1 beyond
  ``r_colregs_2_max_m`` (no rule applies yet), 2 up to it (the give-way ship acts, the
  stand-on ship keeps course and speed, Rule 17(a)(i)), 3 within ``r_colregs_3_max_m`` (the
  stand-on ship may act alone, 17(a)(ii)), 4 within ``colregs_4_lengths`` own ship lengths
  (it must act, 17(b));
- rule compliance score 1 - the sum of the penalties below (floored at 0):

  give-way (head-on, crossing give-way, overtaking):
    late or none: no manoeuvre starting at least ``early_s`` before t_cpa (Rule 16,
      Rule 8(a) "in ample time")                                            gamma_late
    not apparent: the largest departure before the closest approach below ``delta_course_app``
      and no speed reduction to ``1 - delta_speed_reduction_app`` (Rule 8(b))    gamma_na
    not to starboard (head-on, crossing): the first departure beyond ``theta_sm_lim`` is to
      port, or there is none (Rules 14, 15)                                 gamma_ho_nsm
    starboard to starboard (head-on): the target on the own starboard side at the closest
      approach (Rule 14)                                                    gamma_ho_sts
    crossing ahead (crossing give-way): the own ship ahead of the target (in front of the line
      through the target across its course) at the closest approach (Rule 15)  gamma_ahead_cr
  stand-on (crossing stand-on, being overtaken):
    not holding: a manoeuvre starting while the target is still in stage 1 or 2 (range beyond
      ``r_colregs_3_max_m``, Rule 17(a)(i))                                 gamma_so
    not acting: the target reaches stage 4 before any manoeuvre although, unmanoeuvred, it
      would have come inside a domain (Rule 17(b): the stand-on ship must then act; ours,
      weighted as not holding)                                              gamma_so
    port turn (crossing stand-on): the first departure beyond ``theta_sm_lim`` is to port
      (Rule 17(c))                                                          gamma_ho_nsm

- path deviation: the largest distance of the own track from the reference track; time lost:
  the run's end time minus the time the reference reached the along-track progress the own
  ship made by then (progress along the reference's overall direction);
- return to route: from the last target's closest approach, the time until the own ship is
  within ``route_band_m`` of its route (a polyline; by default the reference's straight line
  from first to last point) and stays there for ``route_dwell_s``; None (never) if the run
  ends before.

Tracks are arrays over the same sample times: t (s), north, east (m, NED), course (rad,
clockwise from north), speed (m/s) and optionally heading (rad; the course when not given).
Courses are over ground (the target classification and the departure use them); the hull
outlines and the domains are turned to the heading.
"""
from dataclasses import dataclass

import numpy as np

from ship_guidance import colregs
from ship_guidance.cpa import velocity
from ship_guidance.nav_display import DEFAULT_BEAM_RATIO

#: Largest spacing (m) of the reference points path_deviation measures against.
DEVIATION_STEP_M = 1.0
GIVE_WAY_SITUATIONS = ('head-on', 'crossing-give-way', 'overtaking')
STAND_ON_SITUATIONS = ('crossing-stand-on', 'being-overtaken')


@dataclass(frozen=True)
class ShipDimensions:
    """Length (bow to stern) and beam (m) of a hull; the beam defaults to the length times
    nav_display's DEFAULT_BEAM_RATIO (the outline the map draws)."""
    length_m: float
    beam_m: float = None

    def __post_init__(self):
        if not (np.isfinite(self.length_m) and self.length_m > 0.0):
            raise ValueError(f'ship length must be a positive number, got {self.length_m!r}')
        if self.beam_m is None:
            object.__setattr__(self, 'beam_m', self.length_m * DEFAULT_BEAM_RATIO)

    @property
    def half_diagonal_m(self):
        return 0.5 * float(np.hypot(self.length_m, self.beam_m))


@dataclass(frozen=True)
class EvaluationParams:
    """Evaluator parameters (doc/colav_benchmark.md gives each one's source). Distances that
    judge safety come from the ships' dimensions (ShipDimensions); the angles, fractions and
    weights are the NTNU COLAV simulator's evaluator.yaml."""
    r_min_m: float = 926.0              # safe passing distance, 0.5 NM: a reported statistic
    domain_along: float = 4.0           # Fujii domain semi-axis ahead / astern, ship lengths
    domain_across: float = 1.6          # Fujii domain semi-axis abeam, ship lengths
    r_colregs_2_max_m: float = 5000.0   # stage 2 begins (NTNU AutoVerification, AIS ships)
    r_colregs_3_max_m: float = 3000.0   # stage 3: the stand-on ship may act (17(a)(ii))
    colregs_4_lengths: float = 4.0      # stage 4: the stand-on ship must act (17(b))
    delta_course_md_deg: float = 2.0    # minimum detectable course change
    delta_speed_md: float = 0.2         # minimum detectable speed change (fraction)
    delta_course_app_deg: float = 30.0  # readily apparent course change
    delta_speed_reduction_app: float = 0.5  # apparent speed reduction (fraction)
    theta_sm_lim_deg: float = 10.0      # departure beyond which a manoeuvre has a side
    early_s: float = 300.0              # give-way action at least this long before the CPA
    route_band_m: float = 200.0         # back on the route: within this of the reference track
    route_dwell_s: float = 60.0         # ... for this long
    gamma_min: float = 0.2
    gamma_nm: float = 0.3
    gamma_col: float = 0.5
    gamma_late: float = 0.5
    gamma_na: float = 0.5               # NTNU gamma_na_delta_chi
    gamma_ho_nsm: float = 0.4
    gamma_ho_sts: float = 0.6
    gamma_ahead_cr: float = 0.5
    gamma_so: float = 0.5               # NTNU gamma_so_delta_chi


@dataclass(frozen=True)
class Track:
    """A ship's samples: t (s), north, east (m), course (rad NED), speed (m/s), heading (rad
    NED; None: the course)."""
    t: np.ndarray
    north: np.ndarray
    east: np.ndarray
    course: np.ndarray
    speed: np.ndarray
    heading: np.ndarray = None

    @classmethod
    def of(cls, t, north, east, course, speed, heading=None):
        arrays = [np.asarray(a, dtype=float) for a in (t, north, east, course, speed)]
        return cls(*arrays, None if heading is None else np.asarray(heading, dtype=float))

    @property
    def p(self):
        return np.stack((self.north, self.east), axis=-1)

    @property
    def psi(self):
        return self.course if self.heading is None else self.heading


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


def departure(own, reference):
    """(course departure (rad, + starboard), speed ratio) of ``own`` from ``reference`` at the
    same times (the reference interpolated on the own sample times)."""
    chi_ref = np.interp(own.t, reference.t, np.unwrap(reference.course))
    u_ref = np.interp(own.t, reference.t, reference.speed)
    return _wrap(own.course - chi_ref), own.speed / np.maximum(u_ref, 1e-9)


def manoeuvre_start(dchi, ratio, params):
    """Index of the first sample where the manoeuvre is detectable, or None."""
    hit = (np.abs(dchi) >= np.radians(params.delta_course_md_deg)) | \
        (ratio <= 1.0 - params.delta_speed_md)
    return int(np.argmax(hit)) if hit.any() else None


def first_side(dchi, params, upto):
    """+1 / -1: the side of the first departure beyond theta_sm_lim before index ``upto``; 0
    if none."""
    beyond = np.abs(dchi[:upto + 1]) >= np.radians(params.theta_sm_lim_deg)
    if not beyond.any():
        return 0
    return 1 if dchi[int(np.argmax(beyond))] > 0.0 else -1


def unmanoeuvred_cpa_time(target, reference):
    """Time (s) of the target's closest approach to the reference track (the own ship without
    a manoeuvre): the moment the early / stand-on windows count back from."""
    n = np.interp(target.t, reference.t, reference.north)
    e = np.interp(target.t, reference.t, reference.east)
    return float(target.t[int(np.argmin(np.hypot(target.north - n, target.east - e)))])


def hull_rectangles(track, dims, index=None):
    """shapely Polygons of the hull rectangles (length x beam, centred on the track point,
    turned to the heading) at the samples ``index`` (all when None)."""
    import shapely
    idx = slice(None) if index is None else index
    psi = track.psi[idx]
    fwd = np.stack((np.cos(psi), np.sin(psi)), axis=-1) * (0.5 * dims.length_m)
    stb = np.stack((-np.sin(psi), np.cos(psi)), axis=-1) * (0.5 * dims.beam_m)
    c = track.p[idx]
    corners = np.stack((c + fwd + stb, c + fwd - stb, c - fwd - stb, c - fwd + stb), axis=-2)
    return shapely.polygons(corners)


def hull_contact(own, target, own_dims, target_dims):
    """(collision, smallest distance between the hull rectangles m): the rectangles are
    compared only where the centres are close enough for them to touch or to come closer than
    at the smallest centre distance (each rectangle lies within its half-diagonal of its
    centre)."""
    import shapely
    d = np.hypot(target.north - own.north, target.east - own.east)
    reach = own_dims.half_diagonal_m + target_dims.half_diagonal_m
    near = np.flatnonzero(d <= min(reach, float(d.min()) + reach))
    near = near if near.size else np.array([int(np.argmin(d))])
    a, b = hull_rectangles(own, own_dims, near), hull_rectangles(target, target_dims, near)
    return bool(shapely.intersects(a, b).any()), float(shapely.distance(a, b).min())


def domain_index(observer, other, dims, params):
    """Per sample, where ``other``'s centre lies in ``observer``'s ship domain (Fujii's ellipse
    of ``dims``): sqrt((x / a)^2 + (y / b)^2) with x ahead, y abeam, a = domain_along L,
    b = domain_across L; below 1 inside the domain."""
    rel = other.p - observer.p
    psi = observer.psi
    x = rel[:, 0] * np.cos(psi) + rel[:, 1] * np.sin(psi)
    y = -rel[:, 0] * np.sin(psi) + rel[:, 1] * np.cos(psi)
    return np.hypot(x / (params.domain_along * dims.length_m),
                    y / (params.domain_across * dims.length_m))


def unmanoeuvred_near_miss(target, reference, own_dims, target_dims, params):
    """True if the target would have come inside a domain (its or the own ship's) had the own
    ship not manoeuvred (the reference track on the target's sample times): the risk that makes
    the stand-on ship's action in stage 4 a duty."""
    t = target.t
    ref = Track.of(t, np.interp(t, reference.t, reference.north),
                   np.interp(t, reference.t, reference.east),
                   np.interp(t, reference.t, np.unwrap(reference.course)),
                   np.interp(t, reference.t, reference.speed),
                   np.interp(t, reference.t, np.unwrap(reference.psi)))
    return bool(min(domain_index(ref, target, own_dims, params).min(),
                    domain_index(target, ref, target_dims, params).min()) < 1.0)


def colregs_stage(range_m, own_dims, params=None):
    """COLREGs stage 1-4 of a target at ``range_m`` (module docstring)."""
    p = params or EvaluationParams()
    if range_m <= p.colregs_4_lengths * own_dims.length_m:
        return 4
    if range_m <= p.r_colregs_3_max_m:
        return 3
    return 2 if range_m <= p.r_colregs_2_max_m else 1


def evaluate_target(own, target, reference, own_dims, target_dims=None, params=None,
                    situation=None):
    """dict of the metrics of one target (see the module docstring); ``target_dims`` defaults
    to the own ship's, ``situation`` overrides the classification at the first sample."""
    p = params or EvaluationParams()
    target_dims = target_dims or own_dims
    d = np.hypot(target.north - own.north, target.east - own.east)
    k = int(np.argmin(d))
    d_min = float(d[k])
    collision, clearance = hull_contact(own, target, own_dims, target_dims)
    domain = float(min(domain_index(own, target, own_dims, p).min(),
                       domain_index(target, own, target_dims, p).min()))
    near_miss = collision or domain < 1.0
    if situation is None:
        v_own = velocity(own.course[0], own.speed[0])
        v_tgt = velocity(target.course[0], target.speed[0])
        code = colregs.classify(own.p[0], own.course[0], v_own, target.p[0],
                                target.course[0], v_tgt)
        situation = colregs.SITUATIONS[int(code)]
    dchi, ratio = departure(own, reference)
    start = manoeuvre_start(dchi[:k + 1], ratio[:k + 1], p)
    t_cpa = unmanoeuvred_cpa_time(target, reference)
    t_start = None if start is None else float(own.t[start])
    stage = None if start is None else colregs_stage(float(d[start]), own_dims, p)
    penalties = {}
    if situation in GIVE_WAY_SITUATIONS:
        if t_start is None or t_cpa - t_start < p.early_s:
            penalties['late'] = p.gamma_late
        apparent = (np.abs(dchi[:k + 1]).max() >= np.radians(p.delta_course_app_deg) - 1e-9
                    or ratio[:k + 1].min() <= 1.0 - p.delta_speed_reduction_app + 1e-9)
        if not apparent:
            penalties['not_apparent'] = p.gamma_na
        if situation in ('head-on', 'crossing-give-way') and first_side(dchi, p, k) <= 0:
            penalties['not_starboard'] = p.gamma_ho_nsm
        los = target.p[k] - own.p[k]
        if situation == 'head-on' and np.sin(np.arctan2(los[1], los[0]) - own.course[k]) > 0.0:
            penalties['starboard_to_starboard'] = p.gamma_ho_sts
        v_tgt = velocity(target.course[k], target.speed[k])
        if situation == 'crossing-give-way' and float(np.dot(-los, v_tgt)) > 0.0:
            penalties['crossing_ahead'] = p.gamma_ahead_cr
        role = colregs.GIVE_WAY
    elif situation in STAND_ON_SITUATIONS:
        if stage is not None and stage <= 2:
            penalties['not_holding'] = p.gamma_so
        close = np.flatnonzero(d[:k + 1] <= p.colregs_4_lengths * own_dims.length_m)
        if close.size and (start is None or start > close[0]) and unmanoeuvred_near_miss(
                target, reference, own_dims, target_dims, p):
            penalties['not_acting'] = p.gamma_so
        if situation == 'crossing-stand-on' and first_side(dchi, p, k) < 0:
            penalties['port_turn'] = p.gamma_ho_nsm
        role = colregs.STAND_ON
    else:
        role = 'none'
    below_safe = d_min < p.r_min_m
    safety = 1.0 - (p.gamma_min * below_safe + p.gamma_nm * near_miss + p.gamma_col * collision)
    return {'situation': situation, 'role': role, 'min_distance_m': d_min,
            't_min_s': float(own.t[k]), 't_cpa_reference_s': t_cpa,
            'min_hull_clearance_m': clearance, 'domain_index': domain,
            'collision': collision, 'near_miss': near_miss, 'below_safe': below_safe,
            'safety_score': float(safety), 'manoeuvre_start_s': t_start,
            'manoeuvre_range_m': None if start is None else float(d[start]),
            'manoeuvre_stage': stage,
            'max_departure_deg': float(np.degrees(dchi[np.argmax(np.abs(dchi[:k + 1]))])),
            'min_speed_ratio': float(ratio[:k + 1].min()),
            'penalties': penalties,
            'rule_score': max(0.0, 1.0 - sum(penalties.values()))}


def distance_to_reference(own, reference):
    """Per own sample, its distance (m) from the reference polyline (each reference segment
    resampled to at most ``DEVIATION_STEP_M`` between points, nearest point by a k-d tree: the
    answer is within half a step of the polyline distance)."""
    from scipy.spatial import cKDTree
    p = reference.p
    seg = np.hypot(*np.diff(p, axis=0).T)
    n = np.maximum(np.ceil(seg / DEVIATION_STEP_M).astype(int), 1)
    idx = np.repeat(np.arange(len(seg)), n)
    frac = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    pts = np.vstack((p[idx] + frac[:, None] * (p[idx + 1] - p[idx]), p[-1:]))
    d, _ = cKDTree(pts).query(own.p)
    return d


def path_deviation(own, reference):
    """Largest distance (m) of the own samples from the reference polyline."""
    return float(distance_to_reference(own, reference).max())


def distance_to_polyline(points, polyline):
    """Exact distance (m) of each of ``points`` (N, 2) from the polyline (M, 2), M >= 2 (for
    a route's few legs: N x (M - 1) point-segment distances)."""
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    rel = points[:, None, :] - a[None]
    s = np.clip(np.einsum('nmk,mk->nm', rel, ab) / np.maximum(np.einsum('mk,mk->m', ab, ab),
                                                              1e-12), 0.0, 1.0)
    return np.hypot(*np.moveaxis(rel - s[..., None] * ab[None], -1, 0)).min(axis=1)


def return_to_route(own, route, t_from, params=None):
    """Seconds from ``t_from`` until the own ship is within ``route_band_m`` of the ``route``
    polyline ((M, 2) NED) and stays there for ``route_dwell_s`` (0 if it already is at
    ``t_from``); None if no such stay begins and lasts within the run."""
    p = params or EvaluationParams()
    inside = distance_to_polyline(own.p, np.asarray(route, dtype=float)) <= p.route_band_m
    inside &= own.t >= t_from
    # each stay inside: from a sample that enters to the last one before leaving
    edges = np.diff(np.concatenate(([0], inside.astype(np.int8), [0])))
    for first, last in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1):
        if own.t[last] - own.t[first] >= p.route_dwell_s:
            return float(own.t[first] - t_from)
    return None


def time_lost(own, reference):
    """Seconds behind the reference at the own run's end, by progress along the reference's
    overall direction (first to last sample)."""
    axis = reference.p[-1] - reference.p[0]
    axis = axis / max(np.hypot(*axis), 1e-12)
    s_ref = (reference.p - reference.p[0]) @ axis
    s_own = float((own.p[-1] - reference.p[0]) @ axis)
    s_mono = np.maximum.accumulate(s_ref)
    return float(own.t[-1] - np.interp(s_own, s_mono, reference.t))


def evaluate_run(own, targets, reference, own_dims, target_dims=None, params=None,
                 situations=None, route=None):
    """dict: per target (``evaluate_target`` with its name), the run's minimum distance and
    hull clearance, counts of collisions / near misses / below safe, mean rule score, path
    deviation, time lost, and the return to the route from the last target's closest approach
    (``last_cpa_s``). ``targets``: {name: Track}; ``target_dims``: {name: ShipDimensions}
    (default the own ship's); ``situations``: {name: situation} overrides; ``route``: the
    polyline ((M, 2) NED) to return to, default the straight line from the reference's first
    to its last point."""
    p = params or EvaluationParams()
    situations = situations or {}
    dims = target_dims or {}
    per = {name: evaluate_target(own, tr, reference, own_dims, dims.get(name), p,
                                 situations.get(name))
           for name, tr in targets.items()}
    scored = [v['rule_score'] for v in per.values() if v['role'] != 'none']
    last_cpa = max((v['t_min_s'] for v in per.values()), default=float(own.t[0]))
    return {'targets': per,
            'min_distance_m': min((v['min_distance_m'] for v in per.values()), default=np.inf),
            'min_hull_clearance_m': min((v['min_hull_clearance_m'] for v in per.values()),
                                        default=np.inf),
            'collisions': sum(v['collision'] for v in per.values()),
            'near_misses': sum(v['near_miss'] for v in per.values()),
            'below_safe': sum(v['below_safe'] for v in per.values()),
            'rule_score': float(np.mean(scored)) if scored else 1.0,
            'path_deviation_m': path_deviation(own, reference),
            'time_lost_s': time_lost(own, reference),
            'last_cpa_s': last_cpa,
            'return_to_route_s': return_to_route(
                own, reference.p[[0, -1]] if route is None else route, last_cpa, p)}
