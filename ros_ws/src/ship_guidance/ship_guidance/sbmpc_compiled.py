"""Compiled collision-risk term of SB-MPC (ship_sim.kernels selects it).

``SBMPC.costs``' risk on every prediction step (the module doc of sbmpc.py), the part every
scenario shares taken off, and its maximum over the steps, per scenario and target, in one pass
over the (scenarios, targets, steps) distances instead of masked temporaries. Same arithmetic
in the same order as the array code, so the costs are the same to the last bit.
"""
import numpy as np

from ship_sim import kernels


#: Risk exponents the kernel takes: those numpy raises an array to exactly (a first power is
#: the value, a square x * x). Other powers go through numpy's own pow, which need not round
#: like the compiled one, so SBMPC.costs keeps them on the array path.
EXACT_EXPONENTS = (1.0, 2.0)


def exact_for(params):
    """True when the kernel gives ``params``' costs to the last bit (``EXACT_EXPONENTS``)."""
    return (params.risk_time_exponent in EXACT_EXPONENTS
            and params.risk_distance_exponent in EXACT_EXPONENTS)


def _power(x, exponent):
    """x ** exponent for an exponent of ``EXACT_EXPONENTS``, as numpy evaluates it."""
    return x * x if exponent == 2.0 else x


def _step_risk_max(dist, frac, step, d_safe, t, dt_s, u_ref, floor, horizon_s, p_exp, q_exp,
                   w_collision):
    """(S, M) maximum over the steps of the risk, less what no scenario avoids."""
    n_s, n_m, n_steps = dist.shape
    risk = np.zeros((n_s, n_m, n_steps))
    v_scale = dt_s * u_ref
    inside = False
    for k in range(n_s):
        for m in range(n_m):
            ds = d_safe[m]
            for n in range(n_steps):
                d = dist[k, m, n]
                if d < ds:
                    inside = True
                    t_step = t[n] + frac[k, m, n] * dt_s
                    speed = step[k, m, n] / v_scale
                    if speed < floor:
                        speed = floor
                    speed = speed * speed
                    when = _power(horizon_s / (t_step if t_step > dt_s else dt_s), p_exp)
                    depth = _power(ds / (d if d > 1e-3 else 1e-3), q_exp)
                    risk[k, m, n] = w_collision * speed * when * depth
    out = np.zeros((n_s, n_m))
    if inside:
        for m in range(n_m):
            for n in range(n_steps):
                lo = risk[0, m, n]
                for k in range(1, n_s):
                    if risk[k, m, n] < lo:
                        lo = risk[k, m, n]
                for k in range(n_s):
                    risk[k, m, n] -= lo
    for k in range(n_s):
        for m in range(n_m):
            hi = risk[k, m, 0] if n_steps else 0.0
            for n in range(1, n_steps):
                if risk[k, m, n] > hi:
                    hi = risk[k, m, n]
            out[k, m] = hi
    return out


@kernels.lazy
def step_risk_max():
    kernels.compile_globals(globals(), ['_power'], cache=True, inline='always')
    kernels.compile_globals(globals(), ['_step_risk_max'], cache=True)
    return _step_risk_max


def warm_up():
    """Compile the kernel now (or load it from numba's cache), as own_ship_prediction_compiled
    does, before a node's first decision."""
    one = np.ones((1, 1, 1))
    step_risk_max(one, one, one, np.ones(1), np.zeros(2), 1.0, 1.0, 0.5, 1.0, 1.0, 2.0, 1.0)
