"""String stability of LOS platoons and the exact look-ahead limit with sway dynamics (pure).

Sources
- Seed 001: C. K. Angelopoulos, "String stability of multiple surface marine vessels", NPS
  thesis, 2011. Eqs. 27-30 (one vessel: Nomoto first-order steering r' = a r + b delta, PD law
  delta = k1 (psi + y/d) + k2 r with k1 = -omega_n^2/b, k2 = -(a + 2 zeta omega_n)/b, eq. 20,
  LOS linearised, y' = psi), eqs. 31-32 and 35-37 (two vessels: the leader aims at a point d1
  ahead on the path, the follower at its predecessor, d2 ahead along the path), eqs. 33-34 and
  38-41 (characteristic polynomials and the Routh limit d* = 1 / (2 zeta omega_n)), eqs. 44-45
  (eigenvalues at the limit), Appendix A (the eigenvalue grid scan) and B (Table 1).
- Seed 003: D. A. Simakis, "Vehicle guidance and control along circular trajectories", NPS
  thesis, 1992. Chapter III.A (eqs. 3.1-3.5, the same approximate limit) and III.B (eqs.
  3.6-3.12: sway/yaw model 2.8-2.9 with the same PD law and LOS, quartic characteristic
  equation, Routh, quadratic in d), III.C (sensitivity to the hydrodynamic coefficients), and the
  listings NOMO.FOR / NOMOV.FOR (Appendices A, B).

Units. The seeds are non-dimensional: lengths in ship lengths L, time in L/U, so omega_n is in
units of U/L and d in ship lengths (001 eq. 8, 22: y' = sin psi). Every Nomoto-level function
here takes an optional ``speed`` U: with U (m/s), omega_n (rad/s) and d (m) the same formulas
hold in SI with y' = U psi, and the limit is d* = U / (2 zeta omega_n) metres (see los.py).
The sway/yaw functions (seed 003) work in the seed's non-dimensional units only.

The N-vessel string (001 eq. 37 generalised to N vessels): state (psi_i, r_i, y_i) per vessel,
    psi_i' = r_i
    r_i'   = -omega_i^2 psi_i - 2 zeta_i omega_i r_i - omega_i^2 (y_i - y_{i-1}) / d_i
    y_i'   = U psi_i                          (y_{-1} = 0: the leader aims at the path)
The only coupling is y_{i-1} -> r_i, below the diagonal blocks, so the matrix is block lower
triangular: its eigenvalues are those of the N diagonal 3x3 blocks (001 eq. 40) and the string
is stable iff every vessel is, d_i > U / (2 zeta_i omega_i) (001 eq. 41). At d_i = d_i* the
block's eigenvalues are +-i omega_i and -2 zeta_i omega_i (001 eq. 45), since
(s + 2 zeta w)(s^2 + w^2) = s^3 + 2 zeta w s^2 + w^2 s + 2 zeta w^3.

Table 1 (001 Appendix A): for each omega_n1 the document scans d1 (outer loop) and d2 (inner
loop) over 0.05:0.01:2, computes max(real(eig(A))) of the 6x6 matrix and records the FIRST
point, in scan order, that is not unstable (``V > 0`` is unstable, so V <= 0 counts as stable).
Because stability factorises, that first point is (first stable d1, first stable d2), each a
scalar Routh test per grid point, vectorised here over all rows and grid points. See
doc/string_stability.md for the rows whose printed values differ from the exact boundary.
"""
from dataclasses import dataclass

import numpy as np

#: The document's look-ahead grid (001 Appendix A): start, step, stop.
TABLE1_GRID = (0.05, 0.01, 2.0)
#: The document's parameter sets (001 Sec. III.B.2): zeta, omega_n2/omega_n1, omega_n1.
TABLE1_ZETAS = (0.4, 0.6, 0.8, 1.0, 1.2)
TABLE1_RATIOS = (0.5, 1.0, 1.5)
TABLE1_OMEGA1 = (1.0, 0.1, 4.5)
#: Relative distance under which a look-ahead counts as lying ON the limit (a grid tie).
TIE_RTOL = 1e-9


def _pos(name, x):
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)) or np.any(x <= 0.0):
        raise ValueError(f'{name} must be finite and > 0, got {x}')
    return x


# ---------------------------------------------------------------- Nomoto level (seed 001)

def pd_gains(a, b, zeta, omega_n):
    """PD gains (k1, k2) of 001 eq. 20 / 003 eqs. 2.15-2.16 for r' = a r + b delta."""
    return -np.square(omega_n) / b, -(a + 2.0 * np.asarray(zeta) * omega_n) / b


def nomoto_critical_lookahead(zeta, omega_n, speed=1.0):
    """Routh limit of one LOS + PD + Nomoto loop (001 eq. 34, 003 eq. 3.5), broadcasting.

    d* = U / (2 zeta omega_n); with U = 1 this is the seeds' 1 / (2 zeta omega_n) in ship
    lengths (omega_n in U/L). The loop is asymptotically stable for d > d* only."""
    return _pos('speed', speed) / (2.0 * _pos('zeta', zeta) * _pos('omega_n', omega_n))


def single_vessel_matrix(zeta, omega_n, lookahead, speed=1.0):
    """001 eq. 30 (state psi, r, y), broadcasting over the arguments -> (..., 3, 3)."""
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
    """Monic cubic of 001 eq. 33, (1, 2 zeta w, w^2, U w^2 / d), broadcasting -> (..., 4)."""
    z, w, d, u = np.broadcast_arrays(*(np.asarray(v, dtype=float)
                                       for v in (zeta, omega_n, lookahead, speed)))
    return np.stack([np.ones_like(z), 2.0 * z * w, w * w, u * w * w / d], axis=-1)


def string_matrix(zeta, omega_n, lookahead, speed=1.0):
    """3N x 3N system matrix of an N-vessel platoon (001 eq. 37 generalised; eq. 30 for N=1).

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
    """The eigenvalues at d = d*: (+i omega_n, -i omega_n, -2 zeta omega_n) (001 eq. 45)."""
    w = complex(omega_n)
    return np.array([1j * w, -1j * w, -2.0 * zeta * w])


def is_stable(zeta, omega_n, lookahead, speed=1.0, tie_rtol=TIE_RTOL):
    """Routh test of the cubic (001 eq. 33), broadcasting: all coefficients > 0 and
    2 zeta w * w^2 > U w^2 / d. A look-ahead within ``tie_rtol`` of the limit is marginal and
    counts as NOT stable (asymptotic stability needs d > d* strictly)."""
    d = np.asarray(lookahead, dtype=float)
    return (d > 0.0) & (d > nomoto_critical_lookahead(zeta, omega_n, speed) * (1.0 + tie_rtol))


# ---------------------------------------------------------------- Table 1 (001 App. A, B)

def matlab_colon(start, step, stop):
    """``start:step:stop`` as MATLAB builds it (count from the rounded ratio, values computed
    symmetrically from both ends), so grid points carry the same rounding as the document's."""
    n = int(np.floor((stop - start) / step * (1.0 + 1e-12) + 1e-10))
    k = np.arange(n + 1)
    end = start + n * step
    return np.where(k < n / 2.0, start + k * step, end - (n - k) * step)


def table1_parameters():
    """(zeta, omega_n1, omega_n2) of every row Appendix A scans, in the document's order
    (zeta, then omega_n2/omega_n1, then omega_n1): 5 x 3 x 36 = 540 rows."""
    w1 = matlab_colon(*TABLE1_OMEGA1)
    z, p, w = np.meshgrid(TABLE1_ZETAS, TABLE1_RATIOS, w1, indexing='ij')
    return z.ravel(), w.ravel(), (p * w).ravel()


def first_stable_point(stable1, stable2):
    """Appendix A's bookkeeping, vectorised over rows: the first (d1, d2) grid index, in scan
    order (d1 outer, d2 inner), where both vessels are stable. stable1 (rows, n1), stable2
    (rows, n2) booleans -> (i1, i2) int arrays, -1 where no grid point is stable (the document
    then writes no row for that omega_n1)."""
    both = stable1[:, :, None] & stable2[:, None, :]
    flat = both.reshape(both.shape[0], -1)
    k = np.argmax(flat, axis=1)
    found = flat[np.arange(flat.shape[0]), k]
    i1, i2 = np.divmod(k, stable2.shape[1])
    return np.where(found, i1, -1), np.where(found, i2, -1)


def grid_minima(zeta, omega_n1, omega_n2, grid=TABLE1_GRID, method='routh',
                tie_rtol=TIE_RTOL):
    """Grid minima (d1_sim, d2_sim) of Appendix A for each row, NaN where none is stable.

    method 'routh': the scalar test ``is_stable`` per vessel and grid point (exact boundary,
    ties = marginal = not stable). 'eig': max real part of the eigenvalues of each vessel's 3x3
    block (the diagonal blocks of eq. 37), stable when < -tie_rtol * omega_n. Both then apply
    the document's scan order (``first_stable_point``). ``grid`` is (start, step, stop) or an
    array of look-aheads."""
    z, w1, w2 = np.broadcast_arrays(*(np.atleast_1d(np.asarray(v, dtype=float))
                                      for v in (zeta, omega_n1, omega_n2)))
    g = matlab_colon(*grid) if isinstance(grid, tuple) else np.asarray(grid, dtype=float)
    if method == 'routh':
        s1 = is_stable(z[:, None], w1[:, None], g[None, :], tie_rtol=tie_rtol)
        s2 = is_stable(z[:, None], w2[:, None], g[None, :], tie_rtol=tie_rtol)
    elif method == 'eig':
        s1, s2 = (np.linalg.eigvals(single_vessel_matrix(z[:, None], w[:, None], g[None, :]))
                  .real.max(axis=-1) < -tie_rtol * w[:, None] for w in (w1, w2))
    else:
        raise ValueError(f"method must be 'routh' or 'eig', got {method!r}")
    i1, i2 = first_stable_point(s1, s2)
    ok = i1 >= 0
    return np.where(ok, g[np.maximum(i1, 0)], np.nan), np.where(ok, g[np.maximum(i2, 0)], np.nan)


def appendix_a_scan(zeta, omega_n1, omega_n2, grid=TABLE1_GRID):
    """Appendix A literally for one row: max(real(eig(A))) of the full 6x6 matrix (eq. 42) at
    every (d1, d2) of the grid, V <= 0 counted as stable, first stable point in scan order.
    About 38 000 eigenvalue problems per row (vectorised); a reference for the fast methods and
    for the rounding-noise behaviour at grid points that lie exactly on a limit.
    Returns (d1_sim, d2_sim, V) with V the (n, n) array of max real parts."""
    g = matlab_colon(*grid) if isinstance(grid, tuple) else np.asarray(grid, dtype=float)
    n = g.size
    a = np.zeros((n, n, 6, 6))
    for i, (w, ds) in enumerate(((omega_n1, g[:, None]), (omega_n2, g[None, :]))):
        o = 3 * i
        a[..., o, o + 1] = 1.0
        a[..., o + 1, o] = -w * w
        a[..., o + 1, o + 1] = -2.0 * zeta * w
        a[..., o + 1, o + 2] = -w * w / ds
        a[..., o + 2, o] = 1.0
    a[..., 4, 2] = omega_n2 ** 2 / g[None, :]
    v = np.linalg.eigvals(a).real.max(axis=-1)
    i1, i2 = _scan_order(v <= 0.0)
    if i1 < 0:
        return np.nan, np.nan, v
    return g[i1], g[i2], v


def _scan_order(stable):
    """First True of a 2-D (d1, d2) array in row-major (scan) order, or (-1, -1)."""
    flat = stable.ravel()
    k = int(np.argmax(flat))
    if not flat[k]:
        return -1, -1
    return divmod(k, stable.shape[1])


def on_grid(value, grid=TABLE1_GRID, rtol=TIE_RTOL):
    """True where ``value`` coincides with a grid point (a tie with the scan's test)."""
    g = matlab_colon(*grid) if isinstance(grid, tuple) else np.asarray(grid, dtype=float)
    v = np.asarray(value, dtype=float)
    return np.min(np.abs(v[..., None] - g), axis=-1) <= rtol * np.abs(v)


#: Inferred, not printed: the (zeta, omega_n2/omega_n1) run of Table 1 whose printed minima
#: never go below 0.10 although the exact grid minimum does; every row of that run is
#: reproduced by a scan whose grid starts at 0.10 (see doc/string_stability.md).
TABLE1_RUN_LOWER_END = {(1.0, 1.5): 0.10}

#: Row classes of ``classify_table1``.
ROW_EXACT = 'exact'                    # printed = first grid point above the exact limit
ROW_TIE_D1 = 'd1_limit_on_grid'        # d1* is a grid point: noise decides, d2 pushed up
ROW_TIE_D2 = 'd2_limit_on_grid'        # only d2* is a grid point: d2* or the next point
ROW_LOWER_END = 'run_grid_starts_0.10'  # the run of TABLE1_RUN_LOWER_END, clamped at 0.10


def classify_table1(zeta, omega_n1, omega_n2, grid=TABLE1_GRID):
    """Class of each Table 1 row from the method of Appendix A, and the values it predicts.

    Returns (cls, lo1, hi1, lo2, hi2): the printed d1_sim must lie in [lo1, hi1] and d2_sim in
    [lo2, hi2] (equal bounds = one exact value; hi2 = inf: any grid point from lo2 up).
    - exact: the first grid point above d* (Routh, strict).
    - d1 limit on the grid: the marginal pair +-i omega_n1 has a real part that is pure
      rounding noise (~1e-16), so ``V <= 0`` accepts d1 = d1* at the first d2 whose full 6x6
      eig happens to round to <= 0; d1_sim = d1* and d2_sim is the first such d2 at or above
      the first stable (or marginal) d2: anywhere from there up.
    - only d2* on the grid: d1 exact; d2_sim = d2* (noise <= 0 there) or the next point.
    - the run with a 0.10 lower grid end: max(exact, 0.10).
    """
    z, w1, w2 = np.broadcast_arrays(*(np.atleast_1d(np.asarray(v, dtype=float))
                                      for v in (zeta, omega_n1, omega_n2)))
    g = matlab_colon(*grid) if isinstance(grid, tuple) else np.asarray(grid, dtype=float)
    step = g[1] - g[0]
    e1, e2 = grid_minima(z, w1, w2, g)
    m1, m2 = grid_minima(z, w1, w2, g, tie_rtol=-TIE_RTOL)   # ties counted as stable
    t1 = on_grid(nomoto_critical_lookahead(z, w1), g)
    t2 = on_grid(nomoto_critical_lookahead(z, w2), g)
    floor = np.array([TABLE1_RUN_LOWER_END.get((round(a, 6), round(c / b, 6)), -np.inf)
                      for a, b, c in zip(z, w1, w2)])
    cls = np.full(z.shape, ROW_EXACT, dtype=object)
    lo1, hi1 = np.maximum(e1, floor), np.maximum(e1, floor)
    lo2, hi2 = np.maximum(e2, floor), np.maximum(e2, floor)
    low = ~(t1 | t2) & ((e1 < floor) | (e2 < floor))
    cls[low] = ROW_LOWER_END
    only2 = t2 & ~t1
    cls[only2] = ROW_TIE_D2
    lo2[only2], hi2[only2] = m2[only2], m2[only2] + step
    cls[t1] = ROW_TIE_D1
    lo1[t1], hi1[t1] = m1[t1], m1[t1]
    lo2[t1], hi2[t1] = np.maximum(m2, floor)[t1], np.inf
    return cls, lo1, hi1, lo2, hi2


# ---------------------------------------------------------------- platoon validation

@dataclass(frozen=True)
class VesselLoop:
    """One vessel's steering loop as the stability test sees it.

    zeta, omega_n: the PD autopilot's design (001 eq. 20); omega_n in rad/s with ``speed`` in
    m/s and ``lookahead`` in m, or the seeds' non-dimensional form with speed = 1 (omega_n in
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


def check_platoon(vessels, margin=1.0):
    """Check every vessel of a platoon against its LOS stability limit (001 eq. 41).

    vessels: sequence of VesselLoop or mappings with its fields, leader first. margin >= 1
    demands lookahead > margin * limit. Returns one LookaheadCheck per vessel; the linearised
    string is stable iff all are ok with margin 1 (block-triangular structure, eq. 40)."""
    if not margin >= 1.0:
        raise ValueError(f'margin must be >= 1, got {margin}')
    out = []
    for i, v in enumerate(vessels):
        v = v if isinstance(v, VesselLoop) else VesselLoop(**v)
        crit = float(nomoto_critical_lookahead(v.zeta, v.omega_n, v.speed))
        lookahead = float(_pos(f'lookahead of vessel {i}', v.lookahead))
        ratio = lookahead / crit
        out.append(LookaheadCheck(i, v.name, lookahead, crit, ratio,
                                  bool(ratio > margin * (1.0 + TIE_RTOL))))
    return out


def unstable_vessels(vessels, margin=1.0):
    """The LookaheadChecks of the vessels at or below their limit (empty list: all fine)."""
    return [c for c in check_platoon(vessels, margin) if not c.ok]


# ---------------------------------------------------------------- sway/yaw level (seed 003)

@dataclass(frozen=True)
class SwayYawPlant:
    """Non-dimensional linear sway/yaw model (003 eqs. 2.8-2.9, unified rudder sign):
    v' = a11 v + a12 r + b1 delta,  r' = a21 v + a22 r + b2 delta."""
    a11: float
    a12: float
    a21: float
    a22: float
    b1: float
    b2: float


def sway_yaw_matrix(plant, k1, k2, lookahead):
    """003 eqs. 3.7-3.10: state (psi, v, r, y), delta = k1 (psi + y/d) + k2 r, y' = psi + v."""
    p, d = plant, float(lookahead)
    return np.array([[0.0, 0.0, 1.0, 0.0],
                     [k1 * p.b1, p.a11, p.a12 + k2 * p.b1, k1 * p.b1 / d],
                     [k1 * p.b2, p.a21, p.a22 + k2 * p.b2, k1 * p.b2 / d],
                     [1.0, 1.0, 0.0, 0.0]])


def sway_yaw_char_terms(plant, k1, k2):
    """Coefficients of 003 eq. 3.11, s^4 + B s^3 + (C1 + C2/d) s^2 + (D1 + D2/d) s + E/d,
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
    """Exact critical look-ahead of 003 Sec. III.B (ship lengths), broadcasting over k1, k2.

    With q = 1/d the quartic's Routh-Hurwitz determinant B C D - B^2 E - D^2 (003, A = 1) is the
    quadratic h0 + h1 q + h2 q^2; times d^2 it is 003 eq. 3.12 (alpha1 = h0, alpha2 = h1,
    alpha3 = h2). Stability for d -> infinity needs B > 0, E > 0 and h0 > 0; it is lost where
    the first of H(q) or C(q) = C1 + C2 q reaches zero as q grows from 0, so the critical
    distance is 1 / (smallest positive root) (0 if there is none: stable for every d > 0;
    NaN if the loop is unstable even for large d). This is the document's 'positive root'
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
    """The NPS AUV II of seed 003 (ship_sim.models.nps_auv2, bow/stern ratio -1), with optional
    overrides of its non-dimensional hydrodynamic coefficients (names as nps_auv2.COEFFS)."""
    from ship_sim.models.nps_auv2 import nondimensional_matrices
    return SwayYawPlant(*nondimensional_matrices(coeffs=coeffs))


def nps_auv2_nomoto(plant=None):
    """Non-dimensional first-order Nomoto (a, b) of 003 eq. 2.11 for ``plant``."""
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
    k1, k2 = pd_gains(a, b, np.asarray(zeta, float), np.asarray(omega_n, float))
    return sway_yaw_critical_lookahead(plant, k1, k2)


def nps_auv2_sensitivity(name, factors, zeta=0.8, omega_n=3.0, redesign=False):
    """003 Sec. III.C: d_n = d_crit(coefficient * factor) / d_crit(nominal) for each factor."""
    from ship_sim.models.nps_auv2 import COEFFS
    if name not in COEFFS:
        raise ValueError(f'unknown coefficient {name!r}; one of {sorted(COEFFS)}')
    nominal = float(nps_auv2_critical_lookahead(zeta, omega_n))
    return np.array([float(nps_auv2_critical_lookahead(
        zeta, omega_n, coeffs={name: COEFFS[name] * f}, redesign=redesign)) / nominal
        for f in np.atleast_1d(factors)])
