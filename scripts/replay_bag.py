#!/usr/bin/env python3
"""Regenerate metrics.json, the plots and report.html of a recorded mission from its bag.

    scripts/replay_bag.py BAG_DIR [--out DIR] [--settle S] [--rudder-limit-deg D]
        [--reward-step S] [--episode S] [--progress-topic NAME] [--no-plots]

Writes into --out (default: the directory that holds the bag); report.html (ship_mission.html_report)
takes the scenario, run summary and node logs from the bag's own run folder. Definitions of the metrics:
ros_ws/src/ship_mission/ship_mission/metrics.py. Exit codes: 0 done, 2 not a bag / nothing to analyse.
"""
import math
import sys
from pathlib import Path

from ship_mission import metrics
from ship_mission.bag import BagError
from ship_mission.cli_args import OneLineParser, number
from ship_mission.integrity import summary_line
from ship_mission.report import analyse_bag, traffic_lines


def main(argv=None):
    p = OneLineParser(description=__doc__.split('\n\n')[0])
    p.add_argument('bag', help='rosbag2 directory (one without metadata.yaml, left by a killed '
                   'recorder, is recovered first: ship_mission.bag_recovery)')
    p.add_argument('--out', default=None, help='output directory (default: the bag\'s parent)')
    p.add_argument('--settle', type=number(0.0), default=None, metavar='S',
                   help='seconds excluded at the start (default: 10 %% of the run)')
    p.add_argument('--rudder-limit-deg', type=number(above=0.0, hi=90.0), default=None,
                   help='rudder limit for saturation counts and plots (default: from the bag, else none)')
    p.add_argument('--reward-step', type=number(above=0.0), default=metrics.REWARD_STEP_S, metavar='S',
                   help='step of the cumulative Gaussian reward (Martinsen and Lekkas 2018 Table I), s')
    p.add_argument('--episode', type=number(above=0.0), default=None, metavar='S',
                   help='sum the reward over the first S seconds only (Martinsen and Lekkas 2018: 1000)')
    p.add_argument('--progress-topic', default=None, help='relative name of the progress topic')
    p.add_argument('--no-plots', action='store_true')
    args = p.parse_args(argv)
    limit = math.radians(args.rudder_limit_deg) if args.rudder_limit_deg is not None else None
    topics = {'progress': args.progress_topic} if args.progress_topic else None
    try:
        result = analyse_bag(args.bag, args.out, settle_s=args.settle, rudder_limit_rad=limit, topics=topics,
                             reward_step_s=args.reward_step, episode_s=args.episode, make_pngs=not args.no_plots)
    except BagError as err:
        print(f'replay_bag: {err}', file=sys.stderr)
        return 2
    out = Path(args.out) if args.out else Path(args.bag).resolve().parent
    if result.get('recovered'):
        print(result['recovered'])
    print(summary_line(result['record']))
    for ns, m in result['vessels'].items():
        if 'error' in m:
            print(f'{ns}: {m["error"]}')
            continue
        missing = f' (missing topics: {", ".join(m["missing_topics"])})' if m['missing_topics'] else ''
        print(f'{ns}: xte rms {_fmt(m.get("xte_rms_m"))} m, max {_fmt(m.get("xte_max_abs_m"))} m, '
              f'reward {_fmt(m.get("reward_gaussian_sum"))} @ {m.get("reward_step_s")} s, '
              f'time to complete {_fmt(m.get("time_to_complete_s"))} s{missing}')
    for line in traffic_lines(result):
        print(line)
    print(f'wrote {out / "metrics.json"}' + (f', {len(result.get("plots", []))} plots' if not args.no_plots else '')
          + f' and {out / "report.html"}')
    return 0


def _fmt(x):
    return 'n/a' if x is None else f'{x:.2f}'


if __name__ == '__main__':
    sys.exit(main())
