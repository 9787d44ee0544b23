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
- nps_auv2_sensitivity_map.csv: Simakis 1992 Figs. 9-12, d_n at +-50 % of Yvdot and Yv over
  the (zeta, omega_n) grid (gains fixed at each point's nominal design), and the largest
  deviation |d_n - 1| per point; nps_auv2_gains.csv: Simakis 1992 Fig. 4, k1, k2 vs omega_n.
- eigenvalue_path.csv: Angelopoulos 2011 Fig. 16, the eigenvalues of one vessel's matrix
  (eq. 30) as d1 runs from 4 d1* down to d1*/2, through d1*.
- summary.md and summary.json: timing, the rows that differ and why, the NPS AUV II numbers;
  summary.json carries its provenance (doc/results/string_stability.md renders from its
  committed copy, doc/results/data/string_stability.json).
- PNGs: Angelopoulos 2011 Figures 9-11 (stability regions d2 vs d1), 12-15 (limits vs
  omega_n) and 16 (eigenvalue path), Simakis 1992 Figures 2, 3 (exact vs approximate limit),
  4 (gains vs omega_n), 5-8 (sensitivity) and 9-12 (sensitivity over zeta and omega_n, as
  curves and as maps).
``--map-zetas`` / ``--map-omegas`` set the sensitivity grid, ``--path-design`` the (zeta,
omega_n) pairs of the eigenvalue path.
Exit code 0; 1 if a printed Table 1 value contradicts the method (an unexplained row).
"""
import argparse
import csv
import json
import sys
import time
from pathlib import Path

import numpy as np
from results_pages.provenance import provenance

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


#: Simakis 1992 Figs. 9-12 vary the two coefficients that matter most (Figs. 5-6).
MAP_COEFFS = ('Yvdot', 'Yv')
#: Simakis 1992 Figs. 9-12, as the text reads: "the maximum deviation in the critical value of
#: d for stability is 40% of its nominal value, while for most of the cases this deviation is
#: well below 20%".
DOC_MAP_MAX, DOC_MAP_MOST = 0.40, 0.20


def sensitivity_map(zetas, omegas, factors):
    """Simakis 1992 Figs. 9-12: d_n(factor) of MAP_COEFFS at every (zeta, omega_n), the gains
    designed on the nominal vehicle at that point (as NOMOV.FOR). Returns {name: array (Z, W, F)}
    and the nominal exact limit (Z, W)."""
    nominal = sy.nps_auv2_critical_lookahead(np.asarray(zetas)[:, None],
                                             np.asarray(omegas)[None])
    out = {}
    for name in MAP_COEFFS:
        out[name] = np.array([[sy.nps_auv2_sensitivity(name, factors, zeta=z, omega_n=w)
                               for w in omegas] for z in zetas])
    return out, nominal


def gain_curves(omegas, zetas):
    """Simakis 1992 Fig. 4: PD gains k1, k2 (non-dimensional) of the nominal NPS AUV II over
    omega_n, one curve per zeta; shape (Z, W) each."""
    a, b = sy.nps_auv2_nomoto()
    return np.broadcast_arrays(*pd_gains(a, b, zeta=np.asarray(zetas)[:, None],
                                         omega_n=np.asarray(omegas)[None]))


def eigenvalue_path(zeta, omega_n, ratios):
    """Angelopoulos 2011 Fig. 16: eigenvalues (len(ratios), 3) of one vessel's matrix (eq. 30,
    non-dimensional) at d1 = ratio * d1*, d1* = 1 / (2 zeta omega_n)."""
    d_star = float(critical_lookahead_nondim(zeta, omega_n))
    lam = ss.string_eigenvalues(zeta, omega_n, np.asarray(ratios) * d_star)
    return np.sort_complex(lam), d_star


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


def plots_maps_and_path(out, maps, nominal, map_zetas, map_omegas, factors, gains, gain_omegas,
                        gain_zetas, paths, ratios):
    """Simakis 1992 Figs. 4 and 9-12 (and the maps behind them), Angelopoulos 2011 Fig. 16."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    files = []
    # Fig. 4: gains vs omega_n.
    fig, ax = plt.subplots(figsize=(8, 5.5))
    k1, k2 = gains
    for k, zeta in enumerate(gain_zetas):
        c = plt.get_cmap('coolwarm')(k / max(1, len(gain_zetas) - 1))
        ax.plot(gain_omegas, k2[k], color=c, ls='--', lw=1.8 if abs(zeta - 0.8) < 1e-9 else 0.9,
                label=f'$k_2$, $\\zeta$={zeta:.1f}')
    ax.plot(gain_omegas, k1[0], 'k-', lw=2, label='$k_1$ (any $\\zeta$)')
    ax.plot([3.0, 3.0], [3.2, 1.2], 'rs', mfc='none', ms=9, label='document at $\\omega_n$=3: '
            'about 3.2 and 1.2')
    ax.set(xlabel=r'$\omega_n$ (U/L)', ylabel='gain (rad/rad; rad/(rad L/U))',
           title='NPS AUV II PD gains vs $\\omega_n$ (Simakis 1992 Figure 4 analogue)')
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    files.append(_save(fig, out / 'nps_fig04_gains.png'))

    # Figs. 9-12: d_n curves, zeta family at omega_n = 3 and omega_n family at zeta = 0.8.
    iw = int(np.argmin(np.abs(np.asarray(map_omegas) - 3.0)))
    iz = int(np.argmin(np.abs(np.asarray(map_zetas) - 0.8)))
    fig, axes = plt.subplots(2, 2, figsize=(12, 9), sharex=True, sharey=True)
    for col, name in enumerate(MAP_COEFFS):
        ax = axes[0, col]
        for k, zeta in enumerate(map_zetas):
            ax.plot(factors, maps[name][k, iw], color=plt.get_cmap('coolwarm')(
                k / max(1, len(map_zetas) - 1)), label=f'$\\zeta$={zeta:.1f}')
        ax.set(title=f'Figure {9 + col}: {LATEX[name]}, $\\omega_n$ = {map_omegas[iw]:g}, '
                     'zeta varied')
        ax = axes[1, col]
        for k, w in enumerate(map_omegas):
            ax.plot(factors, maps[name][iz, k], color=plt.get_cmap('viridis')(
                k / max(1, len(map_omegas) - 1)), label=f'$\\omega_n$={w:g}')
        ax.set(title=f'Figure {11 + col}: {LATEX[name]}, $\\zeta$ = {map_zetas[iz]:g}, '
                     'omega_n varied', xlabel='coefficient / nominal')
    for ax in axes.ravel():
        ax.axhline(1.0, color='0.6', lw=0.8)
        for lim in (1 - DOC_MAP_MAX, 1 + DOC_MAP_MAX):
            ax.axhline(lim, color='r', ls=':', lw=0.8)
        ax.grid(alpha=0.3)
        ax.set_ylabel('$d_n = d/d_{nom}$')
    axes[0, 1].legend(fontsize=7, ncol=2)
    axes[1, 1].legend(fontsize=7, ncol=2)
    fig.suptitle('NPS AUV II critical look-ahead sensitivity (Simakis 1992 Figures 9-12 '
                 'analogue); red dotted: the document\'s largest deviation, 40 %')
    files.append(_save(fig, out / 'nps_fig09-12_sensitivity_zeta_omega.png'))

    # The maps: largest |d_n - 1| over +-50 % at every grid point.
    fig, axes = plt.subplots(1, len(MAP_COEFFS), figsize=(13, 5.2), sharey=True)
    for ax, name in zip(axes, MAP_COEFFS):
        dev = np.nanmax(np.abs(maps[name] - 1.0), axis=2)
        im = ax.pcolormesh(map_omegas, map_zetas, 100 * dev, shading='nearest', cmap='magma_r',
                           vmin=0, vmax=max(60.0, 100 * float(np.nanmax(dev))))
        cs = ax.contour(map_omegas, map_zetas, 100 * dev, levels=[20, 40], colors=['w', 'c'])
        ax.clabel(cs, fmt='%d %%', fontsize=8)
        ax.set(xlabel=r'$\omega_n$ (U/L)', title=f'{LATEX[name]}: max $|d_n - 1|$ (%) over '
               '0.5-1.5 x nominal')
        fig.colorbar(im, ax=ax)
    axes[0].set_ylabel(r'$\zeta$')
    fig.suptitle('Where the critical look-ahead is sensitive (Simakis 1992 Figs. 9-12 as maps)')
    files.append(_save(fig, out / 'nps_sensitivity_map.png'))

    # Angelopoulos 2011 Fig. 16.
    fig, ax = plt.subplots(figsize=(8.5, 6.5))
    for k, ((zeta, w), (lam, d_star)) in enumerate(paths.items()):
        c = f'C{k}'
        osc = np.where(np.abs(lam.imag) > 1e-12, lam, np.nan)
        ax.plot(osc.real, osc.imag, '.', color=c, ms=2.5)
        at = int(np.argmin(np.abs(np.asarray(ratios) - 1.0)))
        ax.plot(lam[at].real, lam[at].imag, 'o', color=c, ms=7, mfc='none',
                label=f'$\\zeta$={zeta:g}, $\\omega_n$={w:g}: $d_1^*$={d_star:.3f}, '
                      f'$\\pm i\\omega_n$ at $d_1^*$')
        for end, mk in ((0, '>'), (-1, 'x')):
            ax.plot(lam[end].real, lam[end].imag, mk, color=c, ms=6)
    ax.axvline(0.0, color='k', lw=0.8)
    ax.set(xlabel='Re $\\lambda$ (U/L)', ylabel='Im $\\lambda$ (U/L)',
           title='Eigenvalues of one vessel (eq. 30) as $d_1$ falls from '
                 f'{ratios[0]:g} $d_1^*$ (>) to {ratios[-1]:g} $d_1^*$ (x)\n'
                 '(Angelopoulos 2011 Figure 16 analogue; the real eigenvalue is off the plot '
                 'where it is far left)')
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    files.append(_save(fig, out / 'fig16_eigenvalue_path.png'))
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


def map_summary(maps, nominal, map_zetas, map_omegas, factors):
    """Simakis 1992 Figs. 9-12 in numbers: the largest |d_n - 1| over 0.5-1.5 x nominal at
    each grid point, per coefficient, and the share of points under 20 % / 40 %."""
    lines = ['## Simakis 1992 Figs. 9-12: sensitivity over zeta and omega_n', '',
             f'd_n = d_crit(coefficient x f) / d_crit(nominal), f = {factors[0]:g} ... '
             f'{factors[-1]:g}, gains designed on the nominal vehicle at each (zeta, omega_n). '
             f'Document: largest deviation 40 %, most cases well below 20 %.', '']
    stats = {}
    for name in MAP_COEFFS:
        dev = np.nanmax(np.abs(maps[name] - 1.0), axis=2)
        ok = np.isfinite(dev)
        every = np.abs(maps[name] - 1.0)
        every = every[np.isfinite(every)]
        stats[name] = {'max': float(np.nanmax(dev)),
                       'share_below_20': float(np.mean(dev[ok] < DOC_MAP_MOST)),
                       'share_below_40': float(np.mean(dev[ok] <= DOC_MAP_MAX)),
                       # every (variation, grid point) pair: what a reader of the curves sees
                       'share_values_below_20': float(np.mean(every < DOC_MAP_MOST))}
        lines += [f'### {name}: largest |d_n - 1| (%)', '',
                  '| zeta \\ omega_n | ' + ' | '.join(f'{w:g}' for w in map_omegas) + ' |',
                  '|---' * (1 + len(map_omegas)) + '|']
        lines += [f'| {z:.1f} | ' + ' | '.join(f'{100 * v:.0f}' for v in dev[i]) + ' |'
                  for i, z in enumerate(map_zetas)]
        lines += ['', f"max {100 * stats[name]['max']:.0f} %; grid points whose largest "
                      f"deviation is below 20 %: {100 * stats[name]['share_below_20']:.0f} %, "
                      f"at most 40 %: {100 * stats[name]['share_below_40']:.0f} %; all "
                      f"(variation, grid point) values below 20 %: "
                      f"{100 * stats[name]['share_values_below_20']:.0f} %", '']
    for name in MAP_COEFFS:   # the document's two slices: Figs. 9-10 and 11-12
        iw = int(np.argmin(np.abs(np.asarray(map_omegas) - 3.0)))
        iz = int(np.argmin(np.abs(np.asarray(map_zetas) - 0.8)))
        dev = np.nanmax(np.abs(maps[name] - 1.0), axis=2)
        stats[name]['slice_omega_n'] = {'omega_n': float(map_omegas[iw]),
                                        'zetas': [float(z) for z in map_zetas],
                                        'max_abs_dev': [float(v) for v in dev[:, iw]]}
        stats[name]['slice_zeta'] = {'zeta': float(map_zetas[iz]),
                                     'omegas': [float(w) for w in map_omegas],
                                     'max_abs_dev': [float(v) for v in dev[iz]]}
        lines.append(f"- {name}: omega_n = {map_omegas[iw]:g}, zeta {map_zetas[0]:g}-"
                     f"{map_zetas[-1]:g}: {', '.join(f'{100 * v:.0f}' for v in dev[:, iw])} %; "
                     f"zeta = {map_zetas[iz]:g}, omega_n {map_omegas[0]:g}-{map_omegas[-1]:g}: "
                     f"{', '.join(f'{100 * v:.0f}' for v in dev[iz])} %")
    lines.append('')
    return lines, stats


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--out', type=Path, default=DEFAULT_OUT)
    ap.add_argument('--table', type=Path, default=DEFAULT_TABLE)
    ap.add_argument('--brute-force', choices=('none', 'explained', 'all'), default='explained',
                    help='run the literal 6x6 Appendix A scan on no rows, on the rows that '
                         'differ from the exact boundary (default, ~10 s), or on all (~3 min)')
    ap.add_argument('--no-plots', action='store_true')
    ap.add_argument('--map-zetas', type=float, nargs='+',
                    default=[round(z, 1) for z in np.arange(0.4, 1.2001, 0.1)],
                    help='zeta grid of the sensitivity maps (default 0.4 ... 1.2 step 0.1, the '
                    'range of Simakis 1992 Fig. 3)')
    ap.add_argument('--map-omegas', type=float, nargs='+',
                    default=[round(w, 1) for w in np.arange(1.0, 6.0001, 0.5)],
                    help='omega_n grid (U/L) of the sensitivity maps (default 1 ... 6 step 0.5)')
    ap.add_argument('--path-design', type=float, nargs=2, action='append', metavar=('ZETA', 'WN'),
                    help='(zeta, omega_n) of an eigenvalue path (repeatable; default 0.8 1, '
                    '0.8 2, 0.4 1)')
    args = ap.parse_args(argv)
    args.path_design = args.path_design or [(0.8, 1.0), (0.8, 2.0), (0.4, 1.0)]
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

    # Simakis 1992 Figs. 9-12 (sensitivity over zeta, omega_n) and Fig. 4 (gains).
    map_factors = np.round(np.linspace(0.5, 1.5, 21), 2)
    maps, map_nominal = sensitivity_map(args.map_zetas, args.map_omegas, map_factors)
    write_csv(args.out / 'nps_auv2_sensitivity_map.csv', [
        {'coefficient': name, 'zeta': z, 'omega_n': w,
         'd_nominal': round(float(map_nominal[i, j]), 6),
         **{f'dn_{f:g}': round(float(maps[name][i, j, k]), 6) for k, f in enumerate(map_factors)},
         'max_abs_dev': round(float(np.nanmax(np.abs(maps[name][i, j] - 1.0))), 6)}
        for name in MAP_COEFFS for i, z in enumerate(args.map_zetas)
        for j, w in enumerate(args.map_omegas)])
    gain_omegas = np.round(np.arange(0.5, 6.0001, 0.1), 2)
    gains = gain_curves(gain_omegas, zetas)
    write_csv(args.out / 'nps_auv2_gains.csv', [
        {'zeta': z, 'omega_n': w, 'k1': round(float(gains[0][i, j]), 6),
         'k2': round(float(gains[1][i, j]), 6)}
        for i, z in enumerate(zetas) for j, w in enumerate(gain_omegas)])
    # Angelopoulos 2011 Fig. 16: d1 from 4 d1* down to d1*/2 (ratio 1 exactly on the grid).
    ratios = np.concatenate([np.geomspace(4.0, 1.0, 301), np.geomspace(1.0, 0.5, 151)[1:]])
    paths = {tuple(zw): eigenvalue_path(zw[0], zw[1], ratios) for zw in args.path_design}
    write_csv(args.out / 'eigenvalue_path.csv', [
        {'zeta': z, 'omega_n': w, 'd1_over_d1star': round(float(q), 6),
         'd1': round(float(q * d_star), 6),
         **{f'lambda{k + 1}_{part}': round(float(getattr(lam[i, k], part)), 9)
            for k in range(3) for part in ('real', 'imag')}}
        for (z, w), (lam, d_star) in paths.items() for i, q in enumerate(ratios)])

    files = [] if args.no_plots else plots(args.out, table, omegas, zetas, exact, approx,
                                           checks, sens, factors)
    if not args.no_plots:
        files += plots_maps_and_path(args.out, maps, map_nominal, args.map_zetas,
                                     args.map_omegas, map_factors, gains, gain_omegas, zetas,
                                     paths, ratios)
    map_lines, map_stats = map_summary(maps, map_nominal, args.map_zetas, args.map_omegas,
                                       map_factors)
    i3 = int(np.argmin(np.abs(gain_omegas - 3.0)))
    iz8 = int(np.argmin(np.abs(zetas - 0.8)))
    path_lines = ['## Angelopoulos 2011 Fig. 16: eigenvalues as d1 -> d1*', '',
                  '| zeta | omega_n | d1* | at 2 d1* | at d1* | at d1*/2 |', '|---|---|---|---|---|---|']
    path_points = []
    for (z, w), (lam, d_star) in paths.items():
        cells = []
        point = {'zeta': z, 'omega_n': w, 'd1_star': float(d_star), 'at': {}}
        for q in (2.0, 1.0, 0.5):
            i = int(np.argmin(np.abs(ratios - q)))
            pair = lam[i][np.argmax(lam[i].imag)]
            real = lam[i][np.argmin(np.abs(lam[i].imag))]
            cells.append(f'{pair.real:+.4f} +- {pair.imag:.4f} i, {real.real:.4f}')
            point['at'][f'{q:g}'] = {'pair_real': float(pair.real), 'pair_imag': float(pair.imag),
                                     'real': float(real.real)}
        path_points.append(point)
        path_lines.append(f'| {z:g} | {w:g} | {d_star:.4f} | ' + ' | '.join(cells) + ' |')
    extra = (['', '## Simakis 1992 Fig. 4: PD gains at omega_n = 3', '',
              f'k1 = {gains[0][iz8, i3]:.3f}, k2 = {gains[1][iz8, i3]:.3f} at zeta 0.8 '
              '(document: about 3.2 and 1.2)', ''] + map_lines + path_lines)
    (args.out / 'summary.md').write_text(
        summary_md(t1, omegas, zetas, exact, approx, checks, sens, nomoto, files)
        + '\n'.join(extra) + '\n')
    classes = {}
    for r in t1['rows']:
        c = classes.setdefault(r['class'], {'rows': 0, 'equal_exact_boundary': 0,
                                            'consistent_with_method': 0})
        c['rows'] += 1
        c['equal_exact_boundary'] += r['matches_exact']
        c['consistent_with_method'] += r['consistent_with_method']
    (args.out / 'summary.json').write_text(json.dumps({
        'provenance': provenance(argv and [sys.argv[0], *argv]),
        'table1': {**{k: t1[k] for k in ('timing', 'eig_equals_routh', 'missing', 'brute',
                                         'd_star_max_err')},
                   'printed_rows': len(t1['rows']),
                   'scanned_rows': len(t1['rows']) + len(t1['missing']),
                   'classes': classes},
        'table1_rows_differing': [r for r in t1['rows'] if not r['matches_exact']],
        'nps_auv2_checks': checks, 'nomoto_ab_nondim': nomoto,
        'document_sensitivity': DOC_SENSITIVITY,
        'document_map': {'max_abs_dev': DOC_MAP_MAX, 'most_below': DOC_MAP_MOST},
        'sensitivity_totals': {n: {'fixed': sens[n]['total_fixed'],
                                   'redesign': sens[n]['total_redesign']} for n in SENS_COEFFS},
        'sensitivity_map': map_stats,
        'eigenvalue_path': path_points,
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
    print('sensitivity over zeta, omega_n (Simakis 1992 Figs. 9-12; document: max 40 %, mostly '
          '< 20 %): ' + ', '.join(f"{n} max {100 * v['max']:.0f} %, "
                                   f"{100 * v['share_values_below_20']:.0f} % of the values "
                                   '< 20 %' for n, v in map_stats.items()))
    print(f'wrote {args.out}')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
