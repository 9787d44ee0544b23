"""PD heading autopilot designed by pole placement on the first-order Nomoto model.

Sources
- Angelopoulos 2011, eqs. 12-20, and Simakis 1992, eqs. 2.12-2.16: plant psi_dot = r,
  r_dot = a r + b delta; law delta = k1 (psi - psi_c) + k2 r (Angelopoulos 2011 eq. 16), gains by
  pole placement (``pd_gains``, ship_guidance.heading_loop: the one design the guidance laws'
  stability limits assume too).
- Rudder saturation: hard limit or delta_sat tanh(delta_0 / delta_sat) (Angelopoulos 2011
  eqs. 15, 25), see ship_autopilot.rudder.

Units: a (1/s), b (1/s^2), omega_n (rad/s), zeta (-), k1 (rad rudder per rad heading, i.e. -),
k2 (s). Signs: unified rudder (+ turns to port), NED psi, r; for a normal ship a = -1/T < 0 and
b = -K/T < 0 (K > 0), so k1 > 0 and k2 > 0 (see ship_sim.models.nomoto).
"""
import numpy as np

from ship_guidance.heading_loop import pd_gains

from ship_sim import kernels

from .compiled import pd_step
from .controller import HeadingController
from .rudder import RudderLimiter


def nomoto_ab(K, T):
    """First-order Nomoto (a, b) in the unified rudder sign from K (1/s) and T (s)."""
    return -1.0 / T, -K / T


class PDAutopilot(HeadingController):
    """delta = k1 wrap(psi - psi_c) + k2 r, then saturation (hard/tanh) and rate limit.

    ``PDAutopilot(k1, k2, limiter)``; ``PDAutopilot.from_nomoto(a, b, omega_n, zeta, limiter)``
    designs the gains with ``pd_gains``. No internal state besides the previous command.
    k1, k2 may be arrays of per-vessel gains (a batch, ship_autopilot.batch_closed_loop).
    """

    name = 'pd'
    scalar_law = True

    def __init__(self, k1, k2, limiter):
        self.k1, self.k2 = _gain('k1', k1), _gain('k2', k2)
        super().__init__(limiter)

    @classmethod
    def from_nomoto(cls, a, b, omega_n, zeta, limiter):
        return cls(*pd_gains(a, b, omega_n=omega_n, zeta=zeta), limiter)

    def _law(self, e, r, dt):
        return self.k1 * e + self.k2 * r, {}

    def update(self, psi, r, psi_c, dt):
        """HeadingController.update; a batch (1-D arrays) with the hard limit and a rate limit
        runs the compiled step when ship_sim.kernels selects it (same arithmetic; any
        invalid input hands the step to the array path, which holds per vessel)."""
        lim = self.limiter
        if (kernels.compiled() and type(psi) is np.ndarray and psi.ndim == 1
                and lim.shape == 'hard' and lim.max_rate is not None
                and isinstance(dt, (float, int))):
            n = len(psi)
            raw, delta = np.empty(n), np.empty(n)
            vec = [np.broadcast_to(np.asarray(v, dtype=float), (n,))
                   for v in (r, psi_c, self.k1, self.k2, self.rudder)]
            if pd_step(psi, *vec[:2], float(dt), *vec[2:4], lim.max_angle, lim.max_rate,
                       vec[4], raw, delta):
                self.last_ok = True
                self.rudder, self.raw = delta, raw
                return delta.copy()
        return super().update(psi, r, psi_c, dt)

    def __repr__(self):
        return f'PDAutopilot(k1={self.k1!r}, k2={self.k2!r}, limiter={self.limiter!r})'


def _gain(key, value):
    """A gain as a float, or a copied array of per-vessel gains (a batch); finite."""
    v = np.array(value, dtype=float)
    if not np.all(np.isfinite(v)):
        raise ValueError(f'{key} = {value!r} must be finite')
    return float(v) if v.ndim == 0 else v


__all__ = ['PDAutopilot', 'RudderLimiter', 'nomoto_ab', 'pd_gains']
