"""Score a RunResult with ship_guidance.colav_evaluation against the ship's no-traffic run."""
import numpy as np

from ship_guidance.colav_evaluation import Track, evaluate_run, unmanoeuvred_cpa_time

#: Spacing (s) of the instants at which the Rule 17(b) moment is looked for.
STAND_ON_SCAN_S = 5.0


def track(result, rows=None):
    rows = result.own if rows is None else rows
    return Track.of(result.t, rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3])


def evaluate(result, reference, case, ship=None, case_no=None):
    """evaluate_run of one run; each target's situation is the case's (the encounter as designed,
    own ship's view at t = 0), the same as the classification of the first sample. With ``ship``
    (and ``case_no``, the cache key), each stand-on target's window is widened to the ship's
    Rule 17(b) moment (``stand_on_window``)."""
    situations = {t['name']: t['colregs'] for t in case['targets']}
    targets = {n: track(result, rows) for n, rows in result.targets.items()}
    windows = {}
    if ship is not None:
        for t in case['targets']:
            if t['colregs'] in ('crossing-stand-on', 'being-overtaken'):
                windows[t['name']] = stand_on_window(ship, case_no, t['name'], reference,
                                                     targets, case['own'])
    return evaluate_run(track(result), targets, track(reference), situations=situations,
                        stand_on_windows=windows)


_WINDOWS = {}


def stand_on_window(ship, case_no, name, reference, targets, own):
    """Seconds before the unmanoeuvred closest point at which ``ship`` must act on its own
    (Rule 17(b)) against the target ``name`` that never gives way: the first instant (every
    STAND_ON_SCAN_S along the no-traffic run) at which colav's prediction with the ship's own
    model, given all the case's ``targets`` ({name: Track}), finds that no manoeuvre of the own
    ship alone keeps stand_on_dcpa_m from every threat at once (``Scenarios.must_act``, the
    same test colav applies); 0 if none before the closest point. The targets hold course and
    speed, so the answer depends only on ship, case and target."""
    key = (ship, case_no, name)
    if key in _WINDOWS and case_no is not None:
        return _WINDOWS[key]
    from imazu.runner import build_colav, own_ship_model
    from ship_guidance.colav import ShipState, Target
    from ship_sim.models import make_model
    colav, _ = build_colav({'method': 'sbmpc', **own_ship_model(ship, own['speed_mps'])},
                           bool(make_model(ship).has_shaft))
    ref = track(reference)
    names = sorted(targets)
    index = names.index(name)
    t_cpa = unmanoeuvred_cpa_time(targets[name], ref)
    window = 0.0
    for t in np.arange(0.0, t_cpa, STAND_ON_SCAN_S):
        i = int(np.searchsorted(ref.t, t))
        o = ShipState(ref.north[i], ref.east[i], ref.course[i], ref.speed[i])
        now = []
        for n in names:
            tr = targets[n]
            j = int(np.searchsorted(tr.t, t))
            now.append(Target(tr.north[j], tr.east[j], tr.course[j], tr.speed[j], name=n))
        colav.reset()
        sc = colav.scenarios(o, now, ref.course[i], 1.0)
        if sc.must_act is not None and bool(sc.must_act[index]):
            window = float(t_cpa - ref.t[i])
            break
    if case_no is not None:   # only a numbered case is the same geometry next time
        _WINDOWS[key] = window
    return window


def rows_of(case_no, ship, method, run, result):
    """CSV rows, one per target, with the run's figures repeated."""
    modes = [d[1] for d in result.decisions]
    base = {'case': case_no, 'ship': ship, 'method': method,
            'run_min_distance_m': round(run['min_distance_m'], 1),
            'path_deviation_m': round(run['path_deviation_m'], 1),
            'time_lost_s': round(run['time_lost_s'], 1), 'run_rule_score': round(run['rule_score'], 3),
            'last_resort_decisions': modes.count('last-resort'),
            'decisions': len(modes),
            'decision_ms': round(1e3 * result.decision_wall_s / max(len(modes), 1), 3)}
    out = []
    for name, v in run['targets'].items():
        out.append({**base, 'target': name, 'situation': v['situation'], 'role': v['role'],
                    'min_distance_m': round(v['min_distance_m'], 1), 't_min_s': round(v['t_min_s'], 1),
                    'collision': int(v['collision']), 'near_miss': int(v['near_miss']),
                    'below_safe': int(v['below_safe']), 'rule_score': round(v['rule_score'], 3),
                    'penalties': ' '.join(sorted(v['penalties'])),
                    'manoeuvre_start_s': '' if v['manoeuvre_start_s'] is None
                    else round(v['manoeuvre_start_s'], 1),
                    'max_departure_deg': round(v['max_departure_deg'], 1)})
    return out
