#!/usr/bin/env python3
"""What wind does to a closed loop: run a scenario at several wind speeds and tabulate tracking
and rudder activity (issue 14, wind part).

    .venv/bin/python scripts/wind_study.py                       # flagship at 0 / 10 / 20 m/s
    .venv/bin/python scripts/wind_study.py --speeds 0 15 --direction-deg 45 --quick
    .venv/bin/python scripts/wind_study.py --conditions calm wind10 wind20   # wind and waves
    .venv/bin/python scripts/wind_study.py --scenario scenarios/platoon_mariner_5.yaml \
        --conditions wind10 --runs runs/wind_study_platoon

Each run is the scenario with a top-level `wind:` block (ship_mission.wind_block; from
--direction-deg, gusts of sd --gust-fraction x speed, Gauss-Markov time constant
--time-constant, seed --seed; 0 m/s is the scenario unchanged), run by ship_mission.launcher in
lockstep (so each row repeats bit for bit). Written to --runs: one run folder per speed, the
variant scenario files, wind_study.json and wind_study.md (the table). Metrics are the
launcher's (ship_mission.metrics) after the scenario's settle_s: cross-track error RMS / max,
heading error RMS, mean |rudder|, mean |rudder rate| (total variation per second) and the total
variation over the window.

``--conditions`` runs the study's wind-and-wave conditions instead (ship_mission.conditions: calm,
wind10, wind20, directions relative to the route's overall course): the wind as a top-level
`wind:` block, the sea as each vessel's `waves:` block (vessel i of a platoon: seed SEED + i).
"""
import json
import math
import sys
from pathlib import Path

import yaml

from ship_mission import conditions
from ship_mission.cli_args import OneLineParser, integer, number
from montecarlo.spec import PARAMETERS
from ship_mission.launcher import MissionFailed, check_scenario, run_scenario
from ship_mission.scenario import ScenarioError, load_scenario
from results_pages.provenance import provenance
from ship_sim.safe_load import load_yaml_file

REPO = Path(__file__).resolve().parents[1]


def variant(source, speed, args, folder):
    """Copy of the scenario file with the wind block and absolute routes; returns its path."""
    data = load_yaml_file(source)
    if speed > 0.0:
        data['wind'] = {'speed_mps': speed, 'direction_deg': args.direction_deg,
                        'gust_sd_mps': round(args.gust_fraction * speed, 6),
                        'time_constant_s': args.time_constant, 'seed': args.seed}
    data['name'] = f"{data['name']}_wind{speed:g}"
    for section in ('vessels', 'traffic'):
        for entry in (data.get(section) or {}).values():
            if isinstance(entry, dict) and isinstance(entry.get('route'), str):
                entry['route'] = str((source.parent / entry['route']).resolve())
    if isinstance(data.get('platoon'), dict):
        data['platoon']['route'] = str((source.parent / data['platoon']['route']).resolve())
    path = folder / f"{data['name']}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def condition_variant(source, name, folder, start_timeout=None):
    """Copy of the scenario file in condition ``name`` (ship_mission.conditions), absolute routes;
    ``start_timeout`` (s): every simulator's lockstep_start_timeout (a loaded machine)."""
    from ship_planner.route_loader import load_route
    data = load_yaml_file(source)
    platoon = data.get('platoon') if isinstance(data.get('platoon'), dict) else None
    for section in ('vessels', 'traffic'):
        for entry in (data.get(section) or {}).values():
            if isinstance(entry, dict) and isinstance(entry.get('route'), str):
                entry['route'] = str((source.parent / entry['route']).resolve())
    if platoon:
        platoon['route'] = str((source.parent / platoon['route']).resolve())
        vessels = platoon['vessels']
        route = platoon['route']
    else:
        vessels = list(data['vessels'].values())
        route = vessels[0]['route']
    course = conditions.route_course(load_route(route).route)
    cond = conditions.condition(name)
    wind, _ = conditions.scenario_blocks(cond, course)
    if wind:
        data['wind'] = wind
    for i, v in enumerate(vessels):
        _, waves = conditions.scenario_blocks(cond, course, conditions.SEED + i)
        if waves:
            v['waves'] = waves
        if start_timeout:
            v['vessel'] = dict(v.get('vessel') or {}, lockstep_start_timeout=start_timeout)
    data['name'] = f"{data['name']}_{name}"
    path = folder / f"{data['name']}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _shown(path):
    """A path as the results file keeps it: relative to the repository when inside it."""
    path = Path(path).resolve()
    return str(path.relative_to(REPO)) if path.is_relative_to(REPO) else str(path)


def row(speed, m):
    """Table row of one vessel's metrics (angles in deg)."""
    span = m['duration_s'] - m['settle_s']
    rate = m['rudder_total_variation_rad_per_s']
    return {'wind_mps': speed, 'finished': m['finished'],
            'time_to_complete_s': m.get('time_to_complete_s'),
            'xte_rms_m': m['xte_rms_m'], 'xte_max_m': m['xte_max_abs_m'],
            'heading_rms_deg': math.degrees(m['heading_error_rms_rad']),
            'rudder_mean_abs_deg': math.degrees(m['rudder_mean_abs_rad']),
            'rudder_max_abs_deg': math.degrees(m['rudder_max_abs_rad']),
            'rudder_rate_mean_abs_deg_s': math.degrees(rate),
            'rudder_tv_deg': math.degrees(rate * span),
            'rudder_saturated_fraction': m['rudder_saturated_fraction'],
            'rudder_limit_deg': (math.degrees(m['rudder_limit_rad'])
                                 if m.get('rudder_limit_rad') is not None else None),
            'reward_gaussian_sum': m.get('reward_gaussian_sum')}


COLUMNS = [('condition', 'condition', '{}'), ('wind_mps', 'wind (m/s)', '{:g}'), ('vessel', 'vessel', '{}'),
           ('finished', 'finished', '{}'), ('xte_rms_m', 'XTE RMS (m)', '{:.2f}'),
           ('xte_max_m', 'XTE max (m)', '{:.2f}'), ('heading_rms_deg', 'heading err RMS (deg)',
                                                   '{:.2f}'),
           ('rudder_mean_abs_deg', 'mean abs rudder (deg)', '{:.2f}'),
           ('rudder_max_abs_deg', 'max abs rudder (deg)', '{:.1f}'),
           ('rudder_rate_mean_abs_deg_s', 'mean abs rudder rate (deg/s)', '{:.4f}'),
           ('rudder_tv_deg', 'rudder TV (deg)', '{:.0f}'),
           ('rudder_saturated_fraction', 'saturated', '{:.3f}')]


def table(rows):
    lines = ['| ' + ' | '.join(c[1] for c in COLUMNS) + ' |',
             '|' + '---|' * len(COLUMNS)]
    for r in rows:
        lines.append('| ' + ' | '.join(fmt.format(r[k]) if r[k] is not None else '-'
                                       for k, _, fmt in COLUMNS) + ' |')
    return '\n'.join(lines)


def main(argv=None):
    ap = OneLineParser(description=__doc__.split('\n')[0])
    ap.add_argument('--scenario', type=Path, default=REPO / 'scenarios' / 'flagship_mariner.yaml')
    ap.add_argument('--speeds', type=number(*PARAMETERS['wind_speed_mps'][2]), nargs='+', default=[0.0, 10.0, 20.0],
                    help='mean wind speeds (m/s)')
    ap.add_argument('--direction-deg', type=number(-360.0, 360.0), default=270.0,
                    help='where the wind blows from, clockwise from north (default: west)')
    ap.add_argument('--gust-fraction', type=number(0.0, 1.0), default=0.1,
                    help='gust sd as a fraction of the mean speed')
    ap.add_argument('--time-constant', type=number(above=0.0, hi=1e6), default=60.0, help='gust time constant (s)')
    ap.add_argument('--seed', type=integer(0, 2**32 - 1), default=1, help='gust random seed')
    ap.add_argument('--runs', type=Path, default=REPO / 'runs' / 'wind_study')
    ap.add_argument('--quick', action='store_true', help='300 s runs (development)')
    ap.add_argument('--conditions', nargs='+', choices=tuple(conditions.CONDITIONS),
                    help='wind-and-wave conditions (ship_mission.conditions) instead of --speeds')
    ap.add_argument('--start-timeout', type=number(above=0.0, hi=1e5), default=None,
                    help="with --conditions: every simulator's lockstep_start_timeout (s), for "
                         'many vessels on a loaded machine (timing only, not the physics)')
    args = ap.parse_args(argv)
    started = provenance()     # the code the runs use is the code at their start
    args.runs.mkdir(parents=True, exist_ok=True)
    rows = []
    cases = ([(conditions.CONDITIONS[c].wind_speed, c) for c in args.conditions]
             if args.conditions else [(v, None) for v in args.speeds])
    try:
        for speed, cond in cases:
            if cond:
                print(f'wind_study: {conditions.CONDITIONS[cond].describe()} ...', flush=True)
                scenario = load_scenario(condition_variant(args.scenario, cond, args.runs,
                                                           args.start_timeout))
            else:
                print(f'wind_study: {speed:g} m/s from {args.direction_deg:g} deg ...',
                      flush=True)
                scenario = load_scenario(variant(args.scenario, speed, args, args.runs))
            if args.quick:
                scenario.duration_s = min(scenario.duration_s, 300.0)
            check_scenario(scenario)
            run, metrics = run_scenario(scenario, runs_root=args.runs, progress=lambda s: None)
            for ns, m in metrics['vessels'].items():
                rows.append({'vessel': ns, **row(speed, m), 'condition': cond or '-',
                             'run': _shown(run)})
                print(table(rows[-1:]).splitlines()[-1], flush=True)
    except ScenarioError as exc:
        print(f'wind_study: {exc}', file=sys.stderr)
        return 2
    except MissionFailed as exc:
        print(f'wind_study: FAILED: {exc}', file=sys.stderr)
        return 1
    text = table(rows)
    # provenance: the results pages (doc/results/wind_waves.md, flagship.md) render from this
    (args.runs / 'wind_study.json').write_text(json.dumps(
        {'provenance': started, 'scenario': _shown(args.scenario), 'quick': args.quick,
         'conditions': args.conditions,
         'direction_deg': args.direction_deg,
         'gust_fraction': args.gust_fraction, 'time_constant_s': args.time_constant,
         'seed': args.seed, 'rows': rows}, indent=1))
    (args.runs / 'wind_study.md').write_text(text + '\n')
    print(text)
    return 0


if __name__ == '__main__':
    sys.exit(main())
