"""String stability of LOS platoons: the linear model and the check a platoon runs (pure).

Angelopoulos 2011, eqs. 27-45: one vessel is Nomoto's first-order steering r' = a r + b delta
under the PD law of ship_guidance.heading_loop (eq. 20) and linearised LOS, y' = U psi
(eqs. 27-30); in a string the leader aims at a point d1 ahead on the path, every follower at its
predecessor, d_i ahead along the path (eqs. 31-32, 35-37). The N-vessel string, state
(psi_i, r_i, y_i) per vessel:
    psi_i' = r_i
    r_i'   = -omega_i^2 psi_i - 2 zeta_i omega_i r_i - omega_i^2 (y_i - y_{i-1}) / d_i
    y_i'   = U psi_i                          (y_{-1} = 0: the leader aims at the path)
The only coupling is y_{i-1} -> r_i, below the diagonal blocks, so the matrix is block lower
triangular: its eigenvalues are those of the N diagonal 3x3 blocks (eq. 40) and the string is
stable iff every vessel is, d_i > U / (2 zeta_i omega_i) (eq. 41, ship_guidance.los.
critical_lookahead). At d_i = d_i* the block's eigenvalues are +-i omega_i and -2 zeta_i omega_i
(eq. 45), since (s + 2 zeta w)(s^2 + w^2) = s^3 + 2 zeta w s^2 + w^2 s + 2 zeta w^3.

Units: with U (m/s), omega_n (rad/s) and d (m) the formulas hold in SI; with ``speed`` = 1 they
are the thesis's non-dimensional form (lengths in ship lengths L, time in L/U).

``check_platoon`` is what the follower node and the launcher's platoon check run. The
reproduction of the thesis's Table 1 scan is in string_stability_table1, the exact limit with
sway dynamics (Simakis 1992) in sway_yaw_lookahead; see doc/string_stability.md.
"""
from dataclasses import dataclass

import numpy as np

from .los import critical_lookahead

#: Relative distance under which a look-ahead counts as lying ON the limit (a grid tie).
TIE_RTOL = 1e-9


def _pos(name, x):
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)) or np.any(x <= 0.0):
        raise ValueError(f'{name} must be finite and > 0, got {x}')
    return x


def single_vessel_matrix(zeta, omega_n, lookahead, speed=1.0):
    """eq. 30 (state psi, r, y), broadcasting over the arguments -> (..., 3, 3)."""
    z, w, d, u = np.broadcast_arrays(*(np.asarray(v, dtype=float)
                                       for v in (zeta, omega_n, lookahead, speed)))
    a = np.zeros(z.shape + (3, 3))
    a[..., 0, 1] = 1.0
    a[..., 1, 0] = -w * w
    a[..., 1, 1] = -2.0 * z * w
    a[..., 1, 2] = -w * w / d
    a[..., 2, 0] = u
    return a


def characteristic_coefficients(zeta, omega_n, lookahead, speed=1.0):
    """Monic cubic of eq. 33, (1, 2 zeta w, w^2, U w^2 / d), broadcasting -> (..., 4)."""
    z, w, d, u = np.broadcast_arrays(*(np.asarray(v, dtype=float)
                                       for v in (zeta, omega_n, lookahead, speed)))
    return np.stack([np.ones_like(z), 2.0 * z * w, w * w, u * w * w / d], axis=-1)


def string_matrix(zeta, omega_n, lookahead, speed=1.0):
    """3N x 3N system matrix of an N-vessel platoon (eq. 37 generalised; eq. 30 for N=1).

    zeta, omega_n, lookahead: length-N sequences (scalars broadcast); lookahead[0] is the
    leader's LOS look-ahead d1, lookahead[i] the along-path distance from vessel i to its
    predecessor. State order (psi_0, r_0, y_0, psi_1, ...)."""
    z, w, d, u = np.broadcast_arrays(*(np.atleast_1d(np.asarray(v, dtype=float))
                                       for v in (zeta, omega_n, lookahead, speed)))
    n = z.size
    blocks = single_vessel_matrix(z, w, d, u)
    a = np.zeros((3 * n, 3 * n))
    for i in range(n):
        a[3 * i:3 * i + 3, 3 * i:3 * i + 3] = blocks[i]
        if i > 0:   # psi_c,i = -atan((y_i - y_{i-1}) / d_i): predecessor's offset enters r_i'
            a[3 * i + 1, 3 * i - 1] = w[i] ** 2 / d[i]
    return a


def string_eigenvalues(zeta, omega_n, lookahead, speed=1.0):
    """Eigenvalues of ``string_matrix`` from its diagonal blocks (block lower triangular),
    shape (N, 3), vessel by vessel."""
    z, w, d, u = np.broadcast_arrays(*(np.atleast_1d(np.asarray(v, dtype=float))
                                       for v in (zeta, omega_n, lookahead, speed)))
    return np.linalg.eigvals(single_vessel_matrix(z, w, d, u))


def limit_eigenvalues(zeta, omega_n):
    """The eigenvalues at d = d*: (+i omega_n, -i omega_n, -2 zeta omega_n) (eq. 45)."""
    w = complex(omega_n)
    return np.array([1j * w, -1j * w, -2.0 * zeta * w])


def is_stable(zeta, omega_n, lookahead, speed=1.0, tie_rtol=TIE_RTOL):
    """Routh test of the cubic (Angelopoulos 2011 eq. 33), broadcasting: all coefficients > 0 and
    2 zeta w * w^2 > U w^2 / d. A look-ahead within ``tie_rtol`` of the limit is marginal and
    counts as NOT stable (asymptotic stability needs d > d* strictly)."""
    d = np.asarray(lookahead, dtype=float)
    return (d > 0.0) & (d > critical_lookahead(zeta, omega_n, speed) * (1.0 + tie_rtol))



@dataclass(frozen=True)
class LookaheadLoop:
    """One vessel's steering loop as the stability test sees it.

    zeta, omega_n: the PD autopilot's design (eq. 20); omega_n in rad/s with ``speed`` in
    m/s and ``lookahead`` in m, or the non-dimensional form of with speed = 1 (omega_n in
    U/L, lookahead in ship lengths). lookahead: the leader's LOS look-ahead d1, or for a
    follower the along-path distance to its predecessor (the point it steers at)."""
    zeta: float
    omega_n: float
    lookahead: float
    speed: float = 1.0
    name: str = ''


@dataclass(frozen=True)
class LookaheadCheck:
    index: int
    name: str
    lookahead: float
    critical: float      # U / (2 zeta omega_n), same unit as lookahead
    ratio: float         # lookahead / critical; the string is stable iff every ratio > 1
    ok: bool             # ratio > margin

    def message(self):
        state = 'ok' if self.ok else 'BELOW its stability limit'
        who = self.name or f'vessel {self.index}'
        return (f'{who}: look-ahead {self.lookahead:.4g} vs limit {self.critical:.4g} '
                f'(ratio {self.ratio:.3f}): {state}')


def los_loop(zeta, omega_n, speed, lookahead, integral_gain=0.0, name=''):
    """The LookaheadLoop of a vessel steering (I)LOS with ``lookahead`` (m): ILOS's limit
    (U + 4 zeta^2 sigma) / (2 zeta omega_n) (los.critical_lookahead) is the LOS limit at the
    speed U + 4 zeta^2 sigma, so that is the loop's speed (sigma = 0: plain LOS)."""
    return LookaheadLoop(zeta, omega_n, lookahead, speed + 4.0 * zeta ** 2 * integral_gain, name)


def follower_loops(zeta, omega_n, speed, min_lookahead, fallback_lookahead, integral_gain=0.0,
                   names=('min_lookahead', 'fallback_lookahead')):
    """The LookaheadLoops a follower must keep stable (ship_guidance.follower): its smallest
    look-ahead, with its integral action if any, and its plain-LOS fallback look-ahead. The
    follower and the launcher's platoon check both pass these to ``check_platoon``."""
    return [los_loop(zeta, omega_n, speed, min_lookahead, integral_gain, names[0]),
            los_loop(zeta, omega_n, speed, fallback_lookahead, 0.0, names[1])]


def check_platoon(vessels, margin=1.0):
    """Check every vessel of a platoon against its LOS stability limit (Angelopoulos 2011 eq. 41).

    vessels: sequence of LookaheadLoop or mappings with its fields, leader first. margin >= 1
    demands lookahead > margin * limit. Returns one LookaheadCheck per vessel; the linearised
    string is stable iff all are ok with margin 1 (block-triangular structure, eq. 40)."""
    if not margin >= 1.0:
        raise ValueError(f'margin must be >= 1, got {margin}')
    out = []
    for i, v in enumerate(vessels):
        v = v if isinstance(v, LookaheadLoop) else LookaheadLoop(**v)
        crit = critical_lookahead(v.zeta, v.omega_n, v.speed)
        lookahead = float(_pos(f'lookahead of vessel {i}', v.lookahead))
        ratio = lookahead / crit
        out.append(LookaheadCheck(i, v.name, lookahead, crit, ratio,
                                  bool(ratio > margin * (1.0 + TIE_RTOL))))
    return out


def unstable_vessels(vessels, margin=1.0):
    """The LookaheadChecks of the vessels at or below their limit (empty list: all fine)."""
    return [c for c in check_platoon(vessels, margin) if not c.ok]
