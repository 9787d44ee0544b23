"""Adjacent convex polygons along a candidate route: the route choice becomes a choice of one
point on each crossing line.

After Lee 2004, Chapter 3 ("a dividing technique of adjacent convex polygons"); the construction
is ours (not legible in the source's OCR) and exact: stations along the pulled-straight
candidate, crossing lines through them to the edge of the free water (port end A, t = 0;
starboard end B, t = 1), and quadrilaterals between consecutive lines, shortened by bisection
until each is convex and clear. The waypoint on line k is A_k + t_k (B_k - A_k), t_k in [0, 1];
any choice of t gives straight legs that keep the clearance, since each leg lies in one convex
clear polygon. Units: NED metres.

The construction and its repair rules in full: ros_ws/src/ship_planner/doc/route_planning.md.
"""
from dataclasses import dataclass, field

import numpy as np

from ship_planner.chart import ChartError, segments_clear
from ship_planner.shortest_path import string_pull




@dataclass
class Corridor:
    """Crossing lines of one candidate route (all NED m).

    start, goal     fixed end points (2,)
    centres         (n, 2) stations (on the candidate centre line)
    port            (n, 2) unit vectors from each station towards the port end A
    ext_port, ext_stbd  (n,) extents of each line on either side of its station (m, >= 0)
    """
    start: np.ndarray
    goal: np.ndarray
    centres: np.ndarray
    port: np.ndarray
    ext_port: np.ndarray
    ext_stbd: np.ndarray
    repairs: int = 0
    candidate: np.ndarray = field(default=None, repr=False)

    @property
    def n(self):
        return len(self.centres)

    @property
    def ends(self):
        """(A, B): port and starboard ends of the crossing lines, (n, 2) each."""
        a = self.centres + self.ext_port[:, None] * self.port
        b = self.centres - self.ext_stbd[:, None] * self.port
        return a, b

    def centre_parameters(self):
        """t of each station on its line (the candidate route itself)."""
        width = self.ext_port + self.ext_stbd
        return np.where(width > 0.0, self.ext_port / np.where(width > 0.0, width, 1.0), 0.5)

    def waypoints(self, t):
        """(..., n) line parameters in [0, 1] -> (..., n, 2) waypoints."""
        a, b = self.ends
        t = np.asarray(t, dtype=float)[..., None]
        return a + t * (b - a)

    def polygons(self):
        """The adjacent convex polygons (list of (k, 2) vertex arrays), start to goal."""
        a, b = self.ends
        polys = [np.array([self.start, a[0], b[0]])]
        for k in range(self.n - 1):
            polys.append(np.array([a[k], a[k + 1], b[k + 1], b[k]]))
        polys.append(np.array([a[-1], self.goal, b[-1]]))
        return polys


def simplify(points, tol, chord_ok):
    """Douglas-Peucker simplification keeping a chord only when chord_ok(p, q) is True."""
    pts = np.asarray(points, dtype=float)
    keep = np.zeros(len(pts), dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, len(pts) - 1)]
    while stack:
        i, j = stack.pop()
        if j <= i + 1:
            continue
        p, q = pts[i], pts[j]
        d = q - p
        length = np.hypot(*d)
        inner = pts[i + 1:j]
        if length > 0.0:
            dev = np.abs(d[0] * (inner[:, 1] - p[1]) - d[1] * (inner[:, 0] - p[0])) / length
        else:
            dev = np.hypot(*(inner - p).T)
        if dev.max() <= tol and chord_ok(p, q):
            continue
        k = i + 1 + int(np.argmax(dev))
        keep[k] = True
        stack += [(i, k), (k, j)]
    return pts[keep]


def _ray_extents(chart, mask, centres, dirs, max_len):
    """Distance from each centre along its direction to the last sample before leaving mask."""
    step = 0.5 * chart.resolution_m
    s = np.arange(0.0, max_len + step, step)
    pts = centres[:, None, :] + s[None, :, None] * dirs[:, None, :]
    ok = chart.lookup(mask, pts)                           # (n, m)
    first_bad = np.where(ok.all(axis=1), len(s), np.argmin(ok, axis=1))
    return s[np.maximum(first_bad - 1, 0)]


def _cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _reflex_vertex(poly):
    """Index of a vertex that makes the polygon non-convex (or self-crossing), else None.
    Turns smaller than 1e-9 of the polygon's squared size count as straight."""
    m = len(poly)
    eps = 1e-9 * max(float(np.max(np.abs(poly - poly.mean(axis=0)))) ** 2, 1e-12)
    z = np.array([_cross(poly[i - 1], poly[i], poly[(i + 1) % m]) for i in range(m)])
    big = np.abs(z) > eps
    if not big.any():
        return None
    if (z[big] > 0).all() or (z[big] < 0).all():
        return None
    area = 0.5 * np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
    wrong = np.flatnonzero(big & (np.sign(z) != np.sign(area if area != 0.0 else z[big][0])))
    return int(wrong[0]) if len(wrong) else int(np.flatnonzero(big)[0])


def polygon_clear(chart, free, poly):
    """True when every cell the polygon overlaps is free: cells whose centres it covers, and the
    cells its edges pass through (exact traversal). Every point of the polygon then lies in a
    free cell, so it keeps the clearance (ship_planner.chart)."""
    from skimage.draw import polygon as fill

    poly = np.asarray(poly, dtype=float)
    closed = np.vstack([poly, poly[:1]])
    r = chart.resolution_m
    if not segments_clear(chart, free, closed[:-1], closed[1:]).all():
        return False
    rr, cc = fill((poly[:, 0] - chart.north0) / r, (poly[:, 1] - chart.east0) / r)
    ny, nx = chart.shape
    if len(rr) and (rr.min() < 0 or cc.min() < 0 or rr.max() >= ny or cc.max() >= nx):
        return False
    return bool(free[rr, cc].all())


def build_corridor(chart, free, candidate, spacing, max_half_width=None, simplify_tol=None):
    """Corridor of convex polygons along a candidate polyline (start ... goal), see module doc."""
    cand = np.asarray(candidate, dtype=float)
    r = chart.resolution_m
    if simplify_tol is None:
        simplify_tol = 2.0 * r
    if max_half_width is None:
        max_half_width = float(np.hypot(*(np.array(chart.extent()[1::2]) - np.array(chart.extent()[0::2]))))


    def chord_ok(p, q):
        return bool(segments_clear(chart, free, p[None], q[None])[0])

    verts = string_pull(chart, free, simplify(cand, simplify_tol, chord_ok))
    if not chord_ok(verts[0], verts[1]) and len(cand) > 2:
        raise ChartError('internal: the candidate route is not clear; cannot build its corridor')
    # stations: inner vertices, plus points in between at most `spacing` apart
    centres, dirs, dirs_in = [], [], None
    for k in range(len(verts) - 1):
        p, q = verts[k], verts[k + 1]
        d = q - p
        length = np.hypot(*d)
        if length == 0.0:
            continue
        u = d / length
        m = int(np.ceil(length / spacing))
        for i in range(m):
            if k == 0 and i == 0:
                continue                         # the start is fixed, not a station
            centres.append(p + (i / m) * d)
            if i == 0:
                b = dirs_in + u
                nb = np.hypot(*b)
                dirs.append(b / nb if nb > 1e-6 else u)
            else:
                dirs.append(u)
        dirs_in = u
    if not centres:
        # start sees the goal: one station in the middle keeps the problem well posed
        centres = [0.5 * (verts[0] + verts[-1])]
        d = verts[-1] - verts[0]
        dirs = [d / np.hypot(*d)]
    centres = np.array(centres)
    dirs = np.array(dirs)
    port = np.column_stack([dirs[:, 1], -dirs[:, 0]])        # port normal of a NED direction
    ext_p = _ray_extents(chart, free, centres, port, max_half_width)
    ext_s = _ray_extents(chart, free, centres, -port, max_half_width)
    cor = Corridor(cand[0].copy(), cand[-1].copy(), centres, port, ext_p, ext_s, candidate=cand)
    cor.repairs = _repair(chart, free, cor)
    return cor


def _polygon_state(chart, free, cor, k):
    """(port half clear?, starboard half clear?, reflex vertex or None) of polygon k.

    Polygon k joins line k-1 and line k (k = 0: start and line 0; k = n: line n-1 and goal); its
    halves lie either side of the chord between the stations (or start / goal)."""
    a, b = cor.ends
    c = cor.centres
    n = cor.n
    if k == 0:
        poly = np.array([cor.start, a[0], b[0]])
        halves = (np.array([cor.start, a[0], c[0]]), np.array([cor.start, c[0], b[0]]))
    elif k == n:
        poly = np.array([a[-1], cor.goal, b[-1]])
        halves = (np.array([c[-1], a[-1], cor.goal]), np.array([c[-1], cor.goal, b[-1]]))
    else:
        poly = np.array([a[k - 1], a[k], b[k], b[k - 1]])
        halves = (np.array([c[k - 1], a[k - 1], a[k], c[k]]), np.array([c[k - 1], c[k], b[k], b[k - 1]]))
    ok_port = polygon_clear(chart, free, halves[0])
    ok_stbd = polygon_clear(chart, free, halves[1])
    reflex = _reflex_vertex(poly)
    return ok_port, ok_stbd, reflex


def _largest(ok, hi, tol):
    """Largest value in [0, hi] for which ok(value) holds (bisection; ok(0) assumed), to tol."""
    if ok(hi):
        return hi
    lo = 0.0
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if ok(mid):
            lo = mid
        else:
            hi = mid
    return lo


def _repair(chart, free, cor):
    """Shorten crossing lines until every polygon is convex and clear (doc/route_planning.md, step 3).

    Polygon k joins line k-1 and line k; shortening line k-1 keeps polygon k-1 valid (it shrinks
    to a convex subset of itself). Returns the number of repairs."""
    n = cor.n
    tol = 0.25 * chart.resolution_m
    ext = {'p': cor.ext_port, 's': cor.ext_stbd}
    repairs = 0

    def state(k):
        return _polygon_state(chart, free, cor, k)

    def probe(side, j, value, test):
        old = ext[side][j]
        ext[side][j] = value
        good = test()
        ext[side][j] = old
        return good

    for k in range(n + 1):
        if 0 < k < n:
            repairs += _uncross(cor, k - 1, k)
        for h, side in ((0, 'p'), (1, 's')):
            def half_ok():
                return state(k)[h]
            if half_ok():
                continue
            arr = ext[side]
            lines = [j for j in (k - 1, k) if 0 <= j < n]
            repairs += 1
            if len(lines) == 2 and arr[lines[0]] != arr[lines[1]]:
                # shorten the longer extent, down to the shorter one at most
                j_long, j_short = (lines[0], lines[1]) if arr[lines[0]] > arr[lines[1]] else (lines[1], lines[0])
                floor = arr[j_short]
                if not probe(side, j_long, floor, half_ok):
                    arr[j_long] = floor
                else:
                    arr[j_long] = floor + _largest(lambda v: probe(side, j_long, floor + v, half_ok),
                                                   arr[j_long] - floor, tol)
                    continue
            # then both together (or the only line next to the start / goal)
            saved = {j: arr[j] for j in lines}

            def scaled(f):
                for j, v in saved.items():
                    arr[j] = f * v
                good = half_ok()
                for j, v in saved.items():
                    arr[j] = v
                return good
            f = _largest(scaled, 1.0, tol / max(max(saved.values()), tol))
            for j, v in saved.items():
                arr[j] = f * v
        for _ in range(8):
            if state(k)[2] is None:
                break
            repairs += 1
            lines = [j for j in (k - 1, k) if 0 <= j < n]

            def convex_ok():
                st = state(k)
                return st[0] and st[1] and st[2] is None
            # the single extent whose shortening (to the longest convex value) loses least
            best = None
            for side in 'ps':
                for j in lines:
                    full = ext[side][j]
                    if full == 0.0 or not probe(side, j, 0.0, convex_ok):
                        continue
                    v = _largest(lambda x: probe(side, j, x, convex_ok), full, tol)
                    if best is None or full - v < best[0]:
                        best = (full - v, side, j, v)
            if best is not None:
                ext[best[1]][best[2]] = best[3]
                break
            # else scale both lines of the polygon together
            saved = {(sd, j): ext[sd][j] for sd in 'ps' for j in lines}

            def scaled_ok(f):
                for (sd, j), v in saved.items():
                    ext[sd][j] = f * v
                good = convex_ok()
                for (sd, j), v in saved.items():
                    ext[sd][j] = v
                return good
            f = _largest(scaled_ok, 1.0, 1e-3)
            for (sd, j), v in saved.items():
                ext[sd][j] = f * v
    for k in range(n + 1):
        ok_p, ok_s, reflex = state(k)
        if not (ok_p and ok_s) or reflex is not None:
            raise ChartError(f'internal: corridor polygon {k} is not convex and clear after repair')
    return repairs


def _uncross(cor, i, j):
    """Shorten lines i and j where they cross each other (on the side where they converge) to
    98 % of the distance from each station to the crossing point. Returns 1 if they crossed."""
    a, b = cor.ends
    c, p = cor.centres, cor.port
    # c_i + s p_i = c_j + u p_j  ->  [p_i, -p_j] [s, u]^T = c_j - c_i
    m = np.array([[p[i][0], -p[j][0]], [p[i][1], -p[j][1]]])
    det = np.linalg.det(m)
    if abs(det) < 1e-12:
        return 0
    s_i, s_j = np.linalg.solve(m, c[j] - c[i])
    inside_i = -cor.ext_stbd[i] <= s_i <= cor.ext_port[i]
    inside_j = -cor.ext_stbd[j] <= s_j <= cor.ext_port[j]
    if not (inside_i and inside_j):
        return 0
    for k, sk in ((i, s_i), (j, s_j)):
        if sk >= 0.0:
            cor.ext_port[k] = min(cor.ext_port[k], 0.98 * sk)
        else:
            cor.ext_stbd[k] = min(cor.ext_stbd[k], -0.98 * sk)
    return 1
