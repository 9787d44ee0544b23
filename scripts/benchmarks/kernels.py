"""Section ``kernels``: the batched closed loop on numpy and on the compiled kernels, side by side.

For each MSS ship (mariner, tanker, container) at N = 10 000 episodes, ILOS + PD on the
flagship route (lines and arcs, corners), h = 0.1 s, in one process and one run:

- the closed loop (ship_autopilot.batch_closed_loop.BatchClosedLoop) with
  ship_sim.kernels on ``numpy`` and on ``numba``: CPU and wall vessel-steps/s (best of
  ``repeats`` runs of the stepping alone; set-up and compilation are not in the rates, a short
  warm-up run compiles first), and their ratio numba / numpy;
- the plant alone on the same backend (like with like): numpy ``rk4_step(model.rhs)`` plus
  the current's drift, as PathFollowingBatch.integrate does on numpy, against the compiled
  RK4 (ship_sim.models.compiled.batch_rk4) with the drift, and the loop's share of it.

The 1-minute load average is read before and after each row: CPU rates are the stable figure
under load, wall rates the machine's share. Goals (issue 28): >= 3 M CPU vessel-steps/s for the
Mariner, >= 2 M for the tanker and the container, closed loop on numba.
"""
import os
import time

import numpy as np

from . import batch_closed_loop, common

N = 10_000
MODELS = ('mariner', 'tanker', 'container')
GOALS = {'mariner': 3_000_000.0, 'tanker': 2_000_000.0, 'container': 2_000_000.0}
SIM_S, QUICK_SIM_S = 30.0, 5.0


def loop_rate(model, backend, n, sim_s, repeats):
    """(best wall rate, best CPU rate, fewest minor faults per step) of the closed loop."""
    from ship_autopilot.batch_closed_loop import BatchClosedLoop
    from ship_planner.route_loader import load_route
    from ship_sim import kernels
    route = load_route(common.REPO / 'scenarios' / 'routes' /
                       batch_closed_loop.ROUTES['flagship']).route
    eps = batch_closed_loop.episodes(n)
    walls, cpus, faults = [], [], []
    with kernels.using(backend):
        loop = BatchClosedLoop(model, [route], 'pd', 'ilos')
        loop.run(batch_closed_loop.episodes(10), 1.0)   # compiles (numba), warms caches
        for _ in range(repeats):
            res = loop.run(eps, sim_s)
            walls.append(res.loop_s)
            cpus.append(res.loop_cpu_s)
            faults.append(res.loop_minor_faults / res.steps)
    steps = n * res.steps
    return steps / min(walls), steps / max(min(cpus), 1e-9), min(faults)


def plant_rate(model_name, backend, n, steps):
    """(wall, CPU) vessel-steps/s of the plant alone with the current's drift, best of 3."""
    from ship_sim.integrators import rk4_step
    from ship_sim.models import make_model
    from ship_sim.models.compiled import batch_rk4
    from . import batched
    model = make_model(model_name)
    X, U = batched.batch(model, n)
    U = np.ascontiguousarray(U)
    drift = np.full((n, 2), 0.01)
    h = batched.H
    if backend == 'numba':
        kernel = batch_rk4(model)
        bufs = [np.empty_like(X), np.empty_like(X)]

        def step(x):
            out = kernel(x, U, h, drift, model.IX, model.IY, bufs[0])
            bufs.reverse()
            return out
    else:
        def step(x):
            x = rk4_step(model.rhs, x, U, h)
            x[:, model.IX] += drift[:, 0]
            x[:, model.IY] += drift[:, 1]
            return x
    step(X.copy())
    walls, cpus = [], []
    for _ in range(3):
        x = X.copy()
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(steps):
            x = step(x)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return n * steps / min(walls), n * steps / max(min(cpus), 1e-9)


def run(quick=False):
    from ship_sim import kernels
    if not kernels.numba_available():
        return {'title': 'numba is not installed (requirements/kernels.txt)',
                'columns': [], 'rows': [], 'goals': [], 'failed': True,
                'notes': ['install the kernels extra (make venv-test) to compare']}
    sim_s = QUICK_SIM_S if quick else SIM_S
    repeats = 1 if quick else 2
    plant_steps = 10 if quick else 40
    rows, goals = [], []
    for model in MODELS:
        rates = {}
        for backend in ('numpy', 'numba'):
            load0 = os.getloadavg()[0]
            w, c, f = loop_rate(model, backend, N, sim_s, repeats)
            pw, pc = plant_rate(model, backend, N, plant_steps)
            rates[backend] = c
            rows.append({'model': model, 'backend': backend, 'rate_cpu': c, 'rate_wall': w,
                         'plant_cpu': pc, 'loop_share': c / pc, 'faults_per_step': f,
                         'load': f'{load0:.1f} / {os.getloadavg()[0]:.1f}'})
        rows[-1]['ratio'] = rates['numba'] / rates['numpy']
        rows[-2]['ratio'] = 1.0
        goals.append(common.goal(f'{model}: closed-loop CPU vessel-steps/s at N = {N:,}, '
                                 'ILOS + PD, numba', rates['numba'], GOALS[model], 'steps/s',
                                 below=False))
    return {
        'title': f'batched closed loop numpy vs numba (N = {N:,}, flagship route, '
                 f'ILOS + PD, h = 0.1 s, {sim_s:g} s sim): vessel-steps/s',
        'columns': [['model', 'model'], ['backend', 'kernels'],
                    ['rate_cpu', 'loop steps/s CPU (best)'],
                    ['rate_wall', 'loop steps/s wall (best)'],
                    ['ratio', 'CPU / numpy loop'],
                    ['plant_cpu', 'plant only, same kernels, CPU'],
                    ['loop_share', 'loop / plant (CPU)'],
                    ['faults_per_step', 'faults/step'], ['load', 'load before / after']],
        'rows': rows,
        'goals': goals,
        'notes': [f'{os.cpu_count()} CPUs; load is the 1-minute average before and after each '
                  'row; CPU rates (process_time) are the cost, wall rates the machine share',
                  'the plant-only column runs the plant on the row\'s own kernels (numpy '
                  'rk4_step or the compiled RK4), with the drift, as the loop integrates it'],
    }
