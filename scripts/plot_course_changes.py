#!/usr/bin/env python3
"""Course changes of Lee 2004 (Figs. 5.7-5.18) from a seed batch: heading and rudder per angle.

    scripts/plot_course_changes.py [BATCH_DIR]     default runs/seeds-latest

Reads the batch's results.json (scripts/run_seed_scenarios.py) and the bags of its course-change
runs; writes BATCH_DIR/course_changes_mariner.png and course_changes_tanker.png: per course
change (30, 45, 60, 90 deg) the heading change from the start and the actual rudder against
time, PD and fuzzy PID, with the gain table's gains and with Lee 2004's own (dashed).
"""
import argparse
import sys
from pathlib import Path

import numpy as np

from ship_mission import bag as bagmod
from ship_mission.processes import REPO
from ship_sim.safe_load import load_json_file

ANGLES = (30, 45, 60, 90)
#: ship -> scenario name pattern (angle, controller, suffix)
NAMES = {'mariner': ('course_change_{a}_{c}_004', 'course_mariner_{a}_{c}_thesisgains_004'),
         'tanker': ('course_tanker_{a}_{c}_004', 'course_tanker_{a}_{c}_thesisgains_004')}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('batch', nargs='?', default=str(REPO / 'runs' / 'seeds-latest'))
    batch = Path(ap.parse_args(argv).batch)
    runs = {r['scenario']: r for r in load_json_file(batch / 'results.json')['runs']}
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    for ship, patterns in NAMES.items():
        fig, axes = plt.subplots(2, len(ANGLES), figsize=(16, 7), sharex=True)
        drawn = 0
        for j, a in enumerate(ANGLES):
            for pattern, style in zip(patterns, ('-', '--')):
                for c, colour in (('pd', 'tab:red'), ('fuzzy', 'tab:blue')):
                    name = pattern.format(a=a, c=c)
                    run = runs.get(name, {}).get('run_dir')
                    if not run or not (Path(run) / 'bag').exists():
                        continue
                    v = next(iter(bagmod.read_bag(Path(run) / 'bag').vessels.values()))
                    t = v.t - v.t[0]
                    # ENU yaw falls in a starboard turn: plot the change to starboard, positive
                    change = -np.degrees(np.unwrap(v.yaw) - v.yaw[0])
                    label = (f"{'PD' if c == 'pd' else 'fuzzy PID'}, "
                             f"{'gain table' if style == '-' else 'Lee 2004 gains'}")
                    axes[0, j].plot(t, change, style, color=colour, lw=1.2, label=label)
                    axes[1, j].plot(v.rudder.t - v.t[0], np.degrees(v.rudder.v), style,
                                    color=colour, lw=1.0)
                    drawn += 1
            axes[0, j].axhline(a, color='0.4', lw=0.8, ls=':')
            axes[0, j].set_title(f'{ship}: {a} deg course change')
            axes[1, j].set_xlabel('time (s)')
        axes[0, 0].set_ylabel('heading change to starboard (deg)')
        axes[1, 0].set_ylabel('rudder (deg, + port)')
        axes[0, 0].legend(fontsize=8)
        fig.tight_layout()
        out = batch / f'course_changes_{ship}.png'
        fig.savefig(out, dpi=100)
        plt.close(fig)
        print(f'{out} ({drawn} runs)' if drawn else f'{ship}: no course-change runs in {batch}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
