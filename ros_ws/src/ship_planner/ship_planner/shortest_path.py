"""Baseline: the shortest collision-free path at the same clearance, for the length ratio.

Method (fine-grid Dijkstra with any-angle smoothing, then taut-string relaxation):

1. Dijkstra (scipy.sparse.csgraph) on the 8-connected graph of free cells (a diagonal step only
   when both cells beside it are free), start and goal joined to their cells: this picks the
   route's way around the islands (its homotopy class) to within the 8-neighbour metric's
   <= 8.2 % length error.
2. String pulling: from each kept point, jump to a far point of the path that is still visible
   (straight and clear), found by doubling then bisection.
3. Taut-string relaxation: repeatedly, every corner v between its neighbours u and w is replaced by
   the two points v + s (u - v), v + s (w - v) with the largest s in [0, 1] (bisection to 1/2^14)
   whose chord is clear, and redundant points are pulled out again, until the length changes by
   less than 1e-6 relative. Corners then sit on the corners of the clearance zone: the result is
   the locally shortest path in its homotopy class.

"Clear" is the planner's own test (ship_planner.chart.segments_clear: every cell a leg passes
through is free), so the baseline and the GA route obey the same constraint and the
baseline is itself a valid route. Its length exceeds the exact shortest path in the same class by
the bisection tolerance per corner (sub-metre); the class is the best one unless two ways around
differ by less than the grid metric error, which is why the planner also relaxes every
candidate route and keeps the shortest (``seeds``). On a circular island the result is within
0.3 % of the analytic tangent-arc-tangent length (tests/unit/test_chart_planner_baseline.py).
"""
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from ship_planner.chart import ChartError, segments_clear
from ship_sim.frames import wrap_angle


@dataclass
class ShortestPath:
    """The baseline path: (N, 2) NED points, length (m), total heading change (rad)."""
    points: np.ndarray
    length: float
    heading_change: float
    method: str


def polyline_length(points):
    p = np.asarray(points, dtype=float)
    return float(np.sum(np.hypot(*np.diff(p, axis=0).T)))


def heading_changes(points):
    """Course change (rad, + starboard) at each inner vertex of a polyline."""
    d = np.diff(np.asarray(points, dtype=float), axis=0)
    course = np.arctan2(d[:, 1], d[:, 0])
    return wrap_angle(np.diff(course))


def grid_path(chart, free, start, goal, cell_cost=None):
    """Dijkstra on the 8-connected free cells: (N, 2) polyline start -> cell centres -> goal, or
    None when the goal cannot be reached. cell_cost: optional (ny, nx) factor >= 1 on the length
    of every step, the mean of its two cells (to prefer some water over other)."""
    ny, nx = free.shape
    idx = np.full(free.shape, -1, dtype=np.int64)
    cells = np.flatnonzero(free.ravel())
    idx.ravel()[cells] = np.arange(len(cells))
    r = chart.resolution_m
    rows, cols, w = [], [], []
    for di, dj, cost in ((0, 1, r), (1, 0, r), (1, 1, r * np.sqrt(2.0)), (1, -1, r * np.sqrt(2.0))):
        # pairs (i, j) -> (i + di, j + dj), di >= 0, both inside the raster and free
        j_lo, j_hi = max(0, -dj), nx - max(0, dj)
        both = free[0:ny - di, j_lo:j_hi] & free[di:ny, j_lo + dj:j_hi + dj]
        i0, j0 = np.nonzero(both)
        j0 = j0 + j_lo
        i1, j1 = i0 + di, j0 + dj
        if di and dj:
            ok = free[i0 + di, j0] & free[i0, j0 + dj]
            i0, j0, i1, j1 = i0[ok], j0[ok], i1[ok], j1[ok]
        rows.append(idx[i0, j0])
        cols.append(idx[i1, j1])
        factor = 1.0 if cell_cost is None else 0.5 * (cell_cost[i0, j0] + cell_cost[i1, j1])
        w.append(np.full(len(i0), cost) * factor)
    rows, cols, w = (np.concatenate(v) for v in (rows, cols, w))
    graph = coo_matrix((w, (rows, cols)), shape=(len(cells), len(cells))).tocsr()
    si, sj, s_in = chart.cell_index(np.asarray(start, float))
    gi, gj, g_in = chart.cell_index(np.asarray(goal, float))
    if not (s_in and g_in and free[si, sj] and free[gi, gj]):
        raise ChartError('internal: start or goal cell is not free for the grid search')
    s, g = idx[si, sj], idx[gi, gj]
    dist, pred = dijkstra(graph, directed=False, indices=s, return_predecessors=True)
    if not np.isfinite(dist[g]):
        return None
    path = [g]
    while path[-1] != s:
        path.append(pred[path[-1]])
    flat = cells[np.array(path[::-1])]
    pts = chart.cell_centers(flat // nx, flat % nx)
    return np.vstack([start, pts, goal])


def _clear(chart, free, p, q):
    return bool(segments_clear(chart, free, p[None], q[None])[0])


def string_pull(chart, free, points):
    """Keep a subsequence of points whose consecutive chords are clear, jumping far ahead.
    Consecutive input points must see each other."""
    pts = np.asarray(points, dtype=float)
    out, i, n = [pts[0]], 0, len(pts)
    while i < n - 1:
        good, jump = i + 1, 1
        while good + jump < n and _clear(chart, free, pts[i], pts[good + jump]):
            good += jump
            jump *= 2
        lo, hi = good, min(good + jump, n)           # lo visible, hi (if < n) not
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if _clear(chart, free, pts[i], pts[mid]):
                lo = mid
            else:
                hi = mid
        out.append(pts[lo])
        i = lo
    return np.array(out)


def relax(chart, free, points, max_passes=200, rel_tol=1e-6, bisections=14):
    """Taut-string relaxation of a clear polyline (module docstring, step 3)."""
    pts = string_pull(chart, free, points)
    length = polyline_length(pts)
    for _ in range(max_passes):
        out = [pts[0]]
        for k in range(1, len(pts) - 1):
            u, v, w = out[-1], pts[k], pts[k + 1]
            if _clear(chart, free, u, w):
                continue
            lo, hi = 0.0, 1.0
            for _ in range(bisections):
                s = 0.5 * (lo + hi)
                if _clear(chart, free, v + s * (u - v), v + s * (w - v)):
                    lo = s
                else:
                    hi = s
            if lo > 0.0:
                out += [v + lo * (u - v), v + lo * (w - v)]
            else:
                out.append(v)
        out.append(pts[-1])
        pts = string_pull(chart, free, np.array(out))
        new_length = polyline_length(pts)
        if length - new_length <= rel_tol * length:
            length = new_length
            break
        length = new_length
    return pts


def wide_water_path(chart, free, start, goal, width_m, penalty=4.0):
    """The locally shortest clear path of the way around the islands that a grid search picks
    when steps closer than width_m (m, beyond the clearance zone) to the zone's edge cost
    (1 + penalty) times their length: a route that keeps to wide water where it can (a planner
    candidate for ships that need room to turn). None when unreachable."""
    near = ndimage.distance_transform_edt(free) * chart.resolution_m < width_m
    path = grid_path(chart, free, start, goal, cell_cost=1.0 + penalty * near)
    return None if path is None else relax(chart, free, path)


def shortest_path(chart, free, start, goal, seeds=()):
    """Shortest clear path from start to goal (module docstring). seeds: further clear polylines
    from start to goal (e.g. the candidate routes) whose homotopy classes are relaxed too."""
    start, goal = np.asarray(start, float), np.asarray(goal, float)
    if _clear(chart, free, start, goal):
        pts = np.array([start, goal])
        return ShortestPath(pts, polyline_length(pts), 0.0, 'straight line (start sees the goal)')
    tries = []
    grid = grid_path(chart, free, start, goal)
    if grid is not None:
        tries.append(grid)
    tries += [np.asarray(s, float) for s in seeds]
    if not tries:
        raise ChartError('no navigable connection between start and goal at this clearance')
    best = None
    for t in tries:
        p = relax(chart, free, t)
        if best is None or polyline_length(p) < polyline_length(best):
            best = p
    return ShortestPath(best, polyline_length(best), float(np.sum(np.abs(heading_changes(best)))),
                        '8-connected grid Dijkstra + string pulling + taut-string relaxation')
