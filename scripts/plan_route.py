#!/usr/bin/env python3
"""Plan an optimal route over a real chart and write it as a route file (+ a PNG).

Pipeline and sources: ship_planner.optimal_route (Lee 2004, Chapter 3: closing, thinning,
adjacent convex polygons, real-coded GA). Charts: ship_planner.chart (GSHHG / OSM shoreline from
the roaring-landmask wheel, an S-57 ENC cell, or an image).

Example (the scenario in scenarios/routes/busan_passage.yaml):

    .venv/bin/python scripts/plan_route.py --box 34.68 35.12 128.36 129.10 \\
        --start 35.05 129.05 --goal 34.80 128.455 --resolution 75 --clearance 200 \\
        --turning-diameter 1029 --out scenarios/routes/busan_passage.yaml

Positions are latitude/longitude (deg) for geodetic charts, (north, east) metres for an image
chart. Errors (a point on land, no connection, a box too large, ...) print one line saying what
to change and exit with status 2.
"""
import argparse
import json
import math
import os
import shlex
import sys
import time

import numpy as np

from ship_planner.chart import (DEFAULT_MAX_CELLS, PROVIDERS, ChartError, chart_from_file,
                                default_cache_dir, shoreline_chart)
from ship_planner.fillets import suggest_fillet_radius
from ship_planner.optimal_route import DEFAULT_ENERGY_WEIGHT, PlannerConfig, plan_route, route_yaml_text
from ship_planner.yaml_route_reader import load_route_yaml


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    src = p.add_argument_group('chart')
    src.add_argument('--box', nargs=4, type=float, metavar=('LAT_MIN', 'LAT_MAX', 'LON_MIN', 'LON_MAX'),
                     help='latitude/longitude box of the chart (deg)')
    src.add_argument('--source', choices=PROVIDERS, default='gshhg', help='shoreline data for --box')
    src.add_argument('--chart', help='chart file instead of the shoreline: S-57 ENC cell (.000) or an image '
                                     '(dark land, light water, north up)')
    src.add_argument('--draft', type=float, help='ship draft (m): ENC depth areas shallower than this are blocked')
    src.add_argument('--resolution', type=float, default=100.0, help='chart cell size (m)')
    src.add_argument('--max-cells', type=int, default=DEFAULT_MAX_CELLS, help='largest raster allowed')
    src.add_argument('--cache-dir', default=None, help=f'raster cache (default {default_cache_dir()})')
    src.add_argument('--no-cache', action='store_true', help='always rebuild the raster')
    pts = p.add_argument_group('route')
    pts.add_argument('--start', nargs=2, type=float, required=True, metavar=('A', 'B'),
                     help='start: lat lon (deg), or north east (m) on an image chart')
    pts.add_argument('--goal', nargs=2, type=float, required=True, metavar=('A', 'B'), help='goal, like --start')
    pts.add_argument('--clearance', type=float, default=200.0, help='distance to keep from land (m)')
    pts.add_argument('--turning-diameter', type=float, default=None,
                     help='vessel turning diameter (m); fillet radius = suggest_fillet_radius(D) '
                          '(= D at half rudder)')
    pts.add_argument('--fillet-radius', type=float, default=None,
                     help='fillet radius (m), overrides --turning-diameter')
    pts.add_argument('--min-fillet-radius', type=float, default=None,
                     help='smallest radius a tight corner may fall back to (m; default half the fillet radius)')
    pts.add_argument('--energy-weight', type=float, default=DEFAULT_ENERGY_WEIGHT,
                     help='metres of sailing worth one radian of course change')
    ga = p.add_argument_group('search')
    ga.add_argument('--candidates', type=int, default=3, help='distinct centre-line routes to optimise')
    ga.add_argument('--max-lines', type=int, default=PlannerConfig.max_lines, help='crossing lines per candidate')
    ga.add_argument('--population', type=int, default=PlannerConfig.population)
    ga.add_argument('--generations', type=int, default=PlannerConfig.generations)
    ga.add_argument('--no-refine', action='store_true', help='keep the GA result without the local refinement')
    ga.add_argument('--seed', type=int, default=1)
    out = p.add_argument_group('output')
    out.add_argument('--out', help='route file to write (YAML, schema of ship_planner.yaml_route_reader)')
    out.add_argument('--png', help='picture of chart, centre lines, candidates and route (default: next to --out)')
    out.add_argument('--name', help='route name (default: the output file name)')
    out.add_argument('--results', help='results file (JSON): the summary below with the command, commit, '
                                       'date and load (doc/results/chart_planning.md renders it)')
    out.add_argument('--quiet', action='store_true', help='no progress lines')
    args = p.parse_args(argv)
    if (args.box is None) == (args.chart is None):
        p.error('give exactly one of --box (real shoreline) and --chart (a chart file)')
    return args


def build_chart(args, say):
    if args.box is not None:
        lat_min, lat_max, lon_min, lon_max = args.box
        return shoreline_chart(lat_min, lat_max, lon_min, lon_max, args.resolution, provider=args.source,
                               cache_dir=args.cache_dir, max_cells=args.max_cells, use_cache=not args.no_cache,
                               progress=say)
    kwargs = {'max_cells': args.max_cells}
    if args.chart.lower().endswith('.000'):
        kwargs.update(draft_m=args.draft, progress=say)
    return chart_from_file(args.chart, args.resolution, **kwargs)


def to_local(chart, pair):
    if chart.origin is None:
        return np.array(pair, dtype=float)
    n, e = chart.to_ned(pair[0], pair[1])
    return np.array([float(n), float(e)])


def plot(plan, chart, path, title):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap

    n0, n1, e0, e1 = (v / 1e3 for v in chart.extent())
    fig, ax = plt.subplots(figsize=(11, 11 * (n1 - n0) / (e1 - e0) + 0.8))
    # land dark, clearance zone mid grey, free water white
    img = np.where(~chart.water, 0, np.where(plan_free(plan, chart), 2, 1))
    ax.imshow(img, origin='lower', extent=[e0, e1, n0, n1], cmap=ListedColormap(['#6b6b5a', '#c9d3dc', '#ffffff']),
              interpolation='nearest', vmin=0, vmax=2)
    sk = np.argwhere(plan.skeleton)
    if len(sk):
        c = chart.cell_centers(sk[:, 0], sk[:, 1]) / 1e3
        ax.plot(c[:, 1], c[:, 0], ',', color='#3a9a3a', alpha=0.8)
    cor = plan.corridors[plan.chosen]
    a, b = cor.ends
    for p, q in zip(a, b):
        ax.plot([p[1] / 1e3, q[1] / 1e3], [p[0] / 1e3, q[0] / 1e3], '-', color='#8fb8de', lw=0.6)
    colours = ['#e08a1e', '#9b59b6', '#16a085', '#7f8c8d', '#c0392b']
    for i, cand in enumerate(plan.candidates):
        ax.plot(cand[:, 1] / 1e3, cand[:, 0] / 1e3, ':', color=colours[i % len(colours)], lw=1.2,
                label=f'candidate {i + 1}: {plan.origins[i]}' + (' (chosen)' if i == plan.chosen else ''))
    sp = plan.shortest.points / 1e3
    ax.plot(sp[:, 1], sp[:, 0], '--', color='#1f4e9c', lw=1.2,
            label=f'shortest path {plan.shortest.length / 1e3:.2f} km')
    route = plan.route()
    s = np.linspace(0.0, route.length, max(200, int(route.length / 20.0)))
    pts = np.array([route_point(route, si) for si in s]) / 1e3
    ax.plot(pts[:, 1], pts[:, 0], '-', color='#d62728', lw=2.0,
            label=f'planned route {plan.length / 1e3:.2f} km (x{plan.length_ratio:.3f})')
    wp = plan.waypoints / 1e3
    ax.plot(wp[:, 1], wp[:, 0], 'o', color='#d62728', ms=3.5)
    ax.plot(wp[0, 1], wp[0, 0], 's', color='k', ms=7, label='start')
    ax.plot(wp[-1, 1], wp[-1, 0], '*', color='k', ms=11, label='goal')
    ax.set_xlabel('east (km)')
    ax.set_ylabel('north (km)')
    ax.set_title(title, fontsize=10)
    ax.set_aspect('equal')
    ax.legend(loc='lower right', fontsize=8, framealpha=0.9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plan_free(plan, chart):
    return chart.free_mask(plan.config.clearance_m)


def route_point(route, s):
    """(north, east) at arc length s along a ship_guidance Route."""
    acc = 0.0
    for leg in route.legs:
        if s <= acc + leg.length or leg is route.legs[-1]:
            n, e, _ = leg.point_at(s - acc)
            return float(n), float(e)
        acc += leg.length
    raise ValueError('arc length beyond the route')


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    t0 = time.perf_counter()

    def say(text):
        if not args.quiet:
            print(f'[{time.perf_counter() - t0:6.1f} s] {text}', file=sys.stderr, flush=True)

    try:
        if args.fillet_radius is not None:
            radius = args.fillet_radius
        elif args.turning_diameter is not None:
            radius = suggest_fillet_radius(args.turning_diameter)
        else:
            radius = 0.0
        chart = build_chart(args, say)
        t_chart = time.perf_counter() - t0
        start, goal = to_local(chart, args.start), to_local(chart, args.goal)
        cfg = PlannerConfig(clearance_m=args.clearance, fillet_radius_m=radius,
                            min_fillet_radius_m=args.min_fillet_radius, energy_weight=args.energy_weight,
                            candidates=args.candidates, max_lines=args.max_lines, population=args.population,
                            generations=args.generations, seed=args.seed, refine=not args.no_refine)
        plan = plan_route(chart, start, goal, cfg, progress=say)
    except (ChartError, ValueError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    total = time.perf_counter() - t0
    ga_only = [r.ga_cost for r in plan.ga_results]
    summary = {
        'chart': chart.source,
        'chart_time_s': round(t_chart, 2),
        'planning_time_s': round(plan.timings['total'], 2),
        'total_time_s': round(total, 2),
        'route_length_m': round(plan.length, 1),
        'waypoint_polyline_length_m': round(plan.polyline_length, 1),
        'shortest_path_length_m': round(plan.shortest.length, 1),
        'length_ratio': round(plan.length_ratio, 4),
        'heading_change_deg': round(math.degrees(plan.heading_change), 1),
        'shortest_heading_change_deg': round(math.degrees(plan.shortest.heading_change), 1),
        'waypoints': len(plan.waypoints),
        'fillet_radii_m': [round(float(r)) for r in plan.radii],
        'candidates_km': [round(float(np.sum(np.hypot(*np.diff(c, axis=0).T))) / 1e3, 2) for c in plan.candidates],
        'chosen_candidate': plan.chosen + 1,
        'ga_cost': [round(c, 1) for c in ga_only],
        'refined_cost': [round(r.cost, 1) for r in plan.ga_results],
    }
    for k, v in summary.items():
        print(f'{k}: {v}')
    if args.results:
        from results_pages.provenance import provenance
        record = {'provenance': provenance(None if argv is None else [sys.argv[0], *argv]),
                  'clearance_m': args.clearance,
                  'resolution_m': args.resolution, 'fillet_radius_m': radius, **summary}
        with open(args.results, 'w', encoding='utf-8') as f:
            f.write(json.dumps(record, indent=1) + '\n')
        say(f'wrote {args.results}')
    if args.out:
        name = args.name or os.path.splitext(os.path.basename(args.out))[0]
        cmd = 'scripts/plan_route.py ' + ' '.join(shlex.quote(a) for a in (sys.argv[1:] if argv is None else argv))
        comments = [
            'Planned by ship_planner.optimal_route (Lee 2004, Chapter 3: closing + thinning -> candidate routes,',
            'adjacent convex polygons -> crossing lines, real-coded GA -> waypoints; fillets for the vessel).',
            f'Command: {cmd}',
            f'Chart: {chart.source}; clearance {args.clearance:g} m (+ {chart.grid_margin:.0f} m grid margin).',
            f'Route {plan.length / 1e3:.3f} km with fillets; '
            f'exact-grid shortest path {plan.shortest.length / 1e3:.3f} km '
            f'(ratio {plan.length_ratio:.4f}); course change {math.degrees(plan.heading_change):.0f} deg vs '
            f'{math.degrees(plan.shortest.heading_change):.0f} deg on the shortest path.',
            f'Planning time {plan.timings["total"]:.1f} s (chart {t_chart:.1f} s, includes loading the shoreline '
            'unless cached).',
            '',
        ]
        source = (f'planned by scripts/plan_route.py on {chart.source}; method of Lee 2004 Chapter 3 '
                  '(ship_planner.optimal_route)')
        text = route_yaml_text(plan, chart, name, source, comments=comments,
                               description=f'Optimal route, clearance {args.clearance:g} m, fillet radius '
                                           f'{radius:g} m, energy weight {args.energy_weight:g} m/rad')
        with open(args.out, 'w', encoding='utf-8') as f:
            f.write(text)
        back = load_route_yaml(args.out)           # the file must read back as a valid route
        say(f'wrote {args.out} ({len(plan.waypoints)} waypoints, {back.route.length / 1e3:.3f} km as read back)')
    png = args.png or (os.path.splitext(args.out)[0] + '.png' if args.out else None)
    if png:
        title = (f'{chart.source}\nclearance {args.clearance:g} m, fillet {radius:g} m: route '
                 f'{plan.length / 1e3:.2f} km, shortest {plan.shortest.length / 1e3:.2f} km '
                 f'(ratio {plan.length_ratio:.3f}), planning {plan.timings["total"]:.1f} s')
        plot(plan, chart, png, title)
        say(f'wrote {png}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
