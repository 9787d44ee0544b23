"""The results file of an encounter set's page (Imazu: doc/results/imazu.md, DNV's baseline
situations: doc/results/dnv.md), merged from benchmark folders.

Each folder written by scripts/imazu_benchmark.py holds one or more sets (ship/method) with
their own provenance, so a set can be run on its own and the page shows what has finished.
The file keeps, per set, the run's provenance (the code and load that produced the tracks),
the totals of summary.json and its per-case figures plus the time of the first manoeuvre
(the earliest manoeuvre start any target's evaluation found, from results.csv); the sets of
SHIPS x METHODS that no folder holds are listed as not run.
"""
import csv
import json
from pathlib import Path

#: Totals of a set copied from summary.json (everything but the per-case figures).
TOTALS = ('runs', 'collisions', 'near_misses', 'below_safe', 'min_distance_m', 'rule_score_mean',
          'rule_score_single_target_mean', 'path_deviation_m_mean', 'time_lost_s_mean',
          'return_to_route_s_mean', 'never_back_on_route', 'limit_hit')


class MergeError(ValueError):
    """A folder is not a finished benchmark, or two folders hold the same set."""


def first_actions(csv_path):
    """{(case, 'ship/method'): earliest manoeuvre start s over the run's targets, or None when
    the evaluator found no manoeuvre for any target}."""
    out = {}
    with open(csv_path, newline='') as f:
        for row in csv.DictReader(f):
            key = (int(row['case']), f"{row['ship']}/{row['method']}")
            start = float(row['manoeuvre_start_s']) if row['manoeuvre_start_s'] else None
            old = out.get(key)
            out[key] = start if old is None else old if start is None else min(old, start)
    return out


def folder_sets(folder, encounter_set='imazu'):
    """{'ship/method': set entry} of one benchmark folder of ``encounter_set``."""
    folder = Path(folder)
    try:
        summary = json.loads((folder / 'summary.json').read_text())
    except FileNotFoundError:
        raise MergeError(f'{folder}: no summary.json (not a finished benchmark folder)') from None
    ran = summary.get('set', 'imazu')        # folders from before --set: Imazu
    if ran != encounter_set:
        raise MergeError(f'{folder}: a run of the {ran} set, not of {encounter_set}')
    firsts = first_actions(folder / 'results.csv')
    prov = summary.get('runs_provenance') or summary['provenance']
    run = {k: prov[k] for k in ('command', 'commit', 'date_utc', 'load_1min', 'cpus')}
    run.update(folder=folder.name, limit_s=summary['limit_s'],
               run_wall_s_mean=summary['run_wall_s_mean'],
               decision_ms_mean=summary['decision_ms_mean'])
    if summary.get('runs_provenance'):
        run['rescored_at_commit'] = summary['provenance']['commit']
    sets = {}
    for key, g in summary['groups'].items():
        cases = {str(c): {**v, 'first_action_s': firsts.get((int(c), key))}
                 for c, v in sorted(g['cases'].items(), key=lambda kv: int(kv[0]))}
        sets[key] = {'run': run, 'totals': {k: g[k] for k in TOTALS}, 'cases': cases}
    return sets


def merge(folders, ships, methods, cases, provenance, encounter_set='imazu'):
    """The results file of ``encounter_set`` (imazu.cases.SETS): ``cases`` ({number: case},
    imazu.cases.load_set) gives each case's targets (own view); ``provenance`` is the merge's
    own (results_pages.provenance)."""
    sets = {}
    for folder in folders:
        for key, entry in folder_sets(folder, encounter_set).items():
            if key in sets:
                raise MergeError(f'{key} is in {sets[key]["run"]["folder"]} and in '
                                 f'{entry["run"]["folder"]}: give one folder per set')
            sets[key] = entry
    order = [f'{s}/{m}' for s in ships for m in methods]
    return {'provenance': provenance, 'set': encounter_set,
            'cases': {str(c): [t['colregs'] for t in case['targets']]
                      for c, case in sorted(cases.items())},
            'sets': {k: sets[k] for k in order if k in sets}
            | {k: v for k, v in sets.items() if k not in order},
            'not_run': [k for k in order if k not in sets]}
