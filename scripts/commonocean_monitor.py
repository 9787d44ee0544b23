#!/usr/bin/env python3
"""Run TUM's CommonOcean COLREGs rule monitor (commonocean-rules, GPL-3.0) on tracks given as
JSON; run with .venv-judge's python only (`make venv-judge`), never imported by the project.

    .venv-judge/bin/python scripts/commonocean_monitor.py IN.json OUT.json [--check]

IN: {"dt_s": sample spacing of every track (s), "readings": {name: trace time unit (s)},
"runs": [{"key": text, "own": SHIP, "targets": {name: SHIP}}]}, SHIP = {"length_m",
"beam_m", "x", "y" (m, east / north), "orientation" (rad, anticlockwise from east: the course
over ground), "speed" (m/s)}, all tracks of a run on the same samples.

Each run becomes a CommonOcean scenario (own ship obstacle 1, targets 2, 3, ... in the order
given); the package's configuration and formulas as shipped, monitor mode, the own ship its
only ego vessel. The package's predicate collections are evaluated once per run and each of
its rule monitors (metric temporal logic through the `mtl` package) is run on those predicate
traces as its dispatcher builds them, once per reading: the rules' time intervals are read
on the trace's time axis, sample index x unit; 'seconds' (unit = dt_s) is the package as
configured (its dt is 10 s), 'steps' (unit 1) reads the intervals as counts of samples.
``--check`` also runs the package's top-level evaluation (evaluate_scenario, scenario time
step = the unit; it evaluates the predicates again) and fails unless its verdicts are the
same. Also reported per target: the samples where each predicate holds, which explain a
verdict.

OUT: {"package": version, "runs": [{"key", "verdicts": {reading: {rule: {target: bool}}},
"predicates": {target: {predicate: [sample indices where it holds]}}, "wall_s"}]}.
"""
import json
import sys
import time
from importlib.metadata import version
from pathlib import Path

import numpy as np
from commonocean.prediction.prediction import TrajectoryPrediction
from commonocean.scenario.obstacle import DynamicObstacle, ObstacleType
from commonocean.scenario.scenario import Scenario
from commonocean.scenario.state import YPState
from commonocean.scenario.trajectory import Trajectory
from commonroad.geometry.shape import Rectangle

import rules
from rules.common.commonocean_evaluation_ship import CommonOceanObstacleEvaluation
from rules.common.helper import OperatingMode
from rules.common.utils_ship import create_scenario_vehicles
from rules.monitor.traffic_rule_dispatcher_ship import TrafficRuleDispatcher

CONFIG = str(Path(rules.__file__).parent) + '/'
OWN_ID = 1


def _obstacle(obstacle_id, ship):
    states = [YPState(position=np.array([x, y]), orientation=float(o), velocity=float(v),
                      time_step=k)
              for k, (x, y, o, v) in enumerate(zip(ship['x'], ship['y'], ship['orientation'],
                                                   ship['speed']))]
    shape = Rectangle(length=float(ship['length_m']), width=float(ship['beam_m']))
    return DynamicObstacle(obstacle_id, ObstacleType.MOTORVESSEL, shape, states[0],
                           TrajectoryPrediction(Trajectory(1, states[1:]), shape))


def scenario_of(run, unit_s):
    sc = Scenario(dt=unit_s, scenario_id='ZAM_Judge-1_1_T-1')
    sc.add_objects(_obstacle(OWN_ID, run['own']))
    for i, ship in enumerate(run['targets'].values()):
        sc.add_objects(_obstacle(OWN_ID + 1 + i, ship))
    return sc


def _evaluation():
    ev = CommonOceanObstacleEvaluation(CONFIG)
    ev.simulation_param['operating_mode'] = 'single_vehicle'
    ev.simulation_param['ego_vehicle_id'] = OWN_ID
    return ev


def evaluated(run, dt_s):
    """(dispatcher, ego, others, {predicate: {vehicle id: {sample: bool}}}): the package's
    predicate collections evaluated once on the run (the expensive part)."""
    ev = _evaluation()
    ev.simulation_param['dt'] = dt_s
    sc = scenario_of(run, dt_s)
    dispatcher = TrafficRuleDispatcher(
        ev._traffic_rules_forward, ev._traffic_rule_sets, ev.simulation_param,
        ev._traffic_rules_param, ev.activated_traffic_rule_sets, ev._vehicle_dependent_rules,
        OperatingMode.MONITOR, ev._constraint_param)
    ego, others = create_scenario_vehicles(sc.obstacle_by_id(OWN_ID), ev.ego_vehicle_param,
                                           ev._other_vehicles_param, sc.dynamic_obstacles)
    values = dispatcher.evaluate_predicates(ego, others, (0, 1), OperatingMode.MONITOR)
    return dispatcher, ego, others, values


def verdicts(run, values, dispatcher, ego, others, unit_s):
    """{rule: {target name or 'own': bool}}: each of the package's rule monitors on the
    predicate traces with trace time = sample index x ``unit_s``, each trace taken as the
    package's dispatcher takes it (the target's series, else the own ship's)."""
    names = {OWN_ID + 1 + i: n for i, n in enumerate(run['targets'])}
    out = {}
    for monitor in dispatcher._monitors_forward:
        vehicles = [v.id for v in others] if monitor.vehicle_dependency else [None]
        for vid in vehicles:
            traces = {}
            for pred in monitor.predicates:
                series = values[pred].get(vid) if vid is not None else None
                if series is None:
                    series = values[pred][ego.id]
                traces[pred] = [(k * unit_s, v) for k, v in enumerate(series.values())]
            out.setdefault(monitor.name, {})[names.get(vid, 'own')] = bool(
                monitor.evaluate_monitor(traces))
    return out


def verdicts_top_level(run, unit_s):
    """The same verdicts through the package's top-level evaluation (evaluate_scenario), which
    evaluates the predicates again: ``--check`` compares the two."""
    names = {OWN_ID + 1 + i: n for i, n in enumerate(run['targets'])}
    result = _evaluation().evaluate_scenario(scenario_of(run, unit_s), flag_print=False)
    if not result:
        raise RuntimeError(f'{run["key"]}: the package could not evaluate the scenario')
    out = {}
    for rule_key, ok in result[0][1].items():
        rule, _, vid = rule_key.partition('_veh_')
        out.setdefault(rule, {})[names[int(vid)] if vid else 'own'] = bool(ok)
    return out


def predicate_samples(run, values):
    """{target: {predicate: [sample indices where it holds]}}."""
    names = {OWN_ID + 1 + i: n for i, n in enumerate(run['targets'])}
    out = {n: {} for n in names.values()}
    for pred, per_vehicle in values.items():
        for vid, series in per_vehicle.items():
            if vid in names:
                out[names[vid]][pred] = [int(k) for k, v in series.items() if v]
    return out


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    check = '--check' in argv
    argv = [a for a in argv if a != '--check']
    if len(argv) != 2:
        print('usage: ' + __doc__.split('\n')[3].strip(), file=sys.stderr)
        return 2
    job = json.loads(Path(argv[0]).read_text())
    runs = []
    for run in job['runs']:
        t0 = time.perf_counter()
        dispatcher, ego, others, values = evaluated(run, float(job['dt_s']))
        v = {name: verdicts(run, values, dispatcher, ego, others, float(unit))
             for name, unit in job['readings'].items()}
        if check:
            for name, unit in job['readings'].items():
                top = verdicts_top_level(run, float(unit))
                if top != v[name]:
                    print(f'{run["key"]} {name}: top-level {top} != {v[name]}', file=sys.stderr)
                    return 1
        runs.append({'key': run['key'], 'verdicts': v,
                     'predicates': predicate_samples(run, values),
                     'wall_s': time.perf_counter() - t0})
        print(f'{run["key"]}: {runs[-1]["wall_s"]:.1f} s', file=sys.stderr, flush=True)
    Path(argv[1]).write_text(json.dumps({'package': version('commonocean-rules'), 'runs': runs}))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
