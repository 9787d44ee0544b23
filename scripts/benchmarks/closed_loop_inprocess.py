"""Section ``closed_loop_inprocess``: the flagship closed loop with the pure modules, no ROS.

What runs is what the three nodes of the flagship scenario (scenarios/flagship_mariner.yaml)
compute, in one process, one step after the other:

    VesselSimulator (MSS mariner, dt 0.1 s, start pose and 0.3 m/s current of the scenario)
    -> Guidance (ILOS on the flagship route, the scenario's look-ahead and integral gain)
    -> PD autopilot (build_autopilot('pd', autopilot_gains('mariner')), the mariner's limits)
    -> rudder command back into the simulator,

at 10 Hz for SIM_TIME_S of sim time (10 000 steps). The loop reads the simulator's
``nav_state()`` (the numbers an Odometry carries) and hands the guidance its dt, as the nodes do;
guidance and autopilot parameters (turn-rate lead, PD redesigned for the scenario's omega_n)
are read from the scenario the way the nodes read them.

Reported: wall time of the loop (best and median of ``repeats`` runs, time.perf_counter) and its
CPU time (time.process_time, best), real-time factor sim time / best wall time (goal >= 1000x;
also given in CPU time, which a busy machine disturbs much less), the per-step cost split into
its parts (simulator nav_state and step, guidance update, autopilot update; timed in a
separate run, since timing every call adds its own overhead), and a cProfile summary of one
more run: the five functions with the largest cumulative time (profiling slows the run, so
only the shares mean something). The final cross-track error is printed as a check that the
loop steers.
"""
import cProfile
import math
import os
import pstats
import statistics
import time

from ship_mission.scenario import load_scenario, start_pose

from . import common

SCENARIO = common.REPO / 'scenarios' / 'flagship_mariner.yaml'
SIM_TIME_S = 1000.0
GOAL_RTF = 1000.0
REPEATS = 5
QUICK_REPEATS = 2


def build_loop(scenario_file=SCENARIO):
    """(sim, guidance, autopilot, dt) as the flagship scenario's nodes would build them."""
    scenario = load_scenario(scenario_file)
    return build_vessel(scenario, scenario.vessels[0])


def build_vessel(scenario, spec):
    """(sim, guidance, autopilot controller, dt) of one vessel of a loaded scenario, built as
    its vessel_node, guidance_node and autopilot_node build them."""
    from ship_autopilot.gains import (FUZZY_SCALING_PARAMETERS, build_autopilot,
                                      heading_loop_design)
    from ship_guidance.guidance import Guidance
    from ship_guidance.node_defaults import GUIDANCE_DEFAULTS as G
    from ship_planner.route_loader import load_route
    from ship_sim.current import OceanCurrent
    from ship_sim.frames import yaw_to_psi
    from ship_sim.models import card
    from ship_sim.simulator import VesselSimulator

    from ship_sim.schema import VESSEL_NODE

    route = load_route(spec.route_file).route
    x, y, yaw = start_pose(spec, route)
    vessel_card = card(spec.model)
    table = vessel_card.node_kwargs
    vessel_params = VESSEL_NODE.current_names(spec.vessel_params)
    model = vessel_card.make(**{table[k]: v for k, v in vessel_params.items()
                                if k in table and v})
    cur = spec.current
    current = (OceanCurrent(cur.get('speed_mps', 0.0), math.radians(cur.get('direction_deg', 0.0)))
               if cur else None)
    # the start yaw travels to vessel_node in degrees (ship_mission.launcher.node_parameters)
    psi = float(yaw_to_psi(math.radians(math.degrees(yaw))))
    sim = VesselSimulator(model, dt=scenario.dt_s, north=y, east=x, psi=psi, speed=spec.speed,
                          current=current)
    g = spec.guidance_params
    stability = {}
    if all(k in g for k in ('autopilot_zeta', 'autopilot_omega_n', 'speed')):
        stability = dict(zeta=g['autopilot_zeta'], omega_n=g['autopilot_omega_n'],
                         speed=g['speed'])
    guidance = Guidance(route, law=g.get('law', G['law']),
                        lookahead=g.get('lookahead_m', G['lookahead_m']),
                        acceptance_radius=g.get('acceptance_radius_m', 0.0),
                        integral_gain=g.get('integral_gain', G['integral_gain']),
                        curvature_lead=g.get('curvature_lead', False), **stability)
    # Gains as the autopilot node chooses them (the function it calls).
    a = spec.autopilot_params
    kind = a.get('controller', 'pd')
    keys = ('controller', 'k1', 'k2', 'omega_n', 'zeta', *FUZZY_SCALING_PARAMETERS)
    gains = heading_loop_design(spec.model, **{k: a[k] for k in keys if k in a}).gains
    autopilot = build_autopilot(kind, gains, model.rudder_max, model.rudder_rate_max,
                                a.get('saturation', 'hard'))
    return sim, guidance, autopilot, scenario.dt_s


def run_loop(sim, guidance, autopilot, dt, steps):
    """The closed loop, as the nodes run it (first autopilot step: dt 1e-9, see the node)."""
    nav, gupdate, aupdate, step = sim.nav_state, guidance.update, autopilot.update, sim.step
    t_prev = None
    out = None
    for _ in range(steps):
        t, n, e, psi, u, v, r = nav()
        h = 0.0 if t_prev is None else t - t_prev
        out = gupdate(n, e, psi, h)
        step(aupdate(psi, r, out.heading_cmd, h if h > 0.0 else 1e-9))
        t_prev = t
    return out


def split_costs(steps):
    """Mean per-call time (us) of each part over one loop, each call timed on its own."""
    sim, guidance, autopilot, dt = build_loop()
    clock = time.perf_counter
    acc = [0.0, 0.0, 0.0, 0.0]
    t_prev = None
    for _ in range(steps):
        c0 = clock()
        t, n, e, psi, u, v, r = sim.nav_state()
        c1 = clock()
        h = 0.0 if t_prev is None else t - t_prev
        out = guidance.update(n, e, psi, h)
        c2 = clock()
        delta = autopilot.update(psi, r, out.heading_cmd, h if h > 0.0 else 1e-9)
        c3 = clock()
        sim.step(delta)
        c4 = clock()
        t_prev = t
        acc[0] += c1 - c0
        acc[1] += c2 - c1
        acc[2] += c3 - c2
        acc[3] += c4 - c3
    return [a / steps * 1e6 for a in acc]


def profile_top(steps, n=5):
    """cProfile of one loop: the ``n`` entries with the largest cumulative time."""
    sim, guidance, autopilot, dt = build_loop()
    prof = cProfile.Profile()
    prof.runcall(run_loop, sim, guidance, autopilot, dt, steps)
    st = pstats.Stats(prof)
    total = st.total_tt
    entries = []
    for (file, line, func), (cc, nc, tt, ct, _callers) in st.stats.items():
        if func == 'run_loop' or file.startswith('~') and 'profiler' in func:
            continue
        short = '/'.join(file.split('/')[-2:]) if file != '~' else 'built-in'
        entries.append({'function': f'{short}:{line}({func})', 'calls': nc,
                        'tottime_s': tt, 'cumtime_s': ct,
                        'cum_pct': 100.0 * ct / total if total else math.nan})
    entries.sort(key=lambda d: -d['cumtime_s'])
    return entries[:n], total


def run(quick=False):
    dt = load_scenario(SCENARIO).dt_s
    steps = int(round(SIM_TIME_S / dt))
    repeats = QUICK_REPEATS if quick else REPEATS
    walls, cpus, final = [], [], None
    for _ in range(repeats):
        loop = build_loop()  # fresh state: every repeat runs the same 10 000 steps
        t0, c0 = time.perf_counter(), time.process_time()
        final = run_loop(*loop, steps)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    best, med = min(walls), statistics.median(walls)
    parts = split_costs(steps)
    top, prof_total = profile_top(steps)
    rows = [{'part': 'whole loop (best)', 'wall_s': best, 'us_per_step': best / steps * 1e6,
             'rtf': SIM_TIME_S / best},
            {'part': 'whole loop (median)', 'wall_s': med, 'us_per_step': med / steps * 1e6,
             'rtf': SIM_TIME_S / med},
            {'part': 'whole loop (best CPU time)', 'wall_s': min(cpus),
             'us_per_step': min(cpus) / steps * 1e6, 'rtf': SIM_TIME_S / min(cpus)}]
    for label, us in zip(('sim.nav_state', 'guidance.update', 'autopilot.update',
                          'sim.step'), parts):
        rows.append({'part': f'  {label} (timed alone)', 'us_per_step': us})
    notes = [f'{steps} steps of {dt} s, {repeats} repeats; "CPU time" = time.process_time() of '
             'the loop: what the loop costs without the waits a busy machine adds (the process '
             f'had {100 * min(cpus) / best:.0f} % of a core in the best wall run; 1-minute load '
             f'average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs)',
             f'final cross-track error '
             f'{final.cross_track:+.1f} m at s = {final.s:.0f} m (check that the loop steers)',
             f'cProfile of one more run ({prof_total:.2f} s under the profiler), top 5 by '
             'cumtime:']
    for e in top:
        notes.append(f"  {e['cumtime_s']:.3f} s cum ({e['cum_pct']:.0f} %), "
                     f"{e['tottime_s']:.3f} s own, {e['calls']} calls: {e['function']}")
    return {
        'title': f'flagship loop in one process, no ROS: mariner + ILOS + PD, '
                 f'{SIM_TIME_S:g} s sim at {1 / dt:g} Hz',
        'columns': [['part', 'part'], ['wall_s', 'wall s'], ['us_per_step', 'us/step'],
                    ['rtf', 'real-time factor']],
        'rows': rows,
        'goals': [common.goal('real-time factor (best run)', SIM_TIME_S / best, GOAL_RTF,
                              'x', below=False),
                  common.goal('real-time factor in CPU time (best run)', SIM_TIME_S / min(cpus),
                              GOAL_RTF, 'x', below=False)],
        'notes': notes, 'walls_s': walls, 'cpu_s': cpus, 'profile_top': top, 'steps': steps,
    }
