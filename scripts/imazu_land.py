#!/usr/bin/env python3
"""Imazu cases beside a coast, SB-MPC with and without the land in its cost (issue 29 item 5).

    .venv/bin/python scripts/imazu_land.py [--cases 1,2,3,4,5] [--ships mariner] [--jobs 2]
        [--limit 4000] [--out doc/results/data/land.json]

Each case is run twice by the in-process Imazu runner (scripts/imazu/runner.py) with SB-MPC:
once with the coast of imazu.land (1 NM to starboard of the route, so the give-way alteration
to starboard heads towards it) in its grounding cost (run_scenario(..., land=chart)), once
without (the benchmark's run, the coast only on the chart the outcome is read against). A run
ends as the benchmark's do (imazu.runner.RunEnd) and is scored by the benchmark's evaluator
(scripts/imazu/evaluate.py) against the ship's run without traffic; the track is read against
the coast (imazu.land.land_outcome). Writes the results file of doc/results/land.md (render it
with scripts/render_results.py).
"""
import argparse
import json
import multiprocessing
import os
import sys
import time
from pathlib import Path

from imazu import land as coast
from imazu.cases import load_cases
from imazu.runner import LIMIT_S, SHIPS, RunEnd, case_scenario
from ship_mission.cli_args import OneLineParser, comma_names, integer, number
from ship_mission.scenario import MIN_DURATION_S
from results_pages.provenance import provenance

from ship_guidance.colav_params import ColavParams
from ship_sim.allocator import tune_allocator

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / 'doc' / 'results' / 'data' / 'land.json'
MAX_JOBS = max(2, os.cpu_count() or 1)
#: The two-ship cases and one multi-target case whose give-way ship (case 5's crosser) comes
#: out of the channel while a head-on ship closes: both ask for a turn to starboard.
CASES = (1, 2, 3, 4, 5)
METHOD = 'sbmpc'


def _cases(known):
    def parse(text):
        try:
            out = [int(v) for v in text.split(',') if v.strip()]
        except ValueError:
            raise argparse.ArgumentTypeError(f'case numbers, e.g. 1,2,5: got {text!r}') from None
        bad = [c for c in out if c not in known]
        if bad or not out:
            raise argparse.ArgumentTypeError(f'unknown cases {bad}; choose from 1-{max(known)}')
        return out
    return parse


def parse_args(argv=None):
    cases = load_cases()
    ap = OneLineParser(description=__doc__.split('\n')[0])
    ap.add_argument('--cases', type=_cases(sorted(cases)), default=list(CASES),
                    help='Imazu case numbers (default 1-5)')
    ap.add_argument('--ships', type=comma_names(SHIPS), default=['mariner'])
    ap.add_argument('--jobs', type=integer(1, MAX_JOBS), default=2)
    ap.add_argument('--limit', type=number(MIN_DURATION_S, 86400.0), default=LIMIT_S,
                    help='longest sim time per run, s')
    ap.add_argument('--out', type=Path, default=OUT, help='results file (JSON)')
    return ap.parse_args(argv), cases


def _run(task):
    import tempfile

    from imazu.runner import run_scenario, write_scenario
    key, scenario, route, end, with_land = task
    chart = coast.coast_chart() if with_land else None
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        result = run_scenario(write_scenario(scenario, route, tmp), end=end, land=chart)
        return key, result, time.perf_counter() - t0


def main(argv=None):
    tune_allocator()
    args, cases = parse_args(argv)
    from imazu.evaluate import evaluate
    tasks = [((ship, None, False), *case_scenario(1, cases[1], ship, None, args.limit), None,
              False) for ship in args.ships]
    tasks += [((ship, c, with_land), *case_scenario(c, cases[c], ship, METHOD, args.limit),
               RunEnd.of_case(cases[c]), with_land)
              for c in args.cases for with_land in (False, True) for ship in args.ships]
    print(f'{len(tasks)} runs, {args.jobs} processes', flush=True)
    results, walls, t0 = {}, [], time.perf_counter()
    with multiprocessing.get_context('fork').Pool(args.jobs) as pool:
        for i, (key, result, wall) in enumerate(pool.imap_unordered(_run, tasks), 1):
            results[key] = result
            walls.append(wall)
            print(f'\r  {i}/{len(tasks)} runs, {time.perf_counter() - t0:.0f} s', end='',
                  flush=True)
    print()
    chart = coast.coast_chart()
    runs = []
    for (ship, c, with_land), result in sorted(
            ((k, v) for k, v in results.items() if k[1] is not None),
            key=lambda kv: (kv[0][1], kv[0][0], kv[0][2])):
        run = evaluate(result, results[(ship, None, False)], cases[c], ship)
        on_land = coast.land_outcome(chart, result.t, result.own)
        runs.append({
            'case': c, 'targets': ', '.join(t['colregs'] for t in cases[c]['targets']),
            'ship': ship, 'method': METHOD, 'land_in_cost': with_land,
            'collisions': run['collisions'], 'near_misses': run['near_misses'],
            'below_safe': run['below_safe'],
            'min_distance_m': round(run['min_distance_m'], 1),
            'rule_score': round(run['rule_score'], 3),
            'path_deviation_m': round(run['path_deviation_m'], 1),
            'min_land_distance_m': round(on_land['min_land_distance_m'], 1),
            'grounded': on_land['grounded'],
            'time_on_land_s': round(on_land['time_on_land_s'], 1),
            'max_starboard_m': round(float(result.own[:, 1].max()), 1),
            'run_end': result.end, 'run_end_s': round(float(result.t[-1]), 1),
            'last_resort_decisions': sum(d[1] == 'last-resort' for d in result.decisions),
            'penalties': {n: sorted(v['penalties']) for n, v in run['targets'].items()
                          if v['penalties']},
        })
    p = ColavParams()
    data = {'provenance': provenance(argv if argv is None else [sys.argv[0], *argv]),
            'settings': {'cases': args.cases, 'ships': args.ships, 'method': METHOD,
                         'limit_s': args.limit, 'coast_offset_m': coast.OFFSET_M,
                         'channel_north_m': list(coast.CHANNEL_M),
                         'chart_resolution_m': coast.RESOLUTION_M,
                         'grounding_clearance_m': p.grounding_clearance_m,
                         'w_grounding': p.w_grounding, 'w_collision': p.w_collision,
                         'run_wall_s_mean': round(sum(walls) / len(walls), 1)},
            'runs': runs}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(data, indent=1) + '\n')
    for r in runs:
        print(f"case {r['case']} {r['ship']:8s} land {'yes' if r['land_in_cost'] else 'no ':3s} "
              f"coll {r['collisions']} nm {r['near_misses']} min {r['min_distance_m']:7.0f} m "
              f"score {r['rule_score']:.3f} dev {r['path_deviation_m']:6.0f} m "
              f"land {r['min_land_distance_m']:6.0f} m grounded {r['grounded']} "
              f"stbd {r['max_starboard_m']:6.0f} m")
    print(f'written: {args.out}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
