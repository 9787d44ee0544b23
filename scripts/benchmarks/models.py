"""Section ``models``: cost of one derivative and one RK4 step for a single vessel, in-process.

For every registered model (ship_sim.models.MODEL_NAMES) three ways of stepping one vessel:

- ``float``: ``model.rhs_scalar`` on Python floats + ``integrators.rk4_step_floats`` (the
  single-vessel fast path of the MSS ships; models without ``rhs_scalar`` have no such path);
- ``step()``: ``model.step(x, u, h)`` on 1-D numpy arrays, what a simulator calls (for the MSS
  ships it converts to floats and takes the float path; the others run ``rk4_step`` on numpy);
- ``numpy``: ``model.rhs`` on 1-D arrays + ``integrators.rk4_step``.

The state is a turning one (yaw rate, rudder off zero, command not yet reached) so the
saturation branches and trigonometry are exercised as in a manoeuvre. Step h = 0.1 s.
Goal (issue 2): mariner RK4 step < 50 us on the fast path.
"""
from ship_sim.integrators import rk4_step, rk4_step_floats
from ship_sim.models import MODEL_NAMES, make_model

from . import common

H = 0.1
GOAL_MARINER_STEP_US = 50.0


def turning_state(model):
    """A state part-way into a port turn and the input that drives it (native arrays)."""
    x = model.initial_state()
    x[model.IR] = -0.005                                          # rad/s, turning to port
    x[model.IDELTA] = 0.05 * model.STATE_RUDDER_SIGN              # rudder 0.05 rad to port
    u = model.inputs(0.15)                                        # command 0.15 rad to port
    return x, u


def _paths(model, x, u):
    """(path label, derivative callable or None, step callable) for one model."""
    xl, ul = x.tolist(), u.tolist()
    paths = []
    if hasattr(model, 'rhs_scalar'):
        f = model.rhs_scalar
        paths.append(('float', lambda: f(xl, ul), lambda: rk4_step_floats(f, xl, ul, H)))
    paths.append(('step()', None, lambda: model.step(x, u, H)))
    g = model.rhs
    paths.append(('numpy', lambda: g(x, u), lambda: rk4_step(g, x, u, H)))
    return paths


def run(quick=False):
    rows, notes = [], []
    for name in MODEL_NAMES:
        model = make_model(name)
        x, u = turning_state(model)
        if not hasattr(model, 'rhs_scalar'):
            notes.append(f'{name}: no float path (rhs_scalar); model.step runs rk4_step on numpy')
        for path, rhs_fn, step_fn in _paths(model, x, u):
            row = {'model': name, 'path': path}
            if rhs_fn is not None:
                t = common.time_call(rhs_fn, quick)
                row.update(rhs_best_us=t['best_us'], rhs_median_us=t['median_us'])
            t = common.time_call(step_fn, quick)
            row.update(rk4_best_us=t['best_us'], rk4_median_us=t['median_us'],
                       steps_per_s=1e6 / t['best_us'])
            rows.append(row)
    fast = [r for r in rows if r['model'] == 'mariner' and r['path'] == 'float']
    goals = []
    if fast:
        goals.append(common.goal('mariner RK4 step, float path (best)',
                                 fast[0]['rk4_best_us'], GOAL_MARINER_STEP_US, 'us'))
    return {
        'title': f'one vessel, one derivative / one RK4 step (h = {H} s), microseconds',
        'columns': [['model', 'model'], ['path', 'path'],
                    ['rhs_best_us', 'rhs best'], ['rhs_median_us', 'rhs median'],
                    ['rk4_best_us', 'RK4 best'], ['rk4_median_us', 'RK4 median'],
                    ['steps_per_s', 'steps/s (best)']],
        'rows': rows, 'goals': goals, 'notes': notes, 'h_s': H,
    }
