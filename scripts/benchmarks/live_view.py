"""Section ``live_view``: what ``run_mission.py --live`` costs a lockstep run (goal: <= 10 %).

Rows (lockstep.graph_run: the flagship graph in lockstep, its nodes started with the
launcher's parameters, the recorder with its handshake and the vessel's nav_display_node, as
``make demo`` runs it):
- ``demo graph``: without the live view;
- ``demo graph + live, no client``: with scripts/live_view.py serving the graph (it subscribes
  nothing while no client listens);
- ``demo graph + live + client``: with a Foxglove protocol client (mission.foxglove_client, in
  the bench process) subscribed to every advertised topic from the start, every message of
  every topic forwarded to it.
Each runs REPEATS times, interleaved, so slow phases of a shared machine hit them alike; the
best repeat of each is compared (real-time factor ratio) and the CPU per step of all processes
(less disturbed by other load). Goal: the real-time factor with the live view is at least
GOAL_RATIO of the one without.
"""
import time

from . import common
from .lockstep import RUN_DIR, _row, graph_run

SIM_TIME_S = 300.0
QUICK_SIM_TIME_S = 60.0
REPEATS = 3
GOAL_RATIO = 0.9
BASE, IDLE, CLIENT = 'demo graph', 'demo graph + live, no client', 'demo graph + live + client'


def run(quick=False):
    sim_time = QUICK_SIM_TIME_S if quick else SIM_TIME_S
    steps = int(round(sim_time / 0.1))
    repeats = 1 if quick else REPEATS
    log_root = RUN_DIR / ('live-' + time.strftime('%Y%m%d-%H%M%S'))
    configs = {BASE: None, IDLE: 'idle', CLIENT: 'client'}
    results = {k: [] for k in configs}
    for i in range(repeats):
        for key, live in configs.items():
            results[key].append(graph_run(steps, True, key, log_root / f'r{i}', display=True,
                                          live=live))
    best = {k: min(v, key=lambda r: r['stepping_s']) for k, v in results.items()}
    rows = []
    for key in configs:
        row = _row(best[key])
        row['cpu_best'] = min(_row(r)['cpu_total'] for r in results[key])
        row['rtf_ratio'] = best[BASE]['stepping_s'] / best[key]['stepping_s']
        row['client_messages'] = best[key].get('client_messages')
        walls = [r['stepping_s'] for r in results[key]]
        row['spread'] = max(walls) / min(walls)
        rows.append(row)
    walls = '; '.join(k + ' ' + ', '.join(f"{r['stepping_s']:.2f}" for r in v)
                      for k, v in results.items())
    errors = [r['client_error'] for r in results[CLIENT] if r.get('client_error')]
    notes = [f'{steps} steps ({sim_time:g} s sim), best of {repeats} repeat(s) per row; all '
             f'stepping times (s): {walls}',
             'RT ratio = best stepping time without the live view / with it (1 = no cost); '
             'CPU = best CPU microseconds per step, all processes of the graph (the client '
             'runs in the bench process and is not counted); load = 1-minute load average '
             'when the best run ended',
             f'logs under {log_root}'] + [f'client: {e}' for e in errors]
    bad = [r['config'] for r in rows if r['lockstep_timeouts']]
    if bad:
        notes.insert(0, f'lockstep timeouts in {bad}: those numbers include held steps')
    by = {r['config']: r for r in rows}
    return {
        'title': f'flagship lockstep run (recorder, nav_display) with and without --live, '
                 f'{sim_time:g} s sim',
        'columns': [['config', 'config'], ['steps', 'steps'], ['stepping_s', 'stepping s'],
                    ['rtf', 'RT factor'], ['rtf_ratio', 'RT ratio'], ['cpu_best', 'CPU/step'],
                    ['spread', 'spread'], ['load_1min', 'load'],
                    ['client_messages', 'client msgs'], ['lockstep_timeouts', 'timeouts']],
        'rows': rows,
        'goals': [common.goal('RT factor with --live (no client) / without',
                              by[IDLE]['rtf_ratio'], GOAL_RATIO, '', below=False),
                  common.goal('RT factor with --live and a client on every topic / without',
                              by[CLIENT]['rtf_ratio'], GOAL_RATIO, '', below=False)],
        'notes': notes, 'runs': results, 'failed': bool(bad),
    }
