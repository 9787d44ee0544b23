#!/usr/bin/env python3
"""Write an AIS replay file for a target moving as a light target (constant course and speed,
or timed waypoints; ship_sim.light_traffic), reported every --period s by pyais-encoded
position reports (ship_guidance.ais_replay), in the ENU frame of a geodetic origin.

    scripts/make_ais_replay.py scenarios/ais/head_on_target.nmea --mmsi 257000100 \
        --origin 63.44 10.40 --light '{"x_m": 4000, "y_m": 0, "course_deg": 270, "speed_mps": 7.7175}' \
        --period 6 --duration 600
"""
import argparse
import json
import shlex
import sys

import numpy as np

from ship_guidance.ais_replay import replay_lines
from ship_sim.light_traffic import make_traffic


def make_replay(mmsi, origin, light, period_s, duration_s, msg_type=1):
    """Replay-file lines (header comment first) of the light target ``light`` (the mapping of a
    scenario's `light:` entry) reported at 0, period_s, ... <= duration_s."""
    traffic = make_traffic([{'name': 'ais_target', **light}])
    times = np.arange(0.0, duration_s + 1e-9, period_s)
    states = [traffic.state(t) for t in times]
    north, east, course, speed = (np.array([s[i][0] for s in states]) for i in range(4))
    return replay_lines(mmsi, times, north, east, speed, course, *origin, msg_type=msg_type)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('out', help='replay file to write')
    ap.add_argument('--mmsi', type=int, required=True)
    ap.add_argument('--origin', type=float, nargs=2, required=True, metavar=('LAT', 'LON'),
                    help='geodetic origin of the ENU frame (deg)')
    ap.add_argument('--light', required=True, help="the target as a scenario's light: mapping "
                    '(JSON): {x_m, y_m, course_deg, speed_mps} or {waypoints: [[t_s, x_m, y_m], ...]}')
    ap.add_argument('--period', type=float, default=6.0, help='report interval (s; class A '
                    'at 14-23 kn: 6 s)')
    ap.add_argument('--duration', type=float, required=True, help='last report time (s)')
    ap.add_argument('--class-b', action='store_true', help='message 18 instead of 1')
    a = ap.parse_args(argv)
    try:
        lines = make_replay(a.mmsi, a.origin, json.loads(a.light), a.period, a.duration,
                            18 if a.class_b else 1)
    except ValueError as exc:
        print(f'make_ais_replay: {exc}', file=sys.stderr)
        return 2
    command = ' '.join(shlex.quote(x) for x in ['scripts/make_ais_replay.py', *(argv or sys.argv[1:])])
    with open(a.out, 'w') as f:
        f.write(f'# made by: {command}\n')
        f.write('\n'.join(lines) + '\n')
    print(f'{len(lines)} reports written to {a.out}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
