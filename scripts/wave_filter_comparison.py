#!/usr/bin/env python3
"""Rudder activity and heading tracking with and without the autopilot's wave filter.

    .venv/bin/python scripts/wave_filter_comparison.py [--quick] [--models mariner container tanker]
        [--out runs/wave_filter]

The closed loop of the ROS graph without ROS, step for step as the nodes run it (10 Hz):
vessel_node's plant (ship_sim.simulator) with the wave-frequency motion superposed on what it
reports (ship_sim.environment.sea_state: heading psi + psi_WF, yaw rate r + r_WF, speed from
surge u + u_WF), the autopilot's gain-table PD (ship_autopilot.gains) fed those measurements
directly or through ship_autopilot.wave_filter (notch following the encounter frequency of the
sea's peak). Heading command: 0 deg for the first half, then a 30 deg course change. Sea states:
calm (the filter set for the 10 m/s sea), Hs 2.14 m (the fully developed sea of 10 m/s wind, MSS
vw2hs, PM peak) and Hs 4 m (Tp 10 s), JONSWAP, waves travelling towards 150 deg (bow quartering
from port on the first leg), wave seeds 1-5 (``--seeds``). Without the filter the rate-limited
rudder chases the wave yaw and the run is sensitive to the last digits of its inputs: the
sensitivity check repeats the Hs 4 m sea with Hs changed by +-1e-12 (relative), so the spread a
single run would hide is in the results. Reported per model and sea: mean |rudder rate| (deg/s) and
total variation of the rudder (deg per hour) of the actual rudder, RMS of the low-frequency
heading error (the plant's own heading against the command, deg) after each command has settled
(the first 200 s of each half excluded), and the RMS wave-frequency yaw (deg). Writes
<out>/wave_filter.json and a plot.

``--flagship``: why the filter behaves differently in the graph's flagship
(scenarios/flagship_mariner_waves.yaml: ILOS + turn-rate lead, PD at omega_n = 0.12 rad/s, sea
of 15 m/s wind towards 120 deg). The same loop in process (guidance, PD, wave filter as the
nodes build them, 10 Hz), with the suspects switched one at a time: 'no filter'; 'wave filter'
(as the graph: heading and yaw rate filtered, the guidance steers by the odometry with the
wave motion); 'wave filter, guidance on the low-frequency position' (the guidance given the
plant's own position and heading: no wave motion in the heading command); 'ideal filter' (the
PD given the plant's own heading and yaw rate: no wave motion and no lag). And the loop's phase
margin on the identified Nomoto model, without and with the filter at the encounter
frequencies of the route's legs. Writes <out>/wave_filter_flagship.json.
"""
import json
import math
import sys
import time
from pathlib import Path

import numpy as np
from results_pages.provenance import provenance

from ship_autopilot.gains import build_autopilot, heading_loop_design
from ship_autopilot.steering import HeadingSteering
from ship_autopilot.wave_filter import WaveFilter
from ship_sim.environment.sea_state import SeaState, ShipWaves, rao_table_for
from ship_sim.models import make_model, model_names
from ship_sim.simulator import VesselSimulator

DT, SUB = 0.1, 1          # integration step and steps per control step (10 Hz, as the nodes)
DIRECTION = math.radians(150.0)
#: sea name -> SeaState for a wave seed and a relative change of the wave height (the
#: sensitivity check perturbs Hs by 1e-12); None is calm water
SEAS = {'calm': None,
        'wind 10 m/s (Hs 2.14 m)': lambda seed, rel=0.0: SeaState.from_wind(
            10.0 * (1.0 + rel), direction=DIRECTION, seed=seed),
        'Hs 4 m, Tp 10 s': lambda seed, rel=0.0: SeaState(
            hs=4.0 * (1.0 + rel), tp=10.0, direction=DIRECTION, seed=seed)}
FILTER_SEA_IN_CALM = SEAS['wind 10 m/s (Hs 2.14 m)'](1)


def run(model_name, sea, filtered, duration):
    model = make_model(model_name)
    sim = VesselSimulator(model, dt=DT)
    waves = None if sea is None else ShipWaves(sea, rao_table_for(model_name, model.length))
    fsea = sea or FILTER_SEA_IN_CALM
    gains = heading_loop_design(model_name, 'pd').gains
    steer = HeadingSteering(build_autopilot('pd', gains, model.rudder_max, model.rudder_rate_max))
    filt = (WaveFilter(peak_frequency=fsea.peak_frequency, direction=fsea.direction)
            if filtered else None)
    n = int(round(duration / DT))
    rudder, err, yaw_wf, t_s = (np.empty(n) for _ in range(4))
    for k in range(n):
        t, _, _, psi, u, v, r = sim.nav_state()
        eta, nu = (np.zeros(6), np.zeros(6)) if waves is None else \
            waves.motion(t, sim.speed_water(), psi)
        psi_m, r_m = psi + eta[5], r + nu[5]
        if filt is not None:
            psi_m, r_m = filt.update(t, psi_m, r_m, math.hypot(u + nu[0], v + nu[1]))
        psi_c = 0.0 if t < duration / 2 else math.radians(30.0)
        rudder[k], err[k], yaw_wf[k], t_s[k] = sim.rudder(), math.remainder(psi - psi_c,
                                                                              2 * math.pi), \
            eta[5], t
        sim.step(steer.update(t, psi_m, r_m, psi_c))
    settled = (t_s % (duration / 2)) >= 200.0
    d = np.degrees
    return {'mean_abs_rudder_rate_deg_s': float(np.mean(np.abs(np.diff(d(rudder)))) / DT),
            'rudder_total_variation_deg_per_h': float(np.sum(np.abs(np.diff(d(rudder))))
                                                      * 3600.0 / duration),
            'heading_error_rms_deg': float(np.sqrt(np.mean(d(err[settled]) ** 2))),
            'wave_yaw_rms_deg': float(np.sqrt(np.mean(d(yaw_wf) ** 2))),
            'trace': {'t': t_s[::10].tolist(), 'rudder_deg': d(rudder[::10]).tolist(),
                      'heading_error_deg': d(err[::10]).tolist()}}


FLAGSHIP_VARIANTS = ('no filter', 'wave filter',
                     'wave filter, guidance on the low-frequency position', 'ideal filter')


def flagship_run(variant, duration=1250.0):
    """The flagship with waves in process (module docstring); returns its metrics."""
    from ship_autopilot.gains import heading_loop_design
    from ship_guidance.guidance import Guidance
    from ship_planner.route_loader import load_route
    from ship_sim.current import OceanCurrent
    from ship_sim.environment.sea_state import superpose
    from ship_mission.waves import wave_filter_parameters, wave_parameters
    scenario = Path(__file__).resolve().parents[1] / 'scenarios' / 'flagship_mariner_waves.yaml'
    from ship_sim.safe_load import load_yaml_file
    spec = load_yaml_file(scenario)['vessels']['vessel_0']
    g, a = spec['guidance'], spec['autopilot']
    route = load_route(scenario.parent / spec['route']).route
    wp = wave_parameters(spec['waves'], str(scenario), 'waves.')
    sea = SeaState.from_wind(wp['waves_wind_speed'], spectrum='JONSWAP',
                             direction=math.radians(wp['waves_direction_deg']),
                             spreading=True, n_directions=wp['waves_n_directions'],
                             n_frequencies=wp['waves_n_frequencies'], seed=wp['waves_seed'])
    fp = wave_filter_parameters(wp, {'wave_filter': True})
    model = make_model('mariner')
    n0, e0, gamma = route.point_at(0.0)
    cross = spec['start']['cross_m']
    sim = VesselSimulator(model, dt=DT, north=float(n0 - cross * math.sin(gamma)),
                          east=float(e0 + cross * math.cos(gamma)),
                          psi=math.radians(spec['start']['heading_deg']),
                          current=OceanCurrent(spec['current']['speed_mps'],
                                               math.radians(spec['current']['direction_deg'])))
    waves = ShipWaves(sea, rao_table_for('mariner', model.length))
    guide = Guidance(route, g['law'], g['lookahead_m'], integral_gain=g['integral_gain'],
                     zeta=g['autopilot_zeta'], omega_n=g['autopilot_omega_n'], speed=g['speed'],
                     curvature_lead=g['curvature_lead'])
    gains = heading_loop_design('mariner', 'pd', omega_n=a['omega_n'], zeta=a['zeta']).gains
    steer = HeadingSteering(build_autopilot('pd', gains, model.rudder_max, model.rudder_rate_max))
    filt = None if variant in ('no filter', 'ideal filter') else WaveFilter(
        peak_frequency=2 * math.pi / fp['wave_filter_peak_period'],
        direction=math.radians(fp['wave_filter_direction_deg']))
    n = int(round(duration / DT))
    rudder, xte, t_s, cmd = (np.full(n, np.nan) for _ in range(4))
    finish = math.nan
    for k in range(n):
        t, north, east, psi, u, v, r = sim.nav_state()
        eta, nu = waves.motion(t, sim.speed_water(), psi)
        odom = superpose(eta, nu, north, east, psi, u, v, r)
        gin = (north, east, psi) if variant.endswith('low-frequency position') else odom[:3]
        out = guide.update(*gin, DT if k else 0.0)
        xte[k] = out.cross_track
        if out.finished:
            finish = t
            break
        psi_m, r_m = (psi, r) if variant == 'ideal filter' else (odom[2], odom[5])
        if filt is not None:
            psi_m, r_m = filt.update(t, psi_m, r_m, math.hypot(odom[3], odom[4]))
        rudder[k], t_s[k], cmd[k] = sim.rudder(), t, out.heading_cmd
        sim.step(steer.update(t, psi_m, r_m, out.heading_cmd))
    ok = ~np.isnan(rudder) & (t_s >= 200.0)
    d_rudder = np.abs(np.diff(rudder[~np.isnan(rudder)]))
    rd = rudder[ok]
    f = np.fft.rfftfreq(rd.size, DT) * 2 * math.pi
    power = np.abs(np.fft.rfft(rd - rd.mean())) ** 2
    return {'xte_rms_m': float(np.sqrt(np.mean(xte[ok] ** 2))),
            'xte_max_m': float(np.max(np.abs(xte[ok]))),
            'rudder_mean_abs_rad': float(np.mean(np.abs(rd))),
            'rudder_tv_rad_per_s': float(d_rudder.sum() / (np.count_nonzero(~np.isnan(rudder))
                                                           * DT)),
            'rudder_saturated_fraction': float(np.mean(np.abs(rd) >= model.rudder_max
                                                       * (1 - 1e-9))),
            'rudder_power_below_0.25_rad_s': float(power[f < 0.25].sum() / power.sum()),
            'rudder_peak_frequency_rad_s': float(f[1:][np.argmax(power[1:])]),
            'heading_cmd_rms_above_0.25_rad_s_deg': float(np.degrees(_high_pass_rms(np.unwrap(cmd[ok])))),
            'time_to_complete_s': finish}


def _high_pass_rms(x, corner=0.25):
    """RMS of the part of x (sampled at DT) above ``corner`` rad/s (Parseval on the FFT)."""
    X = np.fft.rfft(x - x.mean())
    f = np.fft.rfftfreq(x.size, DT) * 2 * math.pi
    return math.sqrt(2.0 * np.sum(np.abs(X[f > corner]) ** 2)) / x.size


def phase_margins(omega_n=0.12, zeta=0.8, encounter=(0.33, 0.49, 0.51, 0.70), notch_zeta=0.1):
    """Phase margin (deg) and crossover (rad/s) of the PD heading loop on the Mariner's Nomoto
    model, L(s) = -b (k1 + k2 s) / (s (s - a)), alone and times the wave filter's
    h(s) = (s^2 + 2 zeta_n w_e s + w_e^2) / (s + w_e)^2 / (s / w_e + 1) at each w_e."""
    from ship_autopilot.gains import nomoto_gains
    from ship_autopilot.pd import pd_gains
    nom = nomoto_gains('mariner')
    a, b = nom['a'], nom['b']
    k1, k2 = pd_gains(a, b, omega_n=omega_n, zeta=zeta)
    w = np.logspace(-3, 1, 200001)
    s = 1j * w
    L = -b * (k1 + k2 * s) / (s * (s - a))

    def margin(loop):
        i = np.flatnonzero(np.abs(loop) >= 1.0)[-1]
        return float(w[i]), float(180.0 + np.degrees(np.angle(loop[i])))
    out = {'without filter': margin(L)}
    for we in encounter:
        h = (s ** 2 + 2 * notch_zeta * we * s + we ** 2) / (s + we) ** 2 / (s / we + 1)
        wc, pm = margin(L * h)
        out[f'filter at w_e {we:g} rad/s'] = (wc, pm, float(-np.degrees(np.angle(
            h[np.searchsorted(w, wc)]))))
    return out


def plot(results, out):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    keys = list(results)
    fig, axes = plt.subplots(len(keys), 1, figsize=(9, 2.6 * len(keys)), sharex=True,
                             squeeze=False)
    for ax, key in zip(axes[:, 0], keys):
        for label, res in results[key].items():
            ax.plot(res['trace']['t'], res['trace']['rudder_deg'], lw=0.8, label=label)
        ax.set_title(key, fontsize=9)
        ax.set_ylabel('rudder (deg)')
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[-1, 0].set_xlabel('t (s)')
    fig.tight_layout()
    fig.savefig(out / 'wave_filter_rudder.png', dpi=110)
    plt.close(fig)


def main():
    from ship_mission.cli_args import OneLineParser, number
    ap = OneLineParser(description=__doc__.split('\n')[0])
    ap.add_argument('--quick', action='store_true', help='1200 s runs, the Mariner only')
    ap.add_argument('--models', nargs='+', default=list(model_names('mss')))
    ap.add_argument('--duration', type=number(above=0.0, hi=1e6), default=3600.0, help='s per run')
    ap.add_argument('--out', type=Path, default=Path('runs/wave_filter'))
    ap.add_argument('--seeds', type=int, nargs='+', default=[1, 2, 3, 4, 5],
                    help='wave seeds per sea (default 1-5; --quick: the first)')
    ap.add_argument('--flagship', action='store_true',
                    help="the graph flagship's filter result taken apart (module docstring)")
    args = ap.parse_args()
    started = provenance()     # the code the runs use is the code at their start
    if args.flagship:
        args.out.mkdir(parents=True, exist_ok=True)
        table = heading_loop_design('mariner', 'pd')
        res = {'phase_margins': phase_margins(), 'phase_margins_gain_table': phase_margins(
            omega_n=table.omega_n, zeta=table.zeta)}
        for variant in FLAGSHIP_VARIANTS:
            t0 = time.perf_counter()
            res[variant] = flagship_run(variant)
            print(variant, res[variant], f'{time.perf_counter() - t0:.0f} s', flush=True)
        print(json.dumps(res['phase_margins'], indent=1))
        print(json.dumps(res['phase_margins_gain_table'], indent=1))
        (args.out / 'wave_filter_flagship.json').write_text(json.dumps(res, indent=1))
        return
    models, duration = (['mariner'], 1200.0) if args.quick else (args.models, args.duration)
    seeds = args.seeds[:1] if args.quick else args.seeds
    args.out.mkdir(parents=True, exist_ok=True)
    results, traces = {}, {}
    for model_name in models:
        for sea_name, make_sea in SEAS.items():
            key = f'{model_name}, {sea_name}'
            results[key], traces[key] = {}, {}
            for label, filtered in (('no filter', False), ('wave filter', True)):
                per_seed = []
                for seed in (seeds if make_sea else [None]):     # calm water has no seed
                    t0 = time.perf_counter()
                    res = run(model_name, make_sea and make_sea(seed), filtered, duration)
                    traces[key].setdefault(label, res)
                    per_seed.append({'seed': seed, **{m: v for m, v in res.items()
                                                      if m != 'trace'}})
                    print(f'{key}, {label}, seed {seed}: {time.perf_counter() - t0:.1f} s',
                          file=sys.stderr)
                results[key][label] = per_seed
    # Why single unfiltered runs do not repeat across code versions: a change of Hs in the
    # 12th digit (what a reordered floating-point sum does) moves them, not the filtered ones.
    sensitivity = {}
    for model_name in models:
        for rel in (-1e-12, 0.0, 1e-12):
            sea = SEAS['Hs 4 m, Tp 10 s'](seeds[0], rel)
            for label, filtered in (('no filter', False), ('wave filter', True)):
                res = run(model_name, sea, filtered, duration)
                sensitivity.setdefault(model_name, []).append(
                    {'hs_relative_change': rel, 'input': label,
                     **{m: v for m, v in res.items() if m != 'trace'}})
    print(f'seeds {seeds}: mean [min, max]')
    for key, by_label in results.items():
        for label, per_seed in by_label.items():
            cells = []
            for m in ('mean_abs_rudder_rate_deg_s', 'heading_error_rms_deg'):
                v = [r[m] for r in per_seed]
                cells.append(f'{m} {np.mean(v):.3f} [{min(v):.3f}, {max(v):.3f}]')
            print(f'{key}, {label}: ' + ', '.join(cells))
    # provenance: the results page (doc/results/wind_waves.md) renders from this file
    (args.out / 'wave_filter.json').write_text(json.dumps({
        'provenance': started,
        'settings': {'duration_s': duration, 'dt_s': DT, 'wave_direction_deg': 150.0,
                     'seeds': seeds, 'sensitivity_seed': seeds[0]},
        'runs': results, 'sensitivity': sensitivity}, indent=1))
    plot(traces, args.out)
    print(f'wrote {args.out}/wave_filter.json, wave_filter_rudder.png', file=sys.stderr)

if __name__ == '__main__':
    main()
