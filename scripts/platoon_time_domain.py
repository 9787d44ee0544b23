#!/usr/bin/env python3
"""Time-domain check of the platoon stability limit (Angelopoulos 2011 eqs. 31-41), in-process.

    scripts/platoon_time_domain.py [--models nomoto1 mariner] [--vessels 5] [--margin 0.1]
        [--dt 0.5] [--t-end 30000] [--y0 1e-6] [--ceiling 1] [--out DIR] [--no-plots]

The platoon, its equilibrium, its linearisations and the envelope fits are
ship_autopilot.platoon_simulation; this tool runs the cases and reports.

Cases: every look-ahead (1 +- margin) d*, "above" and "below" the limit, for two limits: the
thesis's d*_doc = U / (2 zeta omega_n) (eq. 34 in metres), and d*_sampled, the exact limit of
the simulated loop. The below cases also run again without a stop, to see where the nonlinear
ship ends up (limit cycle or divergence). The leader starts y0 off its equilibrium, the others
at theirs, so the disturbance travels down the string.

Measured: the growth rate sigma of the envelope of each vessel's cross-track deviation from
equilibrium, fitted with the t^m factor of vessel m (the raw slope, m = 0, is printed too).
Peaks are used after t_skip (the fast real mode has died out), while the amplitude stays below
--ceiling (linear regime) and down to FIT_DECADES of the vessel's largest swing: below that,
rounding noise shows up, amplified by each follower's resonance.

Predicted: the real part of the dominant oscillatory eigenvalue pair of one vessel's loop
(every follower's block has the same, eq. 40), of the thesis's model (doc) and of the sampled
closed loop (sampled).

Writes to --out: summary.json (with the run's provenance: its committed copy
doc/results/data/platoon_time_domain.json renders the tables of doc/results/string_stability.md),
rates.csv, and PNGs <model>_cross_track.png (cross-track
deviation of each vessel vs time above/below, linear and log envelope with the fits).

    scripts/platoon_time_domain.py --thesis-ic [--models nomoto1] [--ic-ratios 1.5 0.8]

Angelopoulos 2011 Figs. 17-21 instead: two vessels started off the path with the thesis's
initial conditions ((y1, y2) = (1, 1.5), (-1, 0), (0, 1) ship lengths; (psi1, psi2) = (0.5,
0.3) rad; r1 = 1 U/L), at look-aheads d_i = ratio x d_i* (the OCR states no values; the text
says only d1 > d1*, d2 > d2*), each run twice: the thesis's linear model (eq. 36,
platoon_simulation.linear_string_response, non-dimensional) and the ship model with its PD
(rudder limit, atan LOS; simulate_platoon with the same initial deviations in metres and
rad/s). Design: the model's gain-table zeta and omega_n (nomoto1: 0.8 and 1 U/L). Writes
thesis_ic.csv (per case and vessel: fitted envelope rate of the linear run and the real part
of its dominant eigenvalue, peak and final |y|), thesis_ic.json (the same rows with the run's
provenance; committed as doc/results/data/platoon_thesis_ic.json) and thesis_ic_<model>.png (the five figures
side by side, above and below the limit).
"""
import argparse
import csv
import json
import math
import time
from pathlib import Path

import numpy as np

from results_pages.provenance import provenance
from ship_autopilot.gains import autopilot_gains
from ship_autopilot.platoon_simulation import (doc_eigenvalues, dominant_pair,
                                               envelope_peaks, envelope_rate,
                                               linear_string_response, make_loop,
                                               sampled_critical_lookahead,
                                               sampled_eigenvalues, simulate_platoon)
from ship_guidance.follower import follower_gain, no_amplification_spacing
from ship_guidance.los import critical_lookahead_nondim
from ship_guidance.string_stability import string_eigenvalues

ROOT = Path(__file__).resolve().parents[1]

DEFAULT_OUT = ROOT / 'runs' / 'analysis' / 'platoon_time_domain'
#: Deviation (m) at which a run without a stop counts as diverged.
LONG_RUN_STOP = 1e4
#: Envelope samples used down to this fraction of a vessel's largest one (see ``analyse``).
FIT_DECADES = 1e-6


# ---------------------------------------------------------------- the report

CASES = (('doc', 'above'), ('doc', 'below'), ('sampled', 'above'), ('sampled', 'below'))


def analyse(loop, n_vessels, margin, dt, t_end, y0, ceiling, t_skip_periods=4.0):
    """Run the four cases (look-ahead (1 +- margin) x d* of the document, and of the sampled
    loop) for one model in one batch; return (rows, runs, info)."""
    d_smp = sampled_critical_lookahead(loop, dt)
    info = {'model': loop.name, 'zeta': loop.zeta, 'omega_n': loop.omega_n,
            'speed': loop.speed, 'd_crit_doc_m': loop.d_crit, 'd_crit_sampled_m': d_smp,
            'dt': dt, 'y0': y0, 'vessels': n_vessels}
    refs = {'doc': loop.d_crit, 'sampled': d_smp}
    ratios = {'above': 1.0 + margin, 'below': 1.0 - margin}
    ds = [ratios[c] * refs[r] for r, c in CASES]
    # The fit cases stop at 10x the ceiling; the below cases run again without a stop to see
    # where the nonlinear ship ends (limit cycle or divergence).
    below = [ci for ci, (_, c) in enumerate(CASES) if c == 'below']
    lookaheads = np.array(ds + [ds[ci] for ci in below])
    stops = np.array([10.0 * ceiling] * len(CASES) + [LONG_RUN_STOP] * len(below))
    t0 = time.perf_counter()
    run = simulate_platoon(loop, np.repeat(lookaheads[:, None], n_vessels, axis=1), t_end, dt,
                           y0, stop_amplitude=stops)
    info['wall_s'] = time.perf_counter() - t0
    info['nonlinear_below'] = {}
    for j, ci in enumerate(below):
        dy = run['dy'][:, len(CASES) + j, :]
        ok = np.isfinite(dy[:, 0])
        last = dy[ok][-int(2.0 * math.pi / loop.omega_n / dt):]
        info['nonlinear_below']['_'.join(CASES[ci])] = {
            'lookahead_m': ds[ci], 'ran_s': float(run['t'][ok][-1]),
            'stopped_at_s': float(run['stopped_at'][len(CASES) + j]),
            'last_period_amplitude_m': np.max(np.abs(last), axis=0).tolist()}
    period = 2.0 * math.pi / loop.omega_n
    nu = np.linspace(1e-4, 3.0, 30000) * loop.omega_n
    rows, runs = [], {}
    for ci, (ref, case) in enumerate(CASES):
        d = ds[ci]
        lam_doc = dominant_pair(doc_eigenvalues(loop, d))
        lam_smp = dominant_pair(sampled_eigenvalues(loop, d, dt))
        fits = []
        for i in range(n_vessels):
            dy = run['dy'][:, ci, i]
            # Six decades below the vessel's own largest (linear-regime) swing: far enough for a
            # long fit, above the rounding noise that the string's resonance amplifies too.
            _, amp = envelope_peaks(run['t'], dy)
            amp = amp[amp < ceiling]
            kw = dict(t_skip=t_skip_periods * period, ceiling=ceiling,
                      floor=FIT_DECADES * (amp.max() if amp.size else 0.0))
            sig, npk = envelope_rate(run['t'], dy, power=i, **kw)
            raw, _ = envelope_rate(run['t'], dy, power=0, **kw)
            fits.append((sig, raw))
            finite = dy[np.isfinite(dy)]
            rows.append({'model': loop.name, 'reference': ref, 'case': case,
                         'ratio_to_ref': ratios[case], 'ratio_to_doc': d / loop.d_crit,
                         'lookahead_m': d, 'vessel': i, 'sigma_fit': sig, 'sigma_raw': raw,
                         'peaks': npk, 're_lambda_sampled': lam_smp.real,
                         'im_lambda_sampled': lam_smp.imag, 're_lambda_doc': lam_doc.real,
                         'max_abs_dev_m': float(np.max(np.abs(finite))),
                         'last_period_max_abs_dev_m': float(np.max(np.abs(
                             finite[-int(period / dt):]))),
                         'stopped_at_s': float(run['stopped_at'][ci])})
        runs[(ref, case)] = {'t': run['t'], 'dy': run['dy'][:, ci, :], 'lookahead': d,
                             'ratio': d / loop.d_crit, 'fits': fits, 'lam_doc': lam_doc,
                             'lam_smp': lam_smp,
                             # the document's G is only meaningful where it is stable
                             'peak_gain': float(np.max(follower_gain(
                                 loop.zeta, loop.omega_n, d, loop.speed, nu)))
                             if d > loop.d_crit else math.nan}
    return rows, runs, info


def plot(loop, runs, path, ceiling):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, len(CASES), figsize=(5 * len(CASES), 8), sharex='col')
    for col, key in enumerate(CASES):
        run = runs[key]
        t, dy = run['t'], run['dy']
        top, bottom = axes[0, col], axes[1, col]
        for i in range(dy.shape[1]):
            top.plot(t, dy[:, i], lw=0.7, label=f'vessel {i}')
            tk, ak = envelope_peaks(t, dy[:, i])
            bottom.semilogy(tk, ak, '.', ms=2.5, color=f'C{i}')
        top.set_yscale('symlog', linthresh=abs(dy[0, 0]))
        bottom.axhline(ceiling, color='0.5', ls=':', lw=0.8)
        top.set_title(f'{loop.name}: d = {run["lookahead"]:.1f} m = {run["ratio"]:.3f} d*_doc\n'
                      f'({key[1]} the {key[0]} limit)', fontsize=10)
        bottom.set_title(f'Re lambda: sampled {run["lam_smp"].real:.2e}, doc '
                         f'{run["lam_doc"].real:.2e} 1/s\nfit vessel 0: {run["fits"][0][0]:.2e} '
                         f'1/s', fontsize=9)
        bottom.set_xlabel('time (s)')
        top.legend(fontsize=7, loc='upper left')
    axes[0, 0].set_ylabel('cross-track deviation (m, symlog)')
    axes[1, 0].set_ylabel('envelope peaks |dy| (m)')
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


# ---------------------------------------------------------------- Angelopoulos 2011 Figs. 17-21

#: (figure, label, initial deviations {(vessel, 'y'|'psi'|'r'): value}) in the thesis's
#: non-dimensional units (y in ship lengths, psi in rad, r in U/L).
THESIS_ICS = (
    (17, 'y1 = 1, y2 = 1.5', {(0, 'y'): 1.0, (1, 'y'): 1.5}),
    (18, 'y1 = -1, y2 = 0', {(0, 'y'): -1.0}),
    (19, 'y1 = 0, y2 = 1', {(1, 'y'): 1.0}),
    (20, 'psi1 = 0.5, psi2 = 0.3', {(0, 'psi'): 0.5, (1, 'psi'): 0.3}),
    (21, 'r1 = 1', {(0, 'r'): 1.0}),
)
#: Length of the thesis-IC runs, in periods 2 pi / omega_n, and the step (fraction of a period).
IC_PERIODS, IC_STEPS_PER_PERIOD = 8.0, 200


def thesis_ic_runs(loop, ratios):
    """Run THESIS_ICS at d_i = ratio d_i* for each ratio, linear model and ship model.
    Returns rows (one per ratio, figure, vessel) and the curves for the plot."""
    w_nd = float(autopilot_gains(loop.name)['omega_n_nd'])
    length = loop.speed * w_nd / loop.omega_n          # omega_n' = omega_n L / U
    zeta, d_nd = loop.zeta, float(critical_lookahead_nondim(loop.zeta, w_nd))
    period = 2.0 * math.pi / w_nd
    t_end, dt = IC_PERIODS * period, period / IC_STEPS_PER_PERIOD
    rows, curves = [], {}
    for ratio in ratios:
        d = ratio * d_nd
        lam = string_eigenvalues([zeta, zeta], [w_nd, w_nd], [d, d])
        re_lam = [float(dominant_pair(row).real) for row in lam]
        dev = np.zeros((len(THESIS_ICS), 2, 3))        # (y, psi, r) per vessel, non-dimensional
        for c, (_, _, ic) in enumerate(THESIS_ICS):
            for (i, what), v in ic.items():
                dev[c, i, ('y', 'psi', 'r').index(what)] = v
        scale = np.array([length, 1.0, loop.speed / length])
        ship = simulate_platoon(loop, np.full((len(THESIS_ICS), 2), ratio * loop.d_crit),
                                t_end * length / loop.speed, dt * length / loop.speed, 0.0,
                                stop_amplitude=1e3 * length, x_dev=dev * scale)
        for c, (fig_no, label, _) in enumerate(THESIS_ICS):
            x0 = np.concatenate([[dev[c, i, 1], dev[c, i, 2], dev[c, i, 0]] for i in range(2)])
            t, x = linear_string_response(zeta, w_nd, [d, d], x0, t_end, dt)
            y = x[:, [2, 5]]
            ys = ship['dy'][:, c, :] / length
            curves[(ratio, fig_no)] = {'t': t, 'y': y, 't_ship': ship['t'] * loop.speed / length,
                                       'y_ship': ys, 'label': label}
            # A follower driven by an excited leader is a Jordan chain (t^1 factor), alone not.
            driven = bool(np.any(x0[:3] != 0.0))
            for i in range(2):
                _, amp = envelope_peaks(t, y[:, i])
                sig, npk = envelope_rate(t, y[:, i], t_skip=2.0 * period, power=i * driven,
                                         floor=1e-9 * (amp.max() if amp.size else 0.0))
                fin = ys[np.isfinite(ys[:, i]), i]
                rows.append({'model': loop.name, 'd_over_dstar': ratio, 'figure': fig_no,
                             'initial': label, 'vessel': i + 1, 'zeta': zeta, 'omega_n_nd': w_nd,
                             'd_nd': d, 'sigma_fit_linear': sig, 'peaks': npk,
                             're_lambda': re_lam[i],
                             'max_abs_y_linear': float(np.max(np.abs(y[:, i]))),
                             'final_abs_y_linear': float(np.max(np.abs(y[-IC_STEPS_PER_PERIOD:, i]))),
                             'max_abs_y_ship': float(np.max(np.abs(fin))) if fin.size else math.nan,
                             'final_abs_y_ship': float(np.max(np.abs(fin[-IC_STEPS_PER_PERIOD:])))
                             if fin.size else math.nan})
    return rows, curves


def plot_thesis_ic(loop, curves, ratios, path):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(ratios), len(THESIS_ICS), figsize=(4.2 * len(THESIS_ICS),
                                                                     3.6 * len(ratios)),
                             sharex=True, squeeze=False)
    for r, ratio in enumerate(ratios):
        for c, (fig_no, label, _) in enumerate(THESIS_ICS):
            ax, cv = axes[r, c], curves[(ratio, fig_no)]
            for i, col in enumerate(('C0', 'C3')):
                ax.plot(cv['t'], cv['y'][:, i], color=col, lw=1.4, label=f'y{i + 1} (eq. 36)')
                ax.plot(cv['t_ship'], cv['y_ship'][:, i], color=col, ls='--', lw=1.0,
                        label=f'y{i + 1} ({loop.name} + PD, rudder limit)')
            ax.axhline(0.0, color='0.6', lw=0.6)
            ax.set_title(f'Fig. {fig_no}: {label}\nd = {ratio:g} d*', fontsize=10)
            ax.grid(alpha=0.3)
            if r == len(ratios) - 1:
                ax.set_xlabel('t (L/U)')
            if c == 0:
                ax.set_ylabel('deviation y (ship lengths)')
            if ratio < 1.0:
                ax.set_yscale('symlog', linthresh=1.0)
    axes[0, -1].legend(fontsize=7)
    fig.suptitle('Angelopoulos 2011 Figs. 17-21 with our curves: two vessels from the thesis\'s '
                 'initial conditions, above and below the look-ahead limit')
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main_thesis_ic(a):
    ok = True
    rows = []
    for name in a.models:
        loop = make_loop(name)
        r, curves = thesis_ic_runs(loop, a.ic_ratios)
        rows += r
        print(f"\n{name}: zeta {loop.zeta}, omega_n' {r[0]['omega_n_nd']:g} U/L; two vessels, "
              f"d_i = ratio x d* = ratio x {critical_lookahead_nondim(loop.zeta, r[0]['omega_n_nd']):.4f} L")
        print(f"{'d/d*':>5}{'fig':>5}  {'initial':24}{'vessel':>7}{'sigma fit':>11}{'Re lam':>10}"
              f"{'max|y| lin':>11}{'end|y| lin':>11}{'max|y| ship':>12}{'end|y| ship':>12}")
        for x in r:
            print(f"{x['d_over_dstar']:5.2f}{x['figure']:5d}  {x['initial']:24}{x['vessel']:7d}"
                  f"{x['sigma_fit_linear']:11.4f}{x['re_lambda']:10.4f}{x['max_abs_y_linear']:11.3g}"
                  f"{x['final_abs_y_linear']:11.3g}{x['max_abs_y_ship']:12.3g}"
                  f"{x['final_abs_y_ship']:12.3g}")
            if np.isfinite(x['sigma_fit_linear']) and \
                    np.sign(x['sigma_fit_linear']) != np.sign(x['re_lambda']):
                ok = False
        if not a.no_plots:
            plot_thesis_ic(loop, curves, a.ic_ratios, a.out / f'thesis_ic_{name}.png')
    with open(a.out / 'thesis_ic.csv', 'w', newline='') as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    (a.out / 'thesis_ic.json').write_text(json.dumps(
        {'provenance': a.provenance, 'ratios': a.ic_ratios, 'rows': rows}, indent=1,
        default=float))
    print(f'\nwritten to {a.out}; every fitted rate has the sign of its eigenvalue: {ok}')
    return 0 if ok else 1


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--models', nargs='+', default=['nomoto1', 'mariner'])
    ap.add_argument('--vessels', type=int, default=5)
    ap.add_argument('--margin', type=float, default=0.1, help='look-aheads (1 +- margin) d*')
    ap.add_argument('--dt', type=float, default=0.5, help='step and autopilot sample time (s)')
    ap.add_argument('--t-end', type=float, default=30000.0, help='simulated time (s)')
    ap.add_argument('--y0', type=float, default=1e-6, help="leader's initial offset (m)")
    ap.add_argument('--ceiling', type=float, default=1.0,
                    help='largest envelope amplitude used in the fits (m); a case stops at 10x')
    ap.add_argument('--out', type=Path, default=DEFAULT_OUT)
    ap.add_argument('--no-plots', action='store_true')
    ap.add_argument('--thesis-ic', action='store_true', help='Angelopoulos 2011 Figs. 17-21: two '
                    'vessels from the thesis\'s initial conditions (default models: nomoto1)')
    ap.add_argument('--ic-ratios', type=float, nargs='+', default=[1.5, 0.8],
                    help='--thesis-ic look-aheads as multiples of d* (default 1.5 0.8)')
    a = ap.parse_args(argv)
    a.provenance = provenance(argv and [__file__, *argv])
    a.out.mkdir(parents=True, exist_ok=True)
    if a.thesis_ic:
        if a.models == ap.get_default('models'):
            a.models = ['nomoto1']
        return main_thesis_ic(a)
    all_rows, infos = [], []
    ok = True
    for name in a.models:
        loop = make_loop(name)
        rows, runs, info = analyse(loop, a.vessels, a.margin, a.dt, a.t_end, a.y0, a.ceiling)
        info['peak_follower_gain'] = {f'{r}_{c}': runs[(r, c)]['peak_gain'] for r, c in CASES}
        info['no_amplification_spacing_m'] = no_amplification_spacing(loop.zeta, loop.omega_n,
                                                                       loop.speed)
        all_rows += rows
        infos.append(info)
        print(f"\n{name}: zeta {loop.zeta}, omega_n {loop.omega_n:.5f} rad/s, U "
              f"{loop.speed:.4f} m/s; d*_doc = U/(2 zeta omega_n) = {loop.d_crit:.2f} m; "
              f"d*_sampled (dt {a.dt} s) = {info['d_crit_sampled_m']:.2f} m "
              f"= {info['d_crit_sampled_m'] / loop.d_crit:.4f} d*_doc; wall {info['wall_s']:.0f} s")
        print(f"{'ref':8}{'case':6}{'d/d*doc':>8}{'vessel':>7}{'sigma fit':>11}{'raw slope':>11}"
              f"{'Re lam smp':>11}{'Re lam doc':>11}{'peaks':>6}{'max|dy| m':>10}"
              f"{'last|dy| m':>11}{'stop s':>8}")
        for r in rows:
            print(f"{r['reference']:8}{r['case']:6}{r['ratio_to_doc']:8.3f}{r['vessel']:7d}"
                  f"{r['sigma_fit']:11.3e}{r['sigma_raw']:11.3e}{r['re_lambda_sampled']:11.3e}"
                  f"{r['re_lambda_doc']:11.3e}{r['peaks']:6d}{r['max_abs_dev_m']:10.2e}"
                  f"{r['last_period_max_abs_dev_m']:11.2e}{r['stopped_at_s']:8.0f}")
            if not np.sign(r['sigma_fit']) == np.sign(r['re_lambda_sampled']):
                ok = False
        print('peak follower gain sup |G(i nu)| of the document model (stable cases): '
              + ', '.join(f'{k} {v:.1f}' for k, v in info['peak_follower_gain'].items()
                          if np.isfinite(v))
              + f'; no amplification needs d >= {info["no_amplification_spacing_m"]:.1f} m')
        for key, v in info['nonlinear_below'].items():
            amps = ', '.join(f'{x:.3g}' for x in v['last_period_amplitude_m'])
            end = (f"diverged (|dy| > {LONG_RUN_STOP:g} m) at {v['stopped_at_s']:.0f} s"
                   if np.isfinite(v['stopped_at_s']) else
                   f"after {v['ran_s']:.0f} s the last period's |dy| per vessel: {amps} m")
            print(f'{key} without a stop (nonlinear): {end}')
        if not a.no_plots:
            plot(loop, runs, a.out / f'{name}_cross_track.png', a.ceiling)
    with open(a.out / 'rates.csv', 'w', newline='') as f:
        w = csv.DictWriter(f, fieldnames=list(all_rows[0]))
        w.writeheader()
        w.writerows(all_rows)
    (a.out / 'summary.json').write_text(json.dumps(
        {'provenance': a.provenance, 'margin': a.margin, 'models': infos, 'rows': all_rows},
        indent=1, default=float))
    print(f'\nwritten to {a.out}; every fitted growth rate has the sign of the sampled '
          f'eigenvalue: {ok}')
    return 0 if ok else 1


if __name__ == '__main__':
    raise SystemExit(main())
