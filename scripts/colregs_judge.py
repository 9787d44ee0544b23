#!/usr/bin/env python3
"""Our COLREGs evaluator and an independent judge, TUM's CommonOcean rule monitor, on the same
Imazu trajectories: per rule and per set, how often the two agree (issue 29 item 3).

    .venv/bin/python scripts/colregs_judge.py RUN_DIR [--jobs 3] [--cases 1,2,3] [--out FILE]

RUN_DIR: a folder written by scripts/imazu_benchmark.py (runs.npz + runs.json). Each run with
a method is scored by our evaluator as the benchmark scores it (imazu.evaluate) and its tracks,
resampled every DT_S seconds (the monitor's configured time step), go to
scripts/commonocean_monitor.py, run with .venv-judge's python (`make venv-judge`; the package
is GPL-3.0 and pins conflicting versions, so it is never imported here) in ``--jobs``
processes, JSON in and out (``--cases``: only those cases' runs, the monitor being slow on a
loaded machine; the results file names the cases judged). imazu.judge_agreement pairs the
verdicts per (run, target) and rule. Writes FILE (default doc/results/data/colregs_judge.json):
per reading of the monitor's time intervals (commonocean_monitor's 'seconds', as shipped, and
'steps'), per set (ship/method) and rule the counts per class, and every pair.
"""
import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from imazu.cases import load_cases
from imazu.evaluate import evaluate, ship_dimensions
from imazu.judge_agreement import RULES, agreement_table, pairs
from imazu.storage import load_runs
from results_pages.provenance import provenance

ROOT = Path(__file__).resolve().parent.parent
JUDGE_PYTHON = ROOT / '.venv-judge' / 'bin' / 'python'
MONITOR = ROOT / 'scripts' / 'commonocean_monitor.py'
OUT = ROOT / 'doc' / 'results' / 'data' / 'colregs_judge.json'
#: Sample spacing (s) of the tracks given to the monitor: its configured time step.
DT_S = 10.0
#: The monitor's readings of its rules' time intervals: trace time unit (s) per sample.
READINGS = {'seconds': DT_S, 'steps': 1.0}


def monitor_ship(t, rows, dims, t_new):
    """A track (N, 4: north, east, course, speed) resampled on ``t_new`` in the monitor's
    frame: x east, y north, orientation anticlockwise from east (the course over ground)."""
    course = np.interp(t_new, t, np.unwrap(rows[:, 2]))
    return {'length_m': dims.length_m, 'beam_m': dims.beam_m,
            'x': np.interp(t_new, t, rows[:, 1]).tolist(),
            'y': np.interp(t_new, t, rows[:, 0]).tolist(),
            'orientation': ((np.pi / 2.0 - course) % (2.0 * np.pi)).tolist(),
            'speed': np.interp(t_new, t, rows[:, 3]).tolist()}


def monitor_run(key, t, own, targets, dims):
    """The monitor's input for one run: the own track and each target's ({name: (N, 4)})."""
    t_new = np.arange(float(t[0]), float(t[-1]) + 1e-9, DT_S)
    return {'key': key, 'own': monitor_ship(t, own, dims, t_new),
            'targets': {n: monitor_ship(t, rows, dims, t_new) for n, rows in targets.items()}}


def run_monitor(runs, jobs=1, python=JUDGE_PYTHON):
    """{key: the monitor's result} for the monitor inputs ``runs``, in ``jobs`` processes."""
    if not Path(python).is_file():
        raise FileNotFoundError(f'{python} not found: make venv-judge')
    chunks = [runs[i::jobs] for i in range(jobs) if runs[i::jobs]]
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        procs = []
        for i, chunk in enumerate(chunks):
            src, dst = Path(tmp) / f'in{i}.json', Path(tmp) / f'out{i}.json'
            src.write_text(json.dumps({'dt_s': DT_S, 'readings': READINGS, 'runs': chunk}))
            procs.append((subprocess.Popen([str(python), str(MONITOR), str(src), str(dst)]), dst))
        for proc, dst in procs:
            if proc.wait() != 0:
                raise RuntimeError(f'{MONITOR.name} failed (exit {proc.returncode})')
            result = json.loads(dst.read_text())
            out.update({r['key']: {**r, 'package': result['package']} for r in result['runs']})
    return out


def judge(ours, theirs):
    """{reading: {'sets': {set: {rule row: counts}}, 'pairs': [...]}} from our evaluations
    ({(ship, method, case): evaluate_run dict}) and the monitor's results (by key text)."""
    out = {}
    for reading in READINGS:
        every, sets = [], {}
        for (ship, method, case), run in sorted(ours.items()):
            key = f'{ship}|{method}|{case}'
            ps = [{**p, 'set': f'{ship}/{method}', 'case': case}
                  for p in pairs(key, run, theirs[key], reading)]
            every += ps
            sets.setdefault(f'{ship}/{method}', []).extend(ps)
        out[reading] = {'sets': {s: agreement_table(ps) for s, ps in sets.items()},
                        'all': agreement_table(every), 'pairs': every}
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('run_dir', type=Path)
    ap.add_argument('--jobs', type=int, default=1, help='monitor processes (default 1)')
    ap.add_argument('--cases', type=lambda s: sorted({int(c) for c in s.split(',') if c.strip()}),
                    help='judge only these cases, e.g. 1,2,3 (default every case of RUN_DIR)')
    ap.add_argument('--out', type=Path, default=OUT)
    args = ap.parse_args(argv)
    started = provenance(None if argv is None else [sys.argv[0], *argv])
    saved = load_runs(args.run_dir)
    results, cases = saved['results'], load_cases()
    ours, inputs = {}, []
    for key in sorted(k for k in results
                      if k[1] is not None and (args.cases is None or k[2] in args.cases)):
        ship, method, case = key
        r = results[key]
        ours[key] = evaluate(r, results[(ship, None, None)], cases[case], ship)
        inputs.append(monitor_run(f'{ship}|{method}|{case}', r.t, r.own, r.targets,
                                  ship_dimensions(ship)))
    print(f'{len(inputs)} runs to the monitor in {args.jobs} processes', flush=True)
    theirs = run_monitor(inputs, args.jobs)
    data = {'provenance': started, 'runs_provenance': saved.get('provenance'),
            'package': next(iter(theirs.values()))['package'] if theirs else None,
            'dt_s': DT_S, 'readings': READINGS,
            'rules': [{'id': r[0], 'title': r[1], 'situation': r[2], 'their_rule': r[3],
                       'their_predicate': r[4]} for r in RULES],
            'runs': len(ours), 'cases': sorted({k[2] for k in ours}),
            'cases_in_run_dir': sorted({k[2] for k in results if k[1] is not None}),
            'monitor_wall_s': sum(v['wall_s'] for v in theirs.values()),
            'readings_result': judge(ours, theirs)}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(data, indent=1, default=_plain) + '\n')
    for reading, res in data['readings_result'].items():
        for rid, row in res['all'].items():
            a = row['agreement']
            print(f'{reading:8s} {rid:20s} n={row["n"]:3d} agree={row["agree"]:3d} '
                  f'({"n/a" if a is None else f"{a:.2f}"})')
    print(f'written: {args.out}')
    return 0


def _plain(v):
    if isinstance(v, (np.bool_,)):
        return bool(v)
    if isinstance(v, np.generic):
        x = v.item()
        return None if isinstance(x, float) and not math.isfinite(x) else x
    raise TypeError(f'not JSON: {type(v)}')


if __name__ == '__main__':
    raise SystemExit(main())
