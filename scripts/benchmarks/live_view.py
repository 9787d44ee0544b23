"""Section ``live_view``: what ``run_mission.py --live`` costs a lockstep run (goal: <= 10 %).

Rows (lockstep.graph_run: the flagship graph in lockstep, its nodes started with the
launcher's parameters, the recorder with its handshake and the vessel's nav_display_node, as
``make demo`` runs it):
- ``demo graph``: without the live view;
- ``demo graph + live, no client``: with scripts/live_view.py serving the graph (it subscribes
  nothing while no client listens);
- ``demo graph + live + client``: with a Foxglove protocol client (ship_mission.foxglove_client, in
  the bench process) subscribed to every advertised topic from the start, every message of
  every topic forwarded to it.
Each runs REPEATS times, interleaved with the order rotated every repeat (ABC, BCA, CAB, ...),
so slow phases of a shared machine hit every configuration alike. A repeat's ratio compares
its runs with each other (stepping time without the live view / with it: 1 = no cost); the
goal is judged on the median of those ratios, and their spread (min-max) is reported beside it,
with the CPU per step of each process (medians over the repeats: the simulator, guidance,
autopilot, recorder, nav_display and the live view itself; the CPU is less disturbed by other
load than the wall time). Goal: the median ratio is at least GOAL_RATIO.
"""
import statistics
import time

from . import common
from .lockstep import RUN_DIR, _row, graph_run

SIM_TIME_S = 300.0
QUICK_SIM_TIME_S = 60.0
REPEATS = 6
GOAL_RATIO = 0.9
BASE, IDLE, CLIENT = 'demo graph', 'demo graph + live, no client', 'demo graph + live + client'


def run(quick=False):
    sim_time = QUICK_SIM_TIME_S if quick else SIM_TIME_S
    steps = int(round(sim_time / 0.1))
    repeats = 2 if quick else REPEATS
    log_root = RUN_DIR / ('live-' + time.strftime('%Y%m%d-%H%M%S'))
    configs = {BASE: None, IDLE: 'idle', CLIENT: 'client'}
    keys = list(configs)
    results = {k: [] for k in configs}
    for i in range(repeats):
        for key in keys[i % len(keys):] + keys[:i % len(keys)]:
            results[key].append(graph_run(steps, True, key, log_root / f'r{i}', display=True,
                                          live=configs[key]))
    rows = []
    for key in configs:
        per = [_row(r) for r in results[key]]
        ratios = [b['stepping_s'] / r['stepping_s'] for b, r in zip(results[BASE], results[key])]
        row = {'config': key, 'steps': steps,
               'rtf': statistics.median(p['rtf'] for p in per),
               'rtf_ratio': statistics.median(ratios),
               'ratio_range': f'{min(ratios):.2f}-{max(ratios):.2f}',
               'load_1min': f"{min(r['load_1min'] for r in results[key]):.0f}-"
                            f"{max(r['load_1min'] for r in results[key]):.0f}",
               'lockstep_timeouts': sum(r['lockstep_timeouts'] or 0 for r in results[key]),
               'client_messages': _median_or_none(r.get('client_messages')
                                                  for r in results[key])}
        for role in ('sim', 'guidance', 'autopilot', 'total'):
            row[f'cpu_{role}'] = _median_or_none(p[f'cpu_{role}'] for p in per)
        for role, label in (('recorder', 'recorder'), ('display', 'nav_display_node'),
                            ('live', 'live_view')):
            row[f'cpu_{role}'] = _median_or_none(_cpu_us(r, label) for r in results[key])
        rows.append(row)
    walls = '; '.join(k + ' ' + ', '.join(f"{r['stepping_s']:.2f}" for r in v)
                      for k, v in results.items())
    errors = [r['client_error'] for r in results[CLIENT] if r.get('client_error')]
    notes = [f'{steps} steps ({sim_time:g} s sim), {repeats} repeat(s) per row, order rotated '
             f'each repeat; all stepping times (s), in repeat order: {walls}',
             'RT ratio = median over the repeats of (stepping time without the live view / '
             'with it) within the same repeat (1 = no cost), range = min-max of those ratios; '
             'CPU = median CPU microseconds per step of each process (total: all processes of '
             'the graph; the client runs in the bench process and is not counted); load = '
             '1-minute load average at the end of each run, min-max',
             f'logs under {log_root}'] + [f'client: {e}' for e in errors]
    bad = [r['config'] for r in rows if r['lockstep_timeouts']]
    if bad:
        notes.insert(0, f'lockstep timeouts in {bad}: those numbers include held steps')
    by = {r['config']: r for r in rows}
    return {
        'title': f'flagship lockstep run (recorder, nav_display) with and without --live, '
                 f'{sim_time:g} s sim',
        'columns': [['config', 'config'], ['rtf', 'RT factor'], ['rtf_ratio', 'RT ratio'],
                    ['ratio_range', 'range'], ['cpu_total', 'CPU/step'],
                    ['cpu_sim', 'sim'], ['cpu_guidance', 'guidance'],
                    ['cpu_autopilot', 'autopilot'], ['cpu_recorder', 'recorder'],
                    ['cpu_display', 'display'], ['cpu_live', 'live view'],
                    ['load_1min', 'load'], ['client_messages', 'client msgs'],
                    ['lockstep_timeouts', 'timeouts']],
        'rows': rows,
        'goals': [common.goal('RT factor with --live (no client) / without, median',
                              by[IDLE]['rtf_ratio'], GOAL_RATIO, '', below=False),
                  common.goal('RT factor with --live and a client on every topic / without, '
                              'median', by[CLIENT]['rtf_ratio'], GOAL_RATIO, '', below=False)],
        'notes': notes, 'runs': results, 'failed': bool(bad),
    }


def _cpu_us(result, label):
    """CPU microseconds per step of the process whose label ends with ``label``, or None."""
    cpu = [v for k, v in (result.get('cpu_s') or {}).items() if k.endswith(label) and v is not None]
    return cpu[0] / result['steps'] * 1e6 if cpu else None


def _median_or_none(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None
