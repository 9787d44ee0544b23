"""One encounter of the search: written as a scenario (imazu.runner.case_scenario), run in
process with the node graph's objects in lockstep order (imazu.runner.run_scenario), scored by
the evaluator (imazu.evaluate.evaluate: ship_guidance.colav_evaluation against the own ship's
run without traffic, each target's situation classified at the start).

A run ends ``PASSED_DWELL_S`` after every target has passed (TCPA < 0 against the own ship's
current velocity, held that long: imazu.runner.RunEnd with no route band), or at ``LIMIT_S``:
the closest approaches are behind it by then, and the return to the route, which the search
does not judge, is not waited for. The scenario written for a failure has the run's end as its
duration, so a replay covers the same samples.

The score (lower: closer to failure) is the evaluator's smallest domain index over the targets
(the centre of one ship in the other's Fujii domain is below 1); a failure is the evaluator's
near miss or collision (a collision is inside the domain as well).
"""
import math
import tempfile
import time
from pathlib import Path

import yaml

from colav_search import encounter

#: Longest run (s): the latest meeting plus time to pass after an avoidance.
LIMIT_S = encounter.MEETING[2] + 1500.0
PASSED_DWELL_S = 60.0
#: The failure level of the score (the domain index).
FAILURE_LEVEL = 1.0


def scenario_of(n_targets, x, ship, method, duration_s=LIMIT_S, name='failure_search'):
    """(scenario, route) dicts of the encounter (imazu.runner.case_scenario), named ``name``."""
    from imazu.runner import case_scenario
    case = encounter.case_of(n_targets, x)
    scenario, route = case_scenario(0, case, ship, method, duration_s)
    scenario['name'] = name
    scenario['source'] = ('scripts/failure_search.py: an encounter of the failure search '
                          '(colav_search.encounter geometry)')
    scenario['description'] = (f'{len(case["targets"])} target(s), own ship {ship}, colav '
                               f'{method}')
    route['source'] = 'Straight route of the Imazu own ship (scripts/colav_search)'
    return case, scenario, route


def write(scenario, route, directory, header):
    """Write ``<name>.yaml`` (``header``: comment lines) and route.yaml into ``directory``."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    (directory / 'route.yaml').write_text(yaml.safe_dump(route, sort_keys=False))
    path = directory / f'{scenario["name"]}.yaml'
    path.write_text(''.join(f'# {line}\n' for line in header)
                    + yaml.safe_dump(scenario, sort_keys=False))
    return path


def run_end(case):
    from imazu.runner import RunEnd
    own = case['own']
    return RunEnd(own['north_m'], own['east_m'], math.radians(own['course_deg']),
                  math.inf, PASSED_DWELL_S)


def run(n_targets, x, ship, method):
    """dict of one episode: score, failure, collision, near_miss, min_distance_m, t_min_s,
    end_s (the last sample), end ('clear' or 'limit'), wall_s."""
    from imazu.evaluate import evaluate
    from imazu.runner import run_scenario
    from montecarlo.encounters import reference
    case, scenario, route = scenario_of(n_targets, x, ship, method)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        result = run_scenario(write(scenario, route, tmp, []), end=run_end(case))
    wall = time.perf_counter() - t0
    scored = evaluate(result, reference(ship, case['own'], LIMIT_S), case, ship)
    per = scored['targets'].values()
    score = min(v['domain_index'] for v in per)
    closest = min(per, key=lambda v: v['min_distance_m'])
    return {'score': float(score), 'failure': bool(scored['near_misses'] > 0),
            'collision': bool(scored['collisions'] > 0),
            'near_miss': bool(scored['near_misses'] > 0),
            'min_distance_m': float(scored['min_distance_m']),
            't_min_s': float(closest['t_min_s']),
            'end_s': float(result.t[-1]), 'end': result.end, 'wall_s': wall}


def write_failure(n_targets, x, ship, method, row, directory, name):
    """Write a failure's scenario (duration: the run's end) with its in-process numbers in the
    header; the path."""
    _, scenario, route = scenario_of(n_targets, x, ship, method, row['end_s'], name)
    header = [f'Failure found by scripts/failure_search.py ({method} on the {ship}):',
              f'in-process min distance {row["min_distance_m"]:.3f} m at t = '
              f'{row["t_min_s"]:.1f} s, domain index {row["score"]:.3f}, '
              f'collision {row["collision"]}',
              'Replay: .venv/bin/python scripts/failure_search.py --replay <this file>']
    return write(scenario, route, directory, header)
