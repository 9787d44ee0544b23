"""The PD heading loop on Nomoto's first-order model: pole placement and its inverse (pure).

Plant r' = a r + b delta, law delta = k1 (psi - psi_c) + k2 r (Angelopoulos 2011 eq. 16;
Simakis 1992 eq. 2.14); the closed loop s^2 - (a + b k2) s - b k1 is matched to
s^2 + 2 zeta omega_n s + omega_n^2 by (Angelopoulos 2011 eq. 20; Simakis 1992 eqs. 2.15-2.16)
    k1 = -omega_n^2 / b,   k2 = -(a + 2 zeta omega_n) / b
and inverted by omega_n = sqrt(-b k1), zeta = (-b k2 - a) / (2 omega_n).

It lives in ship_guidance because the stability limits of the guidance laws (los.py,
string_stability.py) are stated for this loop; ship_autopilot designs its PD with the same
function. Units: a (1/s), b (1/s^2), omega_n (rad/s), k2 (s); or the non-dimensional form
(time in L/U). Signs: unified rudder (+ turns to port), so a normal ship has b < 0, k1, k2 > 0.
"""
import math

import numpy as np


def _as_output(x):
    return float(x) if np.ndim(x) == 0 else x


def pd_gains(a, b, *, omega_n, zeta):
    """PD gains (k1, k2) placing the Nomoto closed-loop poles at omega_n, zeta; broadcasting.

    omega_n and zeta are keyword-only, so their order can never be confused. ValueError if b
    is zero or not finite, a not finite, or omega_n, zeta not finite and > 0."""
    a, b, omega_n, zeta = (np.asarray(v, dtype=float) for v in (a, b, omega_n, zeta))
    if not np.all(np.isfinite(b) & (b != 0.0)):
        raise ValueError(f'b = {b!r} must be finite and nonzero (no rudder authority)')
    if not np.all(np.isfinite(omega_n) & (omega_n > 0.0)):
        raise ValueError(f'omega_n = {omega_n!r} is outside the allowed range (0, inf)')
    if not np.all(np.isfinite(zeta) & (zeta > 0.0)):
        raise ValueError(f'zeta = {zeta!r} is outside the allowed range (0, inf)')
    if not np.all(np.isfinite(a)):
        raise ValueError(f'a = {a!r} must be finite')
    return _as_output(-np.square(omega_n) / b), _as_output(-(a + 2.0 * zeta * omega_n) / b)


def pd_design(a, b, *, k1, k2):
    """(zeta, omega_n) that the PD gains k1, k2 place on the Nomoto model (a, b): the inverse
    of ``pd_gains``. ValueError if the gains give no oscillatory design (-b k1 <= 0)."""
    w2 = -float(k1) * float(b)
    if not w2 > 0.0:
        raise ValueError(f'k1 = {k1} gives no oscillatory design (b = {b})')
    w = math.sqrt(w2)
    return (-float(k2) * float(b) - float(a)) / (2.0 * w), w
