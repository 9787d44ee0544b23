"""Compiled batch steps of the autopilots (ship_sim.kernels selects them).

``pd_step``: one valid PDAutopilot.update of N vessels with the hard limit and a rate limit,
per vessel the arithmetic of the array path: e = wrap_angle(psi - psi_c) (frames.wrap_angle
itself, compiled), raw = k1 e + k2 r, clip to the angle limit, then the rate limit from the
previous command (RudderLimiter: saturate, rate_limit; np.clip is min(max) for the finite
values that reach it). It returns False, having committed nothing, when an input is not
finite or dt <= 0: the array path then counts and holds per vessel.
"""
import math

from ship_sim import kernels
from ship_sim.frames import wrap_angle

_wrap = wrap_angle


def _pd_step(psi, r, psi_c, dt, k1, k2, max_angle, max_rate, rudder, raw, out):
    n = psi.shape[0]
    if not (dt > 0.0 and math.isfinite(dt)):
        return False
    for i in range(n):
        if not (math.isfinite(psi[i]) and math.isfinite(r[i]) and math.isfinite(psi_c[i])):
            return False
    step_max = max_rate * dt
    for i in range(n):
        e = _wrap(psi[i] - psi_c[i])
        x = k1[i] * e + k2[i] * r[i]
        raw[i] = x
        d = min(max(x, -max_angle), max_angle)
        prev = rudder[i]
        out[i] = prev + min(max(d - prev, -step_max), step_max)
    return True


@kernels.lazy
def pd_step():
    kernels.compile_globals(globals(), ['_wrap', '_pd_step'], cache=True)
    return _pd_step
