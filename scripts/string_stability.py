#!/usr/bin/env python3
"""String stability: Table 1 of Angelopoulos 2011 and the exact look-ahead limit of Simakis 1992.

    scripts/string_stability.py [--out runs/analysis/string_stability]
        [--table tests/data/string_stability_table1.csv]
        [--brute-force {none,explained,all}] [--no-plots]

Writes to --out:
- table1_reproduction.csv: every printed row of Angelopoulos 2011 Table 1 next to ours (d1*, d2*,
  the exact grid minima of the thesis's scan, the row's class and whether the printed value is what
  Appendix A's method predicts for that class; see ship_guidance/doc/string_stability.md).
- nps_auv2_critical.csv: exact (sway/yaw, Simakis 1992 Sec. III.B) vs approximate 1/(2 zeta omega_n)
  critical look-ahead of the NPS AUV II over omega_n and zeta.
- nps_auv2_sensitivity.csv: Simakis 1992 Sec. III.C, d_n = d/d_nom for +-50 % of each coefficient.
- summary.md and summary.json: timing, the rows that differ and why, the NPS AUV II numbers.
- PNGs: Angelopoulos 2011 Figures 9-11 (stability regions d2 vs d1) and 12-15 (limits vs
  omega_n), Simakis 1992 Figures 2, 3 (exact vs approximate limit) and 5-8 (sensitivity).
Exit code 0; 1 if a printed Table 1 value contradicts the method (an unexplained row).
"""
import argparse
import csv
import json
import sys
import time
from pathlib import Path

import numpy as np

from ship_guidance import string_stability as ss
from ship_guidance import string_stability_table1 as table1_scan
from ship_guidance import sway_yaw_lookahead as sy
from ship_guidance.heading_loop import pd_gains
from ship_guidance.los import critical_lookahead_nondim
from ship_sim.models.nps_auv2 import COEFFS

ROOT = Path(__file__).resolve().parents[1]

DEFAULT_TABLE = ROOT / 'tests' / 'data' / 'string_stability_table1.csv'  # Angelopoulos 2011 Table 1
DEFAULT_OUT = ROOT / 'runs' / 'analysis' / 'string_stability'
#: Simakis 1992 Figures 5-8 as printed (OCR lost the dots; see the summary for the attribution).
DOC_SENSITIVITY = {'Yvdot': 0.40, 'Yv': 0.37, 'Nrdot': 0.14, 'Nr': 0.102}
SENS_COEFFS = ('Yvdot', 'Yv', 'Nrdot', 'Nr', 'Yr', 'Nv', 'Yrdot', 'Nvdot', 'Yds', 'Nds',
               'Ydb', 'Ndb')
#: Plot labels: symbol plus the plain name (the dot of an added-mass term is easy to miss).
LATEX = {'Yv': r'$Y_v$', 'Yvdot': r'$Y_{\dot v}$ (Yvdot)', 'Yr': r'$Y_r$',
         'Yrdot': r'$Y_{\dot r}$ (Yrdot)', 'Nv': r'$N_v$', 'Nvdot': r'$N_{\dot v}$ (Nvdot)',
         'Nr': r'$N_r$', 'Nrdot': r'$N_{\dot r}$ (Nrdot)', 'Yds': r'$Y_{\delta s}$',
         'Nds': r'$N_{\delta s}$', 'Ydb': r'$Y_{\delta b}$', 'Ndb': r'$N_{\delta b}$'}
SENS_STYLE = {'Yvdot': ('tab:blue', '-'), 'Yv': ('tab:orange', '-'), 'Nrdot': ('tab:green', '-'),
              'Nr': ('tab:red', '-'), 'Yr': ('0.5', ':'), 'Nv': ('0.5', ':'),
              'Yrdot': ('0.5', ':'), 'Nvdot': ('0.5', ':'), 'Yds': ('tab:purple', '--'),
              'Nds': ('tab:brown', '--'), 'Ydb': ('tab:pink', '--'), 'Ndb': ('tab:olive', '--')}


def load_table(path):
    t = np.genfromtxt(path, delimiter=',', names=True)
    if t.size == 0:
        raise SystemExit(f'{path}: empty table')
    return t


def timed(fn, repeat=7):
    """Best and median wall time (s) of fn() over ``repeat`` runs, and its last result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), float(np.median(times)), out


def key(z, w1, w2):
    return (round(float(z), 6), round(float(w1), 6), round(float(w2), 6))


# ---------------------------------------------------------------- Table 1

def reproduce_table1(table, brute_force):
    z, w1, w2 = table1_scan.table1_parameters()
    timing = {}
    for method in ('routh', 'eig'):
        best, med, (d1, d2) = timed(
            lambda m=method: table1_scan.grid_minima(z, w1, w2, method=m),
            repeat=7 if method == 'routh' else 3)
        timing[method] = {'best_s': best, 'median_s': med}
        if method == 'routh':
            d1r, d2r = d1, d2
        else:
            same_eig = (np.array_equal(d1, d1r, equal_nan=True)
                        and np.array_equal(d2, d2r, equal_nan=True))
    ours = {key(*k): i for i, k in enumerate(zip(z, w1, w2))}
    idx = np.array([ours[key(*r)] for r in zip(table['zeta'], table['wn1'], table['wn2'])])
    missing = sorted(set(range(z.size)) - set(idx.tolist()))
    cls, lo1, hi1, lo2, hi2 = table1_scan.classify_table1(table['zeta'], table['wn1'],
                                                          table['wn2'])
    d1s = critical_lookahead_nondim(table['zeta'], table['wn1'])
    d2s = critical_lookahead_nondim(table['zeta'], table['wn2'])
    tol = 1e-9
    consistent = ((table['d1_sim'] >= lo1 - tol) & (table['d1_sim'] <= hi1 + tol)
                  & (table['d2_sim'] >= lo2 - tol) & (table['d2_sim'] <= hi2 + tol))
    rows = []
    for i, r in enumerate(table):
        j = idx[i]
        lim = ss.string_eigenvalues([r['zeta']] * 2, [w1[j], w2[j]], [d1s[i], d2s[i]])
        imag = sorted(np.abs(lim.imag).max(axis=1))
        rows.append({
            'csv_line': i + 2, 'zeta': r['zeta'], 'wn1': r['wn1'], 'wn2': r['wn2'],
            'doc_d1_sim': r['d1_sim'], 'doc_d2_sim': r['d2_sim'],
            'doc_d1_star': r['d1_star'], 'doc_d2_star': r['d2_star'],
            'd1_star': round(float(d1s[i]), 6), 'd2_star': round(float(d2s[i]), 6),
            'exact_d1_grid': round(float(d1r[j]), 2), 'exact_d2_grid': round(float(d2r[j]), 2),
            'matches_exact': bool(abs(r['d1_sim'] - d1r[j]) < tol
                                  and abs(r['d2_sim'] - d2r[j]) < tol),
            'class': cls[i], 'consistent_with_method': bool(consistent[i]),
            'doc_eig': f"{r['eig_a']:g}/{r['eig_b']:g}",
            'eig_at_limit': f'{imag[0]:.6g}/{imag[1]:.6g}',
        })
    brute = []
    if brute_force != 'none':
        sel = range(len(table)) if brute_force == 'all' else \
            [i for i in range(len(table)) if cls[i] != table1_scan.ROW_EXACT]
        t0 = time.perf_counter()
        for i in sel:
            j = idx[i]
            b1, b2, _ = table1_scan.appendix_a_scan(z[j], w1[j], w2[j])
            brute.append({'csv_line': i + 2, 'zeta': float(z[j]), 'wn1': round(float(w1[j]), 6),
                          'wn2': round(float(w2[j]), 6), 'class': cls[i],
                          'doc': (float(table['d1_sim'][i]), float(table['d2_sim'][i])),
                          'numpy_scan': (round(float(b1), 2), round(float(b2), 2)),
                          'exact': (round(float(d1r[j]), 2), round(float(d2r[j]), 2))})
        timing['appendix_a_literal_s'] = time.perf_counter() - t0
        timing['appendix_a_literal_rows'] = len(brute)
    return {
        'rows': rows, 'timing': timing, 'eig_equals_routh': bool(same_eig),
        'missing': [{'zeta': float(z[j]), 'wn1': round(float(w1[j]), 6),
                     'wn2': round(float(w2[j]), 6),
                     'd2_star': float(critical_lookahead_nondim(z[j], w2[j])),
                     'scan_finds_stable_point': bool(np.isfinite(d1r[j]))} for j in missing],
        'brute': brute,
        'd_star_max_err': float(max(np.abs(np.round(d1s, 6) - table['d1_star']).max(),
                                    np.abs(np.round(d2s, 6) - table['d2_star']).max())),
    }


# ---------------------------------------------------------------- NPS AUV II (Simakis 1992)

def nps_auv2(omegas, zetas):
    exact = sy.nps_auv2_critical_lookahead(np.asarray(zetas)[:, None], np.asarray(omegas)[None])
    approx = critical_lookahead_nondim(np.asarray(zetas)[:, None], np.asarray(omegas)[None])
    plant = sy.nps_auv2_plant()
    a, b = sy.nps_auv2_nomoto(plant)
    checks = []
    for zeta, w in ((0.8, 3.0), (0.4, 1.0), (1.2, 5.0), (0.6, 0.5)):
        k1, k2 = pd_gains(a, b, zeta=zeta, omega_n=w)
        d = float(sy.nps_auv2_critical_lookahead(zeta, w))
        d_eig = sy.critical_lookahead_by_eigenvalues(plant, k1, k2, 0.2 * d, 5.0 * d)
        checks.append({'zeta': zeta, 'omega_n': w, 'k1': float(k1), 'k2': float(k2),
                       'exact_routh': d, 'eigen_bisection': d_eig,
                       'approx': float(critical_lookahead_nondim(zeta, w))})
    return exact, approx, checks, (a, b)


def sensitivity(factors):
    out = {}
    for name in SENS_COEFFS:
        fixed = sy.nps_auv2_sensitivity(name, factors)
        redesign = sy.nps_auv2_sensitivity(name, factors, redesign=True)
        out[name] = {'nominal': COEFFS[name], 'fixed': fixed, 'redesign': redesign,
                     'total_fixed': float(fixed[-1] - fixed[0]),
                     'total_redesign': float(redesign[-1] - redesign[0])}
    return out


# ---------------------------------------------------------------- plots

def plots(out, table, omegas, zetas, exact, approx, checks, sens, factors):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    files = []
    top = 2.2
    w1s = np.arange(1.0, 4.51, 0.5)
    cmap = plt.get_cmap('viridis')
    # Angelopoulos 2011 Figures 9-11: stable quadrants d1 > d1*, d2 > d2*, one L-shaped boundary
    # per omega_n1.
    for fig_no, p in zip((9, 10, 11), table1_scan.TABLE1_RATIOS):
        fig, axes = plt.subplots(1, 3, figsize=(15, 5.2), sharey=True)
        for ax, zeta in zip(axes, (0.6, 0.8, 1.2)):
            for k, w1 in enumerate(w1s):
                c = cmap(k / (len(w1s) - 1))
                d1, d2 = (float(critical_lookahead_nondim(zeta, w)) for w in (w1, p * w1))
                ax.plot([d1, top], [d2, d2], color=c, lw=1.6)
                ax.plot([d1, d1], [d2, top], color=c, lw=1.6, label=rf'$\omega_{{n1}}$={w1:g}')
                m = ((np.abs(table['zeta'] - zeta) < 1e-9) & (np.abs(table['wn1'] - w1) < 1e-9)
                     & (np.abs(table['wn2'] - p * w1) < 1e-6))
                if m.any():
                    ax.plot(table['d1_sim'][m], table['d2_sim'][m], 'o', ms=5, mfc='none',
                            color=c)
            if zeta == 0.6:
                ax.text(1.45, 2.12, 'stable: above and right\nof each curve', fontsize=9,
                        ha='center', va='top', color='0.3')
            ax.set(xlim=(0, top), ylim=(0, top), xlabel='$d_1$ (ship lengths)',
                   title=rf'$\zeta$ = {zeta:g},  $\omega_{{n2}} = {p:g}\,\omega_{{n1}}$')
            ax.grid(alpha=0.3)
        axes[0].set_ylabel('$d_2$ (ship lengths)')
        axes[-1].legend(fontsize=8, loc='upper right', title='lines: exact limit\n'
                        'circles: Table 1 grid minima', title_fontsize=8)
        fig.suptitle(f'String stability regions (Angelopoulos 2011 Figure {fig_no} analogue): '
                     'stable iff '
                     r'$d_1 > 1/(2\zeta\omega_{n1})$ and $d_2 > 1/(2\zeta\omega_{n2})$')
        files.append(_save(fig, out / f'fig{fig_no:02d}_regions_ratio_{p:g}.png'))

    # Angelopoulos 2011 Figures 12-15: limit of each vessel vs omega_n1 for zeta 0.4..1.2.
    fig, axes = plt.subplots(2, 2, figsize=(12, 9), sharex=True)
    wgrid = np.linspace(1.0, 4.5, 200)
    panels = [(None, 'vessel 1 (Fig. 12)'),
              (0.5, 'vessel 2, $\\omega_{n2}=0.5\\omega_{n1}$ (Fig. 13)'),
              (1.0, 'vessel 2, $\\omega_{n2}=\\omega_{n1}$ (Fig. 14)'),
              (1.5, 'vessel 2, $\\omega_{n2}=1.5\\omega_{n1}$ (Fig. 15)')]
    for ax, (p, title) in zip(axes.ravel(), panels):
        for k, zeta in enumerate(table1_scan.TABLE1_ZETAS):
            c = plt.get_cmap('plasma')(k / 5)
            w = wgrid if p is None else p * wgrid
            ax.plot(wgrid, critical_lookahead_nondim(zeta, w), color=c,
                    label=f'$\\zeta$={zeta:g}')
            m = np.abs(table['zeta'] - zeta) < 1e-9
            if p is None:
                ax.plot(table['wn1'][m], table['d1_sim'][m], '.', color=c, ms=4)
            else:
                m &= np.abs(table['wn2'] - p * table['wn1']) < 1e-6
                ax.plot(table['wn1'][m], table['d2_sim'][m], '.', color=c, ms=4)
        ax.set(title=title, ylim=(0, 2.6), ylabel='critical look-ahead (ship lengths)')
        ax.axhline(2.0, color='0.5', ls=':', lw=1)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel('$\\omega_{n1}$ (U/L)')
    axes[0, 0].legend(fontsize=9, title='lines: $1/(2\\zeta\\omega_n)$; dots: Table 1',
                      title_fontsize=8)
    fig.suptitle('Critical look-ahead per vessel (Angelopoulos 2011 Figures 12-15 analogue); '
                 'dotted line: the scan grid ends at 2.0')
    files.append(_save(fig, out / 'fig12-15_limits_vs_omega.png'))

    # Simakis 1992 Figure 2: exact vs approximate, zeta = 0.8.
    iz = int(np.argmin(np.abs(np.asarray(zetas) - 0.8)))
    fig, ax = plt.subplots(figsize=(8, 5.5))
    ax.plot(omegas, exact[iz], 'k-', lw=2, label='exact (sway/yaw model, Routh quadratic)')
    ax.plot(omegas, approx[iz], 'k:', lw=2, label=r'approximate $1/(2\zeta\omega_n)$ (Nomoto)')
    c = checks[0]
    ax.plot(c['omega_n'], c['eigen_bisection'], 'rs', ms=8, mfc='none',
            label=f"eigenvalue bisection at $\\omega_n$=3: {c['eigen_bisection']:.4f}")
    ax.set(xlabel=r'$\omega_n$ (U/L)', ylabel='critical look-ahead $d$ (vehicle lengths)',
           title=r'NPS AUV II, $\zeta$ = 0.8 (Simakis 1992 Figure 2 analogue): '
                 'stable above the curve',
           ylim=(0, min(3.0, float(np.nanmax(exact[iz])) * 1.05)))
    ax.grid(alpha=0.3)
    ax.legend()
    files.append(_save(fig, out / 'nps_fig02_exact_vs_approx.png'))

    # Simakis 1992 Figure 3: family over zeta.
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for k, zeta in enumerate(zetas):
        ax.plot(omegas, exact[k], color=plt.get_cmap('coolwarm')(k / (len(zetas) - 1)),
                label=f'$\\zeta$={zeta:.1f}')
    ax.set(xlabel=r'$\omega_n$ (U/L)', ylabel='exact critical look-ahead $d$ (vehicle lengths)',
           title='NPS AUV II exact stability curves (Simakis 1992 Figure 3 analogue)',
           ylim=(0, 2.0))
    ax.grid(alpha=0.3)
    ax.legend(ncol=3, fontsize=9)
    files.append(_save(fig, out / 'nps_fig03_zeta_family.png'))

    # Simakis 1992 Figures 5-8: sensitivity.
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5), sharex=True)
    for ax, (fig_no, name) in zip(axes.ravel(), zip((5, 6, 7, 8), DOC_SENSITIVITY)):
        s = sens[name]
        ax.plot(factors, s['fixed'], 'k-', lw=2, label='gains from nominal model (as NOMOV.FOR)')
        ax.plot(factors, s['redesign'], 'b--', lw=1.3, label='gains redesigned per variant')
        ax.axhline(1.0, color='0.6', lw=0.8)
        ax.axvline(1.0, color='0.6', lw=0.8)
        ax.set(title=f"Figure {fig_no}: {LATEX[name]}  total change {abs(s['total_fixed']):.3f} "
                     f"(document: about {DOC_SENSITIVITY[name]:g})",
               ylabel=r'$d_n = d/d_{nom}$')
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel('coefficient / nominal')
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(r'NPS AUV II critical look-ahead sensitivity, $\omega_n$ = 3, $\zeta$ = 0.8 '
                 '(Simakis 1992 Figures 5-8 analogue)')
    files.append(_save(fig, out / 'nps_fig05-08_sensitivity.png'))

    fig, ax = plt.subplots(figsize=(9, 6))
    for name in SENS_COEFFS:
        colour, style = SENS_STYLE[name]
        ax.plot(factors, sens[name]['fixed'], color=colour, ls=style,
                lw=2 if name in DOC_SENSITIVITY else 1.2,
                label=f"{LATEX[name]} ({sens[name]['total_fixed']:+.3f})")
    ax.set(xlabel='coefficient / nominal', ylabel=r'$d_n = d/d_{nom}$',
           title=r'All coefficients, gains fixed at the nominal design ($\omega_n$=3, $\zeta$=0.8)'
                 '\n(zero coefficients $Y_r$, $N_v$, $Y_{\\dot r}$, $N_{\\dot v}$ stay at 1)')
    ax.grid(alpha=0.3)
    ax.legend(ncol=2, fontsize=9, title='total change 0.5 -> 1.5')
    files.append(_save(fig, out / 'nps_sensitivity_all.png'))
    return files


def _save(fig, path):
    import matplotlib.pyplot as plt
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


# ---------------------------------------------------------------- outputs

def write_csv(path, rows):
    with open(path, 'w', newline='') as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def summary_md(t1, omegas, zetas, exact, approx, checks, sens, nomoto, files):
    rows = t1['rows']
    n_exact = sum(r['matches_exact'] for r in rows)
    lines = ['# String stability: reproduction summary', '',
             'Generated by `scripts/string_stability.py`; method and explanations in '
             '`ros_ws/src/ship_guidance/doc/string_stability.md`.', '',
             '## Angelopoulos 2011 Table 1', '',
             f"- Printed rows: {len(rows)} (the scan covers 540; missing: "
             + ', '.join(f"zeta {m['zeta']:g}, wn1 {m['wn1']:g}, wn2 {m['wn2']:g} "
                         f"(d2* = {m['d2_star']:.3f} > 2)" for m in t1['missing']) + ').',
             f"- d1*, d2*: largest difference to the printed 6 decimals "
             f"{t1['d_star_max_err']:.1e}.",
             f"- Grid minima equal to the exact boundary (first grid point above d*): "
             f"{n_exact} of {len(rows)} rows; all {sum(r['consistent_with_method'] for r in rows)}"
             f" rows are what Appendix A's method gives for their class.",
             f"- Timing (540 rows x 196 x 196 grid points): Routh test "
             f"{1e3 * t1['timing']['routh']['best_s']:.1f} ms best / "
             f"{1e3 * t1['timing']['routh']['median_s']:.1f} ms median; eigenvalues of the 3x3 "
             f"diagonal blocks {t1['timing']['eig']['best_s']:.2f} s best / "
             f"{t1['timing']['eig']['median_s']:.2f} s median; both give identical minima: "
             f"{t1['eig_equals_routh']}."]
    if 'appendix_a_literal_s' in t1['timing']:
        lines.append(f"- The literal Appendix A scan (full 6x6 eig at every grid point, numpy): "
                     f"{t1['timing']['appendix_a_literal_s']:.1f} s for "
                     f"{t1['timing']['appendix_a_literal_rows']} rows.")
    lines += ['', '### Rows that differ from the exact boundary', '',
              '| CSV line | zeta | wn1 | wn2 | printed d1, d2 | exact grid d1, d2 | d1*, d2* '
              '| class |',
              '|---|---|---|---|---|---|---|---|']
    for r in rows:
        if not r['matches_exact']:
            lines.append(f"| {r['csv_line']} | {r['zeta']:g} | {r['wn1']:g} | {r['wn2']:g} | "
                         f"{r['doc_d1_sim']:g}, {r['doc_d2_sim']:g} | {r['exact_d1_grid']:g}, "
                         f"{r['exact_d2_grid']:g} | {r['d1_star']:g}, {r['d2_star']:g} | "
                         f"{r['class']} |")
    if t1['brute']:
        lines += ['', '### Literal Appendix A scan (numpy LAPACK) on the explained rows', '',
                  'Same method, different rounding noise: where a limit lies on the grid the '
                  'marginal eigenvalues have a real part of about 1e-16 whose sign decides.', '',
                  '| CSV line | zeta | wn1 | wn2 | class | document | numpy scan | exact |',
                  '|---|---|---|---|---|---|---|---|']
        for b in t1['brute']:
            lines.append(f"| {b['csv_line']} | {b['zeta']:g} | {b['wn1']:g} | {b['wn2']:g} | "
                         f"{b['class']} | {b['doc'][0]:g}, {b['doc'][1]:g} | "
                         f"{b['numpy_scan'][0]:g}, {b['numpy_scan'][1]:g} | "
                         f"{b['exact'][0]:g}, {b['exact'][1]:g} |")
    lines += ['', '## Simakis 1992: NPS AUV II exact critical look-ahead', '',
              f'Nomoto reduction (Simakis 1992 eq. 2.11, non-dimensional): a = {nomoto[0]:.4f}, '
              f'b = {nomoto[1]:.4f}.', '',
              '| zeta | omega_n | k1 | k2 | exact (Routh) | eigenvalue bisection '
              '| approx 1/(2 zeta wn) | exact/approx |',
              '|---|---|---|---|---|---|---|---|']
    for c in checks:
        lines.append(f"| {c['zeta']:g} | {c['omega_n']:g} | {c['k1']:.3f} | {c['k2']:.3f} | "
                     f"{c['exact_routh']:.5f} | {c['eigen_bisection']:.5f} | {c['approx']:.5f} |"
                     f" {c['exact_routh'] / c['approx']:.3f} |")
    lines += ['', 'exact / approximate over the grid (rows zeta, columns omega_n):', '',
              '| zeta \\ omega_n | ' + ' | '.join(f'{w:g}' for w in omegas[::10]) + ' |',
              '|---' * (1 + len(omegas[::10])) + '|']
    for k, z in enumerate(zetas):
        lines.append(f'| {z:.1f} | ' + ' | '.join(
            f'{e / a:.3f}' for e, a in zip(exact[k, ::10], approx[k, ::10])) + ' |')
    lines += ['', '## Simakis 1992: sensitivity (omega_n = 3, zeta = 0.8, coefficient x 0.5 ... '
              '1.5)',
              '', '| coefficient | nominal | d_n at 0.5 | d_n at 1.5 | total change (gains fixed) '
              '| total change (gains redesigned) | document |', '|---|---|---|---|---|---|---|']
    for name in SENS_COEFFS:
        s = sens[name]
        doc = DOC_SENSITIVITY.get(name)
        lines.append(f"| {name} | {s['nominal']:g} | {s['fixed'][0]:.4f} | {s['fixed'][-1]:.4f} | "
                     f"{s['total_fixed']:+.4f} | {s['total_redesign']:+.4f} | "
                     f"{'about %g' % doc if doc else ''} |")
    lines += ['', '## Files', ''] + [f'- {Path(f).name}' for f in files]
    return '\n'.join(lines) + '\n'


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--out', type=Path, default=DEFAULT_OUT)
    ap.add_argument('--table', type=Path, default=DEFAULT_TABLE)
    ap.add_argument('--brute-force', choices=('none', 'explained', 'all'), default='explained',
                    help='run the literal 6x6 Appendix A scan on no rows, on the rows that '
                         'differ from the exact boundary (default, ~10 s), or on all (~3 min)')
    ap.add_argument('--no-plots', action='store_true')
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    table = load_table(args.table)
    t1 = reproduce_table1(table, args.brute_force)
    write_csv(args.out / 'table1_reproduction.csv', t1['rows'])

    omegas = np.round(np.arange(0.5, 6.0001, 0.05), 2)
    zetas = np.round(np.arange(0.4, 1.2001, 0.1), 1)
    exact, approx, checks, nomoto = nps_auv2(omegas, zetas)
    write_csv(args.out / 'nps_auv2_critical.csv', [
        {'zeta': z, 'omega_n': w, 'exact': round(float(exact[i, j]), 6),
         'approx': round(float(approx[i, j]), 6),
         'ratio': round(float(exact[i, j] / approx[i, j]), 6)}
        for i, z in enumerate(zetas) for j, w in enumerate(omegas)])

    factors = np.round(np.linspace(0.5, 1.5, 101), 2)
    sens = sensitivity(factors)
    write_csv(args.out / 'nps_auv2_sensitivity.csv', [
        {'factor': f, **{f'{n}_fixed': round(float(sens[n]['fixed'][i]), 6) for n in SENS_COEFFS},
         **{f'{n}_redesign': round(float(sens[n]['redesign'][i]), 6) for n in SENS_COEFFS}}
        for i, f in enumerate(factors)])

    files = [] if args.no_plots else plots(args.out, table, omegas, zetas, exact, approx,
                                           checks, sens, factors)
    (args.out / 'summary.md').write_text(
        summary_md(t1, omegas, zetas, exact, approx, checks, sens, nomoto, files))
    (args.out / 'summary.json').write_text(json.dumps({
        'table1': {k: t1[k] for k in ('timing', 'eig_equals_routh', 'missing', 'brute',
                                      'd_star_max_err')},
        'table1_rows_differing': [r for r in t1['rows'] if not r['matches_exact']],
        'nps_auv2_checks': checks, 'nomoto_ab_nondim': nomoto,
        'sensitivity_totals': {n: {'fixed': sens[n]['total_fixed'],
                                   'redesign': sens[n]['total_redesign']} for n in SENS_COEFFS},
    }, indent=1, default=float))

    bad = [r for r in t1['rows'] if not r['consistent_with_method']]
    tm = t1['timing']
    print(f"Table 1: {len(t1['rows'])} rows, {sum(r['matches_exact'] for r in t1['rows'])} equal "
          f"to the exact boundary, {len(bad)} unexplained; Routh scan "
          f"{1e3 * tm['routh']['best_s']:.1f} ms, block-eig scan {tm['eig']['best_s']:.2f} s")
    c = checks[0]
    print(f"NPS AUV II (zeta 0.8, wn 3): exact {c['exact_routh']:.5f}, eigen bisection "
          f"{c['eigen_bisection']:.5f}, approx {c['approx']:.5f}")
    print('sensitivity totals (gains fixed): ' + ', '.join(
        f"{n} {sens[n]['total_fixed']:+.3f}" for n in DOC_SENSITIVITY))
    print(f'wrote {args.out}')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
