"""Score a RunResult with ship_guidance.colav_evaluation against the ship's no-traffic run."""
from ship_guidance.colav_evaluation import ShipDimensions, Track, evaluate_run


def track(result, rows=None):
    """Track of the own ship (with its heading) or, with ``rows``, of a target (light targets
    have no drift: heading = course)."""
    if rows is None:
        rows = result.own
        return Track.of(result.t, rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3], result.heading)
    return Track.of(result.t, rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3])


def ship_dimensions(ship):
    """ShipDimensions of the MSS model ``ship``: its length between perpendiculars, the beam
    nav_display's default ratio of it (the models state no beam)."""
    from ship_sim.models import make_model
    return ShipDimensions(float(make_model(ship).length))


def evaluate(result, reference, case, ship):
    """evaluate_run of one run; each target's situation is the case's (the encounter as designed,
    own ship's view at t = 0), the same as the classification of the first sample. The Imazu
    targets are given the own ship's dimensions (the cases state none; two ships of one size,
    so the hull contact and the domains are symmetric). The route returned to is the case's
    straight route (the one runner.case_scenario writes and RunEnd measures against). A case
    whose targets state their length (and beam), as DNV's situations do, gives each target its
    own hull and domain."""
    import math

    import numpy as np

    from imazu.runner import ROUTE_LENGTH_M
    situations = {t['name']: t['colregs'] for t in case['targets']}
    targets = {n: track(result, rows) for n, rows in result.targets.items()}
    own = case['own']
    start = np.array([own['north_m'], own['east_m']])
    c = math.radians(own['course_deg'])
    route = np.stack((start, start + ROUTE_LENGTH_M * np.array([math.cos(c), math.sin(c)])))
    dims = {t['name']: ShipDimensions(float(t['length_m']), t.get('beam_m'))
            for t in case['targets'] if t.get('length_m')}
    return evaluate_run(track(result), targets, track(reference), ship_dimensions(ship),
                        target_dims=dims, situations=situations, route=route)


def rows_of(case_no, ship, method, run, result):
    """CSV rows, one per target, with the run's figures repeated."""
    modes = [d[1] for d in result.decisions]
    base = {'case': case_no, 'ship': ship, 'method': method,
            'run_min_distance_m': round(run['min_distance_m'], 1),
            'path_deviation_m': round(run['path_deviation_m'], 1),
            'time_lost_s': round(run['time_lost_s'], 1), 'run_rule_score': round(run['rule_score'], 3),
            'run_end_s': round(float(result.t[-1]), 1), 'run_end': result.end,
            'return_to_route_s': '' if run['return_to_route_s'] is None
            else round(run['return_to_route_s'], 1),
            'last_resort_decisions': modes.count('last-resort'),
            'decisions': len(modes),
            'decision_ms': round(1e3 * result.decision_wall_s / max(len(modes), 1), 3)}
    out = []
    for name, v in run['targets'].items():
        out.append({**base, 'target': name, 'situation': v['situation'], 'role': v['role'],
                    'min_distance_m': round(v['min_distance_m'], 1), 't_min_s': round(v['t_min_s'], 1),
                    'min_hull_clearance_m': round(v['min_hull_clearance_m'], 1),
                    'domain_index': round(v['domain_index'], 3),
                    'collision': int(v['collision']), 'near_miss': int(v['near_miss']),
                    'below_safe': int(v['below_safe']), 'rule_score': round(v['rule_score'], 3),
                    'penalties': ' '.join(sorted(v['penalties'])),
                    'manoeuvre_start_s': '' if v['manoeuvre_start_s'] is None
                    else round(v['manoeuvre_start_s'], 1),
                    'manoeuvre_stage': v['manoeuvre_stage'] or '',
                    'max_departure_deg': round(v['max_departure_deg'], 1)})
    return out
