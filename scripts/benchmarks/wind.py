"""Section ``wind``: what the wind loads cost per simulator step (ship_sim.environment.wind).

For each MSS ship, ``VesselSimulator.step`` (one vessel, the float path) in calm air and in a
15 m/s wind with gusts (Blendermann; Isherwood, which runs on numpy), and ``BatchSimulator.step``
at 10,000 vessels, calm and windy. Goal (issue 14, ours): the wind at most doubles the cost
of a one-vessel step (Blendermann).
"""
import math

from ship_sim.environment.wind import WindField
from ship_sim.models import model_names
from ship_sim.simulator import BatchSimulator, VesselSimulator

from . import common

SHIPS = model_names('wind')
N_BATCH = 10_000
GOAL_RATIO = 2.0


def _wind(shape=()):
    return WindField(15.0, math.radians(300.0), gust_sd=1.5, time_constant=60.0, seed=1,
                     shape=shape)


def run(quick=False):
    rows = []
    for name in SHIPS:
        row = {'model': name}
        for key, kw in (('calm_us', {}), ('blendermann_us', {'wind': _wind()}),
                        ('isherwood_us', {'wind': _wind(), 'wind_coefficients': 'isherwood72'})):
            sim = VesselSimulator(name, **kw)
            row[key] = common.time_call(lambda: sim.step(0.01), quick)['best_us']
        row['ratio'] = row['blendermann_us'] / row['calm_us']
        n = N_BATCH // 10 if quick else N_BATCH
        for key, kw in (('batch_calm', {}), ('batch_wind', {'wind': _wind((n,))})):
            sim = BatchSimulator(name, n=n, **kw)
            t = common.time_call(lambda: sim.step(0.01), quick, repeats=3)['best_us']
            row[key] = n / t * 1e6
        rows.append(row)
    worst = max(r['ratio'] for r in rows)
    return {
        'title': 'one vessel step (us) and batched vessel-steps/s, calm vs 15 m/s wind',
        'columns': [['model', 'model'], ['calm_us', 'calm (us)'],
                    ['blendermann_us', 'Blendermann (us)'], ['isherwood_us', 'Isherwood (us)'],
                    ['ratio', 'Blendermann / calm'], ['batch_calm', 'batch calm (steps/s)'],
                    ['batch_wind', 'batch wind (steps/s)']],
        'rows': rows,
        'goals': [common.goal('one-vessel step with wind / calm step (worst ship)', worst,
                              GOAL_RATIO, 'x', below=True)],
        'notes': [f'batch of {N_BATCH // 10 if quick else N_BATCH} vessels'],
    }
