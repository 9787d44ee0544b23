"""Section ``waves``: per-step cost of the wave-frequency motion and of the wave filter.

vessel_node adds the wave-frequency motion (ship_sim.environment.sea_state.ShipWaves.motion)
to every odom it publishes, and the autopilot's wave filter runs once per odom; both sit in
the 10 Hz loop. Goal: the default sea (100 components, one direction) costs less than 1 ms a
step (a tenth of the 10 Hz period, so realtime keeps its margin); the spread sea (16
directions) and the filter are reported. The batched loops (Table I, sweeps) superpose the
surge, sway and yaw only (``dofs=SURGE_SWAY_YAW``): a batch of 10, 100 and 1 000 vessels in
the wind10 sea (100 x 8 components each, a seed per vessel) with all 6 DOF and with those 3,
alternated in one process, CPU time per step and per vessel-step (the machine is shared: wall
time would measure the share) and minor page faults per step. Goal: the 3-DOF cost per
vessel-step at N = 1 000 within a quarter of that at N = 10 (flat in N: the batch runs in
cache-sized blocks of vessels, ship_sim.environment.wave_rao.BLOCK_ELEMENTS).
"""
import math
import time

from . import common


def run(quick=False):
    from ship_autopilot.wave_filter import WaveFilter
    from ship_sim.environment.sea_state import SeaState, ShipWaves, rao_table_for

    table = rao_table_for('container', 175.0)
    rows = []
    cases = (('100 components, 1 direction', SeaState(hs=3.0)),
             ('100 components x 16 directions', SeaState(hs=3.0, spreading=True)))
    for label, sea in cases:
        waves = ShipWaves(sea, table)
        t = common.time_call(lambda: waves.motion(123.4, 7.0, 0.3), quick)
        rows.append({'what': f'wave motion, {label}', 'best_us': t['best_us'],
                     'median_us': t['median_us']})
    rows += batch_rows(quick)
    filt = WaveFilter(peak_frequency=0.6, direction=math.pi)
    state = {'k': 0}

    def step():
        state['k'] += 1
        filt.update(0.1 * state['k'], 0.3, 0.001, 7.0)
    t = common.time_call(step, quick)
    rows.append({'what': 'wave filter update', 'best_us': t['best_us'],
                 'median_us': t['median_us']})
    per_vessel = {r['n']: r['us_per_vessel'] for r in rows if r.get('dofs') == 3}
    return {'title': 'wave-frequency motion and wave filter, per 10 Hz step (us)',
            'columns': [['what', 'what'], ['best_us', 'best us'], ['median_us', 'median us'],
                        ['us_per_vessel', 'us/vessel-step'], ['faults', 'faults/step']],
            'rows': rows,
            'goals': [common.goal('default sea: wave motion per step', rows[0]['median_us'],
                                  1000.0, 'us'),
                      common.goal('batch, 3 DOF: CPU per vessel-step at N = 1 000 / N = 10',
                                  per_vessel[1000] / per_vessel[10], 1.25, '')],
            'notes': [f'{r["what"]}: 3 DOF / 6 DOF CPU = {r["ratio"]:.3f}' for r in rows
                      if 'ratio' in r]}


def batch_rows(quick=False):
    """CPU us per step of a batch's wave motion, all 6 DOF against surge, sway and yaw (the
    same numbers: tests/unit/test_sea_state.py), blocks alternated so both see the same load."""
    import numpy as np
    from ship_mission.conditions import CONDITIONS, sea_state
    from ship_sim.environment.sea_state import ShipWaves, rao_table_for
    from ship_sim.environment.wave_rao import SURGE_SWAY_YAW
    rows = []
    for n in (10, 100, 1000):
        waves = ShipWaves([sea_state(CONDITIONS['wind10'], 0.0, 1 + i) for i in range(n)],
                          rao_table_for('container', 175.0))
        U, psi = np.full(n, 7.0), np.linspace(0.0, 6.0, n)
        calls = max(2, (20 if quick else 100) // (n // 10))
        best = {None: math.inf, SURGE_SWAY_YAW: math.inf}
        faults = {None: math.inf, SURGE_SWAY_YAW: math.inf}
        for dofs in best:   # the stored RAOs of each DOF set are made on the first call
            waves.motion(0.0, U, psi, dofs=dofs)
        for _ in range(3 if quick else 7):
            for dofs in best:
                c0, f0 = time.process_time(), common.minor_faults()
                for k in range(calls):
                    waves.motion(0.1 * k, U, psi, dofs=dofs)
                best[dofs] = min(best[dofs], (time.process_time() - c0) / calls * 1e6)
                faults[dofs] = min(faults[dofs], (common.minor_faults() - f0) / calls)
        full, part = best[None], best[SURGE_SWAY_YAW]
        rows.append({'what': f'wave motion, batch of {n} (100 x 8 components), 6 DOF, CPU',
                     'best_us': full, 'median_us': math.nan, 'us_per_vessel': full / n,
                     'faults': faults[None], 'n': n, 'dofs': 6})
        rows.append({'what': f'wave motion, batch of {n}, surge/sway/yaw only, CPU',
                     'best_us': part, 'median_us': math.nan, 'us_per_vessel': part / n,
                     'faults': faults[SURGE_SWAY_YAW], 'n': n, 'dofs': 3,
                     'ratio': part / full})
    return rows
