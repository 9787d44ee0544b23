"""Evaluation of a collision-avoidance run from its tracks (pure): safety, COLREGs compliance,
path deviation and time lost.

After the protocol of Woerner et al. 2018 ("Quantifying protocol evaluation for autonomous
collision avoidance", Autonomous Robots) with the parameter names and penalty weights the NTNU
COLAV simulator's evaluator publishes (config/evaluator.yaml: r_min, r_nm, r_col, the 30 deg
apparent course change, the halved speed, the 10 deg starboard-manoeuvre limit and the gamma
weights), simplified to step penalties that can be checked by hand
(doc/colav_benchmark.md has every parameter and the composition of the score).

Per target, from the own track, the target track (same sample times) and the own ship's track
in the same run without traffic (the reference):

- safety: minimum distance, and collision (< r_col), near miss (< r_nm), below safe (< r_min);
  safety score 1 - (gamma_min [d < r_min] + gamma_nm [d < r_nm] + gamma_col [d < r_col]);
- situation and role: classified at the first sample (ship_guidance.colregs);
- t_cpa: the time of the target's closest approach to the reference track (when it would have
  been closest had the own ship not manoeuvred; the own manoeuvre moves the actual closest
  approach, so the windows below count back from this one);
- own manoeuvre: the own course's departure from the reference's at the same time (rad, +
  starboard) and the speed ratio to the reference; the manoeuvre starts at the first sample
  where the departure reaches ``delta_course_md`` or the speed has dropped by
  ``delta_speed_md``;
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
    not holding: a manoeuvre starting more than ``stand_on_window_s`` before t_cpa
      (Rule 17(a)(i); 17(a)(ii) allows action once the give-way ship is late, i.e. its action
      due ``early_s`` before t_cpa has not come, so the default window equals early_s; a run
      may widen it per target to the moment Rule 17(b) requires action of a slow-turning own
      ship, computed with the own ship's prediction model by the caller)   gamma_so
    port turn (crossing stand-on): the first departure beyond ``theta_sm_lim`` is to port
      (Rule 17(c))                                                          gamma_ho_nsm

- path deviation: the largest distance of the own track from the reference track; time lost:
  the run's end time minus the time the reference reached the along-track progress the own
  ship made by then (progress along the reference's overall direction).

Tracks are arrays over the same sample times: t (s), north, east (m, NED), course (rad,
clockwise from north), speed (m/s). Courses are over ground (the target classification and the
departure use them).
"""
from dataclasses import dataclass

import numpy as np

from ship_guidance import colregs
from ship_guidance.cpa import velocity

#: Largest spacing (m) of the reference points path_deviation measures against.
DEVIATION_STEP_M = 1.0
GIVE_WAY_SITUATIONS = ('head-on', 'crossing-give-way', 'overtaking')
STAND_ON_SITUATIONS = ('crossing-stand-on', 'being-overtaken')


@dataclass(frozen=True)
class EvaluationParams:
    """Evaluator parameters; distances default to the project's Imazu scale (ColavParams), the
    angles, fractions and weights to the NTNU COLAV simulator's evaluator.yaml."""
    r_min_m: float = 926.0              # safe passing distance (ColavParams.d_safe_m)
    r_nm_m: float = 463.0               # near miss (ColavParams.near_miss_m)
    r_col_m: float = 185.2              # collision (ColavParams.collision_m)
    delta_course_md_deg: float = 2.0    # minimum detectable course change
    delta_speed_md: float = 0.2         # minimum detectable speed change (fraction)
    delta_course_app_deg: float = 30.0  # readily apparent course change
    delta_speed_reduction_app: float = 0.5  # apparent speed reduction (fraction)
    theta_sm_lim_deg: float = 10.0      # departure beyond which a manoeuvre has a side
    early_s: float = 300.0              # give-way action at least this long before the CPA
    stand_on_window_s: float = 300.0    # stand-on may act only this close to the CPA: early_s
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
    """A ship's samples: t (s), north, east (m), course (rad NED), speed (m/s)."""
    t: np.ndarray
    north: np.ndarray
    east: np.ndarray
    course: np.ndarray
    speed: np.ndarray

    @classmethod
    def of(cls, t, north, east, course, speed):
        return cls(*(np.asarray(a, dtype=float) for a in (t, north, east, course, speed)))

    @property
    def p(self):
        return np.stack((self.north, self.east), axis=-1)


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


def evaluate_target(own, target, reference, params=None, situation=None,
                    stand_on_window_s=None):
    """dict of the metrics of one target (see the module docstring); ``situation`` overrides
    the classification at the first sample, ``stand_on_window_s`` the parameter's window (never
    narrower than it)."""
    p = params or EvaluationParams()
    window = p.stand_on_window_s if stand_on_window_s is None else \
        max(p.stand_on_window_s, stand_on_window_s)
    d = np.hypot(target.north - own.north, target.east - own.east)
    k = int(np.argmin(d))
    d_min = float(d[k])
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
        if t_start is not None and t_cpa - t_start > window:
            penalties['not_holding'] = p.gamma_so
        if situation == 'crossing-stand-on' and first_side(dchi, p, k) < 0:
            penalties['port_turn'] = p.gamma_ho_nsm
        role = colregs.STAND_ON
    else:
        role = 'none'
    safety = 1.0 - (p.gamma_min * (d_min < p.r_min_m) + p.gamma_nm * (d_min < p.r_nm_m)
                    + p.gamma_col * (d_min < p.r_col_m))
    return {'situation': situation, 'role': role, 'min_distance_m': d_min,
            't_min_s': float(own.t[k]), 't_cpa_reference_s': t_cpa,
            'collision': d_min < p.r_col_m, 'near_miss': d_min < p.r_nm_m,
            'below_safe': d_min < p.r_min_m, 'safety_score': float(safety),
            'manoeuvre_start_s': t_start,
            'max_departure_deg': float(np.degrees(dchi[np.argmax(np.abs(dchi[:k + 1]))])),
            'min_speed_ratio': float(ratio[:k + 1].min()), 'stand_on_window_s': window,
            'penalties': penalties,
            'rule_score': max(0.0, 1.0 - sum(penalties.values()))}


def path_deviation(own, reference):
    """Largest distance (m) of the own samples from the reference polyline (each reference
    segment resampled to at most ``DEVIATION_STEP_M`` between points, nearest point by a
    k-d tree: the answer is within half a step of the polyline distance)."""
    from scipy.spatial import cKDTree
    p = reference.p
    seg = np.hypot(*np.diff(p, axis=0).T)
    n = np.maximum(np.ceil(seg / DEVIATION_STEP_M).astype(int), 1)
    idx = np.repeat(np.arange(len(seg)), n)
    frac = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    pts = np.vstack((p[idx] + frac[:, None] * (p[idx + 1] - p[idx]), p[-1:]))
    d, _ = cKDTree(pts).query(own.p)
    return float(d.max())


def time_lost(own, reference):
    """Seconds behind the reference at the own run's end, by progress along the reference's
    overall direction (first to last sample)."""
    axis = reference.p[-1] - reference.p[0]
    axis = axis / max(np.hypot(*axis), 1e-12)
    s_ref = (reference.p - reference.p[0]) @ axis
    s_own = float((own.p[-1] - reference.p[0]) @ axis)
    s_mono = np.maximum.accumulate(s_ref)
    return float(own.t[-1] - np.interp(s_own, s_mono, reference.t))


def evaluate_run(own, targets, reference, params=None, situations=None, stand_on_windows=None):
    """dict: per target (``evaluate_target`` with its name), the run's minimum distance, counts
    of collisions / near misses / below safe, mean rule score, path deviation and time lost.
    ``targets``: {name: Track}; ``situations``: {name: situation}, ``stand_on_windows``:
    {name: s} overrides."""
    situations = situations or {}
    windows = stand_on_windows or {}
    per = {name: evaluate_target(own, tr, reference, params, situations.get(name),
                                 windows.get(name))
           for name, tr in targets.items()}
    scored = [v['rule_score'] for v in per.values() if v['role'] != 'none']
    return {'targets': per,
            'min_distance_m': min((v['min_distance_m'] for v in per.values()), default=np.inf),
            'collisions': sum(v['collision'] for v in per.values()),
            'near_misses': sum(v['near_miss'] for v in per.values()),
            'below_safe': sum(v['below_safe'] for v in per.values()),
            'rule_score': float(np.mean(scored)) if scored else 1.0,
            'path_deviation_m': path_deviation(own, reference),
            'time_lost_s': time_lost(own, reference)}
