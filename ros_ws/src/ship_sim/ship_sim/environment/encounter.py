"""Encounter frequency and the significant wave height <-> wind speed relation, MSS
``encounter.m``, ``hs2vw.m`` and ``vw2hs.m`` (Fossen 2021, Sec. 10.2).

Kept minimal here for the waves; g = 9.81 as coded in MSS.
"""
import numpy as np

G = 9.81


def encounter(chi, U, Omega):
    """Encounter frequency w - w^2 U cos(chi) / g (rad/s), MSS ``encounter`` (no abs: negative
    in fast following seas). chi (rad, 0 = following sea, pi = head sea), U (m/s), Omega
    (rad/s, scalar or array)."""
    Omega = np.asarray(Omega, dtype=float)
    return Omega - (Omega ** 2 * U * np.cos(chi) / G)


def hs2vw(Hs):
    """Wind speed (m/s) of a fully developed sea of significant wave height Hs (m)."""
    return np.sqrt(np.asarray(Hs, dtype=float) * G / 0.21)


def vw2hs(Vw):
    """Significant wave height (m) of a fully developed sea in wind speed Vw (m/s)."""
    return 0.21 * np.asarray(Vw, dtype=float) ** 2 / G
