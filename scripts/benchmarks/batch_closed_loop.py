"""Section ``batch_closed_loop``: closed-loop vessel-steps per second of the batched loop.

Three figures side by side, all Mariner, h = 0.1 s:

- the single-vessel in-process loop (section closed_loop_inprocess's flagship loop: float
  paths, one vessel): vessel-steps/s = steps / time;
- ship_autopilot.batch_closed_loop.BatchClosedLoop with ILOS + PD on the flagship route
  (7 legs, lines and arcs) for N = 100, 1 000, 10 000 episodes (starts spread over +-100 m,
  +-0.3 rad, currents 0-0.9 m/s in every direction), and at N = 10 000 on Table I's curved
  path (912 arcs: the dense-curve search);
- the plant alone at N = 10 000 (section batched's rk4_step on the same model): the limit a
  loop that also runs guidance, autopilot and metrics on arrays can approach; the ratio
  closed loop / plant-only says how close it gets;
- the batched loop with a Gauss-Markov current per episode (CURRENT_SD, a seed each) at
  N = 10 000, a fifth of the simulated time, and its ratio to the constant current's CPU rate;
- the batched loop in wind and waves (ship_mission.conditions wind20, a seed per episode) at
  N = 100 and 1 000, one run of a fifth of the simulated time, and its ratio to the calm
  loop's CPU rate at the same N.

Each figure is the best of ``repeats`` runs of the stepping alone (set-up reported apart), in
wall time and in CPU time (time.process_time, which a loaded machine disturbs much less),
with the minor page faults per step of the whole batch (getrusage) beside it. bench.py tunes
the allocator before any section (ship_sim.allocator), so the plant row, run after the loops,
sees the allocator they saw; one more plant row runs in a fresh process with the C library's
default settings, the cost the tuning takes away.
Every figure here is the numpy reference (ship_sim.kernels pinned to numpy for the section, so
the loop and its plant row compare like with like); section ``kernels`` sets the compiled
kernels beside it.
Goal (issue 16): >= 1 000 000 closed-loop vessel-steps/s at N = 10 000 (Mariner, ILOS + PD).
"""
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

from . import batched, closed_loop_inprocess, common

GOAL_N = 10_000
GOAL_RATE = 1_000_000.0
SIZES = (100, 1_000, 10_000)
#: Wind and waves (ship_mission.conditions wind20: gusts, loads, 100 x 8 wave components per
#: episode): N and a fifth of the simulated time (its cost per step is the wave motion's).
WAVES_SIZES = (100, 1_000)
SIM_S, QUICK_SIM_S = 100.0, 20.0
#: Gauss-Markov current (row at GOAL_N): stationary sd of speed (m/s) and direction (rad), T (s).
CURRENT_SD = (0.2, math.radians(20.0))
CURRENT_TIME_CONSTANT_S = 300.0
ROUTES = {'flagship': 'flagship_mariner.yaml', 'curved': 'curved_path_mariner_000.yaml'}


def episodes(n, seed=1):
    rng = np.random.default_rng(seed)
    return {'route': 0, 'along': rng.uniform(0, 500, n), 'cross': rng.uniform(-100, 100, n),
            'heading': rng.uniform(-0.3, 0.3, n), 'current_speed': rng.uniform(0, 0.9, n),
            'current_direction': rng.uniform(-np.pi, np.pi, n)}


def batch_rate(route_name, n, sim_s, repeats, condition='calm', current_sd=None):
    """(best wall rate, best CPU rate, set-up s, fewest minor faults per step) of
    BatchClosedLoop, ILOS + PD, in a
    ship_mission.conditions ``condition`` (a seed per episode, as a sweep's; the sea states' set-up
    is in the set-up time). ``current_sd``: (speed sd m/s, direction sd rad) of a Gauss-Markov
    current about each episode's (CURRENT_TIME_CONSTANT_S, a seed per episode)."""
    from ship_sim.current import OceanCurrent
    import evaluate_controllers as ec
    from ship_autopilot.batch_closed_loop import BatchClosedLoop
    from ship_planner.route_loader import load_route
    route = load_route(common.REPO / 'scenarios' / 'routes' / ROUTES[route_name]).route
    loop = BatchClosedLoop('mariner', [route], 'pd', 'ilos')
    walls, cpus, setup, faults = [], [], [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        wind, waves, _ = ec.disturbances(condition, [route], loop.model, [0] * n, range(n))
        t_dist = time.perf_counter() - t0
        eps = episodes(n)
        current = None if current_sd is None else OceanCurrent.from_std(
            eps['current_speed'], eps['current_direction'], *current_sd,
            CURRENT_TIME_CONSTANT_S, seed=np.arange(n), shape=(n,))
        res = loop.run(eps, sim_s, wind=wind, waves=waves, current=current)
        res.setup_s += t_dist
        walls.append(res.loop_s)
        cpus.append(res.loop_cpu_s)
        setup.append(res.setup_s)
        faults.append(res.loop_minor_faults / res.steps)
        assert not res.metrics['failed'].any()
    steps = n * res.steps
    return steps / min(walls), steps / max(min(cpus), 1e-9), min(setup), min(faults)


def single_rate(steps, repeats):
    """(wall, CPU, minor faults per step) vessel-steps/s of the flagship loop with one vessel
    (float paths)."""
    walls, cpus, faults = [], [], []
    for _ in range(repeats):
        loop = closed_loop_inprocess.build_loop()
        t0, c0, f0 = time.perf_counter(), time.process_time(), common.minor_faults()
        closed_loop_inprocess.run_loop(*loop, steps)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
        faults.append((common.minor_faults() - f0) / steps)
    return steps / min(walls), steps / max(min(cpus), 1e-9), min(faults)


def plant_rate(n, quick):
    """(wall, CPU, minor faults per step) vessel-steps/s of the plant alone: best of 3 blocks
    of RK4 steps after one step."""
    from ship_sim.integrators import rk4_step
    from ship_sim.models import make_model
    model = make_model('mariner')
    X, U = batched.batch(model, n)
    steps = 10 if quick else 50
    rk4_step(model.rhs, X, U, batched.H)
    walls, cpus, faults = [], [], []
    for _ in range(3):
        t0, c0, f0 = time.perf_counter(), time.process_time(), common.minor_faults()
        for _ in range(steps):
            rk4_step(model.rhs, X, U, batched.H)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
        faults.append((common.minor_faults() - f0) / steps)
    return n * steps / min(walls), n * steps / max(min(cpus), 1e-9), min(faults)


def plant_rate_default_allocator(n, quick):
    """plant_rate in a fresh interpreter that leaves the C library's allocator as it starts
    (no ship_sim.allocator): what the tuning saves, measured in the same bench run."""
    code = ('import json, sys; from benchmarks import batch_closed_loop as b; '
            f'print(json.dumps(b.plant_rate({int(n)}, {bool(quick)})))')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         timeout=600, cwd=common.REPO / 'scripts', check=True)
    return tuple(json.loads(out.stdout.splitlines()[-1]))


def run(quick=False):
    from ship_sim import kernels
    with kernels.using('numpy'):
        return _run(quick)


def _run(quick):
    sim_s = QUICK_SIM_S if quick else SIM_S
    repeats = 1 if quick else 3
    load = os.getloadavg()[0]
    rows = []
    w, c, f = single_rate(int(sim_s / 0.1), repeats)
    rows.append({'loop': 'single vessel, float paths (flagship, ILOS + PD)', 'n': 1,
                 'rate_wall': w, 'rate_cpu': c, 'faults_per_step': f})
    for n in SIZES:
        w, c, s, f = batch_rate('flagship', n, sim_s, repeats)
        rows.append({'loop': 'BatchClosedLoop flagship ILOS + PD', 'n': n, 'rate_wall': w,
                     'rate_cpu': c, 'setup_s': s, 'faults_per_step': f})
    goal_row = rows[-1]
    calm = {r['n']: r for r in rows[1:]}
    for n in WAVES_SIZES:   # wind + waves, against the calm row of the same N
        w, c, s, f = batch_rate('flagship', n, sim_s / 5, 1, 'wind20')
        rows.append({'loop': 'BatchClosedLoop flagship ILOS + PD, wind20 (wind + waves)',
                     'n': n, 'rate_wall': w, 'rate_cpu': c, 'setup_s': s,
                     'faults_per_step': f, 'ratio_to_calm': c / calm[n]['rate_cpu']})
    w, c, s, f = batch_rate('flagship', GOAL_N, sim_s / 5, 1, current_sd=CURRENT_SD)
    rows.append({'loop': 'BatchClosedLoop flagship ILOS + PD, Gauss-Markov current',
                 'n': GOAL_N, 'rate_wall': w, 'rate_cpu': c, 'setup_s': s,
                 'faults_per_step': f, 'ratio_to_calm': c / calm[GOAL_N]['rate_cpu']})
    w, c, s, f = batch_rate('curved', GOAL_N, sim_s, 1)
    rows.append({'loop': 'BatchClosedLoop curved path (912 arcs) ILOS + PD', 'n': GOAL_N,
                 'rate_wall': w, 'rate_cpu': c, 'setup_s': s, 'faults_per_step': f})
    pw, pc, f = plant_rate(GOAL_N, quick)
    rows.append({'loop': 'plant only: rk4_step(mariner.rhs) (section batched)', 'n': GOAL_N,
                 'rate_wall': pw, 'rate_cpu': pc, 'faults_per_step': f})
    dw, dc, f = plant_rate_default_allocator(GOAL_N, quick)
    rows.append({'loop': "plant only, fresh process, the C library's default allocator",
                 'n': GOAL_N, 'rate_wall': dw, 'rate_cpu': dc, 'faults_per_step': f})
    for r in rows:
        r['ratio_to_plant'] = r['rate_cpu'] / pc
        r['ratio_to_plant_wall'] = r['rate_wall'] / pw
    return {
        'title': f'batched closed loop (Mariner, h = 0.1 s, {sim_s:g} s sim): vessel-steps/s',
        'columns': [['loop', 'loop'], ['n', 'N'], ['rate_wall', 'steps/s wall (best)'],
                    ['rate_cpu', 'steps/s CPU (best)'], ['ratio_to_plant', 'CPU / plant only'],
                    ['ratio_to_plant_wall', 'wall / plant only'],
                    ['ratio_to_calm', 'CPU / calm, same N'],
                    ['faults_per_step', 'faults/step'], ['setup_s', 'set-up s']],
        'rows': rows,
        'goals': [common.goal(f'closed-loop vessel-steps/s at N = {GOAL_N:,}, ILOS + PD (wall)',
                              goal_row['rate_wall'], GOAL_RATE, 'steps/s', below=False),
                  common.goal(f'closed-loop vessel-steps/s at N = {GOAL_N:,}, ILOS + PD (CPU)',
                              goal_row['rate_cpu'], GOAL_RATE, 'steps/s', below=False)],
        'notes': [f'1-minute load average {load:.1f} on {os.cpu_count()} CPUs at the start; '
                  'wall rates under load are the machine share, CPU rates the cost',
                  'set-up (starts placed, first closest point on the whole route) is not in '
                  'the rates'],
    }
