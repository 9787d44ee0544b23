"""Shared parts of the constant-speed, rudder-only linear models (Nomoto, NPS AUV II).

These models have no propulsion state: the speed U is a parameter, the only input is the
rudder command (native sign = unified sign: positive turns to port), and the rudder follows
its command through a first-order servo with angle and rate limits.
"""
import numpy as np

from ..integrators import rk4_step
from .base import ModelStateError, VesselModel


def check_param(name, value, lo, hi, *, lo_open=False, nonzero=False):
    """Return float(value) or raise ValueError naming the parameter, value and allowed range."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f'{name} = {value!r} is not a number') from None
    lo_ok = v > lo if lo_open else v >= lo
    if not (np.isfinite(v) and lo_ok and v <= hi and not (nonzero and v == 0.0)):
        bracket = '(' if lo_open else '['
        extra = ', nonzero' if nonzero else ''
        raise ValueError(f'{name} = {value!r} is outside the allowed range '
                         f'{bracket}{lo}, {hi}]{extra}')
    return v


class ConstantSpeedModel(VesselModel):
    """Base of the linear models: rudder servo, inputs, straight-running state, RK4 step.

    Subclasses set ``U`` (m/s) and ``rudder_time_constant`` (s) and implement ``rhs``.
    """

    def _rudder_rate(self, delta, delta_c):
        """Servo: saturated command, first-order lag, clipped rate (rad/s)."""
        dc = np.clip(delta_c, -self.rudder_max, self.rudder_max)
        return np.clip((dc - delta) / self.rudder_time_constant,
                       -self.rudder_rate_max, self.rudder_rate_max)

    def inputs(self, rudder_cmd, shaft_cmd=None):
        """Unified rudder command (rad, + to port) -> native input [delta_c] (same sign)."""
        if shaft_cmd is not None:
            raise ValueError(f'{self.name} has no shaft input (got shaft_cmd={shaft_cmd!r})')
        return np.asarray(rudder_cmd, dtype=float)[..., None] * self.RUDDER_SIGN

    def initial_state(self, speed=None, north=0.0, east=0.0, psi=0.0, shaft=None):
        x = np.zeros(self.n_states)
        x[self.IU] = self.U if speed is None else float(speed)
        x[self.IX], x[self.IY], x[self.IPSI] = north, east, psi
        return x

    def check_state(self, x, u=None):
        super().check_state(x, u)
        if u is not None and not np.all(np.isfinite(u)):
            raise ModelStateError(f'{self.name}: input is not finite: {u}')

    def step(self, x, u, h):
        """One RK4 step of length h (s) with the input held (ship_sim.integrators)."""
        return rk4_step(self.rhs, np.asarray(x, dtype=float), np.asarray(u, dtype=float), h)
