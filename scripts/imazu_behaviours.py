#!/usr/bin/env python3
"""The own ship's outcome per target behaviour on the Imazu cases (issue 31 item 4).

    .venv/bin/python scripts/imazu_behaviours.py [--cases 1,2,3,4] [--ships mariner]
        [--methods sbmpc,vo] [--jobs 2] [--limit 4000] [--out doc/results/data/reacting_traffic.json]

Each run is one Imazu case (scripts/imazu/runner.py) with every target given one behaviour of
ship_guidance.reacting_traffic (straight, reciprocal, turns_to_port, no_alteration) where it
applies to that target's encounter (reacting_traffic.applies: turns_to_port to a stand-on
crossing target, no_alteration to a head-on or give-way one; straight and reciprocal to every
target); the other targets of a case keep straight, and a behaviour that applies to none of a
case's targets is not run there. A run ends as the benchmark's do (imazu.runner.RunEnd) and is
scored by the benchmark's evaluator (scripts/imazu/evaluate.py) against the ship's run without
traffic. Writes the results file of doc/results/reacting_traffic.md (render it with
scripts/render_results.py): per run collisions, near misses, minimum distance, rule score,
path deviation, the evaluator's penalties per target, and the targets' own largest alteration
from their start course.
"""
import argparse
import json
import multiprocessing
import os
import sys
import time
from pathlib import Path

from imazu.cases import SINGLE, load_cases
from imazu.runner import LIMIT_S, METHODS, SHIPS, RunEnd, case_scenario
from ship_mission.cli_args import OneLineParser, integer, number
from ship_mission.scenario import MIN_DURATION_S
from results_pages.provenance import provenance

from ship_guidance.reacting_traffic import (APPLIES, PORT_TURN_DEG, TRIGGER_RANGE_M, applies)
from ship_sim.allocator import tune_allocator
from ship_sim.light_traffic import BEHAVIOURS

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / 'doc' / 'results' / 'data' / 'reacting_traffic.json'
MAX_JOBS = max(2, os.cpu_count() or 1)


def _list(choices, cast=str):
    def parse(text):
        out = [cast(v.strip()) for v in text.split(',') if v.strip()]
        bad = [v for v in out if v not in choices]
        if bad:
            raise argparse.ArgumentTypeError(f'unknown {bad}; choose from {", ".join(map(str, choices))}')
        return out
    return parse


def parse_args(argv=None):
    cases = load_cases()
    ap = OneLineParser(description=__doc__.split('\n')[0])
    ap.add_argument('--cases', type=_list(sorted(cases), int), default=list(SINGLE),
                    help='Imazu case numbers (default 1-4, the two-ship cases)')
    ap.add_argument('--ships', type=_list(SHIPS), default=['mariner'])
    ap.add_argument('--methods', type=_list(METHODS), default=list(METHODS))
    ap.add_argument('--behaviours', type=_list(BEHAVIOURS), default=list(BEHAVIOURS))
    ap.add_argument('--jobs', type=integer(1, MAX_JOBS), default=2)
    ap.add_argument('--limit', type=number(MIN_DURATION_S, 86400.0), default=LIMIT_S,
                    help='longest sim time per run, s')
    ap.add_argument('--out', type=Path, default=OUT, help='results file (JSON)')
    return ap.parse_args(argv), cases


def case_behaviours(case, behaviour):
    """{target name: behaviour} for the targets ``behaviour`` applies to (the others straight),
    or None when it applies to none of the case's targets."""
    chosen = {t['name']: behaviour for t in case['targets'] if applies(behaviour, t['colregs'])}
    return chosen or None


def _run(task):
    import tempfile

    from imazu.runner import run_scenario, write_scenario
    key, scenario, route, end, behaviours = task
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        result = run_scenario(write_scenario(scenario, route, tmp), end=end, behaviours=behaviours)
        return key, result, time.perf_counter() - t0


def target_alteration_deg(rows):
    """Signed largest departure (deg, + starboard) of a target's course from its start course."""
    import numpy as np
    d = np.degrees((rows[:, 2] - rows[0, 2] + np.pi) % (2.0 * np.pi) - np.pi)
    return float(d[np.argmax(np.abs(d))])


def main(argv=None):
    tune_allocator()
    args, cases = parse_args(argv)
    from imazu.evaluate import evaluate
    tasks = [((ship, None, None, None), *case_scenario(1, cases[1], ship, None, args.limit),
              None, None) for ship in args.ships]
    for c in args.cases:
        for b in args.behaviours:
            chosen = case_behaviours(cases[c], b)
            if chosen is None:
                continue
            tasks += [((ship, m, c, b), *case_scenario(c, cases[c], ship, m, args.limit),
                       RunEnd.of_case(cases[c]), chosen)
                      for ship in args.ships for m in args.methods]
    print(f'{len(tasks)} runs, {args.jobs} processes', flush=True)
    results, walls, t0 = {}, [], time.perf_counter()
    with multiprocessing.get_context('fork').Pool(args.jobs) as pool:
        for i, (key, result, wall) in enumerate(pool.imap_unordered(_run, tasks), 1):
            results[key] = result
            walls.append(wall)
            print(f'\r  {i}/{len(tasks)} runs, {time.perf_counter() - t0:.0f} s', end='',
                  flush=True)
    print()
    runs = []
    for (ship, method, c, b), result in sorted(
            ((k, v) for k, v in results.items() if k[1] is not None),
            key=lambda kv: (kv[0][2], args.behaviours.index(kv[0][3]), kv[0][0], kv[0][1])):
        run = evaluate(result, results[(ship, None, None, None)], cases[c], ship)
        chosen = case_behaviours(cases[c], b)
        runs.append({
            'case': c, 'targets': ', '.join(t['colregs'] for t in cases[c]['targets']),
            'ship': ship, 'method': method, 'behaviour': b,
            'reacting_targets': sorted(chosen),
            'collisions': run['collisions'], 'near_misses': run['near_misses'],
            'below_safe': run['below_safe'],
            'min_distance_m': round(run['min_distance_m'], 1),
            'rule_score': round(run['rule_score'], 3),
            'path_deviation_m': round(run['path_deviation_m'], 1),
            'run_end': result.end, 'run_end_s': round(float(result.t[-1]), 1),
            'last_resort_decisions': sum(d[1] == 'last-resort' for d in result.decisions),
            'penalties': {n: sorted(v['penalties']) for n, v in run['targets'].items()
                          if v['penalties']},
            'target_alteration_deg': {n: round(target_alteration_deg(result.targets[n]), 1)
                                      for n in sorted(chosen)},
        })
    data = {'provenance': provenance(argv if argv is None else [sys.argv[0], *argv]),
            'settings': {'cases': args.cases, 'ships': args.ships, 'methods': args.methods,
                         'limit_s': args.limit, 'turns_to_port_trigger_range_m': TRIGGER_RANGE_M,
                         'turns_to_port_turn_deg': PORT_TURN_DEG,
                         'applies': {b: list(APPLIES[b]) for b in args.behaviours},
                         'run_wall_s_mean': round(sum(walls) / len(walls), 1)},
            'runs': runs}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(data, indent=1) + '\n')
    for r in runs:
        print(f"case {r['case']} {r['ship']:8s} {r['method']:5s} {r['behaviour']:14s} "
              f"coll {r['collisions']} nm {r['near_misses']} min {r['min_distance_m']:7.0f} m "
              f"score {r['rule_score']:.3f} dev {r['path_deviation_m']:6.0f} m "
              f"tgt {r['target_alteration_deg']}")
    print(f'written: {args.out}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
