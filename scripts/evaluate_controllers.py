#!/usr/bin/env python3
"""Table I of Martinsen and Lekkas 2018 for our controllers: cumulative Gaussian reward per 1000 s curved episode.

    scripts/evaluate_controllers.py [--quick] [--models mariner,container,tanker]
                                    [--starts 5] [--out runs/eval/controllers]
                                    [--condition calm|wind10|wind20] [--wave-filter]
                                    [--currents 0,0.9] [--batched]

Source: Martinsen and Lekkas 2018, Table I ("Cumulative Gaussian
reward for the curved path following problem", LOS vs DRL, Mariner / Container / Tanker at
current 0 and 0.9 m/s) and eq. 8 (Gaussian a = 1, sigma = 10 m, gated by |psi - gamma_p| <=
90 deg: ship_autopilot.learning.env.gaussian_reward).

Setup (the same for every controller):
- Paths: scenarios/routes/curved_path_<model>_000.yaml (sines designed after Martinsen and Lekkas 2018; its
  curves are not in the OCR).
- Start states: ``--starts`` per ship, drawn once from a fixed seed: a point within the first
  500 m of the path, offset sideways uniformly in +-100 m, heading = path angle + uniform
  +-20 deg, straight-running trim at the model's nominal speed/shaft; the 0.9 m/s current's
  direction is drawn per start (uniform, flowing towards), the same for every controller.
- Plant: MSS model, RK4 at 0.1 s, current added to the kinematics (learning.env).
- Reward sampling: the Gaussian is accumulated at every 0.1 s sample (10 000 samples per
  1000 s episode, maximum 10 000). Martinsen and Lekkas 2018 does not state its step; its DRL Mariner figure
  of 3264 per 1000 s episode needs >= 3.3 samples/s, and MSS's sample time is 0.1 s, so the
  numbers should be on the same scale, but Martinsen and Lekkas's paths, start states and current
  directions are unknown: compare orders of magnitude, not digits.
- Controllers: 'los' = LOS guidance + PD autopilot (gains from ship_autopilot/data/
  autopilot_gains.yaml); 'ilos' = integral LOS (sigma = U0 / 4, critically damped, los.py)
  + PD; 'fuzzy_pid' = LOS guidance + fuzzy PID (Lee 2004's combination); look-ahead 2.5 ship
  lengths for all three (stable: checked against the PD's zeta, omega_n); guidance and
  autopilot run every 0.1 s, as the nodes do. 'policy' = the shipped DDPG policy
  (ship_autopilot/data/policies/<model>.npz), acting every control_dt of its file (1 s, the
  step it was trained with) on the eq. 9 state (ship_guidance.path_state) from the same projection.
  'los_lead' = the best classical loop we have (the flagship's): LOS + PD placed at a faster
  omega_n = k U / L (from the identified Nomoto a, b) + the guidance's turn-rate lead
  (psi_c += 2 zeta U kappa / omega_n), look-ahead d ship lengths. (k, d) per ship come from
  ``--tune``: a grid search on the training environment's curve pool (learning.env, other
  curves and starts than this table's), never on the evaluation path; TUNED holds its result.
  'ilos_lead' = the same with integral LOS (sigma = U0 / 4) for the steady drift of a current,
  tuned by the same procedure (``--tune --tune-controller ilos_lead``; TUNED_ILOS).

Wind and waves (``--condition``, ship_mission.conditions: calm, wind10, wind20; issue 14): the wind
loads enter the plant (learning.env's ``wind``: relative wind from the velocity over ground,
each model's own force equations); the gusts and the wave-frequency motion of start i (seed
conditions.SEED + i, the same for every controller and current) are its own; the waves are
superposed on what every controller measures, as vessel_node superposes it on odom
(ship_sim.environment.sea_state.superpose: position, heading, body velocities; RAOs at the
speed through the water). The policies never saw wind or waves in training.
``--wave-filter`` passes heading and yaw rate of the classical autopilots through
ship_autopilot.wave_filter tuned to the sea, as the autopilot node does;
the guidance still sees the unfiltered position and heading (as in the graph). Tracking metrics
and the reward use the measured (total: manoeuvring + wave-frequency) motion, as the graph's
metrics use odom. Calm runs are the undisturbed computation, bit for bit.

Metrics per run: cumulative Gaussian (mean over starts), mean and max |e| (m), mean and max |e|
over the last 500 s (settled), rudder activity = mean |d delta / dt| of the actual rudder
(deg/s), its total variation over the episode (deg), mean |delta| (deg) and the fraction of
samples with the rudder at its limit. Output: <out>.json, <out>.md (also printed) and <out>.html (the same tables,
ship_mission.html_report).
"""
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from results_pages.provenance import provenance

from ship_autopilot.gains import autopilot_gains, build_autopilot, nomoto_gains
from ship_autopilot.learning.env import (EnvConfig, PathFollowingBatch,
                                         gaussian_reward)
from ship_guidance.path_state import PathFeatures
from ship_autopilot.learning.policy import LearnedSteering, load_policy
from ship_autopilot.pd import pd_gains
from ship_guidance.guidance import Guidance
from ship_planner.route_loader import load_route
from ship_autopilot.wave_filter import WaveFilter
from ship_sim.environment.sea_state import ShipWaves, rao_table_for
from ship_sim.allocator import tune_allocator
from ship_sim.models import cards, make_model
from ship_mission.conditions import (CONDITIONS, SEED, Condition, route_course, sea_state,
                                wind_field)

ROOT = Path(__file__).resolve().parent.parent

#: The ships with a shipped learned policy (their cards' ``policy``): the policy is one of
#: the compared controllers.
MODELS = tuple(c.name for c in cards() if c.policy)
CURRENTS = (0.0, 0.9)
CONTROLLERS = ('los', 'ilos', 'fuzzy_pid', 'los_lead', 'ilos_lead', 'policy')
LABELS = {'los': 'LOS + PD', 'ilos': 'ILOS + PD', 'fuzzy_pid': 'LOS + fuzzy PID',
          'los_lead': 'LOS + fast PD + turn-rate lead',
          'ilos_lead': 'ILOS + fast PD + turn-rate lead', 'policy': 'DDPG policy (ours)'}
#: The tuned loops ('los_lead', 'ilos_lead'): fast PD + turn-rate lead, plain or integral LOS.
LEAD_CONTROLLERS = ('los_lead', 'ilos_lead')
#: 'los_lead' tuning per ship: (omega_n in units of U / L, look-ahead in ship lengths), chosen by
#: ``--tune`` (grid TUNE_GRID, mean Gaussian over the training pool's curves; see TUNE_* below;
#: the tanker's optimum lay at the grid's longest look-ahead, so it was searched further with
#: ``--tune --models tanker --grid 1,1.5,2/3.5,5,7``).
TUNED = {'mariner': (2.5, 1.0), 'container': (2.5, 1.5), 'tanker': (1.5, 3.5)}
#: 'ilos_lead' tuning per ship, by the same ``--tune`` procedure and grid (``--tune
#: --tune-controller ilos_lead``; no optimum at the grid's edge).
TUNED_ILOS = {'mariner': (2.5, 1.5), 'container': (1.5, 2.5), 'tanker': (2.5, 1.5)}
TUNE_GRID = {'omega_n_nd': (1.0, 1.5, 2.5, 3.5), 'lookahead_L': (0.75, 1.0, 1.5, 2.5, 3.5)}
TUNE_STARTS, TUNE_SEED = 4, 7
#: Martinsen and Lekkas 2018 Table I: (model, current) -> cumulative Gaussian reward.
SEED_TABLE = {
    'LOS (Martinsen and Lekkas 2018)': {'mariner': (161, 499), 'container': (807, 829), 'tanker': (65, 62)},
    'DRL (Martinsen and Lekkas 2018)': {'mariner': (3264, 3134), 'container': (2430, 2763),
                       'tanker': (1010, 819)},
}
LOOKAHEAD_SHIP_LENGTHS = 2.5
SIM_DT = 0.1


def start_states(k, seed=2024):
    """k start dicts (learning.env.PathFollowingBatch.reset) + current directions, seeded."""
    rng = np.random.default_rng(seed)
    return [{'route': 0, 'along': rng.uniform(0.0, 500.0), 'cross': rng.uniform(-100.0, 100.0),
             'heading': math.radians(rng.uniform(-20.0, 20.0)), 'current_speed': 0.0,
             'current_direction': rng.uniform(-math.pi, math.pi)} for _ in range(k)]


def loop_design(model_name, controller, speed, length, tuning=None):
    """Guidance and heading-loop design of a controller: law, lookahead (m), zeta, omega_n
    (rad/s), lead (turn-rate lead on or off), integral_gain (m/s, ILOS) and, for the tuned loops,
    the PD gains k1, k2 placed at that omega_n on the identified Nomoto model."""
    gains = autopilot_gains(model_name)
    d = {'law': 'ilos' if controller in ('ilos', 'ilos_lead') else 'los',
         'lookahead': LOOKAHEAD_SHIP_LENGTHS * length, 'zeta': gains['zeta'],
         'omega_n': gains['omega_n'], 'lead': False, 'integral_gain': speed / 4.0}
    if controller in LEAD_CONTROLLERS:
        omega_n_nd, lookahead_L = tuning or (TUNED if controller == 'los_lead'
                                             else TUNED_ILOS)[model_name]
        d.update(omega_n=omega_n_nd * speed / length, lookahead=lookahead_L * length, lead=True)
        nomoto = nomoto_gains(model_name)
        d['k1'], d['k2'] = pd_gains(nomoto['a'], nomoto['b'], omega_n=d['omega_n'],
                                    zeta=d['zeta'])
    return d


def guidance_for(route, design, speed):
    """The Guidance of a ``loop_design`` (ValueError beyond the loop's stability limit)."""
    return Guidance(route, design['law'], design['lookahead'],
                    integral_gain=design['integral_gain'], zeta=design['zeta'],
                    omega_n=design['omega_n'], speed=speed, curvature_lead=design['lead'])


def run(model, route, controller, starts, current, duration, policy_file=None, tuning=None,
        current_field=None, condition='calm', wave_filter=False, activity=False, seeds=None):
    """Simulate every start with one controller; returns per-start metric arrays.
    ``tuning``: (omega_n_nd, lookahead_L) for 'los_lead' / 'ilos_lead' instead of TUNED /
    TUNED_ILOS. ``current_field``: a ship_sim.current.OceanCurrent of shape (len(starts),)
    advanced every step (a varying current) instead of the constant one of the starts.
    ``condition``: wind and waves (ship_mission.conditions name or Condition; module docstring;
    ``seeds``: per start, see ``disturbances``), ``wave_filter`` the classical autopilots'
    wave filter; ``activity`` adds the max |e| of the second half,
    the rudder's total variation and its saturated fraction (the batched loop has no such
    metrics, so they are not returned by default)."""
    k = len(starts)
    plant = make_model(model) if isinstance(model, str) else model
    wind, waves, seas = disturbances(condition, [route], plant, [0] * k, seeds)
    env = PathFollowingBatch(plant, k, EnvConfig(mode='straight', sim_dt=SIM_DT,
                                                 control_dt=SIM_DT), routes=[route], wind=wind)
    env.reset(starts=[dict(s, current_speed=current) for s in starts])
    m = env.model
    filters = None
    if wave_filter and waves is not None and controller != 'policy':
        filters = [wave_filters([sea]) for sea in seas]
    gains = autopilot_gains(m.name)
    speed = env.speed0
    d = loop_design(m.name, controller, speed, env.length, tuning)
    guides = [guidance_for(route, d, speed) for _ in range(k)]
    if controller == 'policy':
        policy = load_policy(m.name, policy_file)
        steering = [LearnedSteering(policy) for _ in range(k)]
        features = PathFeatures((k,))
        control_dt = policy.control_dt
    elif controller in LEAD_CONTROLLERS:
        autopilot = build_autopilot('pd', {'k1': d['k1'], 'k2': d['k2']}, m.rudder_max,
                                    m.rudder_rate_max)
    else:
        autopilot = build_autopilot('pd' if controller in ('los', 'ilos') else 'fuzzy_pid',
                                    gains, m.rudder_max, m.rudder_rate_max)
    n_steps = int(round(duration / SIM_DT))
    gauss = np.zeros(k)
    abs_e = np.zeros((n_steps, k))
    rudder = np.zeros((n_steps + 1, k))
    rudder[0] = m.rudder_angle(env.x)
    cmd = np.zeros(k)
    t_feat = -math.inf
    for step in range(n_steps + 1):
        t = step * SIM_DT
        north, east, psi = env.x[:, m.IX], env.x[:, m.IY], env.x[:, m.IPSI]
        r = env.x[:, m.IR]
        if waves is not None:   # what the controllers measure (module docstring)
            north, east, psi, u_m, v_m, r = env.measured(waves, t)
        outs = [g.update(north[i], east[i], psi[i], SIM_DT if step else 0.0)
                for i, g in enumerate(guides)]
        e = np.array([o.cross_track for o in outs])
        if step:  # reward of the state reached by the previous step (samples 0.1 s ... T)
            gauss += gaussian_reward(e, psi - np.array([o.path_angle for o in outs]))
            abs_e[step - 1] = np.abs(e)
            rudder[step] = m.rudder_angle(env.x)
        if step == n_steps:
            break
        if controller == 'policy':
            if t - t_feat >= control_dt - 1e-9:   # features at the policy's own step
                u, v, r = env.ground_velocity() if waves is None else (u_m, v_m, r)
                raw = features(e, [o.path_angle for o in outs], [o.curvature for o in outs],
                               psi, u, v, r, 0.0 if t_feat == -math.inf else t - t_feat)
                cmd = np.array([st.update(raw[i], t) for i, st in enumerate(steering)])
                t_feat = t
        else:
            psi_c = np.array([o.heading_cmd for o in outs])
            if filters is not None:
                filt = [f.update(t, psi[i], r[i], math.hypot(u_m[i], v_m[i]))
                        for i, f in enumerate(filters)]
                psi, r = np.array([p for p, _ in filt]), np.array([q for _, q in filt])
            cmd = np.asarray(autopilot.update(psi, r, psi_c, SIM_DT))
        if current_field is not None:
            env.current[:, 0], env.current[:, 1] = current_field.velocity_ne()
            current_field.advance(SIM_DT)
        ok = env.integrate(cmd, 1)
        if not ok.all():
            raise RuntimeError(f'{model}/{controller}: state left the model domain')
    settle = abs_e[n_steps // 2:]
    out = {'gaussian': gauss, 'mean_abs_e': abs_e.mean(0), 'max_abs_e': abs_e.max(0),
           'rms_e': np.sqrt(np.mean(abs_e ** 2, axis=0)),
           'mean_abs_e_settled': settle.mean(0),
           'rudder_rate_deg_s': np.degrees(np.abs(np.diff(rudder, axis=0)).mean(0) / SIM_DT),
           'mean_abs_rudder_deg': np.degrees(np.abs(rudder).mean(0))}
    if activity:
        out.update(max_abs_e_settled=settle.max(0),
                   rudder_tv_deg=np.degrees(np.abs(np.diff(rudder, axis=0)).sum(0)),
                   rudder_saturated_fraction=np.mean(np.abs(rudder[1:]) >= m.rudder_max
                                                     * (1 - 1e-9), axis=0))
    return out


def wave_filters(seas):
    """The classical autopilots' wave filter (ship_autopilot.wave_filter) tuned to each sea
    state of ``seas``: one filter for one sea, a batch of filters for several."""
    if len(seas) == 1:
        return WaveFilter(peak_frequency=seas[0].peak_frequency, direction=seas[0].direction)
    return WaveFilter(peak_frequency=np.array([s.peak_frequency for s in seas]),
                      direction=np.array([s.direction for s in seas]))


def disturbances(condition, routes, model, route_index, seeds=None):
    """(WindField of shape (k,) or None, batch ShipWaves of k sea states or None, the k
    SeaStates or None) of a condition (a ship_mission.conditions name or Condition) for k episodes
    on ``routes[route_index[i]]`` (one course). ``seeds``: one int per episode, its gusts and
    waves (a stream each, so an episode does not depend on the others); default Table I's,
    SEED + i for episode i."""
    cond = condition if isinstance(condition, Condition) else CONDITIONS[condition]
    k = len(route_index)
    if cond.calm:
        return None, None, None
    courses = {route_course(routes[i]) for i in set(route_index)}
    if len(courses) > 1:
        raise ValueError('wind and waves run on routes of one overall course per batch')
    course = courses.pop()
    seeds = [SEED + i for i in range(k)] if seeds is None else [int(s) for s in seeds]
    wind = wind_field(cond, course, seeds, shape=(k,))
    seas = [sea_state(cond, course, seed) for seed in seeds]
    if seas[0] is None:
        return wind, None, None
    return wind, ShipWaves(seas, rao_table_for(model.name, model.length)), seas


def run_batched(model, routes, controller, starts, duration, tunings=None, condition='calm',
                seeds=None, wave_filter=False, current_field=None):
    """``run`` for many starts at once in the batched closed loop
    (ship_autopilot.batch_closed_loop), each equal to ``run`` to rounding. ``starts``: dicts
    as ``run``'s, each with its ``route`` (index into ``routes``) and ``current_speed``;
    ``tunings``: one (omega_n_nd, lookahead_L) or None per start (tuned loops); ``condition``,
    ``seeds`` and ``wave_filter`` as ``run``'s (``run`` with the same starts and seeds);
    ``current_field`` an OceanCurrent of shape (len(starts),) as ``run``'s. Returns the
    metrics (name -> array per start, BatchClosedLoop.METRICS)."""
    from ship_autopilot.batch_closed_loop import START_KEYS, BatchClosedLoop
    kind = {'fuzzy_pid': 'fuzzy_pid', 'policy': 'policy'}.get(controller, 'pd')
    law = 'ilos' if controller in ('ilos', 'ilos_lead') else 'los'
    loop = BatchClosedLoop(model, routes, kind, law, sim_dt=SIM_DT)
    tunings = tunings or [None] * len(starts)
    designs = {t: loop_design(loop.model.name, controller, loop.speed, loop.length, t)
               for t in dict.fromkeys(tunings)}
    eps = {k: [s[k] for s in starts] for k in START_KEYS}
    eps['lookahead'] = [designs[t]['lookahead'] for t in tunings]
    eps['integral_gain'] = [designs[t]['integral_gain'] for t in tunings]
    if controller in LEAD_CONTROLLERS:
        # The Guidance of each design (its stability check included) gives the lead.
        lead = {t: guidance_for(routes[0], d, loop.speed)._lead for t, d in designs.items()}
        eps['lead'] = [lead[t] for t in tunings]
        eps['k1'] = [designs[t]['k1'] for t in tunings]
        eps['k2'] = [designs[t]['k2'] for t in tunings]
    wind, waves, seas = disturbances(condition, routes, loop.model, eps['route'], seeds)
    filt = (wave_filters(seas) if wave_filter and waves is not None and controller != 'policy'
            else None)
    return loop.run(eps, duration, wind=wind, waves=waves, current=current_field,
                    wave_filter=filt).metrics


def _task(args):
    """One (model, controller) at every current: -> {current: summary}. Batched, the starts of
    every current run in one batch (start i keeps its seed SEED + i at each current)."""
    model, currents, ctrl, starts, duration, policy_file, condition, wave_filter, batched = args
    route = load_route(ROOT / 'scenarios' / 'routes' / f'curved_path_{model}_000.yaml').route
    k = len(starts)
    t0 = time.perf_counter()
    try:
        # The batched closed loop equals run to rounding, wave filter included.
        if batched:
            if policy_file:
                raise ValueError('--batched runs the shipped policies only')
            r = run_batched(model, [route], ctrl, [dict(s, current_speed=c) for c in currents
                                                   for s in starts], duration,
                            condition=condition,
                            seeds=[SEED + i for _ in currents for i in range(k)],
                            wave_filter=wave_filter)
            if r['failed'].any():
                raise RuntimeError(f'{model}/{ctrl}: state left the model domain')
            per = {c: {key: r[key][j * k:(j + 1) * k] for key in r
                       if key not in ('finished', 'finish_time_s', 'failed')}
                   for j, c in enumerate(currents)}
        else:
            per = {c: run(model, route, ctrl, starts, c, duration, policy_file,
                          condition=condition, wave_filter=wave_filter, activity=True)
                   for c in currents}
    except Exception as exc:  # noqa: BLE001 (report a missing policy etc. in the table)
        print(f'{model:9s} {ctrl:10s} ERROR {exc}', flush=True)
        return {c: {'error': str(exc)} for c in currents}
    out = {}
    for c, r in per.items():
        summary = {key: float(np.mean(v)) for key, v in r.items()}
        summary['gaussian_per_start'] = [round(float(g), 1) for g in r['gaussian']]
        print(f'{model:9s} {c:.1f} m/s {ctrl:10s} gaussian {summary["gaussian"]:8.1f}'
              f'  mean|e| {summary["mean_abs_e"]:7.1f} m  max|e| '
              f'{summary["max_abs_e"]:7.1f} m  rudder {summary["rudder_rate_deg_s"]:.3f}'
              f' deg/s  ({time.perf_counter() - t0:.0f} s)', flush=True)
        out[c] = summary
    return out


def tune_starts(model):
    """The tuning episodes of ``model``: TUNE_STARTS (route, start) pairs, start i on a curve
    of the training pool drawn with seed TUNE_SEED + i, current alternating 0 / 0.9 m/s."""
    out = []
    for i in range(TUNE_STARTS):
        rng = np.random.default_rng(TUNE_SEED + i)
        env = PathFollowingBatch(model, 1, EnvConfig(n_routes=1), seed=TUNE_SEED + i)
        start = env.sample_starts(1)[0]
        start['current_speed'] = CURRENTS[i % len(CURRENTS)]
        start['along'] = rng.uniform(0.0, 500.0)
        out.append((env.routes[0], dict(start, route=i)))
    return out


def _tune_task(args):
    """Scores of every stable grid point of one model (-inf beyond the stability limit), all
    grid points and starts in one batched closed loop."""
    model, grid, controller, duration = args
    pairs = tune_starts(model)
    routes = [r for r, _ in pairs]
    stable = []
    for g in grid:
        try:
            m = PathFollowingBatch(model, 1, EnvConfig(mode='straight'), routes=routes[:1])
            guidance_for(routes[0], loop_design(m.model.name, controller, m.speed0, m.length,
                                                g), m.speed0)
            stable.append(g)
        except ValueError as exc:   # a grid point beyond the loop's stability limit
            if 'stability limit' not in str(exc):
                raise
    starts = [s for _ in stable for _, s in pairs]
    tunings = [g for g in stable for _ in pairs]
    gauss = run_batched(model, routes, controller, starts, duration, tunings)['gaussian']
    scores = {g: [-math.inf] * len(pairs) for g in grid}
    for k, g in enumerate(tunings):
        scores[g][k % len(pairs)] = float(gauss[k])
    return scores


def tune(models, jobs=1, grid=None, controller='los_lead', duration=1000.0):
    """Grid search of a tuned loop's (omega_n_nd, lookahead_L) ('los_lead' or 'ilos_lead') per
    ship on TUNE_STARTS curves of the training pool (``tune_starts``), every episode of a ship
    in one batched closed loop; returns {model: {'best': (k, d), 'scores': {"k/d": mean
    Gaussian}}}."""
    g = grid or TUNE_GRID
    grid = [(k, d) for k in g['omega_n_nd'] for d in g['lookahead_L']]
    tasks = [(m, grid, controller, duration) for m in models]
    if jobs > 1:
        import multiprocessing
        with multiprocessing.Pool(jobs) as pool:
            per_model = pool.map(_tune_task, tasks, chunksize=1)
    else:
        per_model = [_tune_task(t) for t in tasks]
    out = {}
    for m, table in zip(models, per_model):
        means = {g: float(np.mean(v)) for g, v in table.items()}
        best = max(means, key=means.get)
        out[m] = {'best': best, 'scores': {f'{k:g}/{d:g}': round(v, 1) if math.isfinite(v)
                                           else 'unstable' for (k, d), v in means.items()}}
        print(f'{m:9s} best omega_n = {best[0]:g} U/L, look-ahead {best[1]:g} L: '
              f'{means[best]:.0f}  ({out[m]["scores"]})', flush=True)
    return out


def evaluate(models, n_starts, duration, controllers, policy_template=None, jobs=1,
             condition='calm', wave_filter=False, currents=CURRENTS, batched=False):
    """Every (model, current, controller) run; ``jobs`` > 1 runs them in processes."""
    starts = start_states(n_starts)
    tasks = [(model, tuple(currents), ctrl, starts, duration,
              policy_template.format(model=model) if policy_template else None, condition,
              wave_filter, batched)
             for model in models for ctrl in controllers]
    if jobs > 1:
        import multiprocessing
        with multiprocessing.Pool(jobs) as pool:
            out = pool.map(_task, tasks, chunksize=1)
    else:
        out = [_task(t) for t in tasks]
    return starts, {f'{t[0]}/{c}/{t[2]}': r[c] for t, r in zip(tasks, out) for c in currents}


def markdown(results, models, controllers, duration, n_starts):
    cols = [(m, c) for m in models for c in CURRENTS]
    head = '| controller | ' + ' | '.join(f'{m} {c:g} m/s' for m, c in cols) + ' |'
    sep = '|---|' + '---:|' * len(cols)
    lines = [f'Cumulative Gaussian reward per {duration:g} s episode (sum at 0.1 s samples, '
             f'max {duration / SIM_DT:.0f}; mean of {n_starts} start states)', '', head, sep]
    for name, table in SEED_TABLE.items():
        lines.append(f'| {name} | ' + ' | '.join(str(table[m][CURRENTS.index(c)])
                                                 for m, c in cols) + ' |')

    def rows(fmt):
        """One row per controller: fmt(result) per column, '-' not run, 'error' failed."""
        out = []
        for ctrl in controllers:
            cells = []
            for m, c in cols:
                r = results.get(f'{m}/{c}/{ctrl}', {})
                cells.append('-' if not r else 'error' if 'error' in r else fmt(r))
            out.append(f'| {LABELS[ctrl]} | ' + ' | '.join(cells) + ' |')
        return out

    lines += rows(lambda r: f'{r["gaussian"]:.0f}')
    lines += ['', 'Cross-track error mean / max (m) and rudder activity (mean |rudder rate|, '
              'deg/s)', '', head, sep]
    lines += rows(lambda r: f'{r["mean_abs_e"]:.1f} / {r["max_abs_e"]:.0f} / '
                            f'{r["rudder_rate_deg_s"]:.2f}')
    lines += ['', 'Max |e| over the last half (m) / rudder total variation per episode (deg) / '
              'rudder at its limit (% of samples)', '', head, sep]
    lines += rows(lambda r: f'{r.get("max_abs_e_settled", math.nan):.0f} / '
                            f'{r["rudder_tv_deg"]:.0f} / '
                            f'{100 * r.get("rudder_saturated_fraction", math.nan):.1f}')
    return '\n'.join(lines) + '\n'


def html_page(path, results, models, controllers, duration, n_starts):
    """<out>.html (ship_mission.html_report.batch_page): Table I (the paper's rows, then ours) and one
    row per (ship, current, controller) case with every metric. No run folders: these are
    in-process simulations, so the rows link nowhere."""
    from ship_mission.html_report import batch_page
    cols = [(m, c) for m in models for c in CURRENTS]
    table1 = [[name] + [table[m][CURRENTS.index(c)] for m, c in cols] for name, table in SEED_TABLE.items()]
    table1 += [[LABELS[ctrl]] + [results.get(f'{m}/{c}/{ctrl}', {}).get('gaussian') for m, c in cols]
               for ctrl in controllers]
    keys = ('gaussian', 'mean_abs_e', 'max_abs_e', 'mean_abs_e_settled', 'rudder_rate_deg_s',
            'mean_abs_rudder_deg')
    rows = [[m, c, LABELS[ctrl]] + [results.get(f'{m}/{c}/{ctrl}', {}).get(k) for k in keys]
            + [results.get(f'{m}/{c}/{ctrl}', {}).get('error', '')]
            for m in models for c in CURRENTS for ctrl in controllers]
    return batch_page(
        path, 'Table I (Martinsen and Lekkas 2018): cumulative Gaussian reward',
        ['controller'] + [f'{m} {c:g} m/s' for m, c in cols], table1,
        intro=f'Per {duration:g} s episode, sum at {SIM_DT:g} s samples (max {duration / SIM_DT:.0f}), '
              f'mean of {n_starts} start states. The paper\'s own rows first.',
        sections=[('Every case (means over the start states)',
                   ['ship', 'current m/s', 'controller', 'Gaussian reward', 'mean |e| m', 'max |e| m',
                    'mean |e| settled m', 'rudder rate deg/s', 'mean |rudder| deg', 'error'], rows)])


def main(argv=None):
    tune_allocator()   # its pools are forked from here and inherit it
    from ship_mission.cli_args import OneLineParser, integer, number
    p = OneLineParser(description=__doc__.split('\n')[0])
    p.add_argument('--quick', action='store_true',
                   help='1 start state, 300 s episodes (a smoke run for make bench)')
    p.add_argument('--models', default=','.join(MODELS))
    p.add_argument('--controllers', default=','.join(CONTROLLERS))
    p.add_argument('--starts', type=integer(1, 10_000), default=5)
    p.add_argument('--duration', type=number(above=0.0, hi=1e6), default=1000.0)
    p.add_argument('--out', default=str(ROOT / 'runs' / 'eval' / 'controllers'))
    p.add_argument('--jobs', type=integer(1, max(2, os.cpu_count() or 1)), default=1,
                   help='parallel processes (default 1, at most the cores)')
    p.add_argument('--policy', default=None, metavar='PATH',
                   help="policy files instead of the shipped ones, '{model}' in the path is "
                        "replaced by the ship, e.g. runs/rl/{model}_scratch/policy.npz")
    p.add_argument('--tune', action='store_true',
                   help="grid-search the 'los_lead' tuning on the training curve pool, print "
                        'it (paste into TUNED) and write <out>_tuning.json; no evaluation')
    p.add_argument('--tune-controller', default='los_lead', choices=LEAD_CONTROLLERS,
                   help='with --tune: the loop to tune (default %(default)s; paste ilos_lead '
                        'into TUNED_ILOS)')
    p.add_argument('--grid', default=None, metavar='K1,K2/D1,D2',
                   help='with --tune: omega_n values (U/L) / look-aheads (L) instead of TUNE_GRID')
    p.add_argument('--condition', default='calm', choices=tuple(CONDITIONS),
                   help='wind and waves (ship_mission.conditions; default %(default)s); not calm: '
                        "'_<condition>' is appended to --out")
    p.add_argument('--wave-filter', action='store_true',
                   help="the classical autopilots filter heading and yaw rate (ship_autopilot."
                        "wave_filter, tuned to the sea); '_filter' is appended to --out")
    p.add_argument('--currents', default=','.join(f'{c:g}' for c in CURRENTS),
                   help='current speeds (m/s) of the table\'s columns (default %(default)s)')
    p.add_argument('--batched', action='store_true',
                   help='every cell in the batched closed loop (ship_autopilot.'
                        "batch_closed_loop, equal to this loop to rounding; the wave "
                        "filter too); '_batched' is appended to --out")
    args = p.parse_args(argv)
    models = [m for m in args.models.split(',') if m]
    controllers = [c for c in args.controllers.split(',') if c]
    bad = [m for m in models if m not in MODELS] + [c for c in controllers if c not in CONTROLLERS]
    if bad:
        p.error(f'unknown {bad}; models {MODELS}, controllers {CONTROLLERS}')
    if args.tune:
        grid = TUNE_GRID
        if args.grid:
            ks, ds = args.grid.split('/')
            grid = {'omega_n_nd': tuple(float(k) for k in ks.split(',')),
                    'lookahead_L': tuple(float(d) for d in ds.split(','))}
        tuned = tune(models, args.jobs, grid, args.tune_controller)
        suffix = '' if args.tune_controller == 'los_lead' else f'_{args.tune_controller}'
        out = Path(args.out + f'_tuning{suffix}.json')
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps({'controller': args.tune_controller, 'grid': grid,
                                   'starts': TUNE_STARTS, 'seed': TUNE_SEED,
                                   'results': tuned}, indent=2))
        print(f'wrote {out}')
        return 0
    n_starts, duration = (1, 300.0) if args.quick else (args.starts, args.duration)
    t0 = time.perf_counter()
    starts, results = evaluate(models, n_starts, duration, controllers, args.policy, args.jobs,
                               args.condition, args.wave_filter,
                               tuple(float(c) for c in args.currents.split(',')), args.batched)
    md = (f'Condition: {CONDITIONS[args.condition].describe()}'
          + (', classical autopilots behind the wave filter' if args.wave_filter else '')
          + '\n\n' + markdown(results, models, controllers, duration, n_starts))
    print(md)
    out = Path(args.out + ('' if args.condition == 'calm' else f'_{args.condition}')
               + ('_filter' if args.wave_filter else '') + ('_batched' if args.batched else ''))
    out.parent.mkdir(parents=True, exist_ok=True)
    # provenance: the results pages (doc/results/ddpg.md) render from this file's committed copy
    doc = {'provenance': provenance(),
           'source': 'Martinsen and Lekkas 2018 Table I layout (scripts/evaluate_controllers.py)',
           'policy_files': args.policy or 'ship_autopilot/data/policies/<model>.npz',
           'duration_s': duration, 'sim_dt_s': SIM_DT, 'starts': starts,
           'lookahead_ship_lengths': LOOKAHEAD_SHIP_LENGTHS, 'seed_table': SEED_TABLE,
           'models': models, 'currents': list(CURRENTS),
           'controllers': {c: LABELS[c] for c in controllers},
           'condition': {'name': args.condition,
                         'description': CONDITIONS[args.condition].describe(),
                         'wave_filter': args.wave_filter},
           'results': results, 'wall_s': round(time.perf_counter() - t0, 1)}
    out.with_suffix('.json').write_text(json.dumps(doc, indent=2))
    out.with_suffix('.md').write_text(md)
    html_page(out.with_suffix('.html'), results, models, controllers, duration, n_starts)
    print(f'wrote {out}.json, {out}.md and {out}.html')
    return 1 if any('error' in r for r in results.values()) else 0


if __name__ == '__main__':
    sys.exit(main())
