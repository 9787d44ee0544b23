"""Fuzzy PID heading autopilot of Lee 2004, Chapter 5 (two fuzzy blocks, scheduled gains).

Source: Lee 2004 (B. Lee, "An Optimal Route Decision and LOS Guidance System for Automatic
Navigation of Ships", Korea Maritime University), Section 5.1, eqs. (5.11)-(5.23), Tables 5.1
and 5.2, Figs. 5.4-5.6; simulations in Section 5.2 (Figs. 5.7-5.11: 30/45/60/90 deg course
changes, where the PD autopilot keeps a steady-state error and the fuzzy PID removes it).

The controller (as implemented here)
------------------------------------
Inputs, scaled and clipped to the universe [-L, L] (Table 5.2):
    x_e = GE * psi_e,   x_r = GR * psi_r,   x_a = GA * psi_a
with psi_e = wrap(psi - psi_c) (rad), psi_r = r (rad/s), psi_a = integral of psi_e (rad s).
Each input has two fuzzy sets, N and P, with linear membership functions on [-L, L]:
    mu_P(x) = (x + L) / (2 L),   mu_N(x) = (L - x) / (2 L)          (1 and 0 outside)
Fuzzy control block 1 (PD-like, inputs x_e, x_r), rules (R1)1-(R4)1:
    EP & RP -> OP,  EP & RN -> OZ,  EN & RP -> OZ,  EN & RN -> ON;   ON, OZ, OP at -L, 0, L
Fuzzy control block 2 (integral, inputs x_r, x_a), rules (R1)2-(R4)2:
    RP & AP -> OPM,  RP & AN -> ONM,  RN & AP -> OPM,  RN & AN -> ONM;   ONM, OPM at -L/2, L/2
Inference: AND = min (Zadeh); rules with the same consequent are merged with the bounded sum
(Lukasiewicz OR, min(1, a + b)); defuzzification = centre of the output singletons weighted by
their merged memberships. The output is (eqs. 5.15, 5.16)
    dU = dU1 + dU2,   U = GU * dU   (rad of rudder),
which in closed form is the PID with gains scheduled on the scaled inputs (eqs. 5.17-5.20):
    U = K_P psi_e + K_D psi_r + K_I psi_a,
    K_P = 0.5 L GU GE / (2L - max(|x_e|, |x_r|)),  K_D = 0.5 L GU GR / (2L - max(|x_e|, |x_r|)),
    K_I = 0.5 L GU GA / (2L - max(|x_r|, |x_a|))          (inside the universe)
The gain scheduling (Fig. 5.6): every gain grows from its value at the origin, K = GU G / 4
(eqs. 5.21-5.22), to twice that at the edge of the universe; the scheduling variable of the
P and D gains is max(|x_e|, |x_r|), that of the I gain max(|x_r|, |x_a|). Design from a linear
PID (eq. 5.23, inverted): GE = 4 K_P / GU, GR = 4 K_D / GU, GA = 4 K_I / GU (see
``scaling_from_pid``).

Sign: the blocks are odd (dU(-x) = -dU(x)), so the seed's law (its own rudder sign, error
psi_d - psi) maps onto ours unchanged: with psi_e = psi - psi_c and the unified rudder (+ turns
to port) all gains are positive, as for the PD law (ship_autopilot.pd).

What the OCR shows, what it does not, and what was chosen
---------------------------------------------------------
Read: the two rule tables (R1)-(R4) of each block; the output sets ON/OZ/OP at -L, 0, L and
ONM/OPM at -L/2, L/2 (Fig. 5.4 labels); the partition of the inputs into regions IC1-IC20
(Fig. 5.5); eq. (5.11): dU1 = 0.5 L / (2L - GE|psi_e|) (GE psi_e + GR psi_r) for
|GR psi_r| <= |GE psi_e| <= L, eq. (5.12) the same with GR|psi_r| in the denominator; Table 5.1
(block 1 outside the universe: (x_r + L)/2, (x_e + L)/2, (x_r - L)/2, (x_e - L)/2, L, 0, -L;
block 2: 0.5 GA psi_a, 0.5 L, -0.5 L); Table 5.2 (the scaled inputs are clipped to +-L); eqs.
(5.15)-(5.20) as written above; the course-change simulations (30/45/60/90 deg, the PD leaves
about 0.6 deg of steady-state error).
Unreadable or missing: the text of 5.1.1, Figs. 5.1-5.3 (block diagram, input membership
functions) were dropped from the OCR; the inference operators and defuzzifier are not named in
what survives; the constant of eqs. (5.13)/(5.14) reads "02B" / "0oz"; eqs. (5.21)-(5.23) are
garbled except their shape (gains = GU * G / 4 relations); the value of L is not given; GU
reads "1°11"; GE = 2.75, GR = 50, GA = 500 are printed without units (degrees? sum or integral
of the error?) and GA/GE = 182 1/s cannot be an integral rate in SI, so they are not used.
Chosen: the memberships and operators above, because they reproduce every surviving formula
exactly (eqs. 5.11, 5.12 and both halves of Table 5.1; this is the analytical structure of
H. Ying's "simplest" two-input fuzzy controllers, whose input-combination (IC) analysis the
chapter follows). They
fix the block 2 constant of (5.13)/(5.14) to 0.5 (dU2 = 0.5 L x_a / (2L - max(|x_r|, |x_a|)),
continuous with Table 5.1's 0.5 GA psi_a at |x_r| = L; 0.25 would jump there). The "rate"
input psi_r is the yaw rate r (= d psi_e / dt for a constant command; no derivative kick at a
command step). L defaults to 1: scaling L by s, every G by s and GU by 1/s gives the same
controller, so L is a pure normalisation.
Gains: ours come from the Nomoto PD design (``scaling_from_pid``, ship_autopilot.gains).

Anti-windup (our addition; the chapter has none besides the input clipping of Table 5.2):
conditional integration with clamping.
(i) psi_a += psi_e dt only where |psi_e| is below the integration band (default e_sat =
    L / GE, the edge of the error universe; the per-model defaults of ship_autopilot.gains use
    10 deg). A large error is the transient of a course change, not an offset to integrate,
    and integrating it during the approach only adds overshoot. A constant disturbance d (rad
    of rudder) that the rudder can hold leaves a fuzzy-PD error of at most d / K_P (block 1's
    scheduled gain is never below K_P), a few degrees, so the integrator does start.
(ii) ... and only where the raw command is not beyond the rudder limit in the direction the
    increment would push it (sign(psi_e) = sign(U) with |U| >= limit freezes it).
(iii) psi_a is clamped to |GA psi_a| <= L: beyond it the block output no longer changes
    (Tables 5.1, 5.2), so any larger state would be pure windup.
``anti_windup=False`` integrates unconditionally without the clamp (for comparison).

Units: rad, rad/s, rad s, s; GE (1/rad), GR (s/rad), GA (1/(rad s)), GU (rad per unit of dU).
Vectorised: the rule evaluation is array arithmetic over a (..., 2, 2) firing-strength array;
it works for one vessel or a batch (leading axes).
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
    it (None: the error universe L / GE). See the module docstring for the anti-windup.
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
