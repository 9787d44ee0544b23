"""Wave filter: the low-frequency heading and yaw rate from measurements that carry the
wave-frequency yaw (Fossen 2021, Sec. 13.2 "wave filtering"; Fossen 2011, Sec. 11.3.3).

A notch at the encounter frequency w_e of the sea's spectral peak cascaded with a first-order
low-pass, on heading and yaw rate alike:

    h(s) = (s^2 + 2 zeta w_e s + w_e^2) / (s + w_e)^2  *  1 / (s / w_f + 1)

zeta (0 < zeta < 1) sets the notch depth (the gain at w_e is zeta) and its width; w_f the
low-pass corner (default w_e: the notch removes the peak, the low-pass the higher
frequencies). Both pass the low frequencies of the heading loop, with a phase lag the loop
must tolerate (the autopilot's bandwidth should stay well below w_e). Discretised with the
bilinear (Tustin) transform at each update's time step, so the filter follows a varying
w_e: with ``peak_frequency`` w0 (rad/s, the sea's) and ``direction`` (rad, where the waves
travel, clockwise from north) the notch tracks the encounter frequency
|w0 - w0^2 U cos(direction - psi) / g| of the vessel's speed U and filtered heading psi;
with ``frequency`` it stays at that w_e. The heading is unwrapped before filtering (the output
is wrapped again); the filter starts at rest on its first input (no start transient).

One filter or a batch of them (the batched closed loop): ``frequency``, ``peak_frequency``
and ``direction`` may be arrays of one batch shape (B,); ``update`` then takes and returns
arrays (B,), each vessel's filter retuned on its own as a single filter would be. The
single filter is the batch of one (the same code and arithmetic).
"""
import numpy as np

from ship_sim.environment.sea_state import peak_encounter_frequency
from ship_sim.frames import wrap_angle

#: Lowest notch frequency (rad/s): below it the notch would sit in the heading loop's band.
MIN_FREQUENCY = 0.05
#: The discrete filter is rebuilt when the notch frequency has moved by this fraction (far
#: below the notch's relative width 2 zeta) or the time step changed.
RETUNE = 1e-3


def _tustin(A, B, C, D, dt):
    """Bilinear discretisation of (A, B, C, D) (or of stacks of them) at time step dt."""
    n = A.shape[-1]
    M = np.linalg.inv(np.eye(n) - 0.5 * dt * A)
    Bd = M @ B * dt
    return M @ (np.eye(n) + 0.5 * dt * A), Bd, C @ M, D + 0.5 * (C @ Bd)


def _cascade(w_e, zeta, w_f):
    """State space (A, B, C, D) of notch -> low-pass (3 states), stacked over the batch of
    w_e and w_f (arrays (B,)): A B x 3 x 3, B B x 3 x 1; C 1 x 3 and D 1 x 1 shared."""
    # notch: y = u + (2 zeta w_e - 2 w_e) s / (s + w_e)^2 u, controllable canonical form
    a1, a0 = 2.0 * w_e, w_e * w_e
    cn = 2.0 * zeta * w_e - a1
    # low-pass x3' = w_f (y_n - x3), output x3
    A = np.zeros(w_e.shape + (3, 3))
    A[:, 0, 1] = 1.0
    A[:, 1, 0], A[:, 1, 1] = -a0, -a1
    A[:, 2, 1] = w_f * cn
    A[:, 2, 2] = -w_f
    B = np.zeros(w_e.shape + (3, 1))
    B[:, 1, 0], B[:, 2, 0] = 1.0, w_f
    return A, B, np.array([[0.0, 0.0, 1.0]]), np.zeros((1, 1))


class WaveFilter:
    """Notch + low-pass wave filter on (psi, r); see the module docstring.

    Give ``frequency`` (w_e, rad/s), or ``peak_frequency`` and ``direction`` (the notch then
    follows the encounter frequency); floats, or arrays (B,) for a batch of filters. ``zeta``
    notch gain at w_e (0, 1); ``lowpass`` corner (rad/s; 0 = the notch frequency).
    """

    def __init__(self, frequency=0.0, *, peak_frequency=0.0, direction=0.0, zeta=0.1,
                 lowpass=0.0):
        self.batch = any(np.ndim(a) for a in (frequency, peak_frequency, direction))
        freq, peak, direc = np.broadcast_arrays(*(np.atleast_1d(np.asarray(a, dtype=float))
                                                  for a in (frequency, peak_frequency,
                                                            direction)))
        if not ((freq > 0.0) | (peak > 0.0)).all():
            raise ValueError('give the notch frequency or the sea\'s peak frequency (> 0)')
        if not 0.0 < zeta < 1.0:
            raise ValueError(f'zeta = {zeta!r}: allowed (0, 1)')
        self.frequency, self.peak_frequency, self.direction = (
            (a.copy() if self.batch else float(a[0])) for a in (freq, peak, direc))
        self._freq, self._peak, self._dir = freq, peak, direc
        self.zeta, self.lowpass = float(zeta), float(lowpass)
        self._x = None          # filter states, B x 3 x 2 (heading, yaw rate)
        self._psi_prev = None   # last heading measurements, unwrapped (B,)
        self._t = None
        self.psi = self.r = None
        self.w_e = None
        self._w = None          # notch frequency of each filter's discrete matrices (B,)
        self._dt = None         # their time step
        self._d = None          # (Ad, Bd, C, D) stacked over the batch

    def _out(self, a):
        return a.copy() if self.batch else float(a[0])

    def _notch(self, speed, psi):
        """Notch frequencies (B,) for speeds (m/s) and headings (rad) (B,)."""
        if not self.batch:   # the scalar functions, as one filter always computed them
            if self._freq[0] > 0.0:
                return self._freq.copy()
            return np.array([max(peak_encounter_frequency(
                float(self._peak[0]), float(speed[0]), float(self._dir[0] - psi[0])),
                MIN_FREQUENCY)])
        w = np.maximum(peak_encounter_frequency(self._peak, speed, self._dir - psi),
                       MIN_FREQUENCY)
        return np.where(self._freq > 0.0, self._freq, w)

    def _inputs(self, *values):
        """Floats or arrays -> arrays (B,)."""
        if not self.batch:
            return [np.array([float(v)]) for v in values]
        return [np.broadcast_to(np.asarray(v, dtype=float), self._freq.shape) for v in values]

    @staticmethod
    def _u(psi, r):
        u = np.empty((psi.shape[0], 1, 2))       # B x 1 x 2
        u[:, 0, 0], u[:, 0, 1] = psi, r
        return u

    def _lowpass(self, w_e):
        return np.full_like(w_e, self.lowpass) if self.lowpass else w_e

    def update(self, t, psi, r, speed=0.0):
        """Filtered (psi, r) of the measurement (psi rad, r rad/s) at time t (s); a batch:
        psi, r and speed arrays (B,), the filtered ones arrays."""
        psi, r, speed = self._inputs(psi, r, speed)
        if self._x is None:
            u = self._u(psi, r)
            self._psi_prev, self._t = psi.copy(), t
            w_e = self._notch(speed, psi)
            A, B, _, _ = _cascade(w_e, self.zeta, self._lowpass(w_e))
            self._x = -np.linalg.solve(A, B) @ u        # at rest: x' = 0 for this input
            self._psi, self._r = psi.copy(), r.copy()
            self.psi, self.r, self.w_e = self._out(psi), self._out(r), self._out(w_e)
            return self.psi, self.r
        dt = t - self._t
        unwrapped = self._psi_prev + wrap_angle(psi - self._psi_prev)
        self._psi_prev = unwrapped
        if not dt > 0.0:
            return self.psi, self.r
        self._t = t
        w_e = self._notch(speed, self._psi)
        if self._d is None or dt != self._dt:
            retune = np.ones(w_e.shape, dtype=bool)
        else:
            retune = np.abs(w_e - self._w) > RETUNE * self._w
        if retune.any():
            idx = np.flatnonzero(retune)
            new = _tustin(*_cascade(w_e[idx], self.zeta, self._lowpass(w_e[idx])), dt)
            if self._d is None or retune.all():
                self._d, self._w = new, w_e.copy()
            else:
                for old, part in zip(self._d, new):
                    old[idx] = part
                self._w[idx] = w_e[idx]
            self._dt = dt
        Ad, Bd, C, D = self._d
        u = self._u(unwrapped, r)
        y = C @ self._x + D @ u
        self._x = Ad @ self._x + Bd @ u
        self._psi, self._r = wrap_angle(y[:, 0, 0]), y[:, 0, 1]
        self.psi, self.r, self.w_e = self._out(self._psi), self._out(self._r), \
            self._out(self._w)
        return self.psi, self.r
