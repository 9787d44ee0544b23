"""Closed-form steady-state heave, roll and pitch in regular waves, MSS ``waveresponse345.m``.

Jensen, Mansour and Olsen (2004), "Estimation of ship motions using closed-form expressions"
(Ocean Engineering 31): a homogeneously loaded box-like hull of length L, beam B, draught T and
block coefficient Cb in a regular wave of amplitude a (m), period T_0 (s) and direction beta
(rad, pi = head sea), at speed U (m/s); roll from its damping ratio zeta4, natural period T4 (s)
and metacentric height GMT (m). Deep water, g = 9.81, rho = 1025 as coded in MSS.

MSS plots the three responses and returns nothing; here they are returned (heave in m, roll and
pitch in rad, MSS plots degrees). Reproduced as coded: the phases use atan, not atan2, so above
the natural frequency they are off by pi (the sign of the response flips against the true
phase lag); roll and pitch share the heave natural frequency and damping (Jensen et al.'s
simplification for pitch); beta = 90 deg makes k_e = 0 and the expressions 0/0. An encounter
frequency <= 0 (a fast following sea) has no real amplitude and is refused.
"""
import numpy as np

G, RHO = 9.81, 1025.0


def _second_order(wn, zeta, w_e):
    """The amplitude divisor Z and the (atan) phase eps of the forced second-order response."""
    Z = np.sqrt((2.0 * wn * zeta) ** 2 + (1.0 / w_e ** 2) * (wn ** 2 - w_e ** 2) ** 2)
    return Z, np.arctan(2.0 * w_e * wn * zeta / (wn ** 2 - w_e ** 2))


def wave_response_345(a, beta, T_0, zeta4, T4, GMT, Cb, U, L, B, T, t=None):
    """(t, heave z (m), roll phi (rad), pitch theta (rad)) on ``t`` (s; default 0..20 s by 0.1 s,
    as MSS plots them)."""
    t = np.arange(201) * 0.1 if t is None else np.asarray(t, dtype=float)
    nabla = Cb * L * B * T
    w_0 = 2.0 * np.pi / T_0
    k = w_0 ** 2 / G
    w_e = w_0 - k * U * np.cos(beta)
    if not w_e > 0.0:
        raise ValueError(f'encounter frequency {w_e:.4g} rad/s <= 0 (U = {U} m/s, beta = '
                         f'{np.rad2deg(beta):.1f} deg): no steady response in this model')
    k_e = abs(k * np.cos(beta))
    sigma = k_e * L / 2.0
    kappa = np.exp(-k_e * T)
    alpha = w_e / w_0
    A = 2.0 * np.sin(k * B * alpha ** 2 / 2.0) * np.exp(-k * T * alpha ** 2)
    f = np.sqrt((1.0 - k * T) ** 2 + (A ** 2 / (k * B * alpha ** 3)) ** 2)
    F = kappa * f * np.sin(sigma) / sigma
    Gp = kappa * f * (6.0 / L) * (1.0 / sigma) * (np.sin(sigma) / sigma - np.cos(sigma))
    wn = np.sqrt(G / (2.0 * T))
    zeta = (A ** 2 / (B * alpha ** 3)) * np.sqrt(1.0 / (8.0 * k ** 3 * T))
    w4 = 2.0 * np.pi / T4
    C44 = RHO * G * nabla * GMT
    M44 = C44 / w4 ** 2
    B44 = 2.0 * zeta4 * w4 * M44
    M = np.sin(beta) * np.sqrt(B44 * RHO * G ** 2 / w_e)
    Z3, eps3 = _second_order(wn, zeta, w_e)
    z = (a * F * wn ** 2 / (Z3 * w_e)) * np.cos(w_e * t + eps3)
    theta = (a * Gp * wn ** 2 / (Z3 * w_e)) * np.sin(w_e * t + eps3)
    Z4, eps4 = _second_order(w4, zeta4, w_e)
    phi = ((M / C44) * w4 ** 2 / (Z4 * w_e)) * np.cos(w_e * t + eps4)
    return t, z, phi, theta
