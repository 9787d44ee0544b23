#!/usr/bin/env python3
"""Run scenarios and write their metrics as one results file for the results pages.

    .venv/bin/python scripts/mission_results.py --out runs/results/platoon.json \
        scenarios/platoon_mariner_5.yaml

Each scenario runs as `scripts/run_mission.py` runs it (ship_mission.launcher, its own run folder
under --runs); the file holds, per scenario name, the run's summary (outcome, sim and wall time)
and its metrics.json as the launcher wrote it, with the provenance of this command (commit,
date, load at the start). For a vessel that ran colav_node, ``colav`` adds its alteration
(mission.encounter: first avoiding decision, its offset, the largest offset) and its closest
approach to every other vessel of the run, as scripts/encounter_report.py prints them (light
and AIS targets have theirs in the metrics' ``traffic``). Copy it to doc/results/data/ and
run scripts/render_results.py.
"""
import argparse
import json
import sys
from pathlib import Path

from ship_mission.launcher import MissionFailed, check_scenario, run_scenario
from ship_mission.scenario import ScenarioError, load_scenario
from results_pages.provenance import provenance

REPO = Path(__file__).resolve().parents[1]


def colav_summary(bag, metrics):
    """{own: {'alteration': ..., 'closest': {other vessel: min_distance dict}}} of the vessels
    whose record has colav decisions."""
    from rosbags.highlevel import AnyReader

    from ship_mission.encounter import alteration, decision_rows, encounter_report
    names = [ns.strip('/') for ns in metrics['vessels']]
    with AnyReader([Path(bag)]) as reader:
        topics = {c.topic for c in reader.connections}
    out = {}
    for own in names:
        # only where the topic exists: asked for no connection, the reader reads every one
        if f'/{own}/colav_decision' not in topics:
            continue
        rows = decision_rows(bag, own)
        if len(rows):
            out[own] = {'alteration': alteration(rows),
                        'closest': {o: {k: v for k, v in encounter_report(bag, own, o).items()
                                        if k not in ('first_avoid_s', 'first_offset_deg',
                                                     'max_offset_deg', 'last_resort')}
                                    for o in names if o != own}}
    return out


def _shown(path):
    """A path as the results file keeps it: relative to the repository when inside it."""
    path = Path(path).resolve()
    return str(path.relative_to(REPO)) if path.is_relative_to(REPO) else str(path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('scenarios', type=Path, nargs='+')
    ap.add_argument('--out', type=Path, required=True, help='the results file (JSON)')
    ap.add_argument('--runs', type=Path, default=REPO / 'runs' / 'results',
                    help='where the run folders go')
    args = ap.parse_args(argv)
    started = provenance()     # the code the runs use is the code at their start
    out = {'provenance': started, 'runs': {}}
    for path in args.scenarios:
        try:
            scenario = load_scenario(path)
            check_scenario(scenario)
            print(f'mission_results: {scenario.name} ...', flush=True)
            run, metrics = run_scenario(scenario, runs_root=args.runs, progress=lambda s: None)
        except ScenarioError as exc:
            print(f'mission_results: {exc}', file=sys.stderr)
            return 2
        except MissionFailed as exc:
            print(f'mission_results: FAILED: {path}: {exc}', file=sys.stderr)
            return 1
        if metrics is None:
            print(f'mission_results: {path} records nothing: no metrics', file=sys.stderr)
            return 1
        metrics['colav'] = colav_summary(run / 'bag', metrics)
        metrics['run_folder'] = _shown(run)
        if 'run' in metrics and 'scenario' in metrics['run']:
            metrics['run']['scenario'] = _shown(metrics['run']['scenario'])
        out['runs'][scenario.name] = metrics
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(out, indent=1) + '\n')
    print(f'mission_results: wrote {args.out}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
