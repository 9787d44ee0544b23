#!/usr/bin/env python3
"""Monte Carlo sweep of the closed loop: many episodes, a table, a summary with confidence intervals, plots.

    scripts/sweep.py SWEEP.yaml [--out DIR] [--workers N] [--chunk N]
                     [--ray [ADDRESS]] [--episodes N] [--duration S]
                     [--where AXIS=V1[,V2]] [--no-plots] [--resume]

SWEEP.yaml: a base environment and the parameters to vary (grid or seeded random); the format
is documented in scripts/montecarlo/spec.py, examples in scenarios/sweeps/. Backends: local
processes (default, ``--workers`` = every core) or Ray (``--ray`` alone: a private local Ray
instance of ``--workers`` CPUs; ``--ray auto``: the cluster started with ``ray start`` on this
machine; ``--ray HOST:6379``: a cluster's head). The table is the same byte for byte for the
same sweep file and seed whatever the backend, the worker count and the chunk size.

Output (default runs/sweeps/<name>/): results.partial.jsonl while it runs (each chunk's rows as
they arrive: a sweep whose backend dies keeps them, names the missing episodes, and ``--resume``
runs only those), then results.csv (one row per episode), summary.md and
summary.json (per grid cell: mean and 95 % confidence interval of each metric), plots
(CDF of max cross-track per controller, or of min distance per colav method in an encounter
sweep; metric against each random parameter), run.json
(backend, workers, chunking, chunks rerun after a lost worker or node, wall time,
throughput), index.html (the summary table and every
plot embedded, one self-contained page: ship_mission.html_report.batch_page). Exit codes: 0 done, 1 a chunk failed,
2 a bad sweep file or arguments.

Test-only: SHIPNAV_SWEEP_FAIL_ONCE=<file> kills the first worker process that starts a chunk
(montecarlo.episodes), to test that a lost worker's chunk is rerun without duplicated rows.
"""
import importlib
import json
import os
import sys
from pathlib import Path

# One BLAS thread per process, set before numpy loads: every worker is already one CPU of the
# sweep (local processes, Ray tasks of num_cpus=1), and OpenBLAS's own threads on top of them
# only contend for the same cores (the policy's matrix products cost twice the CPU with 2).
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

from montecarlo import results
from montecarlo.backends import SweepRunError
from montecarlo.driver import rerun_line, run_sweep
from ship_mission.cli_args import OneLineParser, integer, number, out_folder
from montecarlo.spec import MAX_EPISODES, PARAMETERS, REPO, SweepError, check_size, load
from results_pages.provenance import provenance
from ship_sim.allocator import tune_allocator

#: Most worker processes or Ray CPUs asked for (a cluster's; far beyond one machine's cores).
MAX_WORKERS = 4096


def parse_args(argv=None):
    p = OneLineParser(description=__doc__.split('\n')[0])
    p.add_argument('sweep', type=Path, help='sweep file (YAML)')
    p.add_argument('--out', type=out_folder, default=None,
                   help='output folder (default runs/sweeps/<name>)')
    p.add_argument('--workers', type=integer(1, MAX_WORKERS), default=None,
                   help='processes, or CPUs of a private Ray instance (default: every core)')
    p.add_argument('--chunk', type=integer(1, MAX_EPISODES), default=None,
                   help='episodes per task (default: >= 4 tasks per worker)')
    p.add_argument('--ray', nargs='?', const='local', default=None, metavar='ADDRESS',
                   help="run on Ray: alone, a private local instance; 'auto' or HOST:PORT, "
                        'an existing cluster')
    p.add_argument('--episodes', type=integer(1, MAX_EPISODES), default=None,
                   help="samples per grid cell instead of the file's 'episodes'")
    p.add_argument('--duration', type=number(*PARAMETERS['duration_s'][2]), default=None,
                   help="episode length (s) instead of the file's duration_s")
    p.add_argument('--where', action='append', default=[], metavar='AXIS=V1[,V2]',
                   help='run only the grid cells with these values (repeatable); rows keep the '
                        "whole sweep's episode indices and draws")
    p.add_argument('--no-plots', action='store_true', help='skip the PNG plots')
    p.add_argument('--resume', action='store_true',
                   help=f'run only the episodes missing from OUT/{results.PARTIAL_NAME} (the '
                        'rows a failed run of the same sweep and options kept)')
    return p.parse_args(argv)


#: Optional packages a sweep needs and what installs them: `make demo`'s venv has neither.
INSTALL_HINT = ('make venv-sweep (or: .venv/bin/python -m pip install -r requirements/learning.txt '
                '-r requirements/sweep.txt)')


def missing_packages(ray):
    """Import names of the optional packages a sweep needs that are not installed: gymnasium
    (reading a sweep file checks its controllers against evaluate_controllers, which builds on
    ship_autopilot.learning.env) and ray for --ray."""
    missing = []
    for name in ['gymnasium'] + (['ray'] if ray else []):
        try:
            importlib.import_module(name)   # the sweep imports it anyway
        except ImportError:
            missing.append(name)
    return missing


def main(argv=None):
    tune_allocator()   # local workers are forked from here and inherit it
    args = parse_args(argv)
    missing = missing_packages(args.ray)
    if missing:
        print(f'error: sweeps{" on Ray" if args.ray else ""} need {" and ".join(missing)}, '
              f'not installed in this venv: {INSTALL_HINT}', file=sys.stderr)
        return 2
    try:
        sweep = load(args.sweep)
        if args.episodes:
            check_size(sweep, args.episodes, f'{args.sweep} with --episodes {args.episodes}')
    except SweepError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    out = args.out or REPO / 'runs' / 'sweeps' / sweep.name
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        print(f'error: cannot create {exc.filename or out}: {exc.strerror or exc}', file=sys.stderr)
        return 2
    backend = 'ray' if args.ray else 'local'
    address = None if args.ray in (None, 'local') else args.ray
    where = {}
    for item in args.where:
        axis, sep, value = item.partition('=')
        if not sep or axis not in sweep.grid:
            print(f'error: --where {item}: give AXIS=VALUE with a grid axis of the file '
                  f'({", ".join(sweep.grid) or "none"})', file=sys.stderr)
            return 2
        kinds = {type(v) for v in sweep.grid[axis]}
        try:
            where[axis] = [float(v) if float in kinds else int(v) if int in kinds else v
                           for v in value.split(',')]
        except ValueError:
            print(f'error: --where {item}: {axis} takes a number', file=sys.stderr)
            return 2
    n = sweep.n_cells * (args.episodes or sweep.episodes)
    for axis, values in where.items():
        n = n * len(values) // len(sweep.grid[axis])
    print(f'sweep {sweep.name}: {sweep.n_cells} grid cells x {args.episodes or sweep.episodes} '
          f'episodes = {n}, backend {backend}' + (f' ({address})' if address else ''),
          flush=True)
    partial = out / results.PARTIAL_NAME
    # the code the episodes run is the code at their start
    started = provenance(None if argv is None else [sys.argv[0], *argv])
    try:
        rows, run = run_sweep(sweep, backend, args.workers, args.chunk, address, args.episodes,
                              duration=args.duration, where=where, partial=partial,
                              resume=args.resume)
    except SweepError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    except SweepRunError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f'interrupted; the finished rows are in {partial} (rerun with --resume)',
              file=sys.stderr)
        return 130
    if rerun_line(run):
        print(rerun_line(run), flush=True)
    kind = results.KINDS[sweep.kind]
    (out / 'results.csv').write_text(results.table_text(rows, sweep.columns(), kind.metrics))
    group_by = list(sweep.grid)
    summary = results.summarise(rows, group_by, kind)
    md = results.summary_markdown(summary, group_by, kind)
    (out / 'summary.md').write_text(md)
    # with its provenance and run, summary.json is a results file (doc/results/sweeps.md)
    (out / 'summary.json').write_text(json.dumps(
        {'provenance': started,
         'sweep': str(args.sweep), 'kind': sweep.kind, 'seed': sweep.seed,
         'episodes_per_cell': args.episodes or sweep.episodes, 'group_by': group_by,
         'confidence': f'Student-t 95 % (metrics), Wilson 95 % ({", ".join(kind.proportions)})',
         'groups': [dict(zip(group_by, k), **v) for k, v in summary.items()], 'run': run,
         'table': dict(zip(('header', 'rows'), results.summary_rows(summary, group_by, kind)),
                       caption=results.summary_caption(kind))},
        indent=1))
    (out / 'run.json').write_text(json.dumps(run, indent=1))
    print(md)
    plots = []
    if not args.no_plots:
        from montecarlo.plots import write_plots
        plots = write_plots(rows, sweep, out)
    html_index(out / 'index.html', sweep, summary, group_by, kind, run, plots)
    partial.unlink()   # every row is in results.csv now
    print(f"{run['episodes']} episodes in {run['wall_s']:.1f} s ({run['episodes_per_s']:.1f} "
          f"episodes/s, {run['vessel_steps_per_s']:,.0f} vessel-steps/s, {run['workers']} "
          f"workers, {run['chunks']} chunks of <= {run['chunk_size']}); wrote {out}/")
    return 0


def html_index(path, sweep, summary, group_by, kind, run, plots=()):
    """index.html: the summary table (as summary.md) and the plots embedded."""
    from ship_mission.html_report import batch_page
    header, rows = results.summary_rows(summary, group_by, kind)
    return batch_page(
        path, f'Sweep {sweep.name}', header, rows,
        intro=f"{results.summary_caption(kind)} {run['episodes']} episodes in "
              f"{run['wall_s']:.1f} s on {run['workers']} workers; one row per episode in "
              'results.csv.', figures=plots)


if __name__ == '__main__':
    sys.exit(main())
