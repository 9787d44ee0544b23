"""Fuzzy PID heading autopilot of Lee 2004, Chapter 5 (two fuzzy blocks, scheduled gains).

Block 1 (PD-like) fuzzifies the scaled heading error and yaw rate, block 2 the yaw rate and the
error integral; min inference, bounded-sum merging and centre-of-singletons defuzzification make
the output U = GU (dU1 + dU2) a PID whose gains grow from GU G / 4 at the origin to twice that
at the edge of the universe [-L, L] (Lee 2004, eqs. 5.11-5.23, Tables 5.1-5.2). Gains come from
the Nomoto PD design (``scaling_from_pid``); the anti-windup (conditional integration with a
clamp) is ours. Units: rad, rad/s, rad s, s; GE (1/rad), GR (s/rad), GA (1/(rad s)), GU (rad).
Vectorised over leading axes (one vessel or a batch).

Derivation, what the source's OCR shows and what was chosen where it is unreadable, and the
anti-windup rules: ros_ws/src/ship_autopilot/doc/fuzzy_pid.md.
"""
from dataclasses import dataclass

import numpy as np

from .controller import HeadingController

# Rule -> consequent maps, rows = rules in firing-array order (first input N/P, second N/P),
# columns = output sets. Block 1 (error, rate): outputs (ON, OZ, OP).
_BLOCK1_RULES = np.array([[1.0, 0.0, 0.0],   # EN & RN -> ON
                          [0.0, 1.0, 0.0],   # EN & RP -> OZ
                          [0.0, 1.0, 0.0],   # EP & RN -> OZ
                          [0.0, 0.0, 1.0]])  # EP & RP -> OP
_BLOCK1_CENTRES = np.array([-1.0, 0.0, 1.0])  # times L
# Block 2 (rate, integral): outputs (ONM, OPM).
_BLOCK2_RULES = np.array([[1.0, 0.0],        # RN & AN -> ONM
                          [0.0, 1.0],        # RN & AP -> OPM
                          [1.0, 0.0],        # RP & AN -> ONM
                          [0.0, 1.0]])       # RP & AP -> OPM
_BLOCK2_CENTRES = np.array([-0.5, 0.5])      # times L


def memberships(x, L=1.0):
    """(mu_N, mu_P) of scaled inputs x, stacked on a new last axis; x clipped to [-L, L]."""
    xc = np.minimum(np.maximum(x, -L), L)  # np.clip is several times slower on scalars
    mu_p = (xc + L) / (2.0 * L)
    return np.stack((1.0 - mu_p, mu_p), axis=-1)


def _infer(x1, x2, rules, centres, L):
    """Two-input, two-set fuzzy block: min AND, bounded-sum OR, centre-of-singletons output."""
    m1, m2 = memberships(x1, L), memberships(x2, L)
    firing = np.minimum(m1[..., :, None], m2[..., None, :])          # (..., 2, 2)
    merged = np.minimum(1.0, firing.reshape(firing.shape[:-2] + (4,)) @ rules)
    return L * (merged @ centres) / merged.sum(axis=-1)


def fuzzy_block1(x_e, x_r, L=1.0):
    """PD-like block: dU1 from the scaled error and rate (eqs. 5.11, 5.12, Table 5.1)."""
    return _infer(x_e, x_r, _BLOCK1_RULES, _BLOCK1_CENTRES, L)


def fuzzy_block2(x_r, x_a, L=1.0):
    """Integral block: dU2 from the scaled rate and error integral (eqs. 5.13, 5.14, Table 5.1)."""
    return _infer(x_r, x_a, _BLOCK2_RULES, _BLOCK2_CENTRES, L)


@dataclass(frozen=True)
class FuzzyPIDGains:
    """Scaling gains of Lee 2004 Ch. 5: GE (1/rad), GR (s/rad), GA (1/(rad s)), GU (rad), L."""

    GE: float
    GR: float
    GA: float
    GU: float
    L: float = 1.0

    def __post_init__(self):
        for key in ('GE', 'GR', 'GA', 'GU', 'L'):
            val = float(getattr(self, key))
            if not (np.isfinite(val) and val > 0.0):
                raise ValueError(f'{key} = {val!r} is outside the allowed range (0, inf)')
            object.__setattr__(self, key, val)

    def linear_gains(self):
        """(K_P, K_D, K_I) of the equivalent linear PID at the origin: GU G / 4 (eq. 5.22)."""
        return self.GU * self.GE / 4.0, self.GU * self.GR / 4.0, self.GU * self.GA / 4.0

    def saturation_points(self):
        """Where each input leaves the universe: (e_sat rad, r_sat rad/s, a_sat rad s) = L / G."""
        return self.L / self.GE, self.L / self.GR, self.L / self.GA


def scaling_from_pid(kp, kd, ki, e_sat, L=1.0):
    """Scaling gains whose linearisation at the origin is the PID (kp, kd, ki) (eq. 5.23).

    The one free choice, GU, is set so that the scaled error reaches the edge of the universe
    at |psi_e| = e_sat (rad): GU = 4 kp e_sat / L, GE = L / e_sat, GR = 4 kd / GU,
    GA = 4 ki / GU. Units: kp (-), kd (s), ki (1/s).
    """
    for key, val in (('kp', kp), ('kd', kd), ('ki', ki), ('e_sat', e_sat), ('L', L)):
        if not (np.isfinite(val) and val > 0.0):
            raise ValueError(f'{key} = {val!r} is outside the allowed range (0, inf)')
    gu = 4.0 * kp * e_sat / L
    return FuzzyPIDGains(GE=4.0 * kp / gu, GR=4.0 * kd / gu, GA=4.0 * ki / gu, GU=gu, L=L)


def scheduled_gains(psi_e, psi_r, psi_a, g):
    """(K_P, K_D, K_I) at a point inside the universe, closed form eqs. (5.18)-(5.20)."""
    x_e, x_r, x_a = (np.clip(v, -g.L, g.L) for v in (g.GE * psi_e, g.GR * psi_r, g.GA * psi_a))
    d_pd = 2.0 * g.L - np.maximum(np.abs(x_e), np.abs(x_r))
    d_i = 2.0 * g.L - np.maximum(np.abs(x_r), np.abs(x_a))
    c = 0.5 * g.L * g.GU
    return c * g.GE / d_pd, c * g.GR / d_pd, c * g.GA / d_i


class FuzzyPIDAutopilot(HeadingController):
    """Fuzzy PID of Lee 2004 Ch. 5 + shared rudder shaping; state: the error integral psi_a.

    ``FuzzyPIDAutopilot(gains, limiter, anti_windup=True, integration_band=None)``; ``gains``
    a FuzzyPIDGains; ``integration_band`` (rad, > 0): integrate only while |psi_e| is below
    it (None: the error universe L / GE). Anti-windup: doc/fuzzy_pid.md.
    """

    name = 'fuzzy_pid'

    def __init__(self, gains, limiter, anti_windup=True, integration_band=None):
        if not isinstance(gains, FuzzyPIDGains):
            raise TypeError(f'gains must be FuzzyPIDGains, got {type(gains).__name__}')
        self.gains = gains
        self.anti_windup = bool(anti_windup)
        band = gains.L / gains.GE if integration_band is None else float(integration_band)
        if not (np.isfinite(band) and band > 0.0):
            raise ValueError(f'integration_band = {integration_band!r} is outside the allowed '
                             f'range (0, inf)')
        self.integration_band = band
        super().__init__(limiter)

    def _initial_state(self):
        return {'integral': 0.0}

    def command(self, psi_e, psi_r, psi_a):
        """Raw rudder U (rad) for error, rate and integral, before shaping (eqs. 5.15-5.16)."""
        g = self.gains
        x_r = g.GR * psi_r
        return g.GU * (fuzzy_block1(g.GE * psi_e, x_r, g.L) + fuzzy_block2(x_r, g.GA * psi_a, g.L))

    def _law(self, e, r, dt):
        g = self.gains
        integral = self._state['integral']
        candidate = integral + e * dt
        x_r = g.GR * r
        pd_part = fuzzy_block1(g.GE * e, x_r, g.L)  # block 1 does not depend on the integral
        if not self.anti_windup:
            raw = g.GU * (pd_part + fuzzy_block2(x_r, g.GA * candidate, g.L))
            return raw, {'integral': candidate}
        a_max = g.L / g.GA
        candidate = np.minimum(np.maximum(candidate, -a_max), a_max)
        raw = g.GU * (pd_part + fuzzy_block2(x_r, g.GA * candidate, g.L))
        pushes_deeper = self.limiter.saturated(raw) & (np.sign(e) == np.sign(raw))
        integrate = (np.abs(e) < self.integration_band) & ~pushes_deeper
        if np.all(integrate):
            return raw, {'integral': candidate}
        integral = np.where(integrate, candidate, integral)
        raw = g.GU * (pd_part + fuzzy_block2(x_r, g.GA * integral, g.L))
        return raw, {'integral': integral}

    def __repr__(self):
        return (f'FuzzyPIDAutopilot(gains={self.gains!r}, limiter={self.limiter!r}, '
                f'anti_windup={self.anti_windup!r}, '
                f'integration_band={self.integration_band!r})')
