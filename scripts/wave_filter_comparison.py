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
from port on the first leg), seed 1. Reported per model and sea: mean |rudder rate| (deg/s) and
total variation of the rudder (deg per hour) of the actual rudder, RMS of the low-frequency
heading error (the plant's own heading against the command, deg) after each command has settled
(the first 200 s of each half excluded), and the RMS wave-frequency yaw (deg). Writes
<out>/wave_filter.json and a plot.
"""
import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from ship_autopilot.gains import build_autopilot, heading_loop_design
from ship_autopilot.steering import HeadingSteering
from ship_autopilot.wave_filter import WaveFilter
from ship_sim.environment.sea_state import SeaState, ShipWaves, rao_table_for
from ship_sim.models import make_model
from ship_sim.simulator import VesselSimulator

DT, SUB = 0.1, 1          # integration step and steps per control step (10 Hz, as the nodes)
DIRECTION = math.radians(150.0)
SEAS = {'calm': None,
        'wind 10 m/s (Hs 2.14 m)': SeaState.from_wind(10.0, direction=DIRECTION, seed=1),
        'Hs 4 m, Tp 10 s': SeaState(hs=4.0, tp=10.0, direction=DIRECTION, seed=1)}
#: the filter's sea in calm water (its setting for the 10 m/s sea)
FILTER_SEA_IN_CALM = SEAS['wind 10 m/s (Hs 2.14 m)']


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
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--quick', action='store_true', help='1200 s runs, the Mariner only')
    ap.add_argument('--models', nargs='+', default=['mariner', 'container', 'tanker'])
    ap.add_argument('--duration', type=float, default=3600.0, help='s per run')
    ap.add_argument('--out', type=Path, default=Path('runs/wave_filter'))
    args = ap.parse_args()
    models, duration = (['mariner'], 1200.0) if args.quick else (args.models, args.duration)
    args.out.mkdir(parents=True, exist_ok=True)
    results, rows = {}, []
    for model_name in models:
        for sea_name, sea in SEAS.items():
            key = f'{model_name}, {sea_name}'
            results[key] = {}
            for label, filtered in (('no filter', False), ('wave filter', True)):
                t0 = time.perf_counter()
                res = run(model_name, sea, filtered, duration)
                results[key][label] = res
                rows.append((model_name, sea_name, label, res))
                print(f'{key}, {label}: {time.perf_counter() - t0:.1f} s', file=sys.stderr)
    print('| model | sea | autopilot input | mean abs rudder rate (deg/s) | rudder total '
          'variation (deg/h) | heading error RMS (deg) | wave yaw RMS (deg) |')
    print('|---|---|---|---|---|---|---|')
    for model_name, sea_name, label, r in rows:
        print(f'| {model_name} | {sea_name} | {label} | {r["mean_abs_rudder_rate_deg_s"]:.3f} | '
              f'{r["rudder_total_variation_deg_per_h"]:.0f} | {r["heading_error_rms_deg"]:.3f} | '
              f'{r["wave_yaw_rms_deg"]:.3f} |')
    (args.out / 'wave_filter.json').write_text(json.dumps(
        {k: {lab: {m: v for m, v in r.items() if m != 'trace'} for lab, r in res.items()}
         for k, res in results.items()}, indent=1))
    plot(results, args.out)
    print(f'wrote {args.out}/wave_filter.json, wave_filter_rudder.png', file=sys.stderr)


if __name__ == '__main__':
    main()
