"""Compiled loops of the collision-avoidance prediction (ship_sim.kernels selects them).

The two loops SB-MPC spends most of a decision in, written per scenario / target / step with
the array code's arithmetic in the array code's order (own_ship_prediction.py), so a decision
is the same to the last bit:

- ``course_errors``: ``course_response``'s recursion of the course error and turn rate, which
  the array code runs as a Python loop over the steps with a dozen small array operations
  (and a ``clip``) per step;
- ``segment_min_distance``: the closest approach within every prediction step, which the
  array code builds as a handful of (scenarios, targets, steps) temporaries.

numba is imported on the first compiled call only, so the module stays importable without it.
"""
import math

import numpy as np

from ship_sim import kernels


def _course_errors(e0, r0, authority, dt, lag, gain, g_e, g_r, r_max, err):
    """Fill ``err`` (S, N+1) with the course errors chi_c - chi of ``course_response``; return
    the (S,) turn rates at the last sample."""
    n_s, n_steps = e0.shape[0], dt.shape[0]
    r_end = np.empty(n_s)
    for k in range(n_s):
        e = e0[k]
        r = r0
        a = authority[k]
        err[k, 0] = e
        for n in range(n_steps):
            x = g_e * e - g_r * r
            if x < -r_max:             # np.clip(x, -r_max, r_max) as the array code does it
                x = -r_max
            elif x > r_max:
                x = r_max
            r_d = a * x
            e -= r_d * dt[n] + (r - r_d) * gain[n]
            r = r_d + (r - r_d) * lag[n]
            err[k, n + 1] = e
        r_end[k] = r
    return r_end


def _segment_min_distance(ox, oy, tx, ty, dist, frac, step):
    """Fill ``dist``, ``frac`` and ``step`` (S, M, N) as ``segment_min_distance`` returns them."""
    n_s, n_m, n_steps = dist.shape
    for k in range(n_s):
        for m in range(n_m):
            for n in range(n_steps):
                x0 = tx[m, n] - ox[k, n]
                y0 = ty[m, n] - oy[k, n]
                dx = (tx[m, n + 1] - tx[m, n]) - (ox[k, n + 1] - ox[k, n])
                dy = (ty[m, n + 1] - ty[m, n]) - (oy[k, n + 1] - oy[k, n])
                dd = dx * dx
                dd += dy * dy
                s = x0 * dx
                s += y0 * dy
                s = -s
                if dd > 0.0:
                    s = s / dd
                if s < 0.0:            # 0 where the ships keep station
                    s = 0.0
                elif s > 1.0:
                    s = 1.0
                cx = dx * s + x0
                cy = dy * s + y0
                cx *= cx
                cy *= cy
                dist[k, m, n] = math.sqrt(cx + cy)
                frac[k, m, n] = s
                step[k, m, n] = math.sqrt(dd)


@kernels.lazy
def course_errors():
    kernels.compile_globals(globals(), ['_course_errors'], cache=True)
    return _course_errors


@kernels.lazy
def segment_min_distance():
    kernels.compile_globals(globals(), ['_segment_min_distance'], cache=True)
    return _segment_min_distance


def warm_up():
    """Compile both kernels now (or load them from numba's cache) on one-step inputs, so the
    first decision of a node does not pay the compilation inside a lockstep step."""
    one, two = np.zeros(1), np.zeros((1, 2))
    course_errors(one, 0.0, np.ones(1), np.ones(1), one, one, 1.0, 1.0, 1.0, two)
    out = np.empty((1, 1, 1))
    segment_min_distance(two, two, two, two, out, out, out)
