"""Centre lines of the cruisable area (closing + thinning) and the graph of their branches.

Source: Lee 2004, Chapter 3 and abstract: "the closing technique makes the
rough coastal line smooth, the thinning technique offers the outline of the cruisable area, and
then a variety of routes are decided" (closing and thinning of the chart image, Figs. 3.7-3.10
show dilation and erosion). The equations are not legible in the OCR; the operators are the
standard ones (Gonzalez & Woods, Digital Image Processing, ch. 9):

- closing of the obstacle image (land + clearance zone) with a disc: fills coves and gaps
  narrower than the disc, so the centre lines get no side branches into every small bay.
  Closing the obstacles only ever removes free water, so the centre lines stay clear;
- thinning of the remaining free water to one-pixel 8-connected centre lines that keep its
  topology, one loop around every island (Zhang & Suen 1984, skimage.morphology.skeletonize);
- the centre-line pixels become a graph: pixels with other than two neighbours (ends, junctions;
  adjacent ones merged into one node) are nodes, the pixel chains between them are edges
  weighted by their length (m). Diagonal steps that duplicate a two-step 4-connected path are
  dropped first so a staircase does not look like a junction.

Candidate routes come from the shortest simple paths (Yen's algorithm, networkx) between start
and goal in that branch graph, which differ in at least one branch, i.e. pass islands on
different sides: up to ``max_paths_examined`` of them no longer than ``max_length_ratio`` times
the shortest are pulled straight where the water allows (string pulling on clear chords; the
medial axis wanders far into open water, so its own length ranks routes badly) and the k shortest
after pulling are kept. Start and goal join the graph by straight clear segments to the nearest visible
centre-line pixel in each of eight 45-degree sectors around them; candidates whose polylines
stay within ``min_separation`` (discrete Hausdorff distance; default the larger of 5 cells and 3 %
of the shortest candidate's length) of a shorter one are the same route and are dropped. Units:
metres; points are (north, east) in the chart's frame.
"""
from dataclasses import dataclass

import networkx as nx
import numpy as np
from scipy import ndimage

from ship_planner.chart import segments_clear
from ship_planner.shortest_path import string_pull

_NEIGHBOURS = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)]


def disc(radius_cells):
    """Disc structuring element of the given radius (cells)."""
    r = int(max(0, round(radius_cells)))
    y, x = np.mgrid[-r:r + 1, -r:r + 1]
    return x * x + y * y <= r * r + 1e-9


def close_obstacles(free, radius_cells):
    """Free water after a morphological closing of the obstacles (free stays a subset of free).

    The border is padded with the edge values first so the closing does not eat the raster edge."""
    r = int(max(0, round(radius_cells)))
    if r == 0:
        return free.copy()
    blocked = np.pad(~free, r + 1, mode='edge')
    closed = ndimage.binary_closing(blocked, structure=disc(r))[r + 1:-r - 1, r + 1:-r - 1]
    return free & ~closed


def centre_lines(free, closing_radius_cells):
    """(closed free water, its thinned centre lines) as bool images (Zhang-Suen thinning)."""
    from skimage.morphology import skeletonize

    closed = close_obstacles(free, closing_radius_cells)
    return closed, skeletonize(closed, method='zhang')


@dataclass
class BranchGraph:
    """The centre-line graph: node ids are ints; every edge carries 'length' (m) and 'points'
    ((K, 2) NED polyline from its lower-id node to its higher-id node). Node 'pos' is a point."""
    graph: nx.Graph
    start: int = None
    goal: int = None


def _pixel_adjacency(skel):
    """Sparse neighbour lists of skeleton pixels, redundant diagonals removed.

    Returns (pixels (M, 2) int, index image (-1 off skeleton), list of neighbour index arrays)."""
    pixels = np.argwhere(skel)
    index = np.full(skel.shape, -1, dtype=np.int64)
    index[pixels[:, 0], pixels[:, 1]] = np.arange(len(pixels))
    pad = np.pad(index, 1, constant_values=-1)
    r, c = pixels[:, 0] + 1, pixels[:, 1] + 1
    nbr = np.stack([pad[r + di, c + dj] for di, dj in _NEIGHBOURS], axis=1)     # (M, 8)
    for k, (di, dj) in enumerate(_NEIGHBOURS):
        if di != 0 and dj != 0:
            # a diagonal step is redundant when a 4-neighbour path of two steps joins the same pixels
            redundant = (pad[r + di, c] >= 0) | (pad[r, c + dj] >= 0)
            nbr[redundant, k] = -1
    return pixels, index, [row[row >= 0] for row in nbr]


def build_branch_graph(skel, chart, forced=()):
    """Branch graph of a thinned image. forced: pixel indices (i, j) that must be nodes (where the
    start and goal attach). Returns (BranchGraph without start/goal, {forced pixel: node id})."""
    pixels, index, nbrs = _pixel_adjacency(skel)
    m = len(pixels)
    degree = np.array([len(n) for n in nbrs], dtype=int)
    is_node = degree != 2
    forced_idx = [int(index[i, j]) for i, j in forced if index[i, j] >= 0]
    is_node[forced_idx] = True
    pts = chart.cell_centers(pixels[:, 0], pixels[:, 1]) if m else np.zeros((0, 2))

    # merge touching node pixels into one node (a junction may be a few pixels)
    node_of = np.full(m, -1, dtype=np.int64)
    n_nodes = 0
    for p in np.flatnonzero(is_node):
        if node_of[p] >= 0:
            continue
        stack, node_of[p] = [p], n_nodes
        while stack:
            q = stack.pop()
            for s in nbrs[q]:
                if is_node[s] and node_of[s] < 0:
                    node_of[s] = n_nodes
                    stack.append(s)
        n_nodes += 1

    g = nx.Graph()
    for k in range(n_nodes):
        members = np.flatnonzero(node_of == k)
        g.add_node(k, pos=pts[members].mean(axis=0), pixels=members)

    def add_edge(a, b, chain):
        poly = pts[chain]
        length = float(np.sum(np.hypot(*np.diff(poly, axis=0).T)))
        if a == b or g.has_edge(a, b):
            # a loop or a second chain between the same nodes: split it with a node in its middle
            # (simple graphs keep one edge per pair; the split keeps both routes)
            if len(chain) < 3:
                return
            mid = len(chain) // 2
            k = g.number_of_nodes()
            g.add_node(k, pos=pts[chain[mid]], pixels=np.array([chain[mid]]))
            add_edge(a, k, chain[:mid + 1])
            add_edge(k, b, chain[mid:])
            return
        if a > b:
            a, b, poly = b, a, poly[::-1]
        g.add_edge(a, b, length=max(length, 1e-9), points=poly)

    visited = np.zeros(m, dtype=bool)
    for p in np.flatnonzero(is_node):
        for s in nbrs[p]:
            if is_node[s]:
                if node_of[s] != node_of[p] and not g.has_edge(node_of[p], node_of[s]):
                    add_edge(int(node_of[p]), int(node_of[s]), [p, s])
                continue
            if visited[s]:
                continue
            chain, prev, cur = [p, s], p, s
            while not is_node[cur]:
                visited[cur] = True
                nxt = [q for q in nbrs[cur] if q != prev and (len(chain) < 3 or q != chain[-3])]
                if not nxt:
                    break                           # a dangling end that thinning left with degree 2
                prev, cur = cur, nxt[0]
                chain.append(cur)
                if visited[cur] and not is_node[cur]:
                    break
            if is_node[cur]:
                add_edge(int(node_of[p]), int(node_of[cur]), chain)
    # closed loops without any node (an island ringed by water and nothing else): one node each
    for p in np.flatnonzero(~visited & ~is_node):
        if visited[p]:
            continue
        k = g.number_of_nodes()
        g.add_node(k, pos=pts[p], pixels=np.array([p]))
        node_of[p] = k
        visited[p] = True
        chain, prev, cur = [p], p, p
        while True:
            nxt = [q for q in nbrs[cur] if q != prev and not (visited[q] and q != p)]
            if not nxt:
                break
            prev, cur = cur, nxt[0]
            chain.append(cur)
            if cur == p:
                break
            visited[cur] = True
        if len(chain) > 3 and chain[-1] == p:
            add_edge(k, k, chain)
    attach = {tuple(map(int, pixels[i])): int(node_of[i]) for i in forced_idx}
    return BranchGraph(g), attach


def visible_attachments(point, skel, free, chart, sectors=8, max_checks=400):
    """Skeleton pixels (i, j) seen from point along straight clear segments: the nearest visible
    one in each of `sectors` equal angular sectors around the point."""
    pix = np.argwhere(skel)
    if len(pix) == 0:
        return []
    pts = chart.cell_centers(pix[:, 0], pix[:, 1])
    d = pts - np.asarray(point, dtype=float)
    dist = np.hypot(d[:, 0], d[:, 1])
    sector = ((np.arctan2(d[:, 1], d[:, 0]) + np.pi) / (2.0 * np.pi) * sectors).astype(int) % sectors
    found = {}
    order = np.argsort(dist, kind='stable')
    # check in batches, nearest first, until every sector has one or the budget is spent
    checked = 0
    for start in range(0, len(order), 64):
        batch = order[start:start + 64]
        batch = batch[[sector[b] not in found for b in batch]]
        if len(batch) == 0:
            continue
        ok = segments_clear(chart, free, np.repeat(np.asarray(point, float)[None], len(batch), 0), pts[batch])
        for b, clear in zip(batch, ok):
            if clear and sector[b] not in found:
                found[sector[b]] = tuple(map(int, pix[b]))
        checked += len(batch)
        if len(found) == sectors or checked >= max_checks:
            break
    return list(found.values())


def hausdorff(a, b):
    """Discrete Hausdorff distance (m) between two polylines' vertices (densified by the caller)."""
    from scipy.spatial import cKDTree

    da = cKDTree(b).query(a)[0].max()
    db = cKDTree(a).query(b)[0].max()
    return float(max(da, db))


def densify(poly, step):
    """Points along a polyline no further apart than step."""
    poly = np.asarray(poly, dtype=float)
    d = np.diff(poly, axis=0)
    n = np.maximum(1, np.ceil(np.hypot(d[:, 0], d[:, 1]) / step).astype(np.int64))
    seg = np.repeat(np.arange(len(d)), n)
    first = np.concatenate([[0], np.cumsum(n)[:-1]])
    t = (np.arange(n.sum()) - first[seg] + 1) / n[seg]
    return np.vstack([poly[:1], poly[seg] + t[:, None] * d[seg]])


def candidate_routes(chart, free, start, goal, k=3, closing_radius_cells=2, min_separation=None,
                     max_length_ratio=1.6, max_paths_examined=40):
    """Up to k distinct centre-line routes from start to goal (NED m) through the free mask.

    Returns (list of (N, 2) polylines beginning at start and ending at goal, shortest first;
    closed free image; skeleton image). The closing is skipped when it would cut start from goal.
    """
    start, goal = np.asarray(start, float), np.asarray(goal, float)
    auto_separation = min_separation is None
    for radius in ([closing_radius_cells, 0] if closing_radius_cells > 0 else [0]):
        closed, skel = centre_lines(free, radius)
        att_s = visible_attachments(start, skel, free, chart)
        att_g = visible_attachments(goal, skel, free, chart)
        if not att_s or not att_g:
            continue
        bg, attach = build_branch_graph(skel, chart, forced=att_s + att_g)
        g = bg.graph
        s_node, g_node = g.number_of_nodes(), g.number_of_nodes() + 1
        g.add_node(s_node, pos=start)
        g.add_node(g_node, pos=goal)
        for node, pt, atts in ((s_node, start, att_s), (g_node, goal, att_g)):
            for a in atts:
                other = attach[a]
                q = chart.cell_centers(*a)          # the pixel the segment was checked to
                if not g.has_edge(node, other):
                    poly = np.array([pt, q]) if node < other else np.array([q, pt])
                    g.add_edge(node, other, length=float(np.hypot(*(q - pt))) + 1e-9, points=poly)
        if not nx.has_path(g, s_node, g_node):
            continue
        examined, shortest = [], None
        for n_seen, path in enumerate(nx.shortest_simple_paths(g, s_node, g_node, weight='length')):
            poly = _path_polyline(g, path)
            length = float(np.sum(np.hypot(*np.diff(poly, axis=0).T)))
            if shortest is None:
                shortest = length
            if length > max_length_ratio * shortest or n_seen >= max_paths_examined:
                break
            pulled = string_pull(chart, free, poly)
            examined.append((float(np.sum(np.hypot(*np.diff(pulled, axis=0).T))), n_seen, poly, pulled))
        if auto_separation and examined:
            min_separation = max(5.0 * chart.resolution_m, 0.03 * min(e[0] for e in examined))
        routes, kept = [], []
        step = 2.0 * chart.resolution_m
        for _, _, poly, pulled in sorted(examined, key=lambda e: (e[0], e[1])):
            dense = densify(pulled, step)
            if all(hausdorff(dense, other) >= min_separation for other in kept):
                routes.append(poly)
                kept.append(dense)
                if len(routes) >= k:
                    break
        if routes:
            return routes, closed, skel
    return [], free, np.zeros_like(free)


def _path_polyline(g, path):
    """Concatenated edge polylines of a node path, oriented along the path, duplicates dropped."""
    pieces = []
    for a, b in zip(path[:-1], path[1:]):
        pts = g.edges[a, b]['points']
        pieces.append(pts if a < b else pts[::-1])
    poly = np.concatenate(pieces)
    keep = np.ones(len(poly), dtype=bool)
    keep[1:] = np.hypot(*np.diff(poly, axis=0).T) > 1e-9
    return poly[keep]
