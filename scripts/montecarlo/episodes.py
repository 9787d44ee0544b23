"""Run a chunk of episodes in this process and return one row of metrics per episode.

The closed loop is ship_autopilot.batch_closed_loop.BatchClosedLoop: the chunk's episodes (one
model and controller) stepped together as arrays, each equal to the single-vessel in-process
loop of scripts/evaluate_controllers.py (``run``: MSS plant with RK4 at 0.1 s, guidance and
autopilot every 0.1 s, the policy at its own step, the Table I reward) to rounding. A
Gauss-Markov current runs in the batch too, each episode's from its own seed (a batch holds
one pattern of variability: speed, direction, both or neither). Wind and waves (``weather``)
run in the batch: a batch holds one wind and sea (random wind or wave parameters make
batches of one episode: correct, but slow), each episode's gusts and waves from its own
seed. A chunk of one episode is run with a copy of itself, so that every episode takes the batch's
array path (one vessel alone would take the plant's float path, equal only to rounding) and a
row never depends on the chunking. Metrics per episode (METRICS): the Table I reward (cumulative Gaussian, eq. 8 of
Martinsen and Lekkas 2018, at every 0.1 s sample), cross-track RMS / mean / max and mean over
the second half, rudder use (mean |rudder rate|, mean |rudder|) and completion (the state stayed
in the model's domain and within ``EnvConfig.terminate_cross_track`` of the path all episode).
An episode whose state leaves the domain is a row with completed = 0 and no other metrics.

Test-only hook: with SHIPNAV_SWEEP_FAIL_ONCE=<file>, the first chunk to start in any process
creates <file> (the process id, then the chunk's episode indices) and kills its own process
(``os._exit``), as a lost worker would; later chunks run normally. The backends' retry tests
use it; never set it otherwise.
"""
import math
import os
from pathlib import Path

import numpy as np
from ship_sim.allocator import tune_allocator

from .spec import REPO, resolve_route

FAIL_ONCE_ENV = 'SHIPNAV_SWEEP_FAIL_ONCE'
#: Metric columns of a row, in table order.
METRICS = ('completed', 'reward', 'rms_e_m', 'mean_abs_e_m', 'max_abs_e_m',
           'mean_abs_e_settled_m', 'rudder_rate_deg_s', 'mean_abs_rudder_deg')
_FROM_LOOP = {'reward': 'gaussian', 'rms_e_m': 'rms_e', 'mean_abs_e_m': 'mean_abs_e',
              'max_abs_e_m': 'max_abs_e', 'mean_abs_e_settled_m': 'mean_abs_e_settled',
              'rudder_rate_deg_s': 'rudder_rate_deg_s',
              'mean_abs_rudder_deg': 'mean_abs_rudder_deg'}
_ROUTES = {}


def route_key(episode, sweep_file=None):
    """The episode's route file relative to the repository (absolute if outside it)."""
    path = resolve_route(episode['route'], episode['model'], sweep_file).resolve()
    try:
        return str(path.relative_to(REPO))
    except ValueError:
        return str(path)


def _route(key):
    if key not in _ROUTES:
        from ship_planner.route_loader import load_route
        _ROUTES[key] = load_route(REPO / key).route
    return _ROUTES[key]


def _maybe_fail_once(chunk):
    marker = os.environ.get(FAIL_ONCE_ENV)
    if not marker:
        return
    try:
        fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return
    episodes = ' '.join(str(e['episode']) for e in chunk)
    os.write(fd, f'{os.getpid()}\n{episodes}\n'.encode())
    os.close(fd)
    os._exit(17)


def _current_field(chunk):
    """An OceanCurrent of shape (len(chunk),), each episode's Gauss-Markov speed and direction
    from its own seed (the current of its single-vessel run, ship_sim.current), or None when
    no episode's current varies."""
    if not any(_varying(e) for e in chunk):
        return None
    from ship_sim.current import OceanCurrent

    def col(key):
        return np.array([e[key] for e in chunk], dtype=float)
    return OceanCurrent.from_std(
        col('current_speed_mps'), np.radians(col('current_direction_deg')),
        col('current_speed_std_mps'), np.radians(col('current_direction_std_deg')),
        col('current_time_constant_s'), seed=[e['seed'] for e in chunk], shape=(len(chunk),))


def weather(ep):
    """The episode's wind and sea: a ship_mission.conditions name, or a Condition of the explicit
    keys (spec.WEATHER; 'calm' when they are all zero)."""
    if ep['condition'] != 'calm' or (ep['wind_speed_mps'] == 0.0 and ep['wave_height_m'] == 0.0):
        return ep['condition']
    from ship_mission.conditions import Condition
    return Condition.custom(ep['wind_speed_mps'], ep['wind_direction_deg'], ep['wave_height_m'],
                            ep['wave_period_s'], ep['wave_direction_deg'])


def _batch_key(ep):
    """Episodes of one key run in one batch: one model, controller, length, wind and sea, and
    one pattern of current variability (an episode's current stream is its single run's only
    if it draws for the speed and the direction as every episode of its batch does)."""
    return (ep['model'], ep['controller'], ep['duration_s'], weather(ep),
            ep['current_speed_std_mps'] > 0.0, ep['current_direction_std_deg'] > 0.0)


def _varying(ep):
    return ep['current_speed_std_mps'] > 0.0 or ep['current_direction_std_deg'] > 0.0


def _start(ep, route_index):
    """The start dict of evaluate_controllers.run / run_batched for an episode."""
    return {'route': route_index, 'along': ep['start_along_m'], 'cross': ep['start_cross_m'],
            'heading': math.radians(ep['start_heading_deg']),
            'current_speed': ep['current_speed_mps'],
            'current_direction': math.radians(ep['current_direction_deg'])}


def run_batch(chunk):
    """Metrics (dicts) of episodes of one ``_batch_key`` (each episode's gusts, waves and
    Gauss-Markov current from its own seed), stepped together."""
    import evaluate_controllers as ec
    from ship_autopilot.learning.env import EnvConfig
    first = chunk[0]
    if any(_batch_key(e) != _batch_key(first) for e in chunk):
        raise ValueError('a batch runs one model, one controller, one episode length, one '
                         'wind and sea and one pattern of current variability')
    padded = chunk * 2 if len(chunk) == 1 else chunk
    keys = list(dict.fromkeys(e['route_key'] for e in padded))
    res = ec.run_batched(first['model'], [_route(k) for k in keys], first['controller'],
                         [_start(e, keys.index(e['route_key'])) for e in padded],
                         first['duration_s'], condition=weather(first),
                         seeds=[e['seed'] for e in padded],
                         current_field=_current_field(padded))
    limit = EnvConfig().terminate_cross_track
    out = []
    for i in range(len(chunk)):
        if res['failed'][i]:
            out.append(dict({k: math.nan for k in METRICS}, completed=0))
            continue
        row = {k: float(res[v][i]) for k, v in _FROM_LOOP.items()}
        row['completed'] = int(row['max_abs_e_m'] < limit)
        out.append(row)
    return out


def run_chunk(chunk):
    """Rows (dicts: the episode's parameters and METRICS) for a list of episodes; encounter
    episodes (one sweep kind per chunk) by montecarlo.encounters."""
    tune_allocator()   # a Ray worker starts here, not in sweep.py's main (once per process)
    _maybe_fail_once(chunk)
    if 'encounter' in chunk[0]:
        from .encounters import run_encounter_chunk
        return run_encounter_chunk(chunk)
    metrics = {}
    groups = {}
    for ep in chunk:
        groups.setdefault(_batch_key(ep), []).append(ep)
    for group in groups.values():
        metrics.update(zip((e['episode'] for e in group), run_batch(group)))
    rows = []
    for ep in chunk:
        row = {k: v for k, v in ep.items() if k != 'route_key'}
        row.update(metrics[ep['episode']])
        rows.append(row)
    return rows


def vessel_steps(rows):
    """Plant steps the rows stand for (the throughput's unit), 0.1 s each."""
    return int(sum(round(r['duration_s'] / 0.1) for r in rows))


def episode_chunks(episodes, chunk_size):
    """Consecutive episodes of one (model, controller), at most ``chunk_size`` each: what one
    task runs (the batched loop steps one model and controller at a time)."""
    chunks, cur = [], []
    for ep in episodes:
        if cur and (len(cur) >= chunk_size or (ep['model'], ep.get('controller'))
                    != (cur[0]['model'], cur[0].get('controller'))):
            chunks.append(cur)
            cur = []
        cur.append(ep)
    if cur:
        chunks.append(cur)
    return chunks


#: Largest automatic chunk, in episode-seconds (2000 episodes of 1000 s, 20 M vessel-steps):
#: the batched loop pays numpy's per-call cost once per step for the whole batch, so a step
#: costs about the same wall time from 1 to a few hundred vessels and the cost per vessel-step
#: falls until N ~ 2000 (doc/results/performance.md). Memory stays O(N): a few MB.
CHUNK_EPISODE_SECONDS = 2_000_000


def auto_chunk_size(n_episodes, workers, duration_s):
    """Chunks small enough for >= 4 per worker (balance, a lost worker costs little), as large
    as that allows up to CHUNK_EPISODE_SECONDS, so the batch is large."""
    per_worker = max(1, n_episodes // (4 * max(1, workers)))
    cap = max(1, int(CHUNK_EPISODE_SECONDS / max(1.0, duration_s)))
    return int(np.clip(per_worker, 1, cap))


def with_route_keys(episodes, sweep_file=None):
    """Episodes with 'route_key' (resolved once here, read by the workers)."""
    keys = {}
    out = []
    for ep in episodes:
        k = (ep['route'], ep['model'])
        if k not in keys:
            keys[k] = route_key(ep, sweep_file)
            if not Path(REPO / keys[k]).exists():
                from .spec import SweepError
                raise SweepError(f'route file {keys[k]} (from {ep["route"]!r}) not found')
        out.append(dict(ep, route_key=keys[k]))
    return out
