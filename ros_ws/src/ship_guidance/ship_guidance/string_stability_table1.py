"""Reproduction of Table 1 of Angelopoulos 2011 (Appendix A's eigenvalue grid scan, Appendix B).

For each omega_n1 the thesis scans d1 (outer loop) and d2 (inner loop) over 0.05:0.01:2,
computes max(real(eig(A))) of the 6x6 matrix of two vessels (eq. 42) and records the FIRST
point, in scan order, that is not unstable (``V > 0`` is unstable, so V <= 0 counts as stable).
Because stability factorises (string_stability: block lower triangular, eq. 40), that first
point is (first stable d1, first stable d2), each a scalar Routh test per grid point,
vectorised here over all rows and grid points (``grid_minima``); ``appendix_a_scan`` runs the
literal scan for one row. The look-aheads are in ship lengths, omega_n in units of U/L. See
doc/string_stability.md for the rows whose printed values differ from the exact boundary
(``classify_table1``).
"""
import numpy as np

from .los import critical_lookahead_nondim
from .string_stability import TIE_RTOL, is_stable, single_vessel_matrix

#: The thesis's look-ahead grid (Appendix A): start, step, stop.
TABLE1_GRID = (0.05, 0.01, 2.0)
#: The thesis's parameter sets (Sec. III.B.2): zeta, omega_n2/omega_n1, omega_n1.
TABLE1_ZETAS = (0.4, 0.6, 0.8, 1.0, 1.2)
TABLE1_RATIOS = (0.5, 1.0, 1.5)
TABLE1_OMEGA1 = (1.0, 0.1, 4.5)


def matlab_colon(start, step, stop):
    """``start:step:stop`` as MATLAB builds it (count from the rounded ratio, values computed
    symmetrically from both ends), so grid points carry the same rounding as the thesis's."""
    n = int(np.floor((stop - start) / step * (1.0 + 1e-12) + 1e-10))
    k = np.arange(n + 1)
    end = start + n * step
    return np.where(k < n / 2.0, start + k * step, end - (n - k) * step)


def table1_parameters():
    """(zeta, omega_n1, omega_n2) of every row Appendix A scans, in the thesis's order
    (zeta, then omega_n2/omega_n1, then omega_n1): 5 x 3 x 36 = 540 rows."""
    w1 = matlab_colon(*TABLE1_OMEGA1)
    z, p, w = np.meshgrid(TABLE1_ZETAS, TABLE1_RATIOS, w1, indexing='ij')
    return z.ravel(), w.ravel(), (p * w).ravel()


def first_stable_point(stable1, stable2):
    """Appendix A's bookkeeping, vectorised over rows: the first (d1, d2) grid index, in scan
    order (d1 outer, d2 inner), where both vessels are stable. stable1 (rows, n1), stable2
    (rows, n2) booleans -> (i1, i2) int arrays, -1 where no grid point is stable (the thesis
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
    the thesis's scan order (``first_stable_point``). ``grid`` is (start, step, stop) or an
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
    One eigenvalue problem per grid point (vectorised); a reference for the fast methods and
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
    t1 = on_grid(critical_lookahead_nondim(z, w1), g)
    t2 = on_grid(critical_lookahead_nondim(z, w2), g)
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
