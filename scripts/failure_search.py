#!/usr/bin/env python3
"""Search for collision-avoidance failures: uniform Monte Carlo against the cross-entropy method
at an equal simulation budget (the package colav_search explains the parameterisation, the
samplers, the score and what counts as a distinct failure).

    .venv/bin/python scripts/failure_search.py --ship mariner --method sbmpc --budget 100 \
        --generation 20 --seed 1 --jobs 1 --out runs/failure_search
    .venv/bin/python scripts/failure_search.py ... --ray ADDRESS     # on a Ray cluster
    .venv/bin/python scripts/failure_search.py --replay runs/failure_search/failures

The search writes OUT/failure_search.json (per sampler: sims, failures, distinct failures and
both per 1,000 sims, every failure's parameters and minimum distance) and each failure as a
scenario under OUT/failures/<sampler>/ (route.yaml beside it), its in-process minimum distance
in its header. ``--replay`` runs each scenario of a file or folder through run_mission's
launcher in lockstep and compares the minimum distance (exit 1 if one differs by more than
1 m). Run with the install sourced (source ros_ws/install/setup.bash).

``--ray`` runs each simulation as a Ray task (montecarlo.backends.RayPool): ``--ray`` alone a
private local instance of ``--jobs`` CPUs, ``--ray auto`` the cluster of ``ray start`` on this
machine, ``--ray HOST:6379`` another. Ray reruns a simulation whose worker or node was lost;
the results are the same as on local processes (each simulation is deterministic and kept in
draw order), and a line and the results file (``reran_sims``) say which ran again. Every node
needs this repository at the same path, its .venv (``make venv-sweep``) and the install on its
PYTHONPATH (as the sweeps, doc/results/sweeps.md).

Each finished generation is appended to OUT/failure_search.partial.jsonl (deleted once the
results file is written). A search that stopped (Ctrl-C, a lost cluster) continues with the
same arguments and ``--resume``: the samplers draw the finished generations again (their draws
depend only on the seed and the scores), take their recorded results without running them,
and the results equal an uninterrupted search's.
"""
import json
import sys
import time
from pathlib import Path

from colav_search import episode, replay, study
from imazu.runner import METHODS, SHIPS
from imazu_benchmark import MAX_JOBS, tune_allocator
from ship_mission.cli_args import OneLineParser, integer, out_folder


def parse_args(argv):
    ap = OneLineParser(description=__doc__.split('\n')[0])
    ap.add_argument('--ship', choices=SHIPS, default='mariner', help='own ship (default mariner)')
    ap.add_argument('--method', choices=METHODS, default='sbmpc',
                    help='collision-avoidance method (default sbmpc)')
    ap.add_argument('--budget', type=integer(1, 10 ** 6), default=100,
                    help='simulations per sampler (default 100)')
    ap.add_argument('--generation', type=integer(2, 10 ** 5), default=20,
                    help='simulations per cross-entropy generation (default 20)')
    ap.add_argument('--seed', type=integer(0, 2 ** 31 - 1), default=1,
                    help='seed of both samplers (default 1)')
    ap.add_argument('--samplers', nargs='+', default=list(study.SAMPLERS),
                    choices=study.SAMPLERS, help='default: both')
    ap.add_argument('--jobs', type=integer(1, MAX_JOBS), default=1,
                    help=f'worker processes, 1-{MAX_JOBS} (default 1)')
    ap.add_argument('--ray', nargs='?', const='local', default=None, metavar='ADDRESS',
                    help='run the simulations as Ray tasks: alone a private local instance '
                         'of --jobs CPUs, or a cluster address (auto, HOST:6379, ray://...)')
    ap.add_argument('--out', type=out_folder, default=Path('runs/failure_search'),
                    help='output folder: failure_search.json and failures/ (default '
                         'runs/failure_search)')
    ap.add_argument('--resume', action='store_true',
                    help='continue the search of OUT/failure_search.partial.jsonl (the same '
                         'arguments), running only the generations it lacks')
    ap.add_argument('--replay', type=Path, default=None, metavar='FOLDER_OR_YAML',
                    help='replay written failures through run_mission and compare')
    ap.add_argument('--runs', type=Path, default=Path('runs/failure_replay'),
                    help='run folders of --replay (default runs/failure_replay)')
    args = ap.parse_args(argv)
    if args.replay is not None and not args.replay.exists():
        ap.error(f'{args.replay}: no such file or folder')
    return args


def do_replay(args):
    worst = 0.0
    for path in replay.scenarios(args.replay):
        ours, bag = replay.replay(path, args.runs)
        worst = max(worst, abs(bag - ours))
        print(f'{path}: in process {ours:.3f} m, replayed {bag:.3f} m, '
              f'difference {bag - ours:+.3f} m', flush=True)
    return 0 if worst <= replay.TOLERANCE_M else 1


def main(argv=None):
    from results_pages.provenance import provenance
    args = parse_args(argv)
    if args.replay is not None:
        return do_replay(args)
    started = provenance()     # the code the runs use is the code at their start
    tune_allocator()
    if args.ray is not None:
        try:
            from montecarlo.backends import RayPool
            import ray  # noqa: F401
        except ImportError:
            print('failure_search.py: --ray needs ray (make venv-sweep)', file=sys.stderr)
            return 2
        address = None if args.ray == 'local' else args.ray
        with RayPool(address, args.jobs) as pool:
            return _search(args, started, pool)
    if args.jobs > 1:
        import multiprocessing
        with multiprocessing.get_context('fork').Pool(args.jobs) as pool:
            return _search(args, started, pool)
    return _search(args, started, None)


PARTIAL_NAME = 'failure_search.partial.jsonl'


def _search(args, started, pool):
    from montecarlo.backends import SweepRunError
    from montecarlo.results import PartialRows, SweepError, episodes_fingerprint
    out = {'settings': {'ship': args.ship, 'method': args.method, 'budget': args.budget,
                        'generation': args.generation, 'seed': args.seed,
                        'limit_s': episode.LIMIT_S, 'failure_level': episode.FAILURE_LEVEL},
           'samplers': {}}
    partial = args.out / PARTIAL_NAME
    args.out.mkdir(parents=True, exist_ok=True)
    try:
        kept = PartialRows(partial, episodes_fingerprint([out['settings'], args.samplers]),
                           args.resume, other='another search (--ship, --method, --budget, '
                           '--generation, --seed or --samplers differ)')
    except SweepError as exc:
        print(f'failure_search.py: {exc}', file=sys.stderr)
        return 2

    def record(key, samples, results, reran):
        kept.add([{'episode': key, 'samples': samples, 'out': results, 'reran': reran}])
    try:
        return _samplers(args, started, pool, out, kept, record)
    except (SweepRunError, study.ResumeError, KeyboardInterrupt) as exc:
        why = 'interrupted' if isinstance(exc, KeyboardInterrupt) else str(exc)
        print(f'failure_search.py: {why}; the finished generations are in {partial} (rerun '
              'with --resume)', file=sys.stderr)
        return 130 if isinstance(exc, KeyboardInterrupt) else 1
    finally:
        kept.close()


def _samplers(args, started, pool, out, kept, record):
    t0 = time.perf_counter()
    for k, name in enumerate(args.samplers):
        sampler = study.make_sampler(name, [args.seed, k])
        rows = study.search(sampler, args.budget, args.generation, args.ship, args.method,
                            args.jobs, lambda line: print(line, flush=True), pool,
                            done=kept.done, record=record)
        s = study.summary(rows, args.ship, args.method)
        if s['reran_sims'] is None:
            print(f'{name}: reruns unknown (the cluster\'s key-value store could not be read)')
        elif s['reran_sims']:
            print(f"{name}: {len(s['reran_sims'])} of {s['sims']} simulations ran again after "
                  f"a lost worker or node (sims {s['reran_sims']}); each is kept once")
        folder = args.out / 'failures' / name
        for f in s['failure_list']:
            r = rows[f['index']]
            f['scenario'] = str(episode.write_failure(
                r['n_targets'], r['x'], args.ship, args.method, r, folder,
                f'{name}_{f["index"]:04d}').relative_to(args.out))
        if hasattr(sampler, 'history'):
            s['levels'] = [{'gamma': g, 'elites': e} for g, e in sampler.history]
        out['samplers'][name] = s
    out['wall_s'] = time.perf_counter() - t0
    out['provenance'] = started
    (args.out / 'failure_search.json').write_text(json.dumps(out, indent=1))
    kept.path.unlink()
    print(f'wrote {args.out / "failure_search.json"}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
