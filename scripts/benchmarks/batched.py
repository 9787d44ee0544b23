"""Section ``batched``: RK4 throughput for many vessels at once (vessel-steps per second).

``integrators.rk4_step(model.rhs, X, U, h)`` on (N, n_states) / (N, n_inputs) arrays for the
three MSS ships and N = 1, 100, 10 000 (``--quick``: same sizes, shorter timing). Each vessel
gets its own rudder command (spread over +-0.3 rad) and its own heading, so the saturation
branches differ across the batch. Step h = 0.1 s.
Beside each rate, the minor page faults per step (common.time_call; bench.py tunes the
allocator first, ship_sim.allocator).
Goal (issue 2): >= 1 000 000 vessel-steps/s at N = 10 000.
"""
import numpy as np

from ship_sim.integrators import rk4_step
from ship_sim.models import make_model, model_names

from . import common

H = 0.1
MODELS = model_names('mss')
SIZES = (1, 100, 10_000)
GOAL_N = 10_000
GOAL_RATE = 1_000_000.0


def batch(model, n):
    """N vessels in a spread of turning states with their own rudder commands (native)."""
    x0 = model.initial_state()
    X = np.tile(x0, (n, 1))
    X[:, model.IPSI] = np.linspace(-np.pi, np.pi, n, endpoint=False)
    X[:, model.IR] = -0.005
    U = model.inputs(np.linspace(-0.3, 0.3, n))
    return X, U


def run(quick=False):
    rows = []
    for name in MODELS:
        model = make_model(name)
        for n in SIZES:
            X, U = batch(model, n)
            assert np.all(np.isfinite(rk4_step(model.rhs, X, U, H)))
            t = common.time_call(lambda: rk4_step(model.rhs, X, U, H), quick)
            rows.append({'model': name, 'n': n,
                         'step_best_us': t['best_us'], 'step_median_us': t['median_us'],
                         'rate_best': n / t['best_us'] * 1e6,
                         'rate_median': n / t['median_us'] * 1e6,
                         'us_per_vessel': t['best_us'] / n, 'faults_per_step': t['faults']})
    goals = [common.goal(f'{r["model"]} vessel-steps/s at N = {GOAL_N:,} (best)',
                         r['rate_best'], GOAL_RATE, 'steps/s', below=False)
             for r in rows if r['n'] == GOAL_N]
    return {
        'title': f'batched RK4 (rk4_step(model.rhs, X, U, h), h = {H} s), N vessels at once',
        'columns': [['model', 'model'], ['n', 'N'],
                    ['step_best_us', 'step best us'], ['step_median_us', 'step median us'],
                    ['rate_best', 'vessel-steps/s best'], ['rate_median', 'vessel-steps/s median'],
                    ['us_per_vessel', 'us/vessel'], ['faults_per_step', 'faults/step']],
        'rows': rows, 'goals': goals, 'h_s': H,
        'notes': ['N = 1 here is (1, n) arrays, slower than the 1-D numpy path of section '
                  "'models' (1-element arrays take numpy's full ufunc path, 0-d components "
                  'of a 1-D state do not); one vessel belongs on the float path'],
    }
