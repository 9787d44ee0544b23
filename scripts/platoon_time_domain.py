#!/usr/bin/env python3
"""Time-domain confirmation of the platoon stability limit (seed 001 eqs. 31-41), pure, in-process.

    scripts/platoon_time_domain.py [--models nomoto1 mariner] [--vessels 5] [--margin 0.1]
        [--dt 0.5] [--t-end 30000] [--y0 1e-6] [--ceiling 1] [--out DIR] [--no-plots]

The platoon: N identical vessels on a straight route due north, each a ship_sim model (its
batched ``model.step``, RK4 as the simulator; every vessel of every case in one array), each with
the PD autopilot of its ship_autopilot gains entry (001 eq. 20: zeta, omega_n; ship_autopilot.pd,
rudder saturated at the model's limit), sampled every dt (zero-order hold, as the lockstep graph
does). The leader steers LOS with look-ahead d1, follower i the follower law of
ship_guidance.follower (001 eq. 31, nonlinear atan form) with the look-ahead = its measured
along-path gap to vessel i-1 (no spacing control: the speeds are the ships' own), started at d_i.

Cases: every look-ahead (1 +- margin) d*, "above" and "below" the limit, for two limits: the
document's d*_doc = U / (2 zeta omega_n) (001 eq. 34 in metres), and d*_sampled, the exact limit
of the simulated loop (below). The below cases also run again without a stop, to see where the
nonlinear ship ends up (limit cycle or divergence).

Equilibrium: a ship that needs rudder to run straight (the MSS mariner: about -1.1 deg, its
asymmetry terms Y0, N0) under a PD autopilot without integral settles with a heading and
cross-track offset y_eq(d); follower i then sits at y_{i-1} + y_eq(d_i). It is solved from the
closed-loop derivative (``equilibrium``); the Nomoto model's is zero. The leader starts y0 off
its equilibrium, the others at theirs, so the disturbance travels down the string.

Measured (``envelope_rate``): the growth rate sigma of the envelope of each vessel's cross-track
deviation from equilibrium: half the swing between consecutive extrema (``envelope_peaks``, so a
slowly drifting mean does not bias it), log A = c + sigma t + m log t
fitted by least squares with m = vessel index. The t^m factor is part of the linear response:
the blocks are identical, so vessel i is driven at its own resonance by vessel i-1 and its
deviation is a polynomial of degree i times e^{lambda t} (a Jordan chain); the raw slope (m = 0)
is printed too. Peaks are used after t_skip (the fast real mode has died out), while the
amplitude stays below --ceiling (linear regime; on the mariner the growth
below its limit levels off a few metres further up, see below)
and down to 1e-6 of the vessel's largest swing. Below that, rounding noise (about 1e-13 m on
the leader) shows up, amplified by each follower's resonance: in the decaying cases the
followers end on a noise floor that grows about tenfold per vessel.

Predicted: the real part of the dominant oscillatory eigenvalue pair of one vessel's loop
(every follower's block has the same, 001 eq. 40):
- doc:     001 eq. 30/33 (string_stability.single_vessel_matrix: Nomoto, PD, linearised LOS);
- sampled: the Jacobian of one step dt of the simulated closed loop at the equilibrium (model,
           rudder servo, PD with zero-order hold, LOS), lambda = log(mu) / dt; for the MSS
           mariner this includes its sway dynamics. The exact critical look-ahead of this loop
           (bisection on the sign of its dominant real part) is reported as d*_sampled.

Writes to --out: summary.json, rates.csv, and PNGs <model>_cross_track.png (cross-track
deviation of each vessel vs time above/below, linear and log envelope with the fits).
"""
import argparse
import csv
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from ship_autopilot.gains import autopilot_gains
from ship_autopilot.pd import PDAutopilot
from ship_autopilot.rudder import RudderLimiter
from ship_guidance.follower import (follower_gain, follower_heading_straight,
                                    no_amplification_spacing)
from ship_guidance.string_stability import single_vessel_matrix
from ship_sim.frames import wrap_angle
from ship_sim.models import make_model

ROOT = Path(__file__).resolve().parents[1]

DEFAULT_OUT = ROOT / 'runs' / 'analysis' / 'platoon_time_domain'
#: Deviation (m) at which a run without a stop counts as diverged.
LONG_RUN_STOP = 1e4
#: Envelope samples used down to this fraction of a vessel's largest one (see ``analyse``).
FIT_DECADES = 1e-6


@dataclass
class Loop:
    """One vessel's closed loop: model, PD gains (k1, k2), design zeta, omega_n (rad/s), speed U
    (m/s) and the document's critical look-ahead d* = U / (2 zeta omega_n) (m)."""
    name: str
    model: object
    k1: float
    k2: float
    zeta: float
    omega_n: float
    speed: float
    d_crit: float


def make_loop(name):
    """The model ``name`` with its autopilot_gains entry."""
    model = make_model(name)
    g = autopilot_gains(name)
    speed = float(model.surge_speed(model.initial_state()))
    zeta, omega_n = float(g['zeta']), float(g['omega_n'])
    return Loop(name, model, float(g['pd']['k1']), float(g['pd']['k2']), zeta, omega_n, speed,
                speed / (2.0 * zeta * omega_n))


# ---------------------------------------------------------------- one vessel's loop

def rudder_law(loop, x, psi_c):
    """PD (001 eq. 16) as ship_autopilot.pd, hard-saturated at the model's rudder limit."""
    m = loop.model
    raw = loop.k1 * wrap_angle(x[..., m.IPSI] - psi_c) + loop.k2 * x[..., m.IR]
    return np.clip(raw, -m.rudder_max, m.rudder_max)


def loop_rhs(loop, x, d, y_pred=0.0):
    """Closed-loop derivative: model + PD + (follower) LOS about a path due north; y_pred is the
    predecessor's cross-track (0 for the leader)."""
    m = loop.model
    psi_c = follower_heading_straight(0.0, x[..., m.IY], y_pred, d)
    return m.rhs(x, m.inputs(rudder_law(loop, x, psi_c)))


def loop_step(loop, x, d, dt, y_pred=0.0):
    """One sampled step: rudder computed at the start and held over dt (as the simulator)."""
    m = loop.model
    psi_c = follower_heading_straight(0.0, x[..., m.IY], y_pred, d)
    return m.step(x, m.inputs(rudder_law(loop, x, psi_c)), dt)


def _free(loop):
    """State indices that evolve: all but north (no dynamics depends on it)."""
    return [i for i in range(loop.model.n_states) if i != loop.model.IX]


def equilibrium(loop, d):
    """Straight-running equilibrium of the LOS loop with look-ahead d (m), full state (north 0).

    Solved by least squares on the closed-loop derivative without the north component; for a
    model whose speed is a constant (Nomoto) that state simply stays at its trim value."""
    m = loop.model
    x0 = np.asarray(m.initial_state(), dtype=float)
    free = _free(loop)

    def resid(z):
        x = x0.copy()
        x[free] = z
        return loop_rhs(loop, x, d)[free]

    sol = least_squares(resid, x0[free], method='lm', xtol=1e-15, ftol=1e-15, gtol=1e-15)
    x = x0.copy()
    x[free] = sol.x
    if np.max(np.abs(resid(sol.x))) > 1e-9:
        raise RuntimeError(f'{loop.name}: no equilibrium found for d = {d} m')
    return x


def sampled_eigenvalues(loop, d, dt, x_eq=None):
    """Continuous-time equivalents log(mu)/dt of the eigenvalues mu of the one-step map's
    Jacobian at the equilibrium (central differences). States whose derivative is identically
    zero (a constant speed) are parameters and left out."""
    x_eq = equilibrium(loop, d) if x_eq is None else x_eq
    free = _free(loop)
    n = len(free)
    jac = np.zeros((n, n))
    for j, k in enumerate(free):
        h = 1e-6 * max(1.0, abs(x_eq[k]))
        xp, xm = x_eq.copy(), x_eq.copy()
        xp[k] += h
        xm[k] -= h
        jac[:, j] = (loop_step(loop, xp, d, dt)[free] - loop_step(loop, xm, d, dt)[free]) / (2 * h)
    # A state whose derivative is zero at every perturbed state is a constant (Nomoto's u, v).
    rng = np.random.default_rng(0)
    probes = x_eq + 1e-3 * rng.standard_normal((4, len(x_eq)))
    moving = np.any(loop_rhs(loop, probes, d)[:, free] != 0.0, axis=0)
    keep = np.flatnonzero(moving)
    mu = np.linalg.eigvals(jac[np.ix_(keep, keep)])
    return np.log(mu.astype(complex)) / dt


def dominant_pair(lams):
    """The oscillatory eigenvalue with the largest real part (positive imaginary part)."""
    lams = np.asarray(lams)
    osc = lams[lams.imag > 1e-12]
    return osc[np.argmax(osc.real)]


def doc_eigenvalues(loop, d):
    """001 eq. 30 (dimensional: y' = U psi) eigenvalues for look-ahead d."""
    return np.linalg.eigvals(single_vessel_matrix(loop.zeta, loop.omega_n, d, loop.speed))


def sampled_critical_lookahead(loop, dt, lo=0.5, hi=2.0, rtol=1e-6):
    """Look-ahead where the sampled loop's dominant pair crosses the imaginary axis, by
    bisection between lo d* (unstable) and hi d* (stable)."""
    def re(d):
        return dominant_pair(sampled_eigenvalues(loop, d, dt)).real
    a, b = lo * loop.d_crit, hi * loop.d_crit
    if not (re(a) > 0.0 > re(b)):
        raise RuntimeError(f'{loop.name}: no stability change between {a:.1f} and {b:.1f} m')
    while b - a > rtol * b:
        mid = 0.5 * (a + b)
        a, b = (a, mid) if re(mid) < 0.0 else (mid, b)
    return b


# ---------------------------------------------------------------- the platoon

def simulate_platoon(loop, lookaheads, t_end, dt, y0, stop_amplitude=np.inf):
    """Simulate platoons of identical vessels on a path due north, all cases in one batch.

    lookaheads: (C, N) array, one row per case: d1 of the leader, then the initial gaps (the
    followers' look-aheads). The leader starts y0 (m) east of its equilibrium, the others at
    theirs. A case whose deviation exceeds stop_amplitude (m; scalar or one per case) is
    stopped: from then on it is
    held at its initial state and recorded as NaN. The follower law's look-ahead is the measured
    gap, floored at half the initial gap (as FollowerGuidance's min_lookahead; it acts only far
    outside the linear regime).
    Returns dict t (T,), dy (T, C, N) cross-track deviation from equilibrium, y_eq (C, N),
    stopped_at (C,) time of the stop or NaN."""
    m = loop.model
    d = np.atleast_2d(np.asarray(lookaheads, dtype=float))
    c, n = d.shape
    x = np.zeros((c, n, m.n_states))
    y_eq = np.zeros((c, n))
    for ci in range(c):
        ahead = offset = 0.0
        for i in range(n):
            xe = equilibrium(loop, d[ci, i])
            offset += xe[m.IY]          # follower i: y_{i-1} + y_eq(d_i)
            x[ci, i] = xe
            x[ci, i, m.IY] = y_eq[ci, i] = offset
            x[ci, i, m.IX] = -ahead
            if i + 1 < n:
                ahead += d[ci, i + 1]
    x[:, 0, m.IY] += y0
    x0 = x.copy()
    d_min = 0.5 * d[:, 1:]
    stop = np.broadcast_to(np.asarray(stop_amplitude, dtype=float), (c,))
    pd = PDAutopilot(loop.k1, loop.k2, RudderLimiter(m.rudder_max))
    steps = int(round(t_end / dt))
    dys = np.full((steps + 1, c, n), np.nan)
    stopped_at = np.full(c, np.nan)
    live = np.ones(c, dtype=bool)
    psi_c = np.empty((c, n))
    for k in range(steps + 1):
        north, east, psi = x[..., m.IX], x[..., m.IY], x[..., m.IPSI]
        dy = east - y_eq
        dys[k, live] = dy[live]
        over = live & ~(np.max(np.abs(dy), axis=1) <= stop)   # NaN counts as over
        if over.any():
            live &= ~over
            stopped_at[over] = k * dt
            x[over] = x0[over]
            if not live.any():
                dys = dys[:k + 1]
                break
        if k == steps:
            break
        psi_c[:, 0] = follower_heading_straight(0.0, east[:, 0], 0.0, d[:, 0])
        gap = np.maximum(north[:, :-1] - north[:, 1:], d_min)
        psi_c[:, 1:] = follower_heading_straight(0.0, east[:, 1:], east[:, :-1], gap)
        rudder = pd.update(psi, x[..., m.IR], psi_c, dt)
        x = m.step(x, m.inputs(rudder), dt)
        x[~live] = x0[~live]
    return {'t': dt * np.arange(len(dys)), 'dy': dys, 'y_eq': y_eq, 'stopped_at': stopped_at}


def envelope_peaks(t, y):
    """Envelope samples of an oscillation y(t) about a possibly drifting mean: half the
    difference between consecutive extrema (each refined by a parabola through three samples),
    at the mid time. Returns arrays (t_k, A_k)."""
    y = np.asarray(y, dtype=float)
    slope = np.diff(y)
    k = np.nonzero(slope[:-1] * slope[1:] < 0.0)[0] + 1
    y0, y1, y2 = y[k - 1], y[k], y[k + 1]
    den = y0 - 2.0 * y1 + y2
    off = 0.5 * (y0 - y2) / den
    h = t[1] - t[0]
    te, ve = t[k] + off * h, y1 - 0.25 * (y0 - y2) * off
    return 0.5 * (te[1:] + te[:-1]), 0.5 * np.abs(np.diff(ve))


def envelope_rate(t, y, t_skip, floor=0.0, ceiling=np.inf, power=0):
    """Growth rate sigma (1/s) of the envelope of y(t): least squares of
    log A_k - power log t_k = c + sigma t_k over the peaks with t_k >= t_skip and
    floor < A_k < ceiling. Returns (sigma, number of peaks used); NaN if fewer than 4."""
    tk, ak = envelope_peaks(t, y)
    sel = (tk >= t_skip) & (ak > floor) & (ak < ceiling)
    if np.count_nonzero(sel) < 4:
        return math.nan, int(np.count_nonzero(sel))
    tk, ak = tk[sel], ak[sel]
    slope = np.polyfit(tk, np.log(ak) - power * np.log(tk), 1)[0]
    return float(slope), int(tk.size)


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
    a = ap.parse_args(argv)
    a.out.mkdir(parents=True, exist_ok=True)
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
    (a.out / 'summary.json').write_text(json.dumps({'models': infos, 'rows': all_rows},
                                                   indent=1, default=float))
    print(f'\nwritten to {a.out}; every fitted growth rate has the sign of the sampled '
          f'eigenvalue: {ok}')
    return 0 if ok else 1


if __name__ == '__main__':
    raise SystemExit(main())
