"""Section ``sweep``: throughput of scripts/sweep.py with local processes and Ray, 1 and 2 workers.

One fixed sweep (SWEEP below: Mariner, ILOS + PD on the Table I curved path, random starts and
currents, EPISODES episodes of DURATION_S s, CHUNK episodes per task (QUICK_CHUNK quick), each chunk one batched
closed loop) runs four times: local processes with 1 and 2 workers, then a private local Ray
instance of 1 and 2 CPUs. Each run is timed from handing the chunks to the backend to the last
row back (Ray is started and warmed up before: its start-up is reported apart); the table must
come out the same every time (checked). Goal (issue 16): 2 Ray workers >= 1.7x the throughput
of one on this 2-core machine. The 1-minute load average is printed with every row: on a busy
machine, 2 workers cannot get 2 cores.

Then, in this process, the same sweep with a Gauss-Markov current (VARYING: speed and
direction varying, a stream per episode) run one episode at a time in the single-vessel loop
(evaluate_controllers.run, as sweeps did before the batch modelled such currents) and as one
batch (montecarlo.episodes.run_chunk): the ratio of the two is what batching such episodes
gains; their rewards must agree to rounding (checked).
"""
import os
import resource
import time

from . import common

EPISODES, QUICK_EPISODES = 320, 40
DURATION_S = 200.0
CHUNK, QUICK_CHUNK = 20, 10
GOAL_SPEEDUP = 1.7
SWEEP = {'name': 'bench_sweep', 'seed': 11, 'episodes': 1,
         'base': {'model': 'mariner', 'controller': 'ilos', 'duration_s': DURATION_S},
         'vary': {'current_speed_mps': {'uniform': [0.0, 0.9]},
                  'current_direction_deg': {'uniform': [-180, 180]},
                  'start_along_m': {'uniform': [0, 1000]},
                  'start_cross_m': {'uniform': [-100, 100]},
                  'start_heading_deg': {'uniform': [-20, 20]}}}
VARYING_EPISODES, QUICK_VARYING_EPISODES = 40, 10
VARYING = dict(SWEEP, name='bench_sweep_gm', base=dict(
    SWEEP['base'], current_speed_std_mps=0.2, current_direction_std_deg=20.0,
    current_time_constant_s=300.0))


def _children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _autogroup():
    try:
        with open('/proc/sys/kernel/sched_autogroup_enabled') as f:
            return f.read().strip()
    except OSError:
        return 'unknown'


def _run(sweep, backend, workers, episodes, chunk=CHUNK):
    """One timed sweep; local runs also report their worker processes' CPU seconds per
    episode (reaped children): equal for 1 and 2 workers when a worker carries no overhead,
    so a wall ratio below 2 is then the machine's share, not the design."""
    from montecarlo import results
    from montecarlo.driver import run_sweep
    load = os.getloadavg()[0]
    cpu0 = _children_cpu()
    rows, run = run_sweep(sweep, backend, workers=workers, chunk_size=chunk, episodes=episodes,
                          progress=False)
    cpu = (_children_cpu() - cpu0) / len(rows) if backend == 'local' else None
    return results.table_text(rows, sweep.columns()), dict(run, load=load, cpu_per_episode=cpu)


def _varying_current(quick):
    """Rows of the VARYING sweep one episode at a time and batched, and the rewards' largest
    relative difference between the two."""
    import numpy as np

    import evaluate_controllers as ec
    from montecarlo import spec
    from montecarlo.episodes import _current_field, _route, _start, run_chunk, with_route_keys
    n = QUICK_VARYING_EPISODES if quick else VARYING_EPISODES
    eps = with_route_keys(spec.expand(spec.parse(VARYING, 'bench_sweep_gm'), n))

    def one_at_a_time():
        return [ec.run(ep['model'], _route(ep['route_key']), ep['controller'],
                       [_start(ep, 0)], ep['current_speed_mps'], ep['duration_s'],
                       current_field=_current_field([ep]))['gaussian'][0] for ep in eps]

    def batched():
        return [row['reward'] for row in run_chunk(eps)]

    rows, rewards = [], []
    for label, fn in (('Gauss-Markov current, one at a time (in process)', one_at_a_time),
                      ('Gauss-Markov current, batched (in process)', batched)):
        load = os.getloadavg()[0]
        t0, c0 = time.perf_counter(), time.process_time()
        rewards.append(np.array(fn()))
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        steps = n * round(DURATION_S / 0.1)
        rows.append({'backend': label, 'episodes': n, 'wall_s': wall, 'episodes_per_s': n / wall,
                     'msteps_per_s': steps / wall / 1e6, 'cpu_s_per_episode': cpu / n,
                     'load': load, 'ray_start_s': None})
    diff = float(np.max(np.abs(rewards[1] - rewards[0]) / np.abs(rewards[0])))
    return rows, diff


def run(quick=False):
    from montecarlo import spec
    from montecarlo.backends import start_local_ray
    sweep = spec.parse(SWEEP, 'bench_sweep')
    n = QUICK_EPISODES if quick else EPISODES
    # Imports and route cache in this process, outside the timing: forked workers inherit them
    # (Ray's workers are warmed up by a run of their own below).
    from montecarlo.episodes import run_chunk, with_route_keys
    run_chunk(with_route_keys(spec.expand(sweep, 2)))
    chunk = QUICK_CHUNK if quick else CHUNK
    out, tables, notes = [], set(), []
    for workers in (1, 2):
        text, r = _run(sweep, 'local', workers, n, chunk)
        tables.add(text)
        out.append(dict(r, label=f'local processes x{workers}'))
    try:
        import ray
        for workers in (1, 2):
            t0 = time.monotonic()
            start_local_ray(workers)
            start = time.monotonic() - t0
            try:
                _run(sweep, 'ray', workers, 2 * workers)     # start the workers
                text, r = _run(sweep, 'ray', workers, n, chunk)
            finally:
                ray.shutdown()
            tables.add(text)
            out.append(dict(r, label=f'Ray x{workers}', ray_start_s=start))
    except Exception as exc:  # noqa: BLE001 (report the local figures even without Ray)
        notes.append(f'Ray runs failed: {type(exc).__name__}: {str(exc).splitlines()[0]}')
    rows = [{'backend': r['label'], 'episodes': r['episodes'], 'wall_s': r['wall_s'],
             'episodes_per_s': r['episodes_per_s'], 'msteps_per_s': r['vessel_steps_per_s'] / 1e6,
             'cpu_s_per_episode': r['cpu_per_episode'], 'load': r['load'],
             'ray_start_s': r.get('ray_start_s')} for r in out]
    varying, diff = _varying_current(quick)
    rows += varying
    single, batch = varying
    gm = VARYING['base']
    notes.append(f'Gauss-Markov current ({batch["episodes"]} episodes of {DURATION_S:g} s, '
                 f'speed sd {gm["current_speed_std_mps"]:g} m/s, direction sd '
                 f'{gm["current_direction_std_deg"]:g} deg, T {gm["current_time_constant_s"]:g} '
                 f's): batched / one at a '
                 f'time {batch["episodes_per_s"] / single["episodes_per_s"]:.1f}x wall, '
                 f'{single["cpu_s_per_episode"] / batch["cpu_s_per_episode"]:.1f}x CPU; '
                 f'rewards agree to {diff:.1e} relative')
    goals = []
    speed = {r['label']: r['episodes_per_s'] for r in out}
    for name in ('local processes', 'Ray'):
        one, two = speed.get(f'{name} x1'), speed.get(f'{name} x2')
        if one and two:
            goals.append(common.goal(f'{name}: 2 workers / 1 worker throughput', two / one,
                                     GOAL_SPEEDUP, 'x', below=False))
    notes.append(f'{n} episodes of {DURATION_S:g} s (Mariner, ILOS + PD, random starts and '
                 f'currents), {chunk} per task; identical tables across runs: '
                 f'{"yes" if len(tables) == 1 else "NO"}; {os.cpu_count()} CPUs')
    notes.append(f'kernel autogroup: {_autogroup()} (1: the CPU is shared between sessions '
                 'first; a private Ray instance is a session of its own, local workers share '
                 "the caller's, so under load the wall ratios measure shares, not scaling)")
    return {'title': 'sweep throughput: local processes and Ray, 1 and 2 workers',
            'columns': [['backend', 'backend'], ['episodes', 'episodes'], ['wall_s', 'wall s'],
                        ['episodes_per_s', 'episodes/s'], ['msteps_per_s', 'M vessel-steps/s'],
                        ['cpu_s_per_episode', 'worker CPU s/episode'],
                        ['load', 'load (1 min)'], ['ray_start_s', 'Ray start s']],
            'rows': rows, 'goals': goals, 'notes': notes,
            'failed': len(tables) != 1 or not diff < 1e-9}
