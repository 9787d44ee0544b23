#!/usr/bin/env python3
"""Tune the look-ahead law with the planner's genetic algorithm (Lee 2004, Ch. 4).

    scripts/tune_guidance_ga.py                 both cases, population 50, 50 generations
    scripts/tune_guidance_ga.py --quick         population 8, 4 generations (a smoke run)
    scripts/tune_guidance_ga.py --case coastal --seed 3 --out runs/my_tuning

Two cases on Lee 2004's linear ship (nomoto1, preset mariner: Table 2.2 / 4.1) with the gain
table's PD (ship_autopilot.gains.heading_loop_design), as ship_autopilot.guidance_tuning
describes: coastal (waypoint legs with 800 m turning circles, 0.75 m/s current across the
route, start 200 m off; cost RMS cross-track + rudder) and oceanic (3 km legs with 1500 m
circles, no current, start 300 m off; cost: energy proxy). Each is tuned with
ship_planner.ga.minimize_box and compared against conventional LOS with a constant look-ahead
of 2 ship lengths (322 m, as the Lee 2004 route-following scenarios use). One progress line per
generation. Writes <out>/results.json (tuned parameters, GA history, metrics of tuned and
conventional and of the best constant look-ahead on a 40-point grid of the same range),
<out>/cost.png (best cost per generation) and <out>/tracks.png (tracks and
cross-track error, tuned vs conventional); <out> defaults to runs/guidance_ga-<time>/ and
runs/guidance_ga-latest points at it.
"""
import argparse
import json
import math
import sys
import time
from datetime import datetime
from pathlib import Path

import numpy as np

from ship_autopilot.gains import heading_loop_design
from ship_autopilot.guidance_tuning import (Case, ConstantLookahead, cost, gene_box, metrics,
                                            simulate, tune)
from ship_planner.fillets import fillet_polyline, segments_to_route
from ship_planner.ga import minimize_box
from ship_sim.models import make_model

REPO = Path(__file__).resolve().parents[1]
MODEL = 'nomoto1'                 # Lee 2004's linear ship, preset mariner
CONVENTIONAL_LOOKAHEAD_M = 322.0  # 2 ship lengths, the Lee 2004 route-following scenarios' value
CURRENT_MPS = 0.75                # Lee 2004, Ch. 4 coastal case


def legs_route(courses_deg, length_m, radius_m):
    """A route from the origin by courses (deg, clockwise from north) of equal legs, corners
    rounded with one radius (NED)."""
    pts = [(0.0, 0.0)]
    for c in courses_deg:
        n, e = pts[-1]
        pts.append((n + length_m * math.cos(math.radians(c)), e + length_m * math.sin(math.radians(c))))
    return segments_to_route(fillet_polyline(pts, radius_m))


def make_cases(dt):
    design = heading_loop_design(MODEL)
    common = dict(model=make_model(MODEL), pd=design.gains['pd'], zeta=design.zeta,
                  omega_n=design.omega_n, dt=dt)
    return {
        'coastal': Case('coastal', legs_route((90, 60, 105, 45), 1500.0, 800.0), cost='coastal',
                        current_speed=CURRENT_MPS, current_direction=0.0, start_cross_m=200.0,
                        t_max=2000.0, **common),
        'oceanic': Case('oceanic', legs_route((90, 60, 120), 3000.0, 1500.0), cost='oceanic',
                        start_cross_m=300.0, t_max=3000.0, **common),
    }


def plot(out, results, runs):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(results), figsize=(5 * len(results), 3.5), squeeze=False)
    for ax, (name, r) in zip(axes[0], results.items()):
        ax.plot(range(len(r['ga']['history'])), r['ga']['history'], 'o-')
        ax.axhline(r['conventional']['cost'], color='k', ls='--', label='conventional (322 m)')
        ax.set(title=f'{name}: best cost per generation', xlabel='generation', ylabel='cost')
        ax.legend()
    fig.tight_layout()
    fig.savefig(out / 'cost.png', dpi=110)
    plt.close(fig)
    fig, axes = plt.subplots(2, len(results), figsize=(6 * len(results), 8), squeeze=False)
    for j, (name, (case, tuned, conv)) in enumerate(runs.items()):
        ax = axes[0][j]
        pts = np.array([case.route.point_at(s) for s in np.linspace(0.0, case.route.length, 400)])
        ax.plot(pts[:, 1], pts[:, 0], 'k-', lw=1, label='route')
        for run, lab in ((conv, 'conventional 322 m'), (tuned, 'GA-tuned law')):
            ax.plot(run['east'], run['north'], label=lab)
        ax.set(title=f'{name}: tracks (NED)', xlabel='east m', ylabel='north m', aspect='equal')
        ax.legend()
        ax = axes[1][j]
        for run, lab in ((conv, 'conventional 322 m'), (tuned, 'GA-tuned law')):
            ax.plot(run['t'], run['cross_track'], label=lab)
        ax.set(title=f'{name}: cross-track error', xlabel='t s', ylabel='m')
        ax.legend()
    fig.tight_layout()
    fig.savefig(out / 'tracks.png', dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--case', action='append', choices=('coastal', 'oceanic'),
                    help='tune only this case (repeatable; default both)')
    ap.add_argument('--quick', action='store_true', help='population 8, 4 generations (default 50 x 50, '
                    'as Lee 2004 sets its GA)')
    ap.add_argument('--population', type=int, default=None)
    ap.add_argument('--generations', type=int, default=None)
    ap.add_argument('--seed', type=int, default=0)
    ap.add_argument('--dt', type=float, default=2.0, help='closed-loop step (s)')
    ap.add_argument('--out', type=Path, default=None)
    a = ap.parse_args(argv)
    from results_pages.provenance import provenance
    started = provenance()     # the code the runs use is the code at their start
    pop = a.population or (8 if a.quick else 50)
    gens = a.generations or (4 if a.quick else 50)
    out = a.out or REPO / 'runs' / f'guidance_ga-{datetime.now():%Y%m%d-%H%M%S}'
    out.mkdir(parents=True, exist_ok=True)
    cases = make_cases(a.dt)
    results, runs = {}, {}
    for name in a.case or ('coastal', 'oceanic'):
        case = cases[name]
        t0 = time.time()

        def progress(g, best, name=name, t0=t0):
            print(f'{name}: generation {g}/{gens}  best cost {best:.4f}  ({time.time() - t0:.0f} s)',
                  flush=True)

        law, res = tune(case, minimize_box, population=pop, generations=gens, seed=a.seed,
                        progress=progress)
        conv = ConstantLookahead(CONVENTIONAL_LOOKAHEAD_M)
        tuned_run, conv_run = simulate(case, law), simulate(case, conv)
        lo, hi = gene_box(case)
        # The best constant look-ahead over the same range (how much the law's shape adds).
        grid = np.linspace(lo[0], hi[0], 40) * case.speed
        const_costs = [cost(case, ConstantLookahead(d)) for d in grid]
        best_const = ConstantLookahead(float(grid[int(np.argmin(const_costs))]))
        best_const_run = simulate(case, best_const)
        results[name] = {
            'case': {'cost': case.cost, 'current_mps': case.current_speed,
                     'current_direction_deg': math.degrees(case.current_direction),
                     'start_cross_m': case.start_cross_m, 'route_length_m': float(case.route.length),
                     'speed_mps': case.speed, 'model': MODEL, 'pd': case.pd, 'zeta': case.zeta,
                     'omega_n': case.omega_n, 'dt_s': case.dt},
            'critical_time_s': case.critical_time(),
            'critical_lookahead_m': case.critical_time() * case.speed,
            'gene_box': {'lower': lo.tolist(), 'upper': hi.tolist()},
            'tuned': {'t_min_s': law.t_min, 't_max_s': law.t_max, 'e_scale_m': law.e_scale,
                      'lookahead_on_path_m': law(case.speed, 0.0),
                      'lookahead_min_m': law.minimum(case.speed),
                      'cost': cost(case, law), **metrics(case, tuned_run)},
            'conventional': {'lookahead_m': CONVENTIONAL_LOOKAHEAD_M, 'cost': cost(case, conv),
                             **metrics(case, conv_run)},
            'best_constant': {'lookahead_m': best_const.lookahead_m, 'cost': float(min(const_costs)),
                              **metrics(case, best_const_run)},
            'ga': {'population': pop, 'generations': res.generations, 'seed': a.seed,
                   'evaluations': res.evaluations, 'history': res.history,
                   'wall_s': time.time() - t0},
        }
        runs[name] = (case, tuned_run, conv_run)
        t, c = results[name]['tuned'], results[name]['conventional']
        print(f'{name}: tuned t_min {law.t_min:.1f} s, t_max {law.t_max:.1f} s, e_scale {law.e_scale:.0f} m '
              f'(d on the path {t["lookahead_on_path_m"]:.0f} m, min {t["lookahead_min_m"]:.0f} m; '
              f'critical {results[name]["critical_lookahead_m"]:.0f} m)')
        for lab, m in (('tuned', t), ('conventional', c),
                       (f'constant {best_const.lookahead_m:.0f} m (best)', results[name]['best_constant'])):
            print(f'  {lab:22s} cost {m["cost"]:.4f}  xte RMS {m["xte_rms_m"]:.1f} m  max {m["xte_max_abs_m"]:.1f} m  '
                  f'rudder RMS {m["rudder_rms_deg"]:.2f} deg  rate {m["rudder_rate_mean_abs_deg_s"]:.3f} deg/s  '
                  f'energy {m["energy_proxy"]:.4f}  time {m["time_s"]:.0f} s')
    # with its provenance, results.json is a results file (doc/results/seed_scenarios.md)
    (out / 'results.json').write_text(json.dumps({'provenance': started, **results}, indent=1))
    plot(out, results, runs)
    if a.out is None:
        latest = REPO / 'runs' / 'guidance_ga-latest'
        if latest.is_symlink() or latest.exists():
            latest.unlink()
        latest.symlink_to(out.name)
    print(f'wrote {out}/results.json, cost.png, tracks.png')
    return 0


if __name__ == '__main__':
    sys.exit(main())
