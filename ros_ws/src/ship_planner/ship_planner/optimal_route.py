"""Optimal route on a chart: candidates from the centre lines, convex corridors, GA waypoints,
fillets for the vessel, and the shortest path for comparison.

After Lee 2004, Chapter 3: candidate routes from the closed and thinned chart, adjacent convex
polygons that turn the choice of route into a choice of one point per crossing line, and a
real-coded GA trading sailed distance against turning; Chapter 4 rounds the corners with the
ship's turning circle. The cost is ours, J = S + w E + 10 (F + res N_bad): S the length sailed
with filleted corners, E the total course change (rad) weighted by ``energy_weight`` (m/rad,
the extra sailing a turn costs in lost speed), F the fillet overlap on short legs and N_bad the
arc samples off the eroded free mask. Units: NED metres, radians.

The pipeline step by step, the cost's terms and the default weight's derivation:
ros_ws/src/ship_planner/doc/route_planning.md.
"""
import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from ship_planner import ga
from ship_planner.chart import ChartError, segments_clear
from ship_planner.corridor import build_corridor
from ship_planner.fillets import ArcSpec, LineSpec, fillet_corner, fillet_polyline, segments_to_route
from ship_planner.shortest_path import heading_changes, polyline_length, shortest_path, string_pull, wide_water_path
from ship_planner.skeleton_graph import candidate_routes, densify, hausdorff
from ship_sim.frames import wrap_angle

#: Default turning-energy weight (m of sailing per rad of course change), see doc/route_planning.md.
DEFAULT_ENERGY_WEIGHT = 160.0
_PENALTY = 10.0
_STRAIGHT_DEG = 0.2
_ARC_SAMPLES_MAX = 96


@dataclass
class PlannerConfig:
    """Planner settings (metres, radians). Defaults suit a Mariner-sized ship on a 50-100 m chart."""
    clearance_m: float = 100.0
    fillet_radius_m: float = 0.0            # 0: sharp corners
    min_fillet_radius_m: float = None       # smallest radius a corner may fall back to (default R / 2)
    energy_weight: float = DEFAULT_ENERGY_WEIGHT
    candidates: int = 3
    closing_radius_m: float = None          # default 2 cells
    max_length_ratio: float = 1.6           # candidates longer than this times the shortest are skipped
    max_lines: int = 16                     # crossing lines per candidate (GA genes)
    min_spacing_cells: float = 4.0
    max_half_width_m: float = None
    population: int = 80
    generations: int = 400
    stall_generations: int = 80
    seed: int = 1
    refine: bool = True                     # coordinate pattern search on the GA's best (ga.refine)
    path_candidates: bool = True            # shortest-path and wide-water classes as candidates too


@dataclass
class PlannedRoute:
    """The planned route and what it was chosen from."""
    waypoints: np.ndarray                   # (N, 2) NED m, start and goal included
    radii: np.ndarray                       # (N - 2,) fillet radius per corner (m)
    segments: list                          # LineSpec / ArcSpec, ready for segments_to_route
    length: float                           # sailed length with fillets (m)
    polyline_length: float                  # length through the waypoints (m)
    heading_change: float                   # sum |course change| (rad)
    cost: float
    candidates: list                        # candidate polylines
    chosen: int                             # index of the winning candidate
    corridors: list
    ga_results: list
    shortest: object                        # shortest_path.ShortestPath
    closed: np.ndarray = field(repr=False, default=None)
    skeleton: np.ndarray = field(repr=False, default=None)
    timings: dict = field(default_factory=dict)
    config: PlannerConfig = None
    origins: list = None                    # where each candidate comes from

    @property
    def length_ratio(self):
        return self.length / self.shortest.length

    def route(self):
        """ship_guidance.path.Route (NED) of the filleted route."""
        return segments_to_route(self.segments)


# ---- checks ----------------------------------------------------------------------------------
def check_endpoint(chart, free, clearance, point, what):
    """ChartError unless point is inside the chart, on water and outside the clearance zone."""
    p = np.asarray(point, dtype=float)
    if p.shape != (2,) or not np.all(np.isfinite(p)):
        raise ChartError(f'{what} must be a finite (north, east) point, got {point!r}')
    i, j, inside = chart.cell_index(p)
    desc = chart.describe_point(p)
    if not inside:
        n0, n1, e0, e1 = chart.extent()
        raise ChartError(f'{what} {desc} is outside the chart (north {n0:.0f}..{n1:.0f} m, east {e0:.0f}..{e1:.0f} m): '
                         'enlarge the box or move the point')
    if not chart.water[i, j]:
        raise ChartError(f'{what} {desc} is on land: move it into open water')
    if not free[i, j]:
        d = float(chart.distance_to_land()[i, j])
        need = clearance + chart.grid_margin
        lower = d - chart.grid_margin
        fix = (f'or lower the clearance to {math.floor(lower):.0f} m or less' if lower >= 1.0 else
               f'or use a finer resolution (the grid margin is {chart.grid_margin:.0f} m at '
               f'{chart.resolution_m:g} m cells)')
        raise ChartError(f'{what} {desc} is {d:.0f} m from land, inside the clearance of {clearance:g} m '
                         f'(+ {chart.grid_margin:.0f} m grid margin): move it at least {need - d:.0f} m further '
                         f'from land, {fix}')


def check_connected(chart, free, start, goal, clearance):
    """ChartError when start and goal lie in different free areas (4-connected)."""
    labels, count = ndimage.label(free)
    si, sj, _ = chart.cell_index(start)
    gi, gj, _ = chart.cell_index(goal)
    if labels[si, sj] != labels[gi, gj]:
        area = chart.resolution_m ** 2 / 1e6
        a_s = np.count_nonzero(labels == labels[si, sj]) * area
        a_g = np.count_nonzero(labels == labels[gi, gj]) * area
        raise ChartError(f'no navigable connection between start and goal at a clearance of {clearance:g} m: the free '
                         f'water splits into {count} separate areas (start in one of {a_s:.2f} km2, goal in one of '
                         f'{a_g:.2f} km2); lower the clearance, use a finer resolution, or enlarge the box')


def arc_points(center, radius, theta0, sweep, samples):
    """(..., samples, 2) points on arcs: centre + R (cos, sin)(theta0 + s sweep), s in [0, 1]."""
    s = np.linspace(0.0, 1.0, samples)
    th = theta0[..., None] + s * sweep[..., None]
    r = np.asarray(radius, dtype=float)[..., None] if np.ndim(radius) else radius
    return np.stack([center[..., 0, None] + r * np.cos(th), center[..., 1, None] + r * np.sin(th)], axis=-1)


def _corner_geometry(pts, radius):
    """Per-corner fillet geometry of polylines pts (..., N, 2) for radius (scalar or (..., N-2)).

    Returns legs (..., N-1), delta (..., N-2) course changes, tau tangent lengths, centres
    (..., N-2, 2), theta0 polar angles of the arc starts."""
    d = np.diff(pts, axis=-2)
    legs = np.maximum(np.hypot(d[..., 0], d[..., 1]), 1e-9)
    u = d / legs[..., None]
    course = np.arctan2(u[..., 1], u[..., 0])
    delta = wrap_angle(np.diff(course, axis=-1))
    a = np.minimum(np.abs(delta), np.pi - 1e-3)
    tau = radius * np.tan(0.5 * a)
    u_in = u[..., :-1, :]
    stbd = np.stack([-u_in[..., 1], u_in[..., 0]], axis=-1)
    corner = pts[..., 1:-1, :]
    entry = corner - tau[..., None] * u_in
    centre = entry + (np.sign(delta) * radius)[..., None] * stbd
    theta0 = np.arctan2(entry[..., 1] - centre[..., 1], entry[..., 0] - centre[..., 0])
    return legs, delta, tau, centre, theta0


def route_cost(pts, chart, arc_mask, radius, weight):
    """J of polylines pts (P, N, 2) (doc/route_planning.md); returns (J, S, E, F, N_bad). arc_mask: the
    free mask eroded by one cell, so that arc samples half a cell apart that pass here also pass
    the exact check of the final route."""
    legs, delta, tau, centre, theta0 = _corner_geometry(pts, radius)
    a = np.abs(delta)
    energy = a.sum(axis=-1)
    if radius > 0.0 and delta.shape[-1] > 0:
        t_prev = np.concatenate([np.zeros(tau.shape[:-1] + (1,)), tau], axis=-1)
        t_next = np.concatenate([tau, np.zeros(tau.shape[:-1] + (1,))], axis=-1)
        overlap = np.maximum(t_prev + t_next - legs, 0.0).sum(axis=-1)
        sailed = legs.sum(axis=-1) - (2.0 * tau - radius * a).sum(axis=-1)
        # a fixed number of samples per arc (half a cell apart on a 90 deg turn), the same for every
        # call, so that an individual's cost does not depend on the rest of the population
        n_s = int(min(_ARC_SAMPLES_MAX, max(8, math.ceil(0.5 * math.pi * radius / (0.5 * chart.resolution_m)) + 1)))
        arcs = arc_points(centre, radius, theta0, delta, n_s)          # (P, N-2, n_s, 2)
        bad = (~chart.lookup(arc_mask, arcs)).sum(axis=(-1, -2))
    else:
        overlap = np.zeros(legs.shape[:-1])
        sailed = legs.sum(axis=-1)
        bad = np.zeros(legs.shape[:-1])
    j = sailed + weight * energy + _PENALTY * (overlap + chart.resolution_m * bad)
    return j, sailed, energy, overlap, bad


def cost_parts(cor, t, chart, arc_mask, radius, weight):
    """The terms of J for one individual t of corridor cor (for reports)."""
    pts = np.vstack([cor.start, cor.waypoints(t), cor.goal])[None]
    j, sailed, energy, overlap, bad = route_cost(pts, chart, arc_mask, radius, weight)
    return {'cost': float(j[0]), 'sailed_m': float(sailed[0]), 'turning_rad': float(energy[0]),
            'fillet_overlap_m': float(overlap[0]), 'arc_samples_off': float(bad[0])}


# ---- final route ----------------------------------------------------------------------------
def segments_clear_on(chart, free, segments):
    """True when every line and arc of the route keeps to the free mask (arcs as half-cell chords)."""
    for seg in segments:
        if isinstance(seg, LineSpec):
            if not segments_clear(chart, free, np.array(seg.start)[None], np.array(seg.end)[None])[0]:
                return False
        else:
            c = np.array(seg.center)
            r = float(np.hypot(*(np.array(seg.start) - c)))
            t0 = math.atan2(seg.start[1] - c[1], seg.start[0] - c[0])
            t1 = math.atan2(seg.end[1] - c[1], seg.end[0] - c[0])
            sweep = (t1 - t0) % (2 * math.pi) if seg.clockwise else -((t0 - t1) % (2 * math.pi))
            n = max(2, int(math.ceil(abs(sweep) * r / chart.sample_step)) + 1)
            pts = arc_points(c[None], np.array([r]), np.array([t0]), np.array([sweep]), n)[0]
            if not segments_clear(chart, free, pts[:-1], pts[1:]).all():
                return False
    return True


def drop_straight_points(chart, free, pts, tol_rad=math.radians(_STRAIGHT_DEG)):
    """Remove inner waypoints where the course hardly changes, when the merged leg is clear."""
    pts = [np.asarray(p, float) for p in pts]
    changed = True
    while changed and len(pts) > 2:
        changed = False
        dl = np.abs(heading_changes(np.array(pts)))
        for k in np.argsort(dl):
            if dl[k] >= tol_rad:
                break
            a, b = pts[k], pts[k + 2]
            if segments_clear(chart, free, a[None], b[None])[0]:
                del pts[k + 1]
                changed = True
                break
    return np.array(pts)


def fit_fillets(chart, free, pts, radius, min_radius, slack=0.5):
    """Per-corner radii, start to goal: radius where it fits and keeps the clearance, else the
    largest that does (>= min_radius, bisection to 1 m), each corner leaving what is left of its
    legs to the next. slack (m) of every leg stays straight so rounding in a route file cannot
    make a fillet overflow. Returns (radii, segments); ChartError when a corner cannot take even
    min_radius."""
    n_corner = len(pts) - 2
    radii = np.zeros(n_corner)
    if n_corner == 0:
        return radii, [LineSpec(tuple(pts[0]), tuple(pts[1]), 'leg 1')]
    if radius <= 0.0:
        return radii, fillet_polyline(pts, 0.0)
    legs = np.hypot(*np.diff(pts, axis=0).T)
    taken = np.zeros(n_corner)

    def fits(k, r):
        try:
            f = fillet_corner(pts[k], pts[k + 1], pts[k + 2], r)
        except ValueError:
            return False, 0.0
        if f is None:
            return True, 0.0
        before = taken[k - 1] if k > 0 else 0.0
        if before + f.tangent_length > legs[k] - slack or f.tangent_length > legs[k + 1] - slack:
            return False, f.tangent_length
        arc = ArcSpec(f.entry, f.exit, f.center, f.clockwise)
        return segments_clear_on(chart, free, [arc]), f.tangent_length

    for k in range(n_corner):
        ok, t = fits(k, radius)
        if ok:
            radii[k], taken[k] = radius, t
            continue
        ok, _ = fits(k, min_radius)
        if not ok:
            p = chart.describe_point(pts[k + 1])
            raise ChartError(f'the turn at waypoint {k + 1} ({p}) cannot be rounded with a radius of {min_radius:g} m '
                             'or more within its legs and the clearance; lower the clearance or the minimum turning '
                             'radius, or use a finer resolution')
        lo, hi = min_radius, radius
        while hi - lo > 1.0:
            mid = 0.5 * (lo + hi)
            if fits(k, mid)[0]:
                lo = mid
            else:
                hi = mid
        radii[k] = lo
        taken[k] = fits(k, lo)[1]
    return radii, fillet_polyline(pts, radii)


def sailed_length(segments):
    return float(sum(segments_to_route([s]).length for s in segments))


# ---- the planner ----------------------------------------------------------------------------
def plan_route(chart, start, goal, config=None, progress=None):
    """Plan the optimal route from start to goal (NED m) on chart. Returns a PlannedRoute."""
    cfg = config or PlannerConfig()
    say = progress or (lambda text: None)
    times = {}
    t0 = time.perf_counter()
    if not (np.isfinite(cfg.clearance_m) and cfg.clearance_m >= 0.0):
        raise ChartError(f'clearance must be >= 0 m, got {cfg.clearance_m}')
    if not (np.isfinite(cfg.fillet_radius_m) and cfg.fillet_radius_m >= 0.0):
        raise ChartError(f'fillet radius must be >= 0 m, got {cfg.fillet_radius_m}')
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    free = chart.free_mask(cfg.clearance_m)
    check_endpoint(chart, free, cfg.clearance_m, start, 'start')
    check_endpoint(chart, free, cfg.clearance_m, goal, 'goal')
    if np.hypot(*(goal - start)) < chart.resolution_m:
        raise ChartError('start and goal are less than one chart cell apart; there is no route to plan')
    check_connected(chart, free, start, goal, cfg.clearance_m)
    times['checks'] = time.perf_counter() - t0

    t = time.perf_counter()
    closing = 2.0 if cfg.closing_radius_m is None else cfg.closing_radius_m / chart.resolution_m
    skel_cands, closed, skel = candidate_routes(chart, free, start, goal, k=cfg.candidates,
                                                closing_radius_cells=closing, max_length_ratio=cfg.max_length_ratio)
    times['candidates'] = time.perf_counter() - t
    t = time.perf_counter()
    base = shortest_path(chart, free, start, goal, seeds=skel_cands)
    times['shortest_path'] = time.perf_counter() - t
    # the shortest path's way around the islands is a candidate too, and (for a ship that needs
    # room to turn) the ways that keep to wide water, unless a candidate already follows them
    sep = max(5.0 * chart.resolution_m, 0.03 * base.length)
    step = 2.0 * chart.resolution_m
    cands, origins, kept = [], [], []

    def add(path, origin):
        dense = densify(string_pull(chart, free, path), step)
        if all(hausdorff(dense, other) >= sep for other in kept):
            cands.append(path)
            origins.append(origin)
            kept.append(dense)

    if cfg.path_candidates:
        add(base.points, 'shortest-path class')
    if cfg.path_candidates and cfg.fillet_radius_m > 0.0:
        for width in (0.5 * cfg.fillet_radius_m, cfg.fillet_radius_m):
            wide = wide_water_path(chart, free, start, goal, width)
            if wide is not None:
                add(wide, f'wide water ({width:.0f} m)')
    for c in skel_cands:
        add(c, 'centre line')
    if not cands:
        raise ChartError('no candidate route along the centre lines of the free water joins start and goal; move '
                         'them into wider water, lower the clearance or use a finer resolution')
    say(f'plan: {len(cands)} candidate route(s) (' + ', '.join(
        f'{o} {polyline_length(string_pull(chart, free, c)) / 1e3:.2f} km' for o, c in zip(origins, cands)) + ')')

    radius = float(cfg.fillet_radius_m)
    min_radius = radius / 2.0 if cfg.min_fillet_radius_m is None else float(cfg.min_fillet_radius_m)
    corridors, results, best = [], [], None
    arc_mask = ndimage.binary_erosion(free, structure=np.ones((3, 3), dtype=bool), border_value=0)
    t = time.perf_counter()
    for ci, cand in enumerate(cands):
        spacing = max(cfg.min_spacing_cells * chart.resolution_m, polyline_length(cand) / cfg.max_lines)
        cor = build_corridor(chart, free, cand, spacing, cfg.max_half_width_m)
        corridors.append(cor)

        def cost(tt, cor=cor):
            w = cor.waypoints(tt)
            pts = np.concatenate([np.broadcast_to(cor.start, (len(tt), 1, 2)), w,
                                  np.broadcast_to(cor.goal, (len(tt), 1, 2))], axis=1)
            return route_cost(pts, chart, arc_mask, radius, cfg.energy_weight)[0]

        def report(g, c, ci=ci):
            say(f'plan: candidate {ci + 1}/{len(cands)}: generation {g}, best cost {c:.1f}')

        res = ga.minimize(cost, cor.n, population=cfg.population, generations=cfg.generations,
                          stall_generations=cfg.stall_generations, initial=cor.centre_parameters()[None],
                          seed=cfg.seed + ci, progress=report, progress_every=50)
        res.ga_cost = res.cost
        if cfg.refine:
            res.x, res.cost, res.refine_calls = ga.refine(cost, res.x)
        results.append(res)
        parts = cost_parts(cor, res.x, chart, arc_mask, radius, cfg.energy_weight)
        res.feasible = parts['fillet_overlap_m'] == 0.0 and parts['arc_samples_off'] == 0
        say(f'plan: candidate {ci + 1} ({origins[ci]}): {cor.n} crossing lines, GA {res.generations} generations '
            f'({res.stopped}), cost {res.ga_cost:.1f}' + (f', refined {res.cost:.1f}' if cfg.refine else '')
            + f'; sailed {parts["sailed_m"] / 1e3:.3f} km, turning {math.degrees(parts["turning_rad"]):.0f} deg'
            + ('' if res.feasible else f', NOT feasible: fillets overlap {parts["fillet_overlap_m"]:.0f} m, '
                                       f'{parts["arc_samples_off"]:.0f} arc samples in the clearance zone'))
        if best is None or (res.feasible, -res.cost) > (results[best].feasible, -results[best].cost):
            best = ci
    times['ga'] = time.perf_counter() - t

    t = time.perf_counter()
    cor = corridors[best]
    pts = np.vstack([cor.start, cor.waypoints(results[best].x), cor.goal])
    pts = drop_straight_points(chart, free, pts)
    radii, segments = fit_fillets(chart, free, pts, radius, min_radius)
    if not segments_clear_on(chart, free, segments):
        raise ChartError('internal: the planned route leaves the free water; please report this chart and points')
    sailed = sailed_length(segments)
    e = float(np.sum(np.abs(heading_changes(pts)))) if len(pts) > 2 else 0.0
    j = sailed + cfg.energy_weight * e
    times['finish'] = time.perf_counter() - t

    times['total'] = time.perf_counter() - t0
    plan = PlannedRoute(pts, radii, segments, sailed, polyline_length(pts), e, j, cands, best, corridors, results,
                        base, closed, skel, times, cfg, origins)
    say(f'plan: route {sailed / 1e3:.3f} km ({len(pts)} waypoints), shortest path {base.length / 1e3:.3f} km, '
        f'ratio {plan.length_ratio:.4f}; heading change {math.degrees(e):.0f} deg vs '
        f'{math.degrees(base.heading_change):.0f} deg; {times["total"]:.1f} s')
    return plan


# ---- route file -------------------------------------------------------------------------------
def route_yaml_text(plan, chart, name, source, description=None, comments=()):
    """The planned route as a route file (schema: ship_planner.yaml_route_reader). Geodetic charts give
    frame wgs84 with the chart's origin; synthetic ones frame enu (x east, y north)."""
    lines = [f'# {c}'.rstrip() for c in comments]
    lines.append(f'name: {name}')
    lines.append(f'source: {_quote(source)}')
    if description:
        lines.append(f'description: {_quote(description)}')
    geo = chart.origin is not None
    lines.append(f'frame: {"wgs84" if geo else "enu"}')
    if geo:
        lines.append(f'origin: {{lat_deg: {chart.origin[0]:.7f}, lon_deg: {chart.origin[1]:.7f}}}')
    lines.append('waypoints:')
    for k, p in enumerate(plan.waypoints):
        if geo:
            lat, lon = chart.to_geodetic(p[0], p[1])
            pt = f'lat_deg: {lat:.7f}, lon_deg: {lon:.7f}'
        else:
            pt = f'x_m: {p[1]:.2f}, y_m: {p[0]:.2f}'
        extra = ''
        if 0 < k < len(plan.waypoints) - 1:
            extra = f', fillet_radius_m: {plan.radii[k - 1]:.0f}'
        tag = ', name: start' if k == 0 else (', name: goal' if k == len(plan.waypoints) - 1 else '')
        lines.append(f'  - {{{pt}{extra}{tag}}}')
    return '\n'.join(lines) + '\n'


def _quote(text):
    return '"' + str(text).replace('\\', '\\\\').replace('"', '\\"') + '"'
