#!/usr/bin/env python3
"""The Imazu benchmark on the MSS plants: 22 encounters x own ships x colav methods, in process.

    .venv/bin/python scripts/imazu_benchmark.py [--set imazu|dnv] [--quick] [--cases 1,2,5] [--ships tanker]
        [--methods sbmpc] [--jobs 2] [--limit 4000] [--out runs] [--no-plots]
        [--scenario-out DIR] [--rescore DIR]

Each run (scripts/imazu/runner.py): the own ship (mariner, tanker or container) at 12 kn on a
straight route through its Imazu track, the case's targets as light targets holding course and
speed (not avoiding), colav_node's decision core at its decision period, the same objects and
order as the node graph in lockstep. A run ends once every target has passed and the own
ship is back on its route (imazu.runner.RunEnd), or at the limit (``--limit``, reported as
``limit``). Plus one run per ship without traffic over the whole limit, the reference of path
deviation, time lost, the return to the route and the manoeuvre detection. Scored by
ship_guidance.colav_evaluation with the ships' dimensions (doc/colav_benchmark.md).

``--set dnv`` runs DNV ship-traffic-generator's 55 baseline situations instead
(scripts/imazu/trafficgen_baseline: the own ship at 10 kn, one to three targets at their own
speeds, each scored with its own length and beam from the file), the same way.

Writes runs/<set>-<UTC stamp>/ (imazu- or dnv-): results.csv (one row per run and target), summary.json (per
ship and method, per case, and its provenance: command, commit, UTC date, load), runs.npz and runs.json (the
tracks, for ``--rescore DIR``: score a finished folder again with the current evaluator,
without running), case_NN.png (tracks with 5-minute marks and range to each target,
every ship x method), summary.png, index.html (one row per case x ship x method, linking to
the case's plot; summary.png and every case plot embedded in the page). ``--quick``: the
single-target cases (Imazu 1-4, DNV 1-5) on the mariner, both methods. ``--scenario-out DIR``: write each
selected case as a scenario YAML (scripts/run_mission.py DIR/<name>.yaml runs it through the
node graph) and stop.
"""
import csv
import json
import multiprocessing
import os
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

from imazu.cases import SETS, SINGLE, load_set, single_target
from imazu.runner import LIMIT_S, METHODS, SHIPS, RunEnd, case_scenario, write_scenario
from imazu.storage import load_runs, save_runs
from ship_mission.cli_args import OneLineParser, comma_names, integer, number, out_folder
from ship_mission.scenario import MIN_DURATION_S
from ship_sim.allocator import tune_allocator

ROOT = Path(__file__).resolve().parent.parent

#: Most worker processes: each run is one CPU's work, more processes than cores only contend.
MAX_JOBS = max(2, os.cpu_count() or 1)
#: Longest run (sim s): an Imazu encounter is over within DURATION_S; a day is beyond any use.
MAX_DURATION_S = 86400.0


def _ints(text):
    return [int(v) for v in text.split(',') if v.strip()]


def parse_args(argv=None):
    ap = OneLineParser(description=__doc__.split('\n')[0])
    ap.add_argument('--quick', action='store_true', help='the single-target cases, mariner, both methods')
    ap.add_argument('--set', choices=SETS, default='imazu',
                    help='encounter set: the 22 Imazu cases, or DNV trafficgen\'s 55 baseline '
                         'situations (scripts/imazu/trafficgen_baseline; default imazu)')
    ap.add_argument('--cases', type=_ints, help='case numbers, e.g. 1,2,5 (default all of the set)')
    ap.add_argument('--ships', type=comma_names(SHIPS), help=f'own ships (default {",".join(SHIPS)})')
    ap.add_argument('--methods', type=comma_names(METHODS), help=f'default {",".join(METHODS)}')
    ap.add_argument('--jobs', type=integer(1, MAX_JOBS), default=2,
                    help=f'worker processes, 1-{MAX_JOBS} (default 2)')
    ap.add_argument('--limit', type=number(MIN_DURATION_S, MAX_DURATION_S), default=LIMIT_S,
                    help='longest sim time per run, s (a run ends earlier once every target has '
                         f'passed and the own ship is back on its route; {MIN_DURATION_S:g} to '
                         f'{MAX_DURATION_S:g})')
    ap.add_argument('--out', type=out_folder, default=ROOT / 'runs', help='parent of the run folder')
    ap.add_argument('--no-plots', action='store_true')
    ap.add_argument('--scenario-out', type=out_folder, help='write the scenarios here and stop')
    ap.add_argument('--rescore', type=Path, metavar='DIR',
                    help='score the runs of a finished benchmark folder again, no running')
    args = ap.parse_args(argv)
    if args.rescore and not (args.rescore / 'runs.npz').is_file():
        ap.error(f'{args.rescore}: no runs.npz (a folder written by this benchmark)')
    cases = load_set(args.set)
    if args.quick:
        args.cases = args.cases or list(SINGLE if args.set == 'imazu' else single_target(cases))
        args.ships = args.ships or ['mariner']
    args.cases = args.cases or sorted(cases)
    bad = [c for c in args.cases if c not in cases]
    if bad:
        ap.error(f'no {args.set} case {bad}; cases are {min(cases)}-{max(cases)}')
    if len({tuple(sorted(cases[c]['own'].items())) for c in args.cases}) > 1:
        # one no-traffic reference run per ship serves every case only if they share it
        ap.error(f'the {args.set} cases chosen start the own ship differently')
    args.ships = args.ships or list(SHIPS)
    args.methods = args.methods or list(METHODS)
    return args, cases


def _run(task):
    """Worker: (key, RunResult) of one scenario written into a temporary folder; ``end``
    (the task's last item, a RunEnd or None) may stop it early."""
    import tempfile

    from imazu.runner import run_scenario
    key, scenario, route, end = task
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        result = run_scenario(write_scenario(scenario, route, tmp), end=end)
        return key, result, time.perf_counter() - t0


def main(argv=None):
    tune_allocator()   # SB-MPC's decisions; the forked pool inherits it
    args, cases = parse_args(argv)
    if args.scenario_out:
        n = 0
        for c in args.cases:
            for ship in args.ships:
                for method in args.methods:
                    sc, route = case_scenario(c, cases[c], ship, method, args.limit)
                    write_scenario(sc, route, args.scenario_out)
                    n += 1
        print(f'{n} scenarios in {args.scenario_out}: run one with '
              f'.venv/bin/python scripts/run_mission.py {args.scenario_out}/<name>.yaml')
        return 0
    from imazu.evaluate import evaluate, rows_of

    from ship_guidance.colav_evaluation import EvaluationParams

    stamp = datetime.now(timezone.utc).strftime('%Y%m%d-%H%M%S')
    started = provenance(argv)    # the code the runs import is the code at their start
    if args.rescore:
        out = args.rescore
        saved = load_runs(out)
        results, walls = saved['results'], saved['walls']
        args.cases, args.ships, args.methods = saved['cases'], saved['ships'], saved['methods']
        args.limit = saved['limit']
        args.set = saved.get('set', 'imazu')      # folders from before the DNV set: Imazu
        cases = load_set(args.set)
        tasks = list(results)
        print(f'rescoring {len(tasks)} runs of {out}', flush=True)
    else:
        first = min(cases)
        tasks = [((ship, None, None), *case_scenario(first, cases[first], ship, None, args.limit),
                  None) for ship in args.ships]
        tasks += [((ship, method, c), *case_scenario(c, cases[c], ship, method, args.limit),
                   RunEnd.of_case(cases[c]))
                  for c in args.cases for ship in args.ships for method in args.methods]
        out = args.out / f'{args.set}-{stamp}'
        out.mkdir(parents=True, exist_ok=True)
        print(f'{args.set} benchmark: {len(args.cases)} cases x {len(args.ships)} ships x '
              f'{len(args.methods)} methods + {len(args.ships)} no-traffic runs = {len(tasks)} '
              f'runs of up to {args.limit:g} s sim, {args.jobs} processes -> {out}', flush=True)
        results, walls = {}, []
    per_run = {}
    params = EvaluationParams()
    csv_file = open(out / 'results.csv', 'w', newline='')
    writer = None

    def score(key):
        """Evaluate a finished run once its ship's reference is in; rows go to the CSV at once
        (an interrupted benchmark keeps what it has finished)."""
        nonlocal writer
        ship, method, c = key
        run = evaluate(results[key], results[(ship, None, None)], cases[c], ship)
        run.update(run_end=results[key].end, run_end_s=float(results[key].t[-1]))
        per_run[(c, ship, method)] = run
        rows = rows_of(c, ship, method, run, results[key])
        if writer is None:
            writer = csv.DictWriter(csv_file, fieldnames=list(rows[0]))
            writer.writeheader()
        writer.writerows(rows)
        csv_file.flush()

    t0 = time.perf_counter()
    with csv_file:
        if args.rescore:
            for key in tasks:
                if key[1] is not None:
                    score(key)
        else:
            with multiprocessing.get_context('fork').Pool(args.jobs) as pool:
                for i, (key, result, wall) in enumerate(pool.imap_unordered(_run, tasks), 1):
                    results[key] = result
                    walls.append(wall)
                    ship, method, c = key
                    if method is None:
                        for other in [k for k in results if k[0] == ship and k[1] is not None]:
                            score(other)
                    elif (ship, None, None) in results:
                        score(key)
                    elapsed = time.perf_counter() - t0
                    eta = elapsed / i * (len(tasks) - i)
                    print(f'\r  {i}/{len(tasks)} runs, {elapsed:.0f} s elapsed, ~{eta:.0f} s '
                          'left   ', end='', flush=True)
            print()
            save_runs(out, results, {'walls': walls, 'cases': args.cases, 'ships': args.ships,
                                     'methods': args.methods, 'limit': args.limit,
                                     'set': args.set,
                                     'provenance': dict(started,
                                                        load_1min_end=os.getloadavg()[0])})
    per_run = {k: per_run[k] for k in sorted(per_run)}
    summary = summarise(per_run, results, args, walls)
    summary['provenance'] = started
    if args.rescore:    # the runs' own provenance: the code and load that produced the tracks
        summary['runs_provenance'] = saved.get('provenance')
    (out / 'summary.json').write_text(json.dumps(summary, indent=1))
    (out / 'table.md').write_text(markdown_tables(summary, cases))
    if not args.no_plots:
        from imazu.evaluate import ship_dimensions
        from imazu.plots import case_figure, summary_figure
        refs = {ship: results[(ship, None, None)] for ship in args.ships}
        for c in args.cases:
            runs = {(ship, m): results[(ship, m, c)] for ship in args.ships for m in args.methods}
            case_figure(out / f'case_{c:02d}.png', c, runs, refs, params,
                        {ship: ship_dimensions(ship) for ship in args.ships})
        run_rows = [{'case': c, 'ship': s, 'method': m, 'run_min_distance_m': v['min_distance_m'],
                     'collisions': v['collisions'], 'near_misses': v['near_misses'],
                     'below_safe': v['below_safe'], 'run_rule_score': v['rule_score']}
                    for (c, s, m), v in per_run.items()]
        summary_figure(out / 'summary.png', run_rows, params)
    html_page(out / 'index.html', per_run, summary, cases, plots=not args.no_plots)
    print_table(summary)
    latest = args.out / f'{args.set}-latest'
    if not args.rescore and (latest.is_symlink() or not latest.exists()):
        if latest.is_symlink():
            latest.unlink()
        latest.symlink_to(out.name)
    print(f'written: {out}/results.csv, summary.json' + ('' if args.no_plots else
                                                          ', case_NN.png, summary.png'))
    return 0


def provenance(argv):
    """The command, the code's git commit (with '+dirty' for uncommitted changes), UTC date,
    1-minute load and CPU count of a result (the figures a reader needs to trust or redo it)."""
    def git(*a):
        try:
            return subprocess.run(['git', *a], cwd=ROOT, capture_output=True, text=True,
                                  timeout=10).stdout.strip()
        except OSError:
            return ''
    commit = git('rev-parse', 'HEAD')
    if commit and git('status', '--porcelain', '--untracked-files=no'):
        commit += '+dirty'
    cmd = [sys.argv[0]] + (sys.argv[1:] if argv is None else list(argv))
    return {'command': ' '.join(cmd), 'commit': commit or None,
            'date_utc': datetime.now(timezone.utc).isoformat(timespec='seconds'),
            'load_1min': os.getloadavg()[0], 'cpus': os.cpu_count()}


def summarise(per_run, results, args, walls):
    """summary.json: per (ship, method) totals and per case figures; the decision cost."""
    groups = {}
    for (c, ship, method), run in per_run.items():
        g = groups.setdefault(f'{ship}/{method}', {'runs': 0, 'collisions': 0, 'near_misses': 0,
                                                   'below_safe': 0, 'min_distance_m': float('inf'),
                                                   'scores': [], 'single_scores': [],
                                                   'deviation': [], 'time_lost': [], 'cases': {},
                                                   'returns': [], 'never': 0, 'limit': 0})
        back = run['return_to_route_s']
        if back is None:
            g['never'] += 1
        else:
            g['returns'].append(back)
        g['limit'] += run['run_end'] == 'limit'
        g['runs'] += 1
        g['collisions'] += run['collisions']
        g['near_misses'] += run['near_misses']
        g['below_safe'] += run['below_safe']
        g['min_distance_m'] = min(g['min_distance_m'], run['min_distance_m'])
        g['scores'].append(run['rule_score'])
        if len(run['targets']) == 1:           # the single-target cases
            g['single_scores'].append(run['rule_score'])
        g['deviation'].append(run['path_deviation_m'])
        g['time_lost'].append(run['time_lost_s'])
        g['cases'][c] = {'min_distance_m': round(run['min_distance_m'], 1),
                         'collisions': run['collisions'], 'near_misses': run['near_misses'],
                         'rule_score': round(run['rule_score'], 3),
                         'path_deviation_m': round(run['path_deviation_m'], 1),
                         'time_lost_s': round(run['time_lost_s'], 1),
                         'min_hull_clearance_m': round(run['min_hull_clearance_m'], 1),
                         'last_cpa_s': round(run['last_cpa_s'], 1),
                         'return_to_route_s': None if back is None else round(back, 1),
                         'run_end_s': round(run['run_end_s'], 1), 'run_end': run['run_end'],
                         'penalties': {n: sorted(v['penalties']) for n, v in run['targets'].items()
                                       if v['penalties']}}
    out = {}
    for key, g in sorted(groups.items()):
        out[key] = {'runs': g['runs'], 'collisions': g['collisions'],
                    'near_misses': g['near_misses'], 'below_safe': g['below_safe'],
                    'min_distance_m': round(g['min_distance_m'], 1),
                    'rule_score_mean': _mean(g['scores']),
                    'rule_score_single_target_mean': _mean(g['single_scores']),
                    'path_deviation_m_mean': _mean(g['deviation']),
                    'time_lost_s_mean': _mean(g['time_lost']),
                    'return_to_route_s_mean': _mean(g['returns']),
                    'never_back_on_route': g['never'], 'limit_hit': g['limit'],
                    'cases': g['cases']}
    decisions = sum(len(r.decisions) for r in results.values())
    decide_s = sum(r.decision_wall_s for r in results.values())
    return {'groups': out, 'set': args.set, 'limit_s': args.limit, 'cases': args.cases,
            'ships': args.ships,
            'methods': args.methods, 'runs': len(results), 'run_wall_s_mean': sum(walls) / len(walls),
            'decisions': decisions, 'decision_ms_mean': 1e3 * decide_s / max(decisions, 1),
            'load_average_1min': os.getloadavg()[0], 'cpus': os.cpu_count()}


def markdown_tables(summary, cases):
    """Markdown: the totals per ship and method, then per case 'min distance m / rule score /
    back on route s' in each ship/method column (what the Imazu table of doc/results/imazu.md shows)."""
    groups = summary['groups']
    lines = ['| ship / method | runs | collisions (hull contact) | near misses (ship domain) | '
             'below r_min | min distance m | rule score (all) | rule score (single target) | '
             'path deviation m (mean) | time lost s (mean) | back on route s (mean) | '
             'never back on route | limit hit |', '|' + '---|' * 13]
    for key, g in groups.items():
        lines.append(f'| {key} | {g["runs"]} | {g["collisions"]} | {g["near_misses"]} | '
                     f'{g["below_safe"]} | {g["min_distance_m"]:.0f} | {g["rule_score_mean"]:.3f} | '
                     f'{_num(g["rule_score_single_target_mean"]):.3f} | '
                     f'{g["path_deviation_m_mean"]:.0f} | {g["time_lost_s_mean"]:.1f} | '
                     f'{_num(g["return_to_route_s_mean"]):.0f} | {g["never_back_on_route"]} | '
                     f'{g["limit_hit"]} |')
    keys = list(groups)
    lines += ['', '| case | targets (own view) | ' + ' | '.join(keys) + ' |',
              '|' + '---|' * (len(keys) + 2)]
    for c in summary['cases']:
        sits = ', '.join(t['colregs'] for t in cases[c]['targets'])
        cells = []
        for k in keys:
            v = groups[k]['cases'].get(c) or groups[k]['cases'].get(str(c))
            cells.append('' if v is None else f'{v["min_distance_m"]:.0f} / {v["rule_score"]:.2f}'
                         f' / {_back(v["return_to_route_s"])}')
        lines.append(f'| {c} | {sits} | ' + ' | '.join(cells) + ' |')
    return '\n'.join(lines) + '\n'


def html_page(path, per_run, summary, cases, plots=True):
    """index.html (ship_mission.html_report.batch_page): the totals per ship and method, then one row
    per case x ship x method, its first cell linking to the case's plot (case_NN.png, embedded
    in the page below the tables with summary.png first)."""
    from ship_mission.html_report import batch_page, figure_id
    totals = [[key, g['runs'], g['collisions'], g['near_misses'], g['below_safe'],
               g['min_distance_m'], g['rule_score_mean'], g['rule_score_single_target_mean'],
               g['path_deviation_m_mean'], g['time_lost_s_mean'], g['return_to_route_s_mean'],
               g['never_back_on_route'], g['limit_hit']]
              for key, g in summary['groups'].items()]
    rows, links = [], []
    shown = sorted({c for c, _, _ in per_run})
    for (c, ship, method), run in per_run.items():
        pen = '; '.join(f'{n}: {", ".join(sorted(v["penalties"]))}'
                        for n, v in run['targets'].items() if v['penalties'])
        rows.append([f'case {c}', ship, method,
                     ', '.join(t['colregs'] for t in cases[c]['targets']),
                     round(run['min_distance_m'], 1), run['collisions'], run['near_misses'],
                     run['below_safe'], round(run['rule_score'], 3), pen,
                     round(run['path_deviation_m'], 1), round(run['time_lost_s'], 1),
                     _back(run['return_to_route_s']), run['run_end']])
        links.append('#' + figure_id(f'case_{c:02d}.png') if plots else None)
    return batch_page(
        path, 'Imazu benchmark: collision avoidance on the MSS plants',
        ['case (plot)', 'own ship', 'method', 'targets (own view)', 'min distance m',
         'collisions', 'near misses', 'below r_min', 'rule score', 'penalties',
         'path deviation m', 'time lost s', 'back on route s', 'run end'], rows, links,
        intro=f'{len(rows)} runs, each until every target has passed and the own ship is back '
              f'on its route, at most {summary["limit_s"]:g} s sim; scored by '
              'ship_guidance.colav_evaluation (doc/colav_benchmark.md) against each ship\'s run '
              f'without traffic. Decisions: {summary["decision_ms_mean"]:.2f} ms each (load '
              f'{summary["load_average_1min"]:.1f} on {summary["cpus"]} CPUs).',
        sections=[('Totals per own ship and method',
                   ['ship / method', 'runs', 'collisions', 'near misses', 'below r_min',
                    'min distance m', 'rule score (all)', 'rule score (single target)',
                    'path deviation m (mean)', 'time lost s (mean)', 'back on route s (mean)',
                    'never back on route', 'limit hit'], totals)],
        figures=[path.parent / 'summary.png'] + [path.parent / f'case_{c:02d}.png'
                                                 for c in shown] if plots else (),
        captions={'summary.png': 'minimum distance and rule score per case and ship/method',
                  **{f'case_{c:02d}.png': f'case {c}: tracks (dots every 5 min, labels in '
                     'minutes) and range to each target, per ship and method' for c in shown}})


def _back(seconds):
    return 'never' if seconds is None else round(seconds, 1)


def _mean(xs):
    return round(sum(xs) / len(xs), 3) if xs else None


def _num(x):
    return float('nan') if x is None else x


def print_table(summary):
    print(f'{"ship/method":20s} {"runs":>4s} {"coll":>4s} {"nm":>3s} {"<rmin":>5s} '
          f'{"min d m":>8s} {"score":>6s} {"1-tgt":>6s} {"dev m":>7s} {"lost s":>7s} '
          f'{"back s":>7s} {"never":>5s} {"limit":>5s}')
    for key, g in summary['groups'].items():
        print(f'{key:20s} {g["runs"]:4d} {g["collisions"]:4d} {g["near_misses"]:3d} '
              f'{g["below_safe"]:5d} {g["min_distance_m"]:8.0f} {g["rule_score_mean"]:6.3f} '
              f'{_num(g["rule_score_single_target_mean"]):6.3f} '
              f'{g["path_deviation_m_mean"]:7.0f} {g["time_lost_s_mean"]:7.1f} '
              f'{_num(g["return_to_route_s_mean"]):7.0f} {g["never_back_on_route"]:5d} '
              f'{g["limit_hit"]:5d}')
    print(f'mean run {summary["run_wall_s_mean"]:.1f} s wall, {summary["decisions"]} decisions at '
          f'{summary["decision_ms_mean"]:.2f} ms each (load {summary["load_average_1min"]:.1f} on '
          f'{summary["cpus"]} CPUs)')


if __name__ == '__main__':
    raise SystemExit(main())
