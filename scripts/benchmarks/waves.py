"""Section ``waves``: per-step cost of the wave-frequency motion and of the wave filter.

vessel_node adds the wave-frequency motion (ship_sim.environment.sea_state.ShipWaves.motion)
to every odom it publishes, and the autopilot's wave filter runs once per odom; both sit in
the 10 Hz loop. Goal: the default sea (100 components, one direction) costs less than 1 ms a
step (a tenth of the 10 Hz period, so realtime keeps its margin); the spread sea (16
directions) and the filter are reported.
"""
import math

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
    filt = WaveFilter(peak_frequency=0.6, direction=math.pi)
    state = {'k': 0}

    def step():
        state['k'] += 1
        filt.update(0.1 * state['k'], 0.3, 0.001, 7.0)
    t = common.time_call(step, quick)
    rows.append({'what': 'wave filter update', 'best_us': t['best_us'],
                 'median_us': t['median_us']})
    return {'title': 'wave-frequency motion and wave filter, per 10 Hz step (us)',
            'columns': [['what', 'what'], ['best_us', 'best us'], ['median_us', 'median us']],
            'rows': rows,
            'goals': [common.goal('default sea: wave motion per step', rows[0]['median_us'],
                                  1000.0, 'us')],
            'notes': []}
