#!/usr/bin/env python3
"""Closest approach and the own ship's alteration of a two-ship run (ship_mission.encounter).

    scripts/encounter_report.py runs/latest [--own vessel_0 --target target_0]
"""
import sys
from pathlib import Path

from ship_mission.bag import BagError
from ship_mission.cli_args import OneLineParser
from ship_mission.encounter import encounter_report


def main(argv=None):
    ap = OneLineParser(description=__doc__.split('\n')[0])
    ap.add_argument('run', help='run folder (holding bag/) or the bag folder')
    ap.add_argument('--own', default='vessel_0', help='namespace with colav_node')
    ap.add_argument('--target', default='target_0', help='the other vessel')
    a = ap.parse_args(argv)
    bag = Path(a.run) / 'bag' if (Path(a.run) / 'bag').is_dir() else Path(a.run)
    try:
        r = encounter_report(bag, a.own, a.target)
    except (BagError, ValueError) as exc:
        print(f'encounter_report: {exc}', file=sys.stderr)
        return 2
    first = 'never' if r['first_avoid_s'] is None else f"{r['first_avoid_s']:.1f} s"
    print(f"min distance {r['min_distance_m']:.1f} m at t = {r['t_min_s']:.1f} s, target on "
          f"the own {r['side']} side (bearing {r['bearing_at_min_deg']:.1f} deg from the bow)")
    print(f"first alteration at {first}: {r['first_offset_deg']:+.0f} deg (+ starboard); "
          f"largest offset {r['max_offset_deg']:+.0f} deg; last resort "
          f"{'used' if r['last_resort'] else 'not used'}")
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
