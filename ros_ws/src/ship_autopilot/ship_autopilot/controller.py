"""The interface every heading autopilot implements, and the plumbing they share.

    ctrl.reset(rudder=0.0)
    delta = ctrl.update(psi, r, psi_c, dt)

Conventions (project-wide, see ship_sim.frames):
- ``psi``, ``psi_c``: NED heading and commanded heading (rad, clockwise from north);
  ``r``: NED yaw rate (rad/s, clockwise positive); ``dt``: time since the previous update (s).
- Returned ``delta``: the rudder command (rad) in the unified sign, positive turns the vessel to
  port. With the heading error e = wrap(psi - psi_c) in [-pi, pi) a positive error (vessel to
  starboard of the command) asks for positive rudder, so the law of Angelopoulos and Simakis
  delta = k1 (psi - psi_c) + k2 r (Angelopoulos 2011 eq. 16, Simakis 1992 eq. 2.14) has positive gains
  for a normal ship (Nomoto b < 0, see ship_autopilot.pd).
- Wrap-around: the error is wrapped (ship_sim.frames.wrap_angle), so a command across +-pi is
  reached the short way.
- Shaping: every controller's raw command goes through one ``RudderLimiter`` (saturation, hard
  or tanh, then rudder-rate limit from the previous command), here, after the control law.
- Bad input (hold): if psi, r, psi_c or dt is not finite, or dt <= 0, the controller HOLDS:
  it returns its previous command and leaves its state untouched (per element for a batch);
  ``n_rejected`` counts such updates and ``last_ok`` flags the last one, so a node can log.
  The output is therefore always finite.
- Batches: inputs may be numpy arrays (one element per vessel, broadcast together); the state
  then has that shape. Scalar inputs give a float.

Subclasses implement ``_initial_state()`` (dict of state names -> values) and
``_law(e, r, dt) -> (raw_command, new_state)`` without mutating ``self._state``; this class
commits the new state only where the input was valid. A subclass whose ``_law`` also works
on Python floats sets ``scalar_law = True``: one vessel's valid update then runs on floats
(same arithmetic without numpy's per-call overhead, which dominates one vessel's update;
it runs every control step in the node; figures in the doc/results/performance.md).
"""
import math

import numpy as np

from ship_sim.frames import wrap_angle

from .rudder import RudderLimiter


class HeadingController:
    """Base class: input checks, error wrapping, rudder shaping, state commit."""

    #: Registry name (the autopilot node's ``controller`` parameter).
    name = ''
    #: ``_law`` accepts Python floats (enables the float path of ``update``).
    scalar_law = False

    def __init__(self, limiter):
        if not isinstance(limiter, RudderLimiter):
            raise TypeError(f'limiter must be a RudderLimiter, got {type(limiter).__name__}')
        self.limiter = limiter
        self.reset()

    # -- interface -----------------------------------------------------------------------------
    def reset(self, rudder=0.0):
        """Clear the controller state; the rate limit starts from ``rudder`` (rad, actual).

        ValueError if ``rudder`` is not finite (pass 0.0 when the actual rudder is unknown).
        """
        if not np.all(np.isfinite(rudder)):
            raise ValueError(f'rudder = {rudder!r} must be finite')
        self.rudder = rudder
        self.raw = rudder
        self.n_rejected = 0
        self.last_ok = True
        self._state = self._initial_state()

    def update(self, psi, r, psi_c, dt):
        """One control step -> rudder command (rad, + to port). See the module docstring."""
        if self.scalar_law and type(self.rudder) is float:
            out = self._update_float(psi, r, psi_c, dt)
            if out is not None:
                return out
        psi, r, psi_c, dt = (np.asarray(v, dtype=float) for v in (psi, r, psi_c, dt))
        ok = (np.isfinite(psi) & np.isfinite(r) & np.isfinite(psi_c) & np.isfinite(dt)
              & (dt > 0.0))
        all_ok = bool(np.all(ok))
        if not all_ok:
            self.n_rejected += 1
            # Neutral stand-ins keep the arithmetic finite; their results are discarded below.
            psi, r, psi_c = (np.where(ok, v, 0.0) for v in (psi, r, psi_c))
            dt = np.where(ok, dt, 1.0)
        self.last_ok = all_ok
        e = wrap_angle(psi - psi_c)
        raw, new_state = self._law(e, r, dt)
        delta = self.limiter(raw, self.rudder, dt)
        if all_ok:
            self._state.update(new_state)
            self.rudder, self.raw = delta, raw
        else:
            for key, val in new_state.items():
                self._state[key] = np.where(ok, val, self._state[key])
            self.rudder = np.where(ok, delta, self.rudder)
            self.raw = np.where(ok, raw, self.raw)
        if self.scalar_law and np.ndim(self.rudder) == 0:  # one vessel: back to the float path
            self.rudder, self.raw = float(self.rudder), float(self.raw)
        return _as_output(self.rudder)

    def _update_float(self, psi, r, psi_c, dt):
        """``update`` for one vessel with valid scalar inputs; None hands over to the array
        path (arrays, or an input to refuse: that path counts and holds)."""
        if not (isinstance(psi, _SCALARS) and isinstance(r, _SCALARS)
                and isinstance(psi_c, _SCALARS) and isinstance(dt, _SCALARS)):
            return None
        psi, r, psi_c, dt = float(psi), float(r), float(psi_c), float(dt)
        isfinite = math.isfinite
        if not (isfinite(psi) and isfinite(r) and isfinite(psi_c) and isfinite(dt)
                and dt > 0.0):
            return None
        self.last_ok = True
        raw, new_state = self._law(wrap_angle(psi - psi_c), r, dt)
        delta = float(self.limiter(raw, self.rudder, dt))
        self._state.update(new_state)
        self.rudder, self.raw = delta, raw
        return delta

    @property
    def state(self):
        """A copy of the internal state (dict of floats or arrays), for logging and tests."""
        return {k: _as_output(v) for k, v in self._state.items()}

    # -- for subclasses ------------------------------------------------------------------------
    def _initial_state(self):
        return {}

    def _law(self, e, r, dt):
        """(wrapped error e = psi - psi_c, yaw rate r, dt) -> (raw command, new state dict)."""
        raise NotImplementedError


_SCALARS = (float, int)


def _as_output(x):
    x = np.asarray(x, dtype=float)
    return float(x) if x.ndim == 0 else x.copy()
