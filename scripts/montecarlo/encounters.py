"""Encounter episodes of a sweep: an Imazu case with perturbed targets, run with collision avoidance.

An encounter sweep (a sweep file naming ``encounter``, spec.ENCOUNTER_KEYS) runs each episode as
scripts/imazu_benchmark.py runs a case: ``imazu.runner.case_scenario`` writes the case (own ship
``model`` at 12 kn on a straight route, the targets as light targets holding course and speed,
colav ``colav_method`` with the ship's identified model), ``imazu.runner.run_scenario`` runs it
in process with the node graph's objects in lockstep order, and ``imazu.evaluate.evaluate``
scores it against the ship's run without traffic. That reference run depends only on the own
ship, its start and the episode length, never on the targets: it is run once per process and
kept (``reference``).

The targets of the case are perturbed first (``perturbed_case``), every target alike:

- ``encounter_speed_factor`` f: the target's speed times f, its start moved along its course so
  that it still reaches the point of its unmanoeuvred closest approach to the own ship at the
  same time (the Imazu cases' common meeting point 4 NM ahead at 1200 s): f changes the
  aspect and the closing speed, not where and when the ships meet.
- ``encounter_miss_m`` d: then the target's track is shifted by d perpendicular to its velocity
  relative to the own ship, which leaves the time of closest approach unchanged and adds d to
  the signed miss distance: a case that meets exactly (every Imazu case) passes at an
  unmanoeuvred CPA of |d|. d > 0 puts the target, at that moment, at the bearing of the
  relative velocity minus 90 deg from the own ship: to starboard of it in head-on and
  overtaking, astern of it for a target crossing from starboard, ahead of it for one from port.

The situations scored (Rule 13-17 roles) are the case's as designed, as in the benchmark: a
large miss can turn a give-way encounter into one where no action is needed, which the rule
score then judges as the designed role. Metrics per episode (METRICS), over all targets:
collision / near miss / below r_min (0 or 1: any target's hull touching the own hull / inside a
ship domain / closer than r_min, ship_guidance.colav_evaluation), the minimum distance, the rule score (mean
over the targets), path deviation and time lost against the reference run, the number of
decisions in 'avoid' and in 'last-resort' mode (one decision per colav period, 1 s by
default), and the smallest unmanoeuvred CPA of the perturbed targets (the geometry the ship
met, computed before the run).
"""
import copy
import math

import numpy as np

#: Metric columns of an encounter row, in table order; the first three are proportions.
METRICS = ('collision', 'near_miss', 'below_r_min', 'min_distance_m', 'rule_score',
           'path_deviation_m', 'time_lost_s', 'avoid_decisions', 'last_resort_decisions',
           'unmanoeuvred_cpa_m')
PROPORTIONS = METRICS[:3]
_CASES = {}
_REFERENCES = {}


def _cases():
    if not _CASES:
        from imazu.cases import load_cases
        _CASES.update(load_cases())
    return _CASES


def _own_track(own):
    from ship_guidance.cpa import velocity
    p = np.array([own['north_m'], own['east_m']])
    return p, velocity(math.radians(own['course_deg']), own['speed_mps'])


def target_cpa(own, target):
    """(TCPA s, DCPA m) of ``target`` (a case's target dict) against the unmanoeuvred own ship."""
    from ship_guidance.cpa import cpa, velocity
    p_o, v_o = _own_track(own)
    v_t = velocity(math.radians(target['course_deg']), target['speed_mps'])
    tcpa, dcpa = cpa(p_o, v_o, np.array([target['north_m'], target['east_m']]), v_t)
    return float(tcpa), float(dcpa)


def perturbed_case(case, speed_factor=1.0, miss_m=0.0):
    """A copy of ``case`` (imazu.cases.load_cases entry) with every target perturbed (module
    docstring); the case itself for f = 1, d = 0."""
    from ship_guidance.cpa import velocity
    out = copy.deepcopy(case)
    p_o, v_o = _own_track(case['own'])
    for t in out['targets']:
        if speed_factor != 1.0:
            tcpa, _ = target_cpa(case['own'], t)
            v = velocity(math.radians(t['course_deg']), t['speed_mps'])
            # The meeting point p + v tcpa, reached at tcpa at the new speed f |v|.
            shift = (1.0 - speed_factor) * v * tcpa
            t['north_m'] += float(shift[0])
            t['east_m'] += float(shift[1])
            t['speed_mps'] *= speed_factor
        if miss_m != 0.0:
            rel = velocity(math.radians(t['course_deg']), t['speed_mps']) - v_o
            u = rel / np.hypot(*rel)
            t['north_m'] += miss_m * float(u[1])     # bearing of rel - 90 deg: (u_e, -u_n)
            t['east_m'] -= miss_m * float(u[0])
    return out


def reference(model, own, duration_s):
    """RunResult of the own ship without traffic (imazu_benchmark's reference run), run once
    per process for each (model, own-ship start, length)."""
    key = (model, tuple(sorted(own.items())), float(duration_s))
    if key not in _REFERENCES:
        _REFERENCES[key] = _run_case({'own': own, 'targets': []}, model, None, duration_s)
    return _REFERENCES[key]


def _run_case(case, model, method, duration_s, number=0):
    import imazu_benchmark
    from imazu.runner import RunEnd, case_scenario
    # as the benchmark: a run with traffic ends once all have passed and the ship is back on
    # its route (duration_s the limit); the reference runs the whole duration
    end = RunEnd.of_case(case) if method is not None else None
    _, result, _ = imazu_benchmark._run((None, *case_scenario(number, case, model, method,
                                                               duration_s), end))
    return result


def run_encounter(ep):
    """One encounter episode (a dict of spec.expand) -> its metrics (dict)."""
    from imazu.evaluate import evaluate
    number = ep['encounter']
    case = perturbed_case(_cases()[number], ep['encounter_speed_factor'],
                          ep['encounter_miss_m'])
    result = _run_case(case, ep['model'], ep['colav_method'], ep['duration_s'], number)
    run = evaluate(result, reference(ep['model'], case['own'], ep['duration_s']), case,
                   ep['model'])
    modes = [d[1] for d in result.decisions]
    return {'collision': int(run['collisions'] > 0), 'near_miss': int(run['near_misses'] > 0),
            'below_r_min': int(run['below_safe'] > 0),
            'min_distance_m': float(run['min_distance_m']),
            'rule_score': float(run['rule_score']),
            'path_deviation_m': float(run['path_deviation_m']),
            'time_lost_s': float(run['time_lost_s']),
            'avoid_decisions': modes.count('avoid'),
            'last_resort_decisions': modes.count('last-resort'),
            'unmanoeuvred_cpa_m': min(target_cpa(case['own'], t)[1] for t in case['targets'])}


def run_encounter_chunk(chunk):
    """Rows (the episode's parameters and METRICS) of a list of encounter episodes."""
    return [dict(ep, **run_encounter(ep)) for ep in chunk]
