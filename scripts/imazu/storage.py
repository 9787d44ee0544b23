"""A finished benchmark's runs on disk, for ``imazu_benchmark.py --rescore``: arrays in
runs.npz (read with allow_pickle=False), everything else in runs.json. No pickle: a results
folder is something people pass around, and loading one must not run code from it.

A run's key is (ship, method, case), with method and case None for the ship's reference run
without traffic; in the files it is the text ``ship|method|case`` ('-' for None).
"""
import json

import numpy as np

from imazu.runner import RunResult
from ship_sim.safe_load import load_json_file

ARRAYS = ('t', 'own', 'heading')


def _key_text(key):
    return '|'.join('-' if k is None else str(k) for k in key)


def _key(text):
    ship, method, case = ('' if k == '-' else k for k in text.split('|'))
    return ship, method or None, int(case) if case else None


def save_runs(folder, results, meta):
    """Write ``results`` ({key: RunResult}) and ``meta`` (JSON-able) into ``folder``."""
    arrays, runs = {}, {}
    for key, r in results.items():
        k = _key_text(key)
        for name in ARRAYS:
            value = getattr(r, name)
            if value is not None:
                arrays[f'{k}/{name}'] = np.asarray(value)
        for name, track in r.targets.items():
            arrays[f'{k}/target/{name}'] = np.asarray(track)
        # a decision is (t, mode, course_offset, speed_multiplier): JSON keeps its values
        runs[k] = {'targets': list(r.targets), 'decisions': [list(d) for d in r.decisions],
                   'decision_wall_s': r.decision_wall_s, 'end': r.end}
    np.savez_compressed(folder / 'runs.npz', **arrays)
    (folder / 'runs.json').write_text(json.dumps({'meta': meta, 'runs': runs}))


def load_runs(folder):
    """{'results': {key: RunResult}, **meta} as save_runs wrote them."""
    saved = load_json_file(folder / 'runs.json')
    with np.load(folder / 'runs.npz', allow_pickle=False) as z:
        results = {}
        for k, run in saved['runs'].items():
            targets = {name: z[f'{k}/target/{name}'] for name in run['targets']}
            heading = z[f'{k}/heading'] if f'{k}/heading' in z.files else None
            results[_key(k)] = RunResult(z[f'{k}/t'], z[f'{k}/own'], targets, [tuple(d) for d in run['decisions']],
                                         heading, run['decision_wall_s'], run['end'])
    return {'results': results, **saved['meta']}
