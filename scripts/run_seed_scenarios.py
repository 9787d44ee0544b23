#!/usr/bin/env python3
"""Run the seed scenarios one after another and tabulate their metrics against the seeds' claims.

    scripts/run_seed_scenarios.py                      every scenario of scenarios/*_000|003|004.yaml
    scripts/run_seed_scenarios.py --quick              the same with durations cut to a quarter
    scripts/run_seed_scenarios.py --only course_change --only quarter_circle
    scripts/run_seed_scenarios.py scenarios/figure_eight_003.yaml 'scenarios/curved_*.yaml'

A matrix file (ship_mission.matrix, e.g. scenarios/course_changes_004.yaml) gives all its scenarios,
in the order of their names (as separate files sorted by name would); --only picks by name.
Each scenario goes through ship_mission.launcher.run_scenario (one process per node, lockstep, a
bag), all on one ROS_DOMAIN_ID leased for the batch (quiet_domain_lease). The bag is then analysed
with ship_mission.report.analyse_bag (the run folder's metrics.json and plots, whole run), given the
rudder limit of the vessel model so that saturation is counted. Everything lands in one batch
folder, runs/seeds-<time>/ (runs/seeds-latest points at it): one run folder per scenario,
results.json (per run: scenario, spec summary, outcome, the table's metrics of vessel_0; the
claim checks), results.md, the table that is also printed, and index.html, the same tables with
each run linked to its report.html (ship_mission.html_report). A failed run is recorded as such
and the batch goes on; a run whose bag came out incomplete is run once more (``--retries``).
Exit code 1 if any run failed, 130 on Ctrl-C (the table of the runs so far is still written).
``--reanalyse BATCH_DIR`` recomputes the table of an earlier batch from its bags.

The table's metrics are ship_mission.metrics.vessel_metrics over [start + settle_s, the time the
guidance declared the route finished] (or the end of the run): the launcher stops the nodes a
few sim seconds after route_complete, and that tail is cut (``metrics_to_finish``). Extras:
- ``ref_xte_*``: the cross-track error against a REFERENCE path other than the route followed.
  Simakis 1992 approximates a quarter circle by a chord or by straight legs; the figure of merit
  is the distance from the circle itself, not from the legs (REFERENCE_ROUTES below; the
  scenario schema has no key for it), from the odometry.
- ``rudder_max_abs_from_leg_rad``: the largest rudder angle from a given leg on
  (RUDDER_FROM_LEG; the figure eight's arcs after its one sharp corner).
- ``rudder_min_rad``, ``rudder_max_rad``: the signed extremes of the actual rudder.
- ``rudder_legs`` (RUDDER_PER_LEG): per leg of the route its kind, curvature, max and mean
  |rudder|, and for an arc the steady-turn rudder its curvature needs, from the vehicle model
  (``steady_turn_rudder``: the manoeuvre module's turning circle, solved for the radius).
- course changes (``course_*``, Lee 2004 Figs. 5.7-5.18): the heading step response (overshoot,
  2 % settling time, steady error from settle_s on) and the rudder's use over the whole
  manoeuvre (``course_change_metrics``), tabulated in their own columns.
- ``guidance_finished_s``, ``bag_end_s``, ``tail_after_finish_s``: when the guidance declared
  the route finished, where the bag ends, and the cut tail (s after the first odometry).
The seeds' claims become checks on the rows (``claim_checks``): reproduced yes / NO, or n/a
when a run it needs is missing or failed.

Units in the table: metres, degrees, seconds; reward = ship_mission.metrics cumulative Gaussian reward
(Martinsen and Lekkas 2018 eq. 8, sigma 10 m, sampled every 0.1 s, whole run).
"""
import fnmatch
import glob
import json
import math
import os
import sys
import time
from datetime import datetime
from pathlib import Path

import numpy as np

from ship_mission.cli_args import OneLineParser, integer, number
from ship_mission.domain import DomainLease, LeaseError
from ship_mission.launcher import MissionFailed, run_scenario
from ship_mission.processes import REPO
from ship_mission.scenario import ScenarioError, load_scenario, load_scenarios
from results_pages.provenance import provenance
from ship_sim.safe_load import load_json_file, load_yaml_file

SCENARIO_DIR = REPO / 'scenarios'
DEFAULT_GLOBS = ('*_003.yaml', '*_004.yaml', '*_000.yaml')
QUICK_FACTOR = 0.25          # --quick: duration and settle_s times this
QUICK_MIN_DURATION_S = 20.0
#: scenario name -> reference route (relative to scenarios/) for the ref_xte_* extras
REFERENCE_ROUTES = {f'quarter_circle_{n}_003': 'routes/quarter_circle_arc_003.wpt'
                    for n in ('chord', '03pts', '05pts', '07pts', '13pts', 'arc')}
#: scenario name -> first leg index from which the rudder maximum is also reported
#: (figure eight: leg 2, the arcs after the 90 deg corner at (15, 0) L)
RUDDER_FROM_LEG = {'figure_eight_003': 2}
#: scenarios whose rudder is also reported leg by leg (rudder_legs)
RUDDER_PER_LEG = {'figure_eight_003'}
#: sub-arc length (m) of the route Path (ship_guidance.ros.path_msgs.route_to_path_msg's
#: default); the decoded legs do not depend on it (sub-arcs are merged back)
GUIDED_ARC_STEP_M = 25.0
#: figure eight: mean |rudder| on an arc within this fraction of its steady-turn rudder. Entering
#: an arc the heading loop needs ~1/omega_n (~0.8 s, ~0.8 m at U = 1 m/s) to pick up the turn,
#: under 15 % of a quarter circle of radius 5 L (17.5 m), and over- and undershoot of that
#: transient (zeta = 0.8) largely cancel in the mean: 25 % bounds what a loop that only
#: turns as the curve needs can show.
ARC_RUDDER_RTOL = 0.25
#: Martinsen and Lekkas 2018 Table I, LOS row: cumulative Gaussian reward per ship and current (m/s)
TABLE_I_LOS = {'mariner': {0.0: 161, 0.9: 499}, 'container': {0.0: 807, 0.9: 829},
               'tanker': {0.0: 65, 0.9: 62}}
GROUPS = (  # (name prefix, heading in the table)
    ('quarter_circle_', 'Simakis 1992: quarter circle, arc guidance vs chord and straight legs '
     '(NPS AUV II)'),
    ('figure_eight_', 'Simakis 1992: figure eight with arc guidance (NPS AUV II)'),
    ('course_tanker_', 'Lee 2004: course changes, PD vs fuzzy PID (tanker, deep water)'),
    ('course_mariner_', "Lee 2004: course changes with the thesis's own gains (Mariner)"),
    ('course_change_', 'Lee 2004: course changes, PD vs fuzzy PID (Mariner)'),
    ('route_following_', 'Lee 2004: waypoint route following, LOS + PD vs fuzzy PID'),
    ('curved_path_', 'Martinsen and Lekkas 2018: curved path following, LOS vs ILOS, currents 0 '
     'and 0.9 m/s'),
    ('turn_circle_', 'Lee 2004: turning circles from a rudder angle (LOS point on the circle) vs '
                     'tangent fillets + turn-rate lead'),
)


def quiet_domain_lease(probe_s=1.5):
    """A ROS_DOMAIN_ID for the whole batch (ship_mission.domain.DomainLease, the lease every graph
    on this machine takes) on which a probe node also sees no other node: a launcher that does
    not lease would otherwise mix its messages into ours."""
    return DomainLease(accept=lambda did: _domain_is_quiet(did, probe_s))


def _domain_is_quiet(domain_id, probe_s):
    """True if a probe node on ``domain_id`` (localhost discovery) sees no other node."""
    import rclpy
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    ctx = rclpy.context.Context()
    rclpy.init(context=ctx, domain_id=domain_id)
    try:
        node = rclpy.create_node('seed_batch_domain_probe', context=ctx)
        end = time.monotonic() + probe_s
        while time.monotonic() < end:
            others = [n for n, _ in node.get_node_names_and_namespaces()
                      if n != 'seed_batch_domain_probe']
            if others:
                return False
            time.sleep(0.1)
        node.destroy_node()
        return True
    finally:
        rclpy.try_shutdown(context=ctx)


def find_scenarios(patterns, only):
    """The scenarios (ship_mission.scenario.Scenario, checked) of files/globs (default: the seed
    scenarios), filtered by --only substrings or globs on the scenario's name or its file's
    stem. A matrix file's scenarios come sorted by name. ScenarioError for a bad file."""
    files = []
    for pat in patterns or [str(SCENARIO_DIR / g) for g in DEFAULT_GLOBS]:
        hits = sorted(glob.glob(pat)) or ([pat] if Path(pat).exists() else [])
        if not hits:
            raise SystemExit(f'run_seed_scenarios: no scenario matches {pat!r}')
        files += [Path(h) for h in hits if Path(h) not in files]
    scenarios = [s for f in files for s in sorted(load_scenarios(f), key=lambda s: s.name)]
    if only:
        scenarios = [s for s in scenarios
                     if any(o in key or fnmatch.fnmatch(key, o)
                            for o in only for key in (s.name, s.file.stem))]
    return scenarios


def rudder_limit(spec):
    """Rudder angle limit (rad) of a vessel spec: its rudder_max_deg override, else the model's."""
    from ship_sim.models import make_model
    override = float(spec.vessel_params.get('rudder_max_deg', 0.0) or 0.0)
    # The instance's limit: some models (nps_auv2) set theirs in the constructor only.
    return math.radians(override) if override else float(make_model(spec.model).rudder_max)


def steady_turn_rudder(model, radius_m, clockwise, rudder_max, t_end=300.0):
    """The rudder (rad, unified sign: + to port) at which ``model`` turns steadily on a circle
    of ``radius_m``, clockwise (starboard) or not: the steady radius of the manoeuvre module's
    turning circle (ship_sim.maneuvers, V / |r| after t_end s), solved for the radius
    by bisection on |rudder| in (0, rudder_max]. None if even rudder_max turns wider."""
    from scipy.optimize import brentq

    from ship_sim.maneuvers import integrate, turning_metrics
    sign = -1.0 if clockwise else 1.0
    x0 = np.asarray(model.initial_state(), dtype=float)[None]   # the batched path: every model

    def excess(mag):
        u = np.asarray(model.inputs(np.array([sign * mag])), dtype=float)
        t, st = integrate(model, x0, u, 0.1, t_end)
        st = st[:, 0]
        tc = turning_metrics(t, st[:, model.IX], st[:, model.IY],
                             st[:, model.IPSI], np.hypot(model.surge_speed(st), st[:, model.IV]),
                             st[:, model.IR])
        return tc.steady_radius_m - radius_m
    if excess(rudder_max) > 0.0:
        return None
    return sign * brentq(excess, 1e-6 * rudder_max, rudder_max, xtol=1e-9)


def rudder_per_leg(route, rudder, leg, model, rudder_max):
    """[{leg, kind, curvature_1pm, rudder_max_abs_rad, rudder_mean_abs_rad,
    steady_turn_rudder_rad}] per leg of ``route`` (ship_guidance.path.Route) from the rudder
    samples and the guidance's leg index at each sample."""
    out, steady = [], {}
    for i, g in enumerate(route.legs):
        sel = np.abs(leg - i) < 0.5
        kappa = float(getattr(g, 'curvature', 0.0))
        row = {'leg': i, 'kind': g.kind, 'curvature_1pm': kappa,
               'rudder_max_abs_rad': float(np.max(np.abs(rudder[sel]))) if sel.any() else None,
               'rudder_mean_abs_rad': float(np.mean(np.abs(rudder[sel]))) if sel.any() else None,
               'steady_turn_rudder_rad': 0.0}
        if g.kind == 'arc':
            k = (round(g.radius, 9), g.clockwise)
            if k not in steady:
                steady[k] = steady_turn_rudder(model, g.radius, g.clockwise, rudder_max)
            row['steady_turn_rudder_rad'] = steady[k]
        out.append(row)
    return out


def metrics_to_finish(bag_dir, namespace, settle_s, rudder_limit_rad, ref_route=None,
                      rudder_from_leg=None, per_leg=None, step_response=False):
    """ship_mission.metrics.vessel_metrics over [start, route finished] (or the whole run if it never
    finishes; ship_mission.report's cut), plus the ref_* and rudder-after-leg extras; ``per_leg``
    (route, model) adds rudder_legs, ``step_response`` the course-change extras."""
    from ship_mission import bag as bagmod
    from ship_mission.metrics import cross_track_stats, project_on_route, vessel_metrics
    from ship_mission.report import vessel_completion, vessel_until
    whole = bagmod.read_bag(bag_dir, namespaces=[namespace]).vessels[namespace]
    t_fin, _ = vessel_completion(whole)
    v = whole if t_fin is None else vessel_until(whole, t_fin)
    t, x, y, yaw = v.t, v.x, v.y, v.yaw
    cut = {k: getattr(v, k) if len(getattr(v, k).t) else None
           for k in ('rudder', 'rudder_cmd', 'heading_cmd', 'cross_track_error')}
    m = vessel_metrics(t, x, y, yaw, xte=cut['cross_track_error'], rudder=cut['rudder'],
                       rudder_cmd=cut['rudder_cmd'], heading_cmd=cut['heading_cmd'],
                       route=(v.route.x, v.route.y) if v.route is not None else None,
                       settle_s=settle_s, rudder_limit_rad=rudder_limit_rad)
    m['guidance_finished_s'] = None if t_fin is None else t_fin - v.t[0]
    m['bag_end_s'] = float(whole.t[-1] - v.t[0])
    # Steps the recorder lost (lockstep odometry comes every step: a gap is a lost message).
    steps = np.diff(whole.t) / np.median(np.diff(whole.t))
    m['bag_missing_odom'] = int(np.sum(np.maximum(np.round(steps) - 1.0, 0.0)))
    m['tail_after_finish_s'] = float(whole.t[-1] - v.t[-1])
    t_from = v.t[0] + (settle_s or 0.0)
    if ref_route is not None:
        from ship_planner.route_loader import load_route
        north, east, _ = load_route(ref_route).route.to_poses(max_arc_step=0.05)
        _, e, _, _ = project_on_route(x, y, east, north)
        st = cross_track_stats(t, e, t_from)
        m.update({'ref_route': str(ref_route), 'ref_xte_rms_m': st['xte_rms_m'],
                  'ref_xte_max_abs_m': st['xte_max_abs_m'], 'ref_xte_mean_m': st['xte_mean_m']})
    rudder = cut['rudder']
    if rudder is not None and len(rudder.t):
        m['rudder_min_rad'] = float(np.min(rudder.v))
        m['rudder_max_rad'] = float(np.max(rudder.v))
    if step_response and cut['heading_cmd'] is not None:
        m.update(course_change_metrics(v, cut['heading_cmd'], rudder, t_from, rudder_limit_rad))
    if rudder_from_leg is not None and len(v.progress.t) and rudder is not None:
        leg = np.interp(rudder.t, v.progress.t, v.progress.v[:, v.progress_labels.index('leg')])
        sel = leg >= rudder_from_leg - 1e-9
        m['rudder_from_leg'] = rudder_from_leg
        m['rudder_max_abs_from_leg_rad'] = (float(np.max(np.abs(rudder.v[sel])))
                                            if np.any(sel) else None)
    if per_leg is not None and len(v.progress.t) and rudder is not None:
        # The leg of each rudder sample: the latest progress message (a step function).
        k = np.clip(np.searchsorted(v.progress.t, rudder.t, side='right') - 1, 0, None)
        leg = v.progress.v[k, v.progress_labels.index('leg')]
        m['rudder_legs'] = rudder_per_leg(per_leg[0], rudder.v, leg, per_leg[1], rudder_limit_rad)
    return m


def course_change_metrics(v, heading_cmd, rudder, t_steady, rudder_limit_rad):
    """Lee 2004 Figs. 5.7-5.18 extras of a course change: the heading step response
    (ship_mission.metrics.step_response_stats, steady window from settle_s) and the rudder's use over
    the whole manoeuvre (from the step on: mean |rudder|, total variation per second = mean
    |rudder rate|, time at the limit), prefixed ``manoeuvre_rudder``."""
    from ship_mission.metrics import rudder_stats, rudder_time_at_limit, step_response_stats
    out = step_response_stats(heading_cmd.t, heading_cmd.v, v.t, v.yaw, t_steady)
    if rudder is not None and out['step_time_s'] is not None:
        t0 = out['step_time_s']
        out.update(rudder_stats(rudder.t, rudder.v, t0, rudder_limit_rad, 'manoeuvre_rudder'))
        out['manoeuvre_rudder_time_at_limit_s'] = rudder_time_at_limit(rudder.t, rudder.v, t0,
                                                                       rudder_limit_rad)
    return out


def spec_summary(scenario):
    s = scenario.vessels[0]
    return {'model': s.model, 'law': s.guidance_params.get('law', 'ilos'),
            'controller': s.autopilot_params.get('controller', 'pd'),
            'current_mps': float(s.current.get('speed_mps', 0.0)),
            'lookahead_m': s.guidance_params.get('lookahead_m'),
            'duration_s': scenario.duration_s, 'dt_s': scenario.dt_s, 'settle_s': scenario.settle_s}


def analyse_run(scenario, run, make_pngs=True):
    """The run folder's metrics.json + plots (whole run, as run_mission.py writes them) and,
    returned, the table's metrics (up to the end of the route, with the extras)."""
    from ship_mission.report import analyse_bag
    limit = rudder_limit(scenario.vessels[0])
    analyse_bag(run / 'bag', run, settle_s=scenario.settle_s, rudder_limit_rad=limit,
                make_pngs=make_pngs)
    ref = REFERENCE_ROUTES.get(scenario.name)
    per_leg = None
    if scenario.name in RUDDER_PER_LEG:
        from ship_guidance.path import Route
        from ship_planner.route_loader import load_route
        from ship_sim.models import make_model
        spec = scenario.vessels[0]
        # The legs as the guidance numbers them: the route goes out as a nav_msgs/Path (arcs
        # cut into sub-arcs) and is decoded with consecutive arcs of one circle merged, so the
        # progress topic's leg index counts the decoded route's legs, not the file's rows.
        route = load_route(spec.route_file).route
        per_leg = (Route.from_poses(*route.to_poses(max_arc_step=GUIDED_ARC_STEP_M)),
                   make_model(spec.model))
    return metrics_to_finish(run / 'bag', f'/{scenario.vessels[0].namespace}', scenario.settle_s,
                             limit, ref_route=SCENARIO_DIR / ref if ref else None,
                             rudder_from_leg=RUDDER_FROM_LEG.get(scenario.name),
                             per_leg=per_leg,
                             step_response=scenario.name.startswith('course_'))


def reanalyse(batch):
    """Recompute the metrics of every run of an earlier batch (its results.json) from the bags."""
    old = load_json_file(batch / 'results.json')
    results, seeds = [], {}
    for r in old['runs']:
        if r.get('run_dir') and (Path(r['run_dir']) / 'bag').exists():
            scenario = _rerun_scenario(r, seeds)
            scenario.settle_s = r['spec']['settle_s']   # as run (--quick scales it)
            scenario.duration_s = r['spec']['duration_s']
            try:
                r['metrics'] = analyse_run(scenario, Path(r['run_dir']), make_pngs=False)
            except Exception as exc:  # noqa: BLE001 - recorded, the others go on
                r['metrics'], r['error'] = None, f'{type(exc).__name__}: {exc}'
            problem = bag_problem(r, scenario) if r['metrics'] else None
            if problem:
                r['outcome'], r['error'] = 'bag incomplete', problem
        results.append(r)
    return results, old


def _rerun_scenario(result, seeds):
    """The scenario of an earlier batch's run: its file's, or, when that file is gone (the course
    changes now come from one matrix file), the seed scenario of that name (``seeds``: name ->
    scenario, filled on first use)."""
    if Path(result['file']).exists():
        return load_scenario(result['file'], result['scenario'])
    if not seeds:
        seeds.update((s.name, s) for s in find_scenarios([], []))
    if result['scenario'] not in seeds:
        raise ScenarioError(f"{result['file']}: no such file, and no seed scenario is called "
                            f"{result['scenario']!r}")
    return seeds[result['scenario']]


def bag_problem(result, scenario):
    """None if the bag holds the whole run, else what is missing. The launcher signals every
    process at once when a run ends, and a recorder that lags the lockstep graph (a loaded
    machine) loses what it had not yet written: the bag then ends early. Under load it also
    loses messages within a run (seen: 216 of 5001 odometry messages)."""
    m, run = result.get('metrics') or {}, result.get('run') or {}
    end = m.get('bag_end_s')
    if end is None:
        return 'no odometry in the bag'
    if run.get('outcome') == 'completed' and m.get('guidance_finished_s') is None:
        return f'the bag ends at {end:.1f} s, before the route was finished'
    if run.get('outcome') == 'duration reached' and end < scenario.duration_s - 2 * scenario.dt_s:
        return f'the bag ends at {end:.1f} s of {scenario.duration_s:.0f} s'
    if m.get('bag_missing_odom'):
        return f'the bag misses {m["bag_missing_odom"]} odometry messages (steps) of the run'
    return None


def run_one(scenario, batch_dir, quick, wall_timeout_s, verbose, domain_id, retries=1):
    """Run + analyse one scenario (ship_mission.scenario.Scenario); returns its result dict (never
    raises for a failed run). A run whose bag came out incomplete is run again, up to
    ``retries`` times."""
    if quick:
        scenario.duration_s = max(QUICK_MIN_DURATION_S, scenario.duration_s * QUICK_FACTOR)
        scenario.settle_s = scenario.settle_s * QUICK_FACTOR
    t0 = time.monotonic()

    def progress(line):
        if verbose or not line.startswith('  t ='):
            print(f'  {line}', flush=True)
    for attempt in range(retries + 1):
        result = {'scenario': scenario.name, 'file': str(scenario.file), 'source': scenario.source,
                  'spec': spec_summary(scenario), 'outcome': 'failed', 'metrics': None,
                  'attempts': attempt + 1}
        try:
            run, _ = run_scenario(scenario, runs_root=batch_dir, record=True, analyse=False,
                                  progress=progress, wall_timeout_s=wall_timeout_s,
                                  domain_id=domain_id)
            result['run_dir'] = str(run)
            summary = load_yaml_file(run / 'run.json')  # the launcher writes YAML
            result['outcome'] = summary['outcome']
            result['run'] = summary
            result['metrics'] = analyse_run(scenario, run)
        except MissionFailed as exc:
            result['error'] = str(exc)
            print(f'  FAILED: {exc}', flush=True)
            break
        except Exception as exc:  # noqa: BLE001 - analysis errors are recorded, the batch goes on
            result['error'] = f'{type(exc).__name__}: {exc}'
            result['outcome'] = 'analysis failed'
            print(f'  ANALYSIS FAILED: {result["error"]}', flush=True)
            break
        problem = bag_problem(result, scenario)
        if problem is None:
            break
        result['outcome'] = 'bag incomplete'
        result['error'] = problem
        print(f'  BAG INCOMPLETE: {problem}' + ('; running it again' if attempt < retries else ''),
              flush=True)
    result['wall_s'] = time.monotonic() - t0
    return result


# -- claims --------------------------------------------------------------------------------------

def _m(rows, name, key):
    """metrics[key] of the run called name; None if absent or failed."""
    r = rows.get(name)
    return (r.get('metrics') or {}).get(key) if r else None


def _all(values):
    return None if any(v is None for v in values) else all(values)


def _lt(a, b):
    return None if a is None or b is None else a < b


def claim_checks(rows):
    """[(claim, verdict True/False/None, evidence text)] for the seed claims the batch can test."""
    out = []
    pts = ('03pts', '05pts', '07pts', '13pts')
    arc, chord = 'quarter_circle_arc_003', 'quarter_circle_chord_003'
    if chord in rows:
        lo, hi = _m(rows, chord, 'rudder_min_rad'), _m(rows, chord, 'rudder_max_rad')
        sat = _m(rows, chord, 'rudder_saturated_fraction')
        limit = _m(rows, chord, 'rudder_limit_rad') or 0.4
        out.append(('Simakis 1992 Figs. 14-15: the 2-point chord saturates the rudder (about '
                    '-23 deg, the 0.4 rad limit, turning to starboard onto the chord)',
                    None if lo is None or sat is None
                    else bool(sat > 0.0 and lo <= -limit * (1 - 1e-3)),
                    f'rudder {_fmt(_deg(lo), 1)} ... {_fmt(_deg(hi), 1)} deg (limit '
                    f'{_fmt(_deg(limit), 1)}), at the limit {_fmt(None if sat is None else 100 * sat, 1)}'
                    ' % of the run'))
    if arc in rows:
        for key, what in (('ref_xte_rms_m', 'tracks the circle closer (RMS distance)'),
                          ('rudder_total_variation_rad_per_s', 'with less rudder activity '
                           '(total variation)')):
            names = ('chord',) + pts
            pairs = [(p, _m(rows, f'quarter_circle_{p}_003', key)) for p in names]
            pairs = [(p, v) for p, v in pairs if p != 'chord' or chord in rows]
            a = _m(rows, arc, key)
            verdict = _all([_lt(a, v) for _, v in pairs])
            unit = (lambda x: x, 'm') if key.endswith('_m') else (_deg, 'deg/s')
            ev = f'arc {_fmt(unit[0](a), 3)}; ' + ', '.join(f'{p} {_fmt(unit[0](v), 3)}'
                                                           for p, v in pairs) + f' {unit[1]}'
            out.append((f'Simakis 1992 Figs. 14-27: the arc {what} than the 2-point chord and '
                        '3/5/7/13-point legs', verdict, ev))
        names = (('chord',) if chord in rows else ()) + pts
        refs = [_m(rows, f'quarter_circle_{p}_003', 'ref_xte_rms_m') for p in names]
        mono = _all([_lt(b, a) for a, b in zip(refs, refs[1:])]) if None not in refs else None
        out.append(('Simakis 1992 Ch. IV.A: more points track the circle more closely (RMS '
                    'distance falls, 2-point chord -> 13 points)', mono,
                    ', '.join(f'{p} {_fmt(v)}' for p, v in zip(names, refs))))
    if 'figure_eight_003' in rows:
        mx = _m(rows, 'figure_eight_003', 'rudder_max_abs_from_leg_rad')
        mx_all = _m(rows, 'figure_eight_003', 'rudder_max_abs_rad')
        done = _m(rows, 'figure_eight_003', 'guidance_finished_s')
        out.append(('Simakis 1992 Figs. 28-29: the figure eight is completed and the rudder stays '
                    'off its 0.4 rad limit on the arcs (legs after the 90 deg corner)',
                    None if mx is None else done is not None and mx < 0.4 * (1 - 1e-3),
                    f'max abs rudder after the corner {_fmt(mx, 3)} rad, over the run '
                    f'{_fmt(mx_all, 3)} rad (the 90 deg corner), finished at {_fmt(done, 0)} s'))
        out.append(figure_eight_arc_claim(_m(rows, 'figure_eight_003', 'rudder_legs')))
    for ang in (30, 45, 60, 90):
        pd = _m(rows, f'course_change_{ang}_pd_004', 'heading_error_mean_rad')
        fz = _m(rows, f'course_change_{ang}_fuzzy_004', 'heading_error_mean_rad')
        if pd is None and fz is None:
            continue
        ok = None if pd is None or fz is None else abs(fz) < abs(pd)
        out.append((f'Lee 2004 Fig. 5.7-5.11, {ang} deg: the fuzzy PID removes the steady heading '
                    'error the PD keeps (smaller mean error over the last 100 s)', ok,
                    f'PD {_fmt(_deg(pd), 2)} deg, fuzzy PID {_fmt(_deg(fz), 2)} deg'))
    out += lee_course_change_claims(rows)
    for ship in ('mariner', 'tanker'):
        names = [f'route_following_{ship}_{c}_004' for c in ('pd', 'fuzzy')]
        if not any(n in rows for n in names):
            continue
        fin = [_m(rows, n, 'guidance_finished_s') for n in names]
        out.append((f'Lee 2004 route following ({ship}): both autopilots complete the route',
                    None if not all(n in rows for n in names) else all(f is not None for f in fin),
                    ', '.join(f'{n.split("_")[3]} at {_fmt(f, 0)} s' for n, f in zip(names, fin))))
        xte = [_m(rows, n, 'xte_rms_m') for n in names]
        out.append((f'Lee 2004 route following ({ship}): the fuzzy PID tracks the route at least as '
                    'closely as the PD (RMS cross-track error)',
                    None if None in xte else xte[1] <= xte[0],
                    f'PD {_fmt(xte[0], 1)} m, fuzzy PID {_fmt(xte[1], 1)} m'))
    out += lee_current_claims(rows)
    for cur, tag in ((0.0, '0'), (0.9, '09')):
        ours = {ship: _m(rows, f'curved_path_{ship}_current{tag}_los_000', 'reward_gaussian_sum')
                for ship in TABLE_I_LOS}
        if all(v is None for v in ours.values()):
            continue
        seed = {ship: TABLE_I_LOS[ship][cur] for ship in TABLE_I_LOS}
        rank = (None if None in ours.values() else
                sorted(ours, key=ours.get) == sorted(seed, key=seed.get))
        out.append((f'Martinsen and Lekkas 2018 Table I, LOS at {cur} m/s: the three ships rank as in the paper '
                    '(absolute values depend on the unpublished curve, start and time step)', rank,
                    ', '.join(f'{ship} {_fmt(ours[ship], 0)} (paper {seed[ship]})'
                              for ship in TABLE_I_LOS)))
    out += turn_circle_checks(rows)
    return out


#: turning-circle runs (Lee 2004 Ch. 4): ship -> chosen rudder (deg) of its route file
TURN_RUDDER_DEG = {'mariner': 10.0, 'tanker': 3.0}


def turn_circle_checks(rows):
    """Lee 2004 Ch. 4: corners as the ship's turning circle at a chosen rudder, LOS point on the
    circle, against our tangent fillets + turn-rate lead on the same legs (route_following_*_pd)."""
    out = []
    for ship, rudder in TURN_RUDDER_DEG.items():
        names = (f'turn_circle_{ship}_los_point_004', f'turn_circle_{ship}_lead_004',
                 f'route_following_{ship}_pd_004')
        if names[0] not in rows:
            continue
        fin = _m(rows, names[0], 'guidance_finished_s')
        sat = _m(rows, names[0], 'rudder_saturated_fraction')
        out.append((f'Lee 2004 Ch. 4 ({ship}): the route of {rudder:g} deg turning circles with the LOS point '
                    'on the circle is completed without saturating the rudder', None if fin is None and
                    sat is None else fin is not None and sat == 0.0,
                    f'finished at {_fmt(fin, 0)} s, rudder saturated {_fmt(None if sat is None else 100 * sat, 1)} '
                    f'% of the time, max {_fmt(_deg(_m(rows, names[0], "rudder_max_abs_rad")), 1)} deg'))
        xte = [_m(rows, n, 'xte_rms_m') for n in names]
        mx = [_m(rows, n, 'xte_max_abs_m') for n in names]
        out.append((f'Lee 2004 Ch. 4 ({ship}): Lee\'s turning guidance tracks at least as closely as our '
                    'tangent fillets + turn-rate lead (RMS cross-track)',
                    None if None in (xte[0], xte[2]) else xte[0] <= xte[2],
                    'RMS / max m: LOS point ' + ', '.join(
                        f'{what} {_fmt(a, 1)} / {_fmt(b, 1)}' for what, a, b in
                        zip(('LOS point', 'same circles + lead', 'ours'), xte, mx)).removeprefix('LOS point ')))
    return out


def figure_eight_arc_claim(legs):
    """Simakis 1992 Fig. 29: "the small values of the rudder angle" on the arcs, as a check: on
    every arc the mean |rudder| is within ARC_RUDDER_RTOL of the steady-turn rudder its
    curvature needs (the rudder does what the curve needs, no more), and the largest |rudder|
    on any arc stays below the largest at the straight-leg corner before them (the advantage
    "over the use of line segments only")."""
    claim = ('Simakis 1992 Fig. 29: the rudder on the figure eight\'s arcs is small: mean abs '
             'rudder per arc within 25 % of the steady-turn rudder of its curvature, max below '
             'the straight-leg corner\'s')
    if not legs:
        return claim, None, 'no per-leg rudder'
    arcs = [g for g in legs if g['kind'] == 'arc' and g['rudder_mean_abs_rad'] is not None]
    lines = [g for g in legs if g['kind'] == 'line' and g['rudder_max_abs_rad'] is not None]
    if not arcs or not lines or any(g['steady_turn_rudder_rad'] is None for g in arcs):
        return claim, None, 'arcs, lines or steady-turn rudder missing'
    ratio = [g['rudder_mean_abs_rad'] / abs(g['steady_turn_rudder_rad']) for g in arcs]
    arc_max = max(g['rudder_max_abs_rad'] for g in arcs)
    corner = max(g['rudder_max_abs_rad'] for g in lines)
    ok = all(abs(q - 1.0) <= ARC_RUDDER_RTOL for q in ratio) and arc_max < corner
    ev = (f'steady-turn rudder {_fmt(_deg(abs(arcs[0]["steady_turn_rudder_rad"])), 2)} deg; '
          'mean / steady per arc ' + ', '.join(f'{q:.2f}' for q in ratio)
          + f'; max on the arcs {_fmt(_deg(arc_max), 1)} deg vs {_fmt(_deg(corner), 1)} deg on '
          'the straight legs')
    return claim, ok, ev
#: Lee 2004 sec. 5.2.1: the PD (Kp = 9, Kd = 70) keeps about this steady heading error (deg)
#: after the Mariner's course changes (Fig. 5.7(b)); the claim allows +-THESIS_PD_ERROR_TOL_DEG
THESIS_PD_ERROR_DEG = 0.6
THESIS_PD_ERROR_TOL_DEG = 0.2


def lee_course_change_claims(rows):
    """Lee 2004 Figs. 5.14-5.18 (tanker, deep water) and the thesis's own PD gains."""
    out = []
    for ang in (30, 45, 60, 90):
        pd = _m(rows, f'course_tanker_{ang}_pd_004', 'steady_error_rad')
        fz = _m(rows, f'course_tanker_{ang}_fuzzy_004', 'steady_error_rad')
        if pd is None and fz is None:
            continue
        out.append((f'Lee 2004 Figs. 5.14-5.18 (tanker, depth 1000 m), {ang} deg: the fuzzy PID removes '
                    'the steady heading error the PD keeps', None if None in (pd, fz) else
                    abs(fz) < abs(pd), f'PD {_fmt(_deg(pd), 2)} deg, fuzzy PID '
                    f'{_fmt(_deg(fz), 2)} deg'))
    errs = {ang: _m(rows, f'course_mariner_{ang}_pd_thesisgains_004', 'steady_error_rad')
            for ang in (30, 45, 60, 90)}
    if any(e is not None for e in errs.values()):
        ok = _all([None if e is None else
                   abs(abs(_deg(e)) - THESIS_PD_ERROR_DEG) <= THESIS_PD_ERROR_TOL_DEG
                   for e in errs.values()])
        ours = [_m(rows, f'course_change_{ang}_pd_004', 'steady_error_rad') for ang in errs]
        out.append((f'Lee 2004 sec. 5.2.1, Fig. 5.7(b): with Kp = 9, Kd = 70 the PD keeps about '
                    f'{THESIS_PD_ERROR_DEG} deg of steady heading error (Mariner; within '
                    f'+-{THESIS_PD_ERROR_TOL_DEG} deg)', ok,
                    'thesis gains ' + ', '.join(_fmt(_deg(e), 2) for e in errs.values()) +
                    ' deg; our gain table ' + ', '.join(_fmt(_deg(e), 2) for e in ours) +
                    ' deg (30/45/60/90)'))
    return out


def lee_current_claims(rows):
    """Lee 2004 Ch. 4-5 route following in a 0.75 m/s current: both autopilots finish, and the
    fuzzy PID (integral action) tracks at least as closely as the PD."""
    out = []
    for ship in ('mariner', 'tanker'):
        names = [f'route_following_{ship}_{c}_current075_004' for c in ('pd', 'fuzzy')]
        if not any(n in rows for n in names):
            continue
        fin = [_m(rows, n, 'guidance_finished_s') for n in names]
        xte = [_m(rows, n, 'xte_rms_m') for n in names]
        mean = [_m(rows, n, 'xte_mean_m') for n in names]
        out.append((f'Lee 2004 route following ({ship}, 0.75 m/s current): both autopilots complete '
                    'the route and the fuzzy PID tracks at least as closely as the PD (RMS '
                    'cross-track error)', None if None in xte else
                    all(f is not None for f in fin) and xte[1] <= xte[0],
                    f'PD {_fmt(xte[0], 1)} m (mean {_fmt(mean[0], 1)}), fuzzy PID '
                    f'{_fmt(xte[1], 1)} m (mean {_fmt(mean[1], 1)}); finished at '
                    f'{_fmt(fin[0], 0)} / {_fmt(fin[1], 0)} s'))
    return out


# -- table ---------------------------------------------------------------------------------------

def _deg(x):
    return None if x is None else math.degrees(x)


def _fmt(x, nd=2):
    if x is None:
        return '-'
    if isinstance(x, bool):
        return 'yes' if x else 'no'
    return f'{x:.{nd}f}'


COLUMNS = (  # header, function(result) -> text
    ('scenario', lambda r: r['scenario']),
    ('model', lambda r: r['spec']['model']),
    ('guidance', lambda r: r['spec']['law']),
    ('autopilot', lambda r: r['spec']['controller']),
    ('current m/s', lambda r: _fmt(r['spec']['current_mps'], 1)),
    ('xte RMS m', lambda r: _fmt(_get(r, 'xte_rms_m'), 2)),
    ('xte max m', lambda r: _fmt(_get(r, 'xte_max_abs_m'), 2)),
    ('ref. RMS / max m', lambda r: (f"{_fmt(_get(r, 'ref_xte_rms_m'), 3)} / "
                                    f"{_fmt(_get(r, 'ref_xte_max_abs_m'), 3)}")
     if _get(r, 'ref_xte_rms_m') is not None else ''),
    ('mean abs rudder deg', lambda r: _fmt(_deg(_get(r, 'rudder_mean_abs_rad')), 2)),
    ('max abs rudder deg', lambda r: _fmt(_deg(_get(r, 'rudder_max_abs_rad')), 1)),
    ('rudder TV deg/s', lambda r: _fmt(_deg(_get(r, 'rudder_total_variation_rad_per_s')), 3)),
    ('sat. %', lambda r: _fmt(None if _get(r, 'rudder_saturated_fraction') is None
                             else 100 * _get(r, 'rudder_saturated_fraction'), 1)),
    ('heading err. mean deg', lambda r: _fmt(_deg(_get(r, 'heading_error_mean_rad')), 2)),
    ('finished at s', lambda r: _fmt(_get(r, 'guidance_finished_s'), 0)),
    ('reward', lambda r: _fmt(_get(r, 'reward_gaussian_sum'), 0)),
    ('outcome', lambda r: r['outcome']),
    ('wall s', lambda r: _fmt(r.get('wall_s'), 0)),
)


def _get(r, key):
    return (r.get('metrics') or {}).get(key)


COURSE_CHANGE_COLUMNS = (  # Lee 2004 Figs. 5.7-5.18: the step response and the rudder's use
    ('scenario', lambda r: r['scenario']),
    ('model', lambda r: r['spec']['model']),
    ('autopilot', lambda r: r['spec']['controller']),
    ('gains', lambda r: 'Lee 2004' if 'thesisgains' in r['scenario'] else 'gain table'),
    ('step deg', lambda r: _fmt(_deg(_get(r, 'step_rad')), 1)),
    ('overshoot deg', lambda r: _fmt(_deg(_get(r, 'overshoot_rad')), 2)),
    ('settling s (2 %)', lambda r: _fmt(_get(r, 'settling_time_s'), 0)),
    ('steady err. deg', lambda r: _fmt(_deg(_get(r, 'steady_error_rad')), 2)),
    ('mean abs rudder deg', lambda r: _fmt(_deg(_get(r, 'manoeuvre_rudder_mean_abs_rad')), 2)),
    ('max abs rudder deg', lambda r: _fmt(_deg(_get(r, 'manoeuvre_rudder_max_abs_rad')), 1)),
    ('mean abs rudder rate deg/s',
     lambda r: _fmt(_deg(_get(r, 'manoeuvre_rudder_total_variation_rad_per_s')), 3)),
    ('at limit s', lambda r: _fmt(_get(r, 'manoeuvre_rudder_time_at_limit_s'), 0)),
    ('outcome', lambda r: r['outcome']),
    ('wall s', lambda r: _fmt(r.get('wall_s'), 0)),
)


def markdown(results, claims, header):
    lines = [header, '']
    lines.append('Statistics from settle_s (scenario file) to the route\'s end (guidance '
                 'finished) or the end of the run; reward from the start (Martinsen and Lekkas 2018 eq. 8, '
                 'sigma 10 m, 0.1 s grid). xte = the guidance\'s cross-track error; ref. = '
                 'distance from the reference circle (Simakis 1992); rudder = actual rudder angle; TV = '
                 'total variation per second; sat. = share of samples at the limit; heading err. '
                 '= yaw - command (ENU: negative = to starboard of the command).')
    lines.append('')
    grouped = {}
    for r in results:
        title = next((t for p, t in GROUPS if r['scenario'].startswith(p)), 'Other scenarios')
        grouped.setdefault(title, []).append(r)
    for title, rows in grouped.items():
        cols = (COURSE_CHANGE_COLUMNS if all(r['scenario'].startswith('course_') for r in rows)
                else COLUMNS)
        lines += [f'### {title}', '', '| ' + ' | '.join(h for h, _ in cols) + ' |',
                  '|' + '---|' * len(cols)]
        lines += ['| ' + ' | '.join(f(r) for _, f in cols) + ' |' for r in rows]
        lines.append('')
    for r in results:
        legs = _get(r, 'rudder_legs')
        if legs:
            lines += [f"### {r['scenario']}: rudder per leg", '',
                      '| leg | kind | radius m | max abs rudder deg | mean abs rudder deg | '
                      'steady-turn rudder deg (model) |', '|---|---|---|---|---|---|']
            lines += [f"| {g['leg']} | {g['kind']} | "
                      f"{_fmt(1.0 / abs(g['curvature_1pm']) if g['curvature_1pm'] else None, 2)} | "
                      f"{_fmt(_deg(g['rudder_max_abs_rad']), 2)} | "
                      f"{_fmt(_deg(g['rudder_mean_abs_rad']), 2)} | "
                      f"{_fmt(_deg(g['steady_turn_rudder_rad']), 2)} |" for g in legs]
            lines.append('')
    if claims:
        lines += ['### Seed claims', '', '| claim | reproduced | evidence |', '|---|---|---|']
        verdict = {True: 'yes', False: 'NO', None: 'n/a'}
        lines += [f'| {c} | {verdict[v]} | {e} |' for c, v, e in claims]
        lines.append('')
    return '\n'.join(lines)


def main(argv=None):
    ap = OneLineParser(description=__doc__.split('\n')[0])
    ap.add_argument('scenarios', nargs='*', help='scenario files or globs (default: the seed '
                    'scenarios, scenarios/*_00{0,3,4}.yaml)')
    ap.add_argument('--only', action='append', default=[], metavar='PATTERN',
                    help='keep scenarios whose name contains PATTERN or matches it as a glob '
                    '(repeatable)')
    ap.add_argument('--quick', action='store_true', help=f'durations x{QUICK_FACTOR} '
                    f'(at least {QUICK_MIN_DURATION_S:.0f} s) for development; claims may fail')
    ap.add_argument('--runs', default=str(REPO / 'runs'), help='parent folder of the batch folder')
    ap.add_argument('--wall-timeout', type=number(above=0.0), default=600.0,
                    help='fail a run after this many wall seconds (default 600)')
    ap.add_argument('--domain-id', type=integer(0, 232), default=None, help='ROS_DOMAIN_ID for every run '
                    '(default: a leased one on which no other node is seen)')
    ap.add_argument('--retries', type=integer(0, 10), default=1, help='run a scenario again when its bag '
                    'came out incomplete, at most this many times (default 1)')
    ap.add_argument('--verbose', action='store_true', help='show the launchers\' progress lines')
    ap.add_argument('--list', action='store_true', help='list the scenarios and exit')
    ap.add_argument('--reanalyse', metavar='BATCH_DIR', help='recompute the table of an earlier '
                    'batch from its bags (no runs)')
    args = ap.parse_args(argv)
    if args.reanalyse:
        batch = Path(args.reanalyse)
        try:
            results, old = reanalyse(batch)
        except ScenarioError as exc:
            print(f'run_seed_scenarios: {exc}', file=sys.stderr)
            return 2
        claims = claim_checks({r['scenario']: r for r in results})
        table = markdown(results, claims, f'## Seed scenarios (re-analysed): {len(results)} runs '
                         f'of {batch.name}')
        write_results(batch, results, claims, table, old.get('quick'), old.get('wall_time_s'),
                      provenance())
        return 0

    try:
        scenarios = find_scenarios(args.scenarios, args.only)   # a bad file: before anything runs
    except ScenarioError as exc:
        print(f'run_seed_scenarios: {exc}', file=sys.stderr)
        return 2
    if args.list:
        print('\n'.join(f'{s.name}  ({s.file})' for s in scenarios))
        return 0
    stamp = datetime.now().strftime('%Y%m%d-%H%M%S')
    started = provenance()     # the code the runs use is the code at their start
    batch = Path(args.runs) / f'seeds{"-quick" if args.quick else ""}-{stamp}'
    batch.mkdir(parents=True)
    latest = Path(args.runs) / 'seeds-latest'
    if latest.is_symlink() or latest.exists():
        latest.unlink()
    latest.symlink_to(batch.name)
    print(f'{len(scenarios)} scenarios -> {batch}' + (' (quick)' if args.quick else ''), flush=True)

    results, code, t0 = [], 0, time.monotonic()
    try:
        lease = quiet_domain_lease() if args.domain_id is None else None
    except LeaseError as exc:
        print(f'run_seed_scenarios: {exc}', file=sys.stderr)
        return 1
    domain_id = args.domain_id if lease is None else lease.domain_id
    print(f'ROS_DOMAIN_ID {domain_id}' + (' (leased, quiet)' if lease else ''), flush=True)
    try:
        for i, scenario in enumerate(scenarios, 1):
            print(f'[{i}/{len(scenarios)}] {scenario.name}', flush=True)
            r = run_one(scenario, batch, args.quick, args.wall_timeout, args.verbose, domain_id,
                        args.retries)
            results.append(r)
            if r['outcome'] not in ('completed', 'duration reached'):
                code = 1
    except KeyboardInterrupt:
        print('run_seed_scenarios: interrupted; writing what ran so far', file=sys.stderr)
        code = 130
    finally:
        if lease is not None:
            lease.close()
    wall = time.monotonic() - t0
    claims = claim_checks({r['scenario']: r for r in results})
    header = (f'## Seed scenarios{" (quick: durations x%g)" % QUICK_FACTOR if args.quick else ""}'
              f': {len(results)} runs in {wall:.0f} s wall ({stamp})')
    write_results(batch, results, claims, markdown(results, claims, header), args.quick, wall,
                  started)
    return code


def html_index(batch, results, claims, header):
    """batch/index.html (ship_mission.html_report.batch_page): the runs grouped as in results.md,
    each scenario linked to its run's report.html, then the claims with their evidence."""
    from ship_mission.html_report import batch_page
    grouped = {}
    for r in results:
        title = next((t for p, t in GROUPS if r['scenario'].startswith(p)), 'Other scenarios')
        grouped.setdefault(title, []).append(r)

    def report(r):
        path = Path(r['run_dir']) / 'report.html' if r.get('run_dir') else None
        return path if path and path.exists() else None

    sections = []
    for title, rows in grouped.items():
        cols = (COURSE_CHANGE_COLUMNS if all(r['scenario'].startswith('course_') for r in rows)
                else COLUMNS)
        sections.append((title, [h for h, _ in cols], [[f(r) for _, f in cols] for r in rows],
                         [report(r) for r in rows]))
    verdict = {True: 'yes', False: 'NO', None: 'n/a'}
    if claims:
        sections.append(('Seed claims', ['claim', 'reproduced', 'evidence'],
                         [[c, verdict[v], e] for c, v, e in claims]))
    runs = [[r['scenario'], r['outcome'], r.get('error') or ''] for r in results]
    links = [report(r) for r in results]
    return batch_page(batch / 'index.html', header.lstrip('# '), ['run (its report)', 'outcome', 'error'],
                      runs, links, intro=f'{len(results)} runs; the tables as in results.md.',
                      sections=sections)


def write_results(batch, results, claims, table, quick, wall, started):
    """results.md, index.html and results.json; ``started``: the provenance at the start (the
    results page doc/results/seed_scenarios.md renders its claims from results.json)."""
    (batch / 'results.md').write_text(table + '\n')
    html_index(batch, results, claims, table.splitlines()[0])
    with open(batch / 'results.json', 'w') as fh:
        json.dump({'provenance': started, 'batch': str(batch), 'quick': quick,
                   'wall_time_s': wall, 'runs': results,
                   'claims': [{'claim': c, 'reproduced': v, 'evidence': e} for c, v, e in claims]},
                  fh, indent=2, allow_nan=False, default=str)
    print()
    print(table)
    print(f'written: {batch / "results.md"}, {batch / "results.json"}, {batch / "index.html"}')


if __name__ == '__main__':
    sys.exit(main())
