"""The exact critical look-ahead of LOS + PD with sway dynamics (Simakis 1992, Ch. III) (pure).

Simakis 1992, Sec. III.B (eqs. 3.6-3.12): the linear sway/yaw model (eqs. 2.8-2.9) under the
PD law of ship_guidance.heading_loop and LOS has a quartic characteristic equation; Routh gives
a quadratic in 1/d whose smallest positive root is the exact limit (the first-order Nomoto
limit U / (2 zeta omega_n), ship_guidance.los, is its approximation, Sec. III.A). Sec. III.C:
its sensitivity to the hydrodynamic coefficients; the listings NOMO.FOR / NOMOV.FOR
(Appendices A, B) design the autopilot once on the nominal vehicle. Non-dimensional units only
(lengths in vehicle lengths L, time in L/U).
"""
from dataclasses import dataclass

import numpy as np

from .heading_loop import pd_gains


@dataclass(frozen=True)
class SwayYawPlant:
    """Non-dimensional linear sway/yaw model (Simakis 1992 eqs. 2.8-2.9, unified rudder sign):
    v' = a11 v + a12 r + b1 delta,  r' = a21 v + a22 r + b2 delta."""
    a11: float
    a12: float
    a21: float
    a22: float
    b1: float
    b2: float


def sway_yaw_matrix(plant, k1, k2, lookahead):
    """eqs. 3.7-3.10: state (psi, v, r, y), delta = k1 (psi + y/d) + k2 r, y' = psi + v."""
    p, d = plant, float(lookahead)
    return np.array([[0.0, 0.0, 1.0, 0.0],
                     [k1 * p.b1, p.a11, p.a12 + k2 * p.b1, k1 * p.b1 / d],
                     [k1 * p.b2, p.a21, p.a22 + k2 * p.b2, k1 * p.b2 / d],
                     [1.0, 1.0, 0.0, 0.0]])


def sway_yaw_char_terms(plant, k1, k2):
    """Coefficients of Simakis 1992 eq. 3.11, s^4 + B s^3 + (C1 + C2/d) s^2 + (D1 + D2/d) s + E/d,
    returned as (B, C1, C2, D1, D2, E) with C2, D2, E the factors of 1/d. Broadcasting."""
    p = plant
    cross = p.a11 * p.b2 - p.a21 * p.b1
    b = -(p.a11 + p.a22) - k2 * p.b2
    c1 = (p.a11 * p.a22 - p.a12 * p.a21) + cross * k2 - k1 * p.b2
    c2 = -k1 * p.b1
    d1 = cross * k1
    d2 = (p.a22 * p.b1 - p.a12 * p.b2) * k1 - k1 * p.b2
    e = cross * k1
    return b, c1, c2, d1, d2, e


def sway_yaw_critical_lookahead(plant, k1, k2):
    """Exact critical look-ahead of Sec. III.B (ship lengths), broadcasting over k1, k2.

    With q = 1/d the quartic's Routh-Hurwitz determinant B C D - B^2 E - D^2 (A = 1) is the
    quadratic h0 + h1 q + h2 q^2; times d^2 it is Simakis 1992 eq. 3.12 (alpha1 = h0, alpha2 = h1,
    alpha3 = h2). Stability for d -> infinity needs B > 0, E > 0 and h0 > 0; it is lost where
    the first of H(q) or C(q) = C1 + C2 q reaches zero as q grows from 0, so the critical
    distance is 1 / (smallest positive root) (0 if there is none: stable for every d > 0;
    NaN if the loop is unstable even for large d). This is the thesis's 'positive root'
    chosen so that every d above it is stable."""
    b, c1, c2, d1, d2, e = np.broadcast_arrays(*sway_yaw_char_terms(plant, k1, k2))
    h0 = b * c1 * d1 - d1 * d1
    h1 = b * c1 * d2 + b * c2 * d1 - b * b * e - 2.0 * d1 * d2
    h2 = b * c2 * d2 - d2 * d2
    disc = h1 * h1 - 4.0 * h0 * h2
    sq = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
    with np.errstate(divide='ignore', invalid='ignore'):
        lin = np.where(h1 != 0.0, -h0 / h1, np.nan)
        roots = np.stack([np.where(h2 != 0.0, (-h1 - sq) / (2.0 * h2), lin),
                          np.where(h2 != 0.0, (-h1 + sq) / (2.0 * h2), np.nan),
                          np.where(c2 != 0.0, -c1 / c2, np.nan)])
    roots = np.where(roots > 0.0, roots, np.inf)
    q_max = roots.min(axis=0)
    d_crit = np.where(np.isfinite(q_max), 1.0 / q_max, 0.0)
    ok_far = (b > 0.0) & (e > 0.0) & (h0 > 0.0) & (c1 > 0.0)
    return np.where(ok_far, d_crit, np.nan)


def critical_lookahead_by_eigenvalues(plant, k1, k2, d_lo, d_hi, rel_tol=1e-10):
    """Independent check: bisection on the sign of the largest real part of the eigenvalues of
    ``sway_yaw_matrix`` between d_lo (unstable) and d_hi (stable)."""
    def max_real(d):
        return np.linalg.eigvals(sway_yaw_matrix(plant, k1, k2, d)).real.max()
    if not (max_real(d_lo) > 0.0 > max_real(d_hi)):
        raise ValueError(f'no stability change bracketed in [{d_lo}, {d_hi}]')
    while d_hi - d_lo > rel_tol * d_hi:
        mid = 0.5 * (d_lo + d_hi)
        if max_real(mid) < 0.0:
            d_hi = mid
        else:
            d_lo = mid
    return d_hi


def nps_auv2_plant(coeffs=None):
    """The NPS AUV II of Simakis 1992 (ship_sim.models.nps_auv2, bow/stern ratio -1), with optional
    overrides of its non-dimensional hydrodynamic coefficients (names as nps_auv2.COEFFS)."""
    from ship_sim.models.nps_auv2 import nondimensional_matrices
    return SwayYawPlant(*nondimensional_matrices(coeffs=coeffs))


def nps_auv2_nomoto(plant=None):
    """Non-dimensional first-order Nomoto (a, b) of Simakis 1992 eq. 2.11 for ``plant``."""
    from ship_sim.models.nps_auv2 import nondimensional_nomoto_ab
    p = plant or nps_auv2_plant()
    return nondimensional_nomoto_ab(p.a11, p.a12, p.a21, p.a22, p.b1, p.b2)


def nps_auv2_critical_lookahead(zeta, omega_n, coeffs=None, redesign=False):
    """Exact critical look-ahead (vehicle lengths) of the NPS AUV II with sway dynamics,
    broadcasting over zeta and omega_n (units of U/L).

    coeffs: perturbed hydrodynamic coefficients of the vehicle. The PD gains come from the
    NOMINAL vehicle's Nomoto model (as NOMOV.FOR does: the autopilot is designed once and the
    true vehicle differs) unless ``redesign`` (gains from the perturbed vehicle's Nomoto model)."""
    nominal = nps_auv2_plant()
    plant = nps_auv2_plant(coeffs) if coeffs else nominal
    a, b = nps_auv2_nomoto(plant if redesign else nominal)
    k1, k2 = pd_gains(a, b, zeta=np.asarray(zeta, float), omega_n=np.asarray(omega_n, float))
    return sway_yaw_critical_lookahead(plant, k1, k2)


def nps_auv2_sensitivity(name, factors, zeta=0.8, omega_n=3.0, redesign=False):
    """Sec. III.C: d_n = d_crit(coefficient * factor) / d_crit(nominal) for each factor."""
    from ship_sim.models.nps_auv2 import COEFFS
    if name not in COEFFS:
        raise ValueError(f'unknown coefficient {name!r}; one of {sorted(COEFFS)}')
    nominal = float(nps_auv2_critical_lookahead(zeta, omega_n))
    return np.array([float(nps_auv2_critical_lookahead(
        zeta, omega_n, coeffs={name: COEFFS[name] * f}, redesign=redesign)) / nominal
        for f in np.atleast_1d(factors)])
