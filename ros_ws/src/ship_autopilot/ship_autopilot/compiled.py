"""Compiled batch steps of the autopilots (ship_sim.kernels selects them).

``pd_step``: one valid PDAutopilot.update of N vessels with the hard limit and a rate limit,
per vessel the arithmetic of the array path: e = wrap_angle(psi - psi_c) (frames.wrap_angle
itself, compiled), raw = k1 e + k2 r, clip to the angle limit, then the rate limit from the
previous command (RudderLimiter: saturate, rate_limit; np.clip is min(max) for the finite
values that reach it). It returns False, having committed nothing, when an input is not
finite or dt <= 0: the array path then counts and holds per vessel.

``metrics_step``: one step of BatchClosedLoop's running metrics, per vessel what its array
lines do (learning.reward.gaussian_reward's Gaussian with that function's own defaults, the
sums and maxima of |e|, the rudder's rate, saturation and magnitude), in place.
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


def _max(m, a):
    """np.maximum(m, a) of two floats (NaN wins)."""
    if m != m:
        return m
    return a if (a > m or a != a) else m


def _metrics_step(e, rel, x, i_rudder, rudder_sign, settled_too, amplitude, sigma, yaw_max,
                  rudder_limit, gauss, sum_e, sum_e2, max_e, settled, max_settled, rate_sum,
                  saturated, abs_rud, rud_prev):
    for i in range(e.shape[0]):
        ei = e[i]
        g = amplitude * math.exp(-ei ** 2 / (2.0 * sigma ** 2))
        gauss[i] += g if abs(_wrap(rel[i])) <= yaw_max else 0.0
        a = abs(ei)
        sum_e[i] += a
        sum_e2[i] += ei * ei
        max_e[i] = _max(max_e[i], a)
        if settled_too:
            settled[i] += a
            max_settled[i] = _max(max_settled[i], a)
        rud = rudder_sign * x[i, i_rudder]
        rate_sum[i] += abs(rud - rud_prev[i])
        saturated[i] += 1.0 if abs(rud) >= rudder_limit else 0.0
        abs_rud[i] += abs(rud)
        rud_prev[i] = rud


@kernels.lazy
def metrics_step():
    kernels.compile_globals(globals(), ['_wrap', '_max'], cache=True, inline='always')
    kernels.compile_globals(globals(), ['_metrics_step'], cache=True)
    return _metrics_step


@kernels.lazy
def pd_step():
    kernels.compile_globals(globals(), ['_wrap'], cache=True, inline='always')
    kernels.compile_globals(globals(), ['_pd_step'], cache=True)
    return _pd_step
