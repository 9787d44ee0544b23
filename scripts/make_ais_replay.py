#!/usr/bin/env python3
"""Write an AIS replay file for a target moving as a light target (constant course and speed,
or timed waypoints; ship_sim.light_traffic), reported every --period s by pyais-encoded
position reports (ship_guidance.ais_replay), in the ENU frame of a geodetic origin.

    scripts/make_ais_replay.py scenarios/ais/head_on_target.nmea --mmsi 257000100 \
        --origin 63.44 10.40 --light '{"x_m": 4000, "y_m": 0, "course_deg": 270, "speed_mps": 7.7175}' \
        --period 6 --duration 600
"""
import shlex
import sys

import numpy as np

from ship_mission.cli_args import OneLineParser, integer, number
from ship_guidance.ais_replay import replay_lines
from ship_sim.light_traffic import make_traffic
from ship_sim.safe_load import InputError, load_json

#: Most reports in one file (--duration / --period): a day of class A reports every 2 s.
MAX_REPORTS = 50_000


def make_replay(mmsi, origin, light, period_s, duration_s, msg_type=1):
    """Replay-file lines (header comment first) of the light target ``light`` (the mapping of a
    scenario's `light:` entry) reported at 0, period_s, ... <= duration_s."""
    traffic = make_traffic([{'name': 'ais_target', **light}])
    times = np.arange(0.0, duration_s + 1e-9, period_s)
    states = [traffic.state(t) for t in times]
    north, east, course, speed = (np.array([s[i][0] for s in states]) for i in range(4))
    return replay_lines(mmsi, times, north, east, speed, course, *origin, msg_type=msg_type)


def main(argv=None):
    ap = OneLineParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('out', help='replay file to write')
    ap.add_argument('--mmsi', type=integer(1, 999_999_999), required=True,
                    help='maritime mobile service identity (9 digits)')
    ap.add_argument('--origin', type=number(-180.0, 180.0), nargs=2, required=True,
                    metavar=('LAT', 'LON'), help='geodetic origin of the ENU frame (deg)')
    ap.add_argument('--light', required=True, help="the target as a scenario's light: mapping "
                    '(JSON): {x_m, y_m, course_deg, speed_mps} or {waypoints: [[t_s, x_m, y_m], ...]}')
    ap.add_argument('--period', type=number(above=0.0, hi=3600.0), default=6.0,
                    help='report interval (s; class A at 14-23 kn: 6 s)')
    ap.add_argument('--duration', type=number(0.0, 86400.0), required=True,
                    help='last report time (s)')
    ap.add_argument('--class-b', action='store_true', help='message 18 instead of 1')
    a = ap.parse_args(argv)
    if not -90.0 <= a.origin[0] <= 90.0:
        ap.error(f'argument --origin: the latitude must be within [-90, 90], got {a.origin[0]:g}')
    if a.duration / a.period > MAX_REPORTS:
        ap.error(f'--duration {a.duration:g} s / --period {a.period:g} s is more than '
                 f'{MAX_REPORTS} reports')
    try:
        light = load_json(a.light, '--light')
        if not isinstance(light, dict):
            raise ValueError(f'--light: a JSON mapping, got {a.light!r}')
        lines = make_replay(a.mmsi, a.origin, light, a.period, a.duration,
                            18 if a.class_b else 1)
    except (InputError, ValueError) as exc:
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
