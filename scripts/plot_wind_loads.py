#!/usr/bin/env python3
"""Plot the wind loads of the three MSS ships against the relative wind angle (doc/results/
wind_waves.md): surge and sway force, roll and yaw moment at a given relative wind speed, Blendermann
1994 (the ship's type) and Isherwood 1972, from ship_sim.environment.wind with each ship's
stated geometry (WIND_PROFILES).

    .venv/bin/python scripts/plot_wind_loads.py                 # 20 m/s -> runs/wind_loads.png
    .venv/bin/python scripts/plot_wind_loads.py --speed 10 --out /tmp/w.png

Angles 0..180 deg: wind from ahead (0) round the port side to astern (180); a wind from
starboard gives the mirror image (Y, K, N change sign).
"""
import argparse
import sys
from pathlib import Path

import matplotlib
import numpy as np

from ship_sim.environment.wind import WIND_PROFILES, wind_loads

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402  (after the backend choice)

REPO = Path(__file__).resolve().parents[1]
PANELS = (('X (kN)', 0, 1e3), ('Y (kN)', 1, 1e3), ('K (MN m)', 2, 1e6), ('N (MN m)', 3, 1e6))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--speed', type=float, default=20.0, help='relative wind speed (m/s)')
    ap.add_argument('--out', type=Path, default=REPO / 'runs' / 'wind_loads.png')
    args = ap.parse_args(argv)
    if not 0.0 < args.speed <= 60.0:
        ap.error(f'--speed {args.speed} m/s is out of range; allowed: 0 < speed <= 60')
    gamma = np.radians(np.arange(0.0, 180.5, 1.0))
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    for (name, profile), colour in zip(WIND_PROFILES.items(), ('C0', 'C1', 'C2')):
        for coefficients, style in (('blendermann94', '-'), ('isherwood72', '--')):
            loads = wind_loads(profile, args.speed, gamma, coefficients)
            for ax, (label, i, scale) in zip(axes.flat, PANELS):
                ax.plot(np.degrees(gamma), loads[i] / scale, style, color=colour,
                        label=f'{name}, {coefficients}')
    for ax, (label, _, _) in zip(axes.flat, PANELS):
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.axhline(0.0, color='k', lw=0.5)
    for ax in axes[1]:
        ax.set_xlabel('relative wind angle gamma_rw (deg, 0 = from ahead, + from port)')
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(f'Wind loads at {args.speed:g} m/s relative wind (body frame; K = 0 for '
                 'Isherwood)')
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f'wrote {args.out}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
