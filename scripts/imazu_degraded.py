#!/usr/bin/env python3
"""The Imazu cases with colav fed by degraded sensors: collisions, near misses, minimum distances.

    .venv/bin/python scripts/imazu_degraded.py [--cases 1,2,5] [--levels perfect,poor_ais]
        [--seeds 3] [--ships mariner] [--methods sbmpc] [--jobs 2]
        [--out doc/results/data/degraded_sensors.json]

Each run is scripts/imazu/runner.py's (imazu_benchmark.py's runs: the own ship on its route,
the case's targets holding course and speed, colav_node's core at its decision period, ended
once every target has passed and the own ship is back on its route) with colav deciding on
what a sensor level gives it (``run_scenario(..., sensing=(level, seed))``: the AIS sensor
model or the radar, and the tracker; the levels are ship_guidance.sensor_levels'), scored on
the true tracks by ship_guidance.colav_evaluation against the ship's run without traffic (as
the benchmark scores). ``perfect`` has no randomness and runs once (seed 0); every other level
runs with seeds 1..N.

Writes the results file the page doc/results/degraded_sensors.md renders
(scripts/render_results.py): every run's figures, per (ship, method, level) the totals, per
case the worst and best over the seeds, and where the method breaks (``summarise``: per degraded
level the cases with a collision or a near miss in any seed, the cases below r_min that are
not below it at ``perfect``, the largest loss of minimum distance against ``perfect``), with
the provenance. The study of doc/results/degraded_sensors.md ran a subset of the cases (its
command names them): the machine it ran on allowed about 50 runs in the time given to it.
"""
import argparse
import json
import multiprocessing
import os
import sys
import tempfile
import time
from pathlib import Path

from imazu.cases import load_cases
from imazu.runner import LIMIT_S, METHODS, SHIPS, RunEnd, case_scenario, run_scenario, \
    write_scenario
from results_pages.provenance import provenance

from ship_guidance.colav_evaluation import EvaluationParams
from ship_mission.cli_args import comma_names
from ship_guidance.sensor_levels import LEVELS

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / 'doc' / 'results' / 'data' / 'degraded_sensors.json'
_REFERENCES = {}        # ship -> RunResult without traffic (set before the pool forks)


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--cases', type=lambda s: [int(v) for v in s.split(',') if v.strip()],
                    help='Imazu case numbers (default all 22)')
    ap.add_argument('--levels', type=comma_names(list(LEVELS)), default=list(LEVELS),
                    help=f'sensor levels (default {",".join(LEVELS)})')
    ap.add_argument('--seeds', type=int, default=3, help='seeds per degraded level (default 3)')
    ap.add_argument('--ships', type=comma_names(SHIPS), default=['mariner'])
    ap.add_argument('--methods', type=comma_names(METHODS), default=['sbmpc'])
    ap.add_argument('--jobs', type=int, default=2, help='worker processes (default 2)')
    ap.add_argument('--out', type=Path, default=OUT)
    ap.add_argument('--cache', type=Path,
                    help='JSON-lines file of finished runs: a run found in it is not run again '
                         'and every run finished is appended, so a study cut short goes on '
                         'where it stopped (only while the code is the same)')
    args = ap.parse_args(argv)
    cases = load_cases()
    args.cases = args.cases or sorted(cases)
    bad = [c for c in args.cases if c not in cases]
    if bad:
        ap.error(f'no Imazu case {bad}; cases are 1-22')
    if not 1 <= args.seeds <= 100 or not 1 <= args.jobs <= 16:
        ap.error('--seeds must be 1-100 and --jobs 1-16')
    return args, cases


def _reference(ship, case):
    with tempfile.TemporaryDirectory() as tmp:
        sc, route = case_scenario(0, {'own': case['own'], 'targets': []}, ship, None, LIMIT_S)
        return run_scenario(write_scenario(sc, route, tmp))


def run_one(task):
    """Worker: the scored figures of one (ship, method, case, level, seed) run."""
    from imazu.evaluate import evaluate
    ship, method, number, case, level, seed = task
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        sc, route = case_scenario(number, case, ship, method, LIMIT_S)
        result = run_scenario(write_scenario(sc, route, tmp), end=RunEnd.of_case(case),
                              sensing=(level, seed))
    run = evaluate(result, _REFERENCES[ship], case, ship)
    modes = [d[1] for d in result.decisions]
    return {'ship': ship, 'method': method, 'case': number, 'level': level, 'seed': seed,
            'min_distance_m': round(run['min_distance_m'], 1),
            'collisions': run['collisions'], 'near_misses': run['near_misses'],
            'below_safe': run['below_safe'], 'rule_score': round(run['rule_score'], 3),
            'path_deviation_m': round(run['path_deviation_m'], 1),
            'time_lost_s': round(run['time_lost_s'], 1), 'run_end': result.end,
            'run_end_s': round(float(result.t[-1]), 1),
            'last_resort_decisions': modes.count('last-resort'),
            'targets': {n: {'min_distance_m': round(v['min_distance_m'], 1),
                            'collision': bool(v['collision']), 'near_miss': bool(v['near_miss'])}
                        for n, v in run['targets'].items()},
            'sensing': {k: (round(v, 2) if isinstance(v, float) else v)
                        for k, v in (result.sensing or {}).items()},
            'wall_s': round(time.perf_counter() - t0, 1)}


def summarise(runs, levels, r_min_m):
    """Per (ship/method, level): totals, per case the worst over the seeds; and ``breaks``: per
    group and degraded level the cases with a collision or near miss in any seed, and those
    whose smallest minimum distance is below r_min while the perfect run's is not."""
    groups = {}
    for r in runs:
        g = groups.setdefault(f'{r["ship"]}/{r["method"]}', {}).setdefault(r['level'], {
            'runs': 0, 'collisions': 0, 'near_misses': 0, 'below_safe': 0,
            'runs_with_collision': 0, 'runs_with_near_miss': 0, 'min_distance_m': None,
            'min_distance_case': None, 'mean_min_distance_m': 0.0, 'last_resort_runs': 0,
            'limit_hit': 0, 'cases': {}})
        g['runs'] += 1
        for k in ('collisions', 'near_misses', 'below_safe'):
            g[k] += r[k]
        g['runs_with_collision'] += r['collisions'] > 0
        g['runs_with_near_miss'] += r['near_misses'] > 0
        g['last_resort_runs'] += r['last_resort_decisions'] > 0
        g['limit_hit'] += r['run_end'] == 'limit'
        g['mean_min_distance_m'] += r['min_distance_m']
        if g['min_distance_m'] is None or r['min_distance_m'] < g['min_distance_m']:
            g['min_distance_m'], g['min_distance_case'] = r['min_distance_m'], r['case']
        c = g['cases'].setdefault(str(r['case']), {
            'seeds': 0, 'min_distance_m': None, 'max_min_distance_m': None, 'collisions': 0,
            'near_misses': 0, 'position_error_m_rms_max': None})
        c['seeds'] += 1
        c['min_distance_m'] = _min(c['min_distance_m'], r['min_distance_m'])
        c['max_min_distance_m'] = -_min(None if c['max_min_distance_m'] is None
                                        else -c['max_min_distance_m'], -r['min_distance_m'])
        c['collisions'] += r['collisions']
        c['near_misses'] += r['near_misses']
        err = r['sensing'].get('position_error_m_rms')
        if err is not None:
            c['position_error_m_rms_max'] = -_min(None if c['position_error_m_rms_max'] is None
                                                  else -c['position_error_m_rms_max'], -err)
    for by_level in groups.values():
        for g in by_level.values():
            g['mean_min_distance_m'] = round(g['mean_min_distance_m'] / g['runs'], 1)
            g['cases'] = dict(sorted(g['cases'].items(), key=lambda kv: int(kv[0])))
    breaks = {}
    for key, by_level in groups.items():
        perfect = by_level.get('perfect', {}).get('cases', {})
        for lv, g in by_level.items():
            if lv == 'perfect':
                continue
            unsafe = [int(c) for c, v in g['cases'].items() if v['collisions'] or v['near_misses']]
            below = [int(c) for c, v in g['cases'].items()
                     if v['min_distance_m'] < r_min_m and c in perfect
                     and perfect[c]['min_distance_m'] >= r_min_m]
            worse = sorted(((perfect[c]['min_distance_m'] - v['min_distance_m'], int(c))
                            for c, v in g['cases'].items() if c in perfect), reverse=True)
            breaks.setdefault(key, {})[lv] = {
                'cases_with_collision_or_near_miss': unsafe,
                'cases_newly_below_r_min': below,
                'largest_loss_m': round(worse[0][0], 1) if worse else None,
                'largest_loss_case': worse[0][1] if worse else None}
    order = {lv: i for i, lv in enumerate(levels)}
    return {k: dict(sorted(v.items(), key=lambda kv: order[kv[0]])) for k, v in groups.items()}, \
        breaks


def _min(a, b):
    return b if a is None else min(a, b)


def main(argv=None):
    args, cases = parse_args(argv)
    t0 = time.perf_counter()
    tasks = [(ship, method, c, cases[c], level, seed)
             for c in args.cases for ship in args.ships for method in args.methods
             for level in args.levels
             for seed in ((0,) if LEVELS[level].perfect else range(1, args.seeds + 1))]
    print(f'{len(tasks)} runs ({len(args.cases)} cases x {args.ships} x {args.methods} x '
          f'{args.levels}, {args.seeds} seeds per degraded level), {args.jobs} processes',
          flush=True)
    done = {}
    if args.cache is not None and args.cache.is_file():
        for line in args.cache.read_text().splitlines():
            r = json.loads(line)
            done[(r['ship'], r['method'], r['case'], r['level'], r['seed'])] = r
    keys = [(t[0], t[1], t[2], t[4], t[5]) for t in tasks]
    runs = [done[k] for k in keys if k in done]
    todo = [t for t, k in zip(tasks, keys) if k not in done]
    if runs:
        print(f'{len(runs)} runs from {args.cache}', flush=True)
    for ship in sorted({t[0] for t in todo}):
        _REFERENCES[ship] = _reference(ship, cases[min(cases)])
    with multiprocessing.get_context('fork').Pool(args.jobs) as pool:
        for i, r in enumerate(pool.imap_unordered(run_one, todo), 1):
            runs.append(r)
            if args.cache is not None:
                with args.cache.open('a') as f:
                    f.write(json.dumps(r) + '\n')
            print(f'\r  {i}/{len(todo)} runs, {time.perf_counter() - t0:.0f} s', end='',
                  flush=True)
    print()
    runs.sort(key=lambda r: (r['ship'], r['method'], r['case'], list(LEVELS).index(r['level']),
                             r['seed']))
    r_min = EvaluationParams().r_min_m
    groups, breaks = summarise(runs, args.levels, r_min)
    levels = {name: _level_doc(LEVELS[name]) for name in args.levels}
    data = {'cases': args.cases, 'ships': args.ships, 'methods': args.methods,
            'levels': levels, 'seeds': args.seeds, 'limit_s': LIMIT_S, 'r_min_m': r_min,
            'groups': groups, 'breaks': breaks, 'runs': runs,
            'wall_s': round(time.perf_counter() - t0, 1),
            'provenance': provenance(sys.argv if argv is None else [sys.argv[0], *argv])}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(data, indent=1) + '\n')
    for key, by_level in groups.items():
        for lv, g in by_level.items():
            print(f'{key:18s} {lv:12s} runs {g["runs"]:3d} collisions {g["collisions"]:2d} '
                  f'near misses {g["near_misses"]:2d} min distance {g["min_distance_m"]:7.1f} m '
                  f'(case {g["min_distance_case"]})')
    print(f'written {args.out} in {data["wall_s"]:.0f} s (load {os.getloadavg()[0]:.1f})')
    return 0


def _level_doc(level):
    """A level's numbers for the results file (what the page's level table shows)."""
    out = {'summary': level.summary}
    if level.ais is not None:
        a = level.ais
        out['ais'] = {'class': level.ais_class, 'loss_probability': a.loss_probability,
                      'mean_burst_length': a.mean_burst_length,
                      'position_sigma_m': a.position_sigma_m, 'sog_sigma_kn': a.sog_sigma_kn,
                      'cog_sigma_deg': a.cog_sigma_deg, 'latency_s': a.latency_s,
                      'latency_jitter_s': a.latency_jitter_s, 'antenna_m': list(level.antenna)}
    if level.radar is not None:
        r = level.radar
        out['radar'] = {'scan_period_s': r.scan_period_s, 'range_sigma_m': r.range_sigma_m,
                        'bearing_sigma_deg': r.bearing_sigma_deg,
                        'detection_range_m': r.detection_range_m,
                        'detection_probability': r.detection_probability,
                        'confirm_plots': level.radar_confirm_plots,
                        'coast_s': level.radar_coast_s}
    return out


if __name__ == '__main__':
    sys.exit(main())
