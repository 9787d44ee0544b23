"""Encounter frequency and the significant wave height <-> wind speed relation, as coded in MSS.

Source: Fossen, Marine Systems Simulator (github.com/cybergalactic/MSS, commit 736a3d1),
``LIBRARY/environment/{encounter,hs2vw,vw2hs}.m``; Fossen 2021 (Handbook, Ch. 10.2). g = 9.81
m/s^2 as in MSS.

- ``encounter``: omega_e = omega - omega^2 U cos(chi) / g with chi the wave direction relative
  to the ship's course (0 = following sea, pi = head sea). Reproduced: no abs(), so omega_e is
  negative in fast following seas (the MSS RAO functions take abs() of their own copy).
- ``hs2vw`` / ``vw2hs``: Hs = 0.21 V^2 / g (the Pierson-Moskowitz relation, V the wind speed;
  the height it refers to is not stated in MSS). Fixed: MSS vw2hs squares with a matrix power,
  so a vector input errors; here arrays work element by element.
"""
import numpy as np

G = 9.81   # m/s^2, MSS


def encounter(chi, U, omega):
    """Encounter frequency (rad/s) of waves of frequency ``omega`` (rad/s) at speed U (m/s)."""
    omega = np.asarray(omega, dtype=float)
    return omega - (omega ** 2 * U * np.cos(chi) / G)


def hs2vw(Hs):
    """Wind speed (m/s) of a fully developed sea of significant wave height Hs (m)."""
    return np.sqrt(np.asarray(Hs, dtype=float) * G / 0.21)


def vw2hs(Vw):
    """Significant wave height (m) of a fully developed sea in wind of speed Vw (m/s)."""
    return 0.21 * np.asarray(Vw, dtype=float) ** 2 / G
