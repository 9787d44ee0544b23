"""Run a scenario: `run_mission scenarios/<name>.yaml [options]` (see ship_mission.launcher).

Installed as `ros2 run ship_mission run_mission`; scripts/run_mission.py runs the same main.

Starts every node as its own process from the colcon install (run `make build` first, or use
`make demo SCENARIO=...`), records a bag, and writes metrics and plots to runs/<name>-<time>/
(runs/latest points there). Exit code 0 on success, 1 if a node failed, the run timed out or
the run folder could not be written (one line naming the path and the OS error), 2 for an
invalid scenario or option (checked before anything starts), 130 on Ctrl-C or SIGTERM.
"""
import sys

from ship_mission.cli_args import OneLineParser, integer, number
from ship_mission.console import summary_line
from ship_mission.launcher import MissionFailed, check_scenario, install_stop_handlers, run_scenario
from ship_mission.recorder import COMPRESSIONS
from ship_mission.report import traffic_lines
from ship_mission.scenario import COMPOSE, MIN_DURATION_S, ScenarioError, load_scenario


def main(argv=None):
    ap = OneLineParser(description=__doc__.split('\n')[0])
    ap.add_argument('scenario', help='scenario YAML file')
    ap.add_argument('--name', default=None, help='the scenario of a matrix file (ship_mission.matrix) '
                    'to run, e.g. course_tanker_90_pd_004 of scenarios/course_changes_004.yaml')
    ap.add_argument('--runs', default=None, help='folder for run folders (default: runs/)')
    ap.add_argument('--domain-id', type=integer(0, 232), default=None,
                    help='ROS_DOMAIN_ID, 0-232 (default: a free one, leased)')
    ap.add_argument('--no-record', action='store_true', help='no bag, no metrics')
    ap.add_argument('--duration', type=number(MIN_DURATION_S), default=None,
                    help='override duration_s')
    ap.add_argument('--stepping', choices=('lockstep', 'realtime'), default=None)
    ap.add_argument('--wall-timeout', type=number(above=0.0), default=None,
                    help='fail after this many s')
    ap.add_argument('--loopback-only', action='store_true', help='Fast DDS sockets on 127.0.0.1 '
                    'only (by default it also binds 0.0.0.0; doc/security.md)')
    ap.add_argument('--bag-compression', choices=COMPRESSIONS, default=None,
                    help="the bag's MCAP chunk compression (default: the scenario's "
                    "bag_compression, else zstd)")
    ap.add_argument('--live', action='store_true', help='serve the topics to Foxglove / '
                    'Lichtblick while the run goes (scripts/live_view.py; doc/guide/live_view.md)')
    ap.add_argument('--live-port', type=integer(0, 65535), default=8765,
                    help='port of --live (127.0.0.1)')
    ap.add_argument('--live-nice', type=integer(0, 19), default=10, help='CPU niceness of --live once '
                    'serving (0: it keeps up on a busy machine, at the graph\'s expense)')
    ap.add_argument('--compose', choices=COMPOSE, default=None,
                    help="several nodes per process: one container per vessel or one for all "
                    "(default: the scenario's compose, else none; ship_mission.composition)")
    args = ap.parse_args(argv)
    try:
        scenario = load_scenario(args.scenario, args.name)
        # The options first, so that the check sees what will run.
        if args.duration is not None:
            scenario.duration_s = args.duration
        if args.stepping:
            scenario.stepping = args.stepping
        if args.compose:
            scenario.compose = args.compose
        if args.bag_compression:
            scenario.bag_compression = args.bag_compression
        if args.live:
            scenario.live_port = args.live_port
            scenario.live_nice = max(0, args.live_nice)
        check_scenario(scenario)
    except ScenarioError as exc:
        print(f'run_mission: {exc}', file=sys.stderr)
        return 2
    kw = {'runs_root': args.runs} if args.runs else {}
    install_stop_handlers()   # Ctrl-C and SIGTERM stop every node, exit 130
    try:
        run, metrics = run_scenario(scenario, domain_id=args.domain_id,
                                    record=False if args.no_record else None,
                                    wall_timeout_s=args.wall_timeout,
                                    loopback_only=args.loopback_only, **kw)
    except MissionFailed as exc:
        print(f'run_mission: FAILED: {exc}', file=sys.stderr)
        return 1
    except OSError as exc:   # writing the run folder (scenario copy, parameters, metrics, plots)
        where = exc.filename or args.runs or 'runs/'
        print(f'run_mission: FAILED: {where}: {exc.strerror or exc}', file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print('run_mission: interrupted; all nodes stopped', file=sys.stderr)
        return 130
    if metrics:
        for ns, m in metrics['vessels'].items():
            print(summary_line(ns, m))
        for line in traffic_lines(metrics):
            print(line)
    return 0


if __name__ == '__main__':
    sys.exit(main())
