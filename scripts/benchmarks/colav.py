"""Section ``colav``: cost of one collision-avoidance decision (ship_guidance.colav), in-process.

Ten targets converge on the own ship (Mariner at 15 kn, north) from a fan of bearings, every one
a threat so that the whole scenario set is scored: spread at 3.0-6.6 km and, the harder case for
the risk terms, all within 0.6-1.5 km. Both methods with the default parameters (13 course
offsets x 3 speed factors, 600 s horizon at 5 s). The object keeps its state between calls
(latched situations, the previous decision), as in the node, so the figure is the steady cost.
Each method runs on each kernel backend (ship_sim.kernels: numpy, and numba when installed;
the decisions are the same to the last bit, tests/unit/test_colav_kernels.py), with the ratio
of the two in the same run and the load beside each row. Goals: at most 10 ms per decision
with 10 targets on any backend, so a 1 Hz decision fits beside a 10 Hz loop on this 2-core
machine (issue 13); at most 2 ms for SB-MPC on the compiled kernels (issue 28). Beside the
times, the minor page faults per decision.
"""
import math
import os

from ship_guidance.colav import ShipState, Target
from ship_guidance.colav_methods import METHODS, make_colav
from ship_guidance.colav_params import ColavParams
from ship_guidance.own_ship_prediction import OwnShipModel
from ship_sim import kernels

from . import common

U = 7.7175                   # m/s, the Mariner's 15 kn
#: The own-ship model's speed lost in a turn (s): the MSS mariner's k, 27 s identified at 12 kn
#: (scripts/imazu/runner.py turn_speed_loss), at 15 kn (k U / L is the nondimensional constant).
TURN_SPEED_LOSS_S = 27.0 * 6.1733 / U
N_TARGETS = 10
GOAL_MS = 10.0
#: SB-MPC's decision on the compiled kernels, 10 targets (issue 28 item 2).
COMPILED_GOAL_MS = 2.0
LAYOUTS = {'spread 3.0-6.6 km': (3000.0, 6600.0), 'close 0.6-1.5 km': (600.0, 1500.0)}


def converging_targets(r_min, r_max, n=N_TARGETS):
    """n targets on bearings -80..+80 deg, ranges r_min..r_max, each heading for the point the
    own ship reaches at its own arrival time (a collision course at the targets' speed U)."""
    out = []
    for i in range(n):
        bearing = math.radians(-80.0 + 160.0 * i / (n - 1))
        r = r_min + (r_max - r_min) * i / (n - 1)
        north, east = r * math.cos(bearing), r * math.sin(bearing)
        t_meet = r / U                                # both ships sail U towards one point
        meet_n = U * t_meet
        course = math.atan2(0.0 - east, meet_n - north)
        speed = math.hypot(meet_n - north, east) / t_meet
        out.append(Target(north, east, course, speed, name=f'ts{i}'))
    return out


def backends():
    return ('numpy', 'numba') if kernels.numba_available() else ('numpy',)


def run(quick=False):
    rows = []
    own = ShipState(0.0, 0.0, 0.0, U)
    for layout, (r_min, r_max) in LAYOUTS.items():
        targets = converging_targets(r_min, r_max)
        for method in METHODS:
            for backend in backends():
                load0 = os.getloadavg()[0]
                with kernels.using(backend):
                    col = make_colav(method, ColavParams(), OwnShipModel(
                        speed_at_factor_one_mps=U, turn_speed_loss_s=TURN_SPEED_LOSS_S))
                    decision = col.decide(0.0, own, targets, 0.0, 1.0)
                    t = common.time_call(lambda: col.decide(0.0, own, targets, 0.0, 1.0), quick)
                rows.append({'layout': layout, 'method': method, 'backend': backend,
                             'best_ms': t['best_us'] / 1e3, 'median_ms': t['median_us'] / 1e3,
                             'faults': t['faults'], 'mode': decision.mode,
                             'threats': sum(a.threat for a in decision.targets),
                             'load': f'{load0:.1f} / {os.getloadavg()[0]:.1f}'})
                if backend != 'numpy':   # this row's numpy twin is the one before it
                    rows[-1]['speedup'] = rows[-2]['median_ms'] / rows[-1]['median_ms']
    worst = max(r['median_ms'] for r in rows)
    goals = [common.goal('decision with 10 targets, worst median', worst, GOAL_MS, 'ms')]
    compiled = [r['median_ms'] for r in rows if r['method'] == 'sbmpc' and r['backend'] == 'numba']
    if compiled:
        goals.append(common.goal('SB-MPC decision with 10 targets on compiled kernels, worst '
                                 'median', max(compiled), COMPILED_GOAL_MS, 'ms'))
    return {
        'title': f'one decision, {N_TARGETS} targets, default scenario set and horizon, ms',
        'columns': [['layout', 'layout'], ['method', 'method'], ['backend', 'kernels'],
                    ['best_ms', 'best ms'], ['median_ms', 'median ms'],
                    ['speedup', 'numpy / this (median)'], ['faults', 'faults/decision'],
                    ['mode', 'mode'], ['threats', 'threats'], ['load', 'load before / after']],
        'rows': rows,
        'goals': goals,
        'notes': [] if kernels.numba_available() else
                 ['numba is not installed: numpy kernels only (requirements/kernels.txt)'],
    }
