"""Section ``imazu``: cost of Imazu benchmark runs in process (scripts/imazu/runner.py).

A few cases (quick: case 1; else cases 1, 6 and 12: one, two and three targets) with the mariner
and each method, 600 s of sim time each (the decisions of the first 10 minutes, when the
threats appear): wall time per run, the share spent in colav decisions, decisions per second
of decision time. The full benchmark (scripts/imazu_benchmark.py) runs 22 x 3 x 2 of these at
2000 s each; this section says what one costs on this machine.
"""
import os
import tempfile
import time


DURATION_S = 600.0


def run(quick=False):
    from imazu.cases import load_cases
    from imazu.runner import METHODS, case_scenario, run_scenario, write_scenario
    cases = load_cases()
    rows = []
    for number in ((1,) if quick else (1, 6, 12)):
        for method in METHODS:
            with tempfile.TemporaryDirectory() as tmp:
                path = write_scenario(*case_scenario(number, cases[number], 'mariner', method,
                                                     DURATION_S), tmp)
                t0, c0 = time.perf_counter(), time.process_time()
                r = run_scenario(path)
                wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            n = len(r.decisions)
            rows.append({'case': number, 'targets': len(cases[number]['targets']),
                         'method': method, 'wall_s': wall, 'cpu_s': cpu,
                         'rtf': DURATION_S / wall, 'decisions': n,
                         'decision_ms': 1e3 * r.decision_wall_s / max(n, 1),
                         'decisions_per_s': n / max(r.decision_wall_s, 1e-9),
                         'decision_share': r.decision_wall_s / wall})
    return {
        'title': f'Imazu runs in process, mariner, {DURATION_S:g} s sim each (decision every 1 s)',
        'columns': [['case', 'case'], ['targets', 'targets'], ['method', 'method'],
                    ['wall_s', 'wall s'], ['cpu_s', 'CPU s'], ['rtf', 'real-time factor'],
                    ['decision_ms', 'ms/decision'], ['decisions_per_s', 'decisions/s'],
                    ['decision_share', 'decision share']],
        'rows': rows, 'goals': [],
        'notes': [f'1-minute load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs'],
    }
