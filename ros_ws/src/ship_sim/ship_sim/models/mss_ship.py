"""Shared machinery of the three MSS ship models (mariner, tanker, container).

Source: Fossen, Marine Systems Simulator, github.com/cybergalactic/MSS, commit 736a3d1,
``CRAFT/SHIP/models/{mariner,tanker,container}.m``. What the three share, as MSS codes it:

- Rudder servo: the command is saturated at ``rudder_max``, the rudder follows it with a 1 s
  time constant (delta_dot = delta_c - delta) and that rate is clipped at ``rudder_rate_max``.
- Derivatives are a pure function of (state, input); the state is the model's own (NED/FRD,
  SI units except shaft speed in rpm).
- External loads (e.g. wind, ship_sim.environment.wind): ``loads`` = (X, Y, K, N), body-frame
  surge and sway force (N) and roll and yaw moment (N m), is an optional extra argument of
  ``rhs``, ``rhs_scalar`` and ``step``, held over a step like the input. Each model adds it
  to its OWN force equations in their own scaling (the prime system of mariner.m and
  container.m, the force per unit mass of tanker.m), so the loads act through the model's
  inertia; models without roll ignore K. ``loads=None`` evaluates the MSS equations unchanged
  (bit for bit).

Each subclass writes its equations once, in ``_derivatives(ops, *state, *inputs)``, against
the ``ops`` backends of ``math_backends``; this class evaluates them on arrays (``rhs``,
batched) or on floats (``rhs_scalar``, the fast single-vessel path), integrates them with
MSS's RK4 (``step``), converts the unified rudder command (rad, positive turns to port) to the
native input (``inputs``), finds straight-running trim (``initial_state``) and refuses states
where the equations break (``check_state`` -> ModelStateError naming the quantity).
"""
import math

import numpy as np
from scipy.optimize import brentq

from ..integrators import rk4_step, rk4_step_floats
from .base import ModelStateError, VesselModel
from .math_backends import ARRAY_OPS, FLOAT_OPS

# Search interval (m/s) for the straight-running surge equilibrium of the propelled models.
_TRIM_SPEED_BRACKET = (1e-3, 40.0)
# Smallest shaft speed (rpm) tried when solving the shaft for a requested speed.
_TRIM_SHAFT_MIN = 1e-3


def rudder_servo(ops, delta_c, delta, rudder_max, rudder_rate_max):
    """MSS rudder: saturate the command, 1 s first-order lag, clip the rate. Returns delta_dot."""
    return ops.sat(ops.sat(delta_c, rudder_max) - delta, rudder_rate_max)


def _checked_limit(name, value, upper):
    value = float(value)
    if not (math.isfinite(value) and 0.0 < value <= upper):
        raise ValueError(f'{name} = {value!r} is out of range; allowed: 0 < {name} <= {upper:.6g}')
    return value


class MssShip(VesselModel):
    """Base class of the MSS ship ports: dual float/array evaluation, RK4, sign, trim, checks."""

    #: Shaft speed (rpm) used by ``inputs`` and ``initial_state`` when none is given.
    shaft_nominal = None

    def __init__(self, rudder_max=None, rudder_rate_max=None):
        # Per-instance overrides of the MSS limits (rad, rad/s).
        if rudder_max is not None:
            self.rudder_max = _checked_limit('rudder_max', rudder_max, math.pi / 2)
        if rudder_rate_max is not None:
            self.rudder_rate_max = _checked_limit('rudder_rate_max', rudder_rate_max, math.inf)

    # --- equations ------------------------------------------------------------------------
    #: rhs, rhs_scalar and step take ``loads`` = (X, Y, K, N) external loads (module docstring).
    takes_external_loads = True

    def _derivatives(self, ops, *args, loads=None):
        """Native derivative components from state then input components (subclass)."""
        raise NotImplementedError

    def rhs(self, x, u, loads=None):
        """MSS derivative on arrays: x (..., n_states), u (..., n_inputs) -> (..., n_states).

        Leading axes broadcast (e.g. N states with one shared input). No domain check here;
        call ``check_state`` (states the MSS function rejects give NaN or nonsense). ``loads``:
        optional external loads (X, Y, K, N) in N and N m, each broadcasting like x's batch.
        """
        x = np.asarray(x, dtype=float)
        u = np.asarray(u, dtype=float)
        if x.shape[-1:] != (self.n_states,) or u.shape[-1:] != (self.n_inputs,):
            raise ValueError(f'{self.name}: expected x (..., {self.n_states}) and '
                             f'u (..., {self.n_inputs}), got {x.shape} and {u.shape}')
        comps = self._derivatives(ARRAY_OPS, *np.moveaxis(x, -1, 0), *np.moveaxis(u, -1, 0),
                                  loads=loads)
        return np.stack(np.broadcast_arrays(*comps), axis=-1)

    def rhs_scalar(self, x, u, loads=None):
        """Same derivative for one vessel on sequences of floats; returns a tuple of floats.

        ``loads``: optional (X, Y, K, N) floats. A state outside the model's domain raises
        ModelStateError (naming the quantity).
        """
        try:
            return self._derivatives(FLOAT_OPS, *x, *u, loads=loads)
        except (ArithmeticError, ValueError) as exc:  # division by zero, math domain error
            self.check_state(x, u)
            raise ModelStateError(f'{self.name}: equations failed at x={list(x)}, '
                                  f'u={list(u)}: {exc}') from exc

    def step(self, x, u, h, loads=None):
        """One MSS RK4 step of length h (s), input (and loads) held. 1-D x: float path."""
        x = np.asarray(x, dtype=float)
        u = np.asarray(u, dtype=float)
        if x.ndim == 1 and u.ndim == 1:
            if loads is None:
                return np.array(rk4_step_floats(self.rhs_scalar, x.tolist(), u.tolist(), h))
            loads = tuple(float(t) for t in loads)
            return np.array(rk4_step_floats(lambda a, b: self.rhs_scalar(a, b, loads),
                                            x.tolist(), u.tolist(), h))
        if loads is None:
            return rk4_step(self.rhs, x, u, h)
        return rk4_step(lambda a, b: self.rhs(a, b, loads), x, u, h)

    # --- unified interface ----------------------------------------------------------------
    def _extra_inputs(self):
        """Native inputs after rudder (and shaft), e.g. the tanker's water depth."""
        return ()

    def inputs(self, rudder_cmd, shaft_cmd=None):
        """Unified rudder (rad, + turns to port) and shaft (rpm) -> native input array.

        Out-of-range commands are passed on: the model saturates them inside, as MSS does.
        Array commands give a batch (..., n_inputs).
        """
        cols = [self.RUDDER_SIGN * np.asarray(rudder_cmd, dtype=float)]
        if self.has_shaft:
            cols.append(np.asarray(self.shaft_nominal if shaft_cmd is None else shaft_cmd,
                                   dtype=float))
        elif shaft_cmd is not None:
            raise ValueError(f'{self.name} has no shaft input (got shaft_cmd={shaft_cmd!r})')
        cols.extend(np.asarray(v, dtype=float) for v in self._extra_inputs())
        if all(c.ndim == 0 for c in cols):
            return np.array([float(c) for c in cols])
        return np.stack(np.broadcast_arrays(*cols), axis=-1)

    def initial_state(self, speed=None, north=0.0, east=0.0, psi=0.0, shaft=None):
        """Straight running at a pose (NED, rad): v = r = 0, rudder 0, surge trim (subclass)."""
        x = np.zeros(self.n_states)
        x[self.IX], x[self.IY], x[self.IPSI] = north, east, psi
        self._set_trim(x, speed, shaft)
        self.check_state(x)
        return x

    def _set_trim(self, x, speed, shaft):
        # The propelled models (tanker, container) trim on the shaft; the mariner overrides.
        self._set_propelled_trim(x, speed, shaft)

    # --- helpers for the propelled models (tanker, container) -----------------------------
    def _surge_accel(self, x, speed, shaft):
        y = x.copy()
        y[self.IU], y[self.IN] = speed, shaft
        return self.rhs_scalar(y.tolist(), self.inputs(0.0, shaft).tolist())[self.IU]

    def _set_propelled_trim(self, x, speed, shaft):
        """Surge equilibrium (u_dot = 0) at zero rudder with n = n_c, as the MSS manoeuvres.

        speed None: solve u at ``shaft`` (default ``shaft_nominal``); shaft None: solve n for
        ``speed``; both given: used as given (then not necessarily an equilibrium).
        """
        if speed is not None and shaft is not None:
            x[self.IU], x[self.IN] = speed, shaft
            return
        if speed is None:
            n = float(self.shaft_nominal if shaft is None else shaft)
            if not 0.0 < n <= self.shaft_max:
                raise ValueError(f'{self.name}: shaft = {n!r} rpm out of range for trim; '
                                 f'allowed: 0 < shaft <= {self.shaft_max}')
            x[self.IN] = n
            lo, hi = _TRIM_SPEED_BRACKET
            x[self.IU] = brentq(lambda s: self._surge_accel(x, s, n), lo, hi, xtol=1e-13)
            return
        speed = float(speed)
        top = self._surge_accel(x, speed, self.shaft_max)
        if not (speed > 0.0 and top > 0.0):
            u_max = brentq(lambda s: self._surge_accel(x, s, self.shaft_max),
                           *_TRIM_SPEED_BRACKET, xtol=1e-13)
            raise ValueError(f'{self.name}: speed = {speed!r} m/s out of range for trim; '
                             f'allowed: 0 < speed < {u_max:.4f} (shaft limit '
                             f'{self.shaft_max} rpm)')
        x[self.IU] = speed
        x[self.IN] = brentq(lambda n: self._surge_accel(x, speed, n),
                            _TRIM_SHAFT_MIN, self.shaft_max, xtol=1e-12)

    # --- domain checks --------------------------------------------------------------------
    def check_state(self, x, u=None):
        """Raise ModelStateError if x (or the input u) is where the MSS equations break.

        Works on one vessel or a batch; the message names the quantity, the value and, for a
        batch, the first offending vessel index.
        """
        x = np.asarray(x, dtype=float)
        super().check_state(x)
        if u is not None:
            u = np.asarray(u, dtype=float)
            if not np.all(np.isfinite(u)):
                raise ModelStateError(f'{self.name}: input is not finite: {u}')
        self._check_domain(x, u)

    def _check_domain(self, x, u):
        """Model-specific domain checks on arrays x and u (u may be None)."""

    def _require(self, ok, message, value):
        """Raise ModelStateError(message) with the first offending value if any ``ok`` fails."""
        ok = np.asarray(ok)
        if ok.all():
            return
        bad = np.flatnonzero(~ok.ravel())[0]
        where = f' (vessel index {bad})' if ok.ndim else ''
        got = np.broadcast_to(value, ok.shape).ravel()[bad]
        raise ModelStateError(f'{self.name}: {message}; got {got:.6g}{where}')
