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
    n = A.shape[0]
    M = np.linalg.inv(np.eye(n) - 0.5 * dt * A)
    Bd = M @ B * dt
    return M @ (np.eye(n) + 0.5 * dt * A), Bd, C @ M, D + 0.5 * (C @ Bd)


def _cascade(w_e, zeta, w_f):
    """State space (A, B, C, D) of notch -> low-pass (3 states)."""
    # notch: y = u + (2 zeta w_e - 2 w_e) s / (s + w_e)^2 u, controllable canonical form
    a1, a0 = 2.0 * w_e, w_e * w_e
    An = np.array([[0.0, 1.0], [-a0, -a1]])
    Cn = np.array([[0.0, 2.0 * zeta * w_e - a1]])
    # low-pass x3' = w_f (y_n - x3), output x3
    A = np.zeros((3, 3))
    A[:2, :2] = An
    A[2, :2] = w_f * Cn[0]
    A[2, 2] = -w_f
    B = np.array([[0.0], [1.0], [w_f]])
    C = np.array([[0.0, 0.0, 1.0]])
    return A, B, C, np.zeros((1, 1))


class WaveFilter:
    """Notch + low-pass wave filter on (psi, r); see the module docstring.

    Give ``frequency`` (w_e, rad/s), or ``peak_frequency`` and ``direction`` (the notch then
    follows the encounter frequency). ``zeta`` notch gain at w_e (0, 1); ``lowpass`` corner
    (rad/s; 0 = the notch frequency).
    """

    def __init__(self, frequency=0.0, *, peak_frequency=0.0, direction=0.0, zeta=0.1,
                 lowpass=0.0):
        if not (frequency > 0.0 or peak_frequency > 0.0):
            raise ValueError('give the notch frequency or the sea\'s peak frequency (> 0)')
        if not 0.0 < zeta < 1.0:
            raise ValueError(f'zeta = {zeta!r}: allowed (0, 1)')
        self.frequency, self.peak_frequency = float(frequency), float(peak_frequency)
        self.direction, self.zeta, self.lowpass = float(direction), float(zeta), float(lowpass)
        self._x = None          # filter states, 3 x 2 (heading, yaw rate)
        self._psi_prev = None   # last heading measurement, unwrapped
        self._t = None
        self.psi = self.r = None
        self.w_e = None
        self._tuned = None      # (w_e, dt) of the discrete matrices in _d
        self._d = None

    def notch_frequency(self, speed, psi):
        """The notch frequency w_e (rad/s) for speed (m/s) and heading psi (rad)."""
        if self.frequency > 0.0:
            return self.frequency
        return max(peak_encounter_frequency(self.peak_frequency, speed, self.direction - psi),
                   MIN_FREQUENCY)

    def update(self, t, psi, r, speed=0.0):
        """Filtered (psi, r) of the measurement (psi rad, r rad/s) at time t (s)."""
        if self._x is None:
            u = np.array([[psi, r]])
            self._psi_prev, self._t = psi, t
            self.w_e = self.notch_frequency(speed, psi)
            A, B, C, D = _cascade(self.w_e, self.zeta, self.lowpass or self.w_e)
            self._x = -np.linalg.solve(A, B) @ u        # at rest: x' = 0 for this input
            self.psi, self.r = psi, r
            return psi, r
        dt = t - self._t
        unwrapped = self._psi_prev + wrap_angle(psi - self._psi_prev)
        self._psi_prev = unwrapped
        if not dt > 0.0:
            return self.psi, self.r
        self._t = t
        w_e = self.notch_frequency(speed, self.psi)
        if self._tuned is None or dt != self._tuned[1] or abs(w_e - self._tuned[0]) > \
                RETUNE * self._tuned[0]:
            self._tuned = (w_e, dt)
            self._d = _tustin(*_cascade(w_e, self.zeta, self.lowpass or w_e), dt)
        self.w_e = self._tuned[0]
        Ad, Bd, C, D = self._d
        u = np.array([[unwrapped, r]])
        y = C @ self._x + D @ u
        self._x = Ad @ self._x + Bd @ u
        self.psi, self.r = float(wrap_angle(y[0, 0])), float(y[0, 1])
        return self.psi, self.r
