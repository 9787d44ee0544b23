"""Shared helpers of the benchmark sections: repository root, timing, goals, tables, machine info.

Timing follows the ``timeit`` advice: the loop count is grown until one repeat takes at least
``min_time`` seconds, the repeat is done several times, and the best and the median per-call
times are reported (microseconds), with the minor page faults per call over the repeats
(``minor_faults``: memory a call maps afresh instead of reusing, see ship_sim.allocator; a
count the machine's load does not disturb). Goals are judged on the best: it is the least disturbed by
other processes (timeit's own advice), which matters on a shared machine; the median shows how
much disturbance there was.
"""
import datetime
import os
import platform
import resource
import statistics
import timeit
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def minor_faults():
    """Minor page faults of this process so far (getrusage); differences count a section's."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


def time_call(fn, quick=False, min_time=None, repeats=None):
    """Per-call time of ``fn()`` in microseconds and minor page faults per call (over the
    repeats after the first): {'best_us', 'median_us', 'faults', 'loops', 'repeats'}."""
    min_time = (0.05 if quick else 0.2) if min_time is None else min_time
    repeats = (3 if quick else 7) if repeats is None else repeats
    timer = timeit.Timer(fn)
    loops = 1
    while True:
        t = timer.timeit(loops)
        if t >= min_time:
            break
        # Aim a little above min_time from the last measurement; at least double.
        loops = max(2 * loops, int(loops * 1.2 * min_time / max(t, 1e-9)))
    f0 = minor_faults()
    runs = [t] + timer.repeat(repeat=repeats - 1, number=loops)
    faults = (minor_faults() - f0) / (loops * max(repeats - 1, 1))
    per_call = [r / loops * 1e6 for r in runs]
    return {'best_us': min(per_call), 'median_us': statistics.median(per_call),
            'faults': faults, 'loops': loops, 'repeats': repeats}


def goal(text, value, target, unit, below=True):
    """A goal line: ``value`` must be below (or, below=False, at least) ``target``."""
    met = value < target if below else value >= target
    return {'text': text, 'value': value, 'target': target, 'unit': unit,
            'relation': '<' if below else '>=', 'met': bool(met)}


def machine_info():
    """What the numbers depend on: CPU, Python, numpy, date."""
    import numpy as np
    info = {
        'date': datetime.datetime.now(datetime.timezone.utc).isoformat(timespec='seconds'),
        'cpu_count': os.cpu_count(),
        'cpu_model': _cpu_model(),
        'platform': platform.platform(),
        'python': platform.python_version(),
        'python_implementation': platform.python_implementation(),
        'numpy': np.__version__,
    }
    try:
        info['load_avg_1min'] = os.getloadavg()[0]
    except OSError:
        pass
    return info


def _cpu_model():
    try:
        for line in Path('/proc/cpuinfo').read_text().splitlines():
            if line.startswith('model name'):
                return line.split(':', 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or 'unknown'


# -- printing ----------------------------------------------------------------------------------

def _fmt(value):
    if isinstance(value, bool):
        return 'yes' if value else 'no'
    if isinstance(value, int):
        return f'{value:,}'
    if isinstance(value, float):
        if value != value:  # NaN
            return '-'
        a = abs(value)
        if a >= 1e3:
            return f'{value:,.0f}'
        if a >= 100:
            return f'{value:.1f}'
        if a >= 1:
            return f'{value:.2f}'
        return f'{value:.3g}'
    return '-' if value is None else str(value)


def format_table(columns, rows):
    """Plain-text table: columns [[key, header], ...], rows [{key: value}]; numbers on the right."""
    cells = [[_fmt(row.get(key)) for key, _ in columns] for row in rows]
    heads = [h for _, h in columns]
    widths = [max([len(h)] + [len(c[i]) for c in cells]) for i, h in enumerate(heads)]
    numeric = [all(isinstance(r.get(k), (int, float)) or r.get(k) is None for r in rows)
               for k, _ in columns]

    def line(items):
        return '  '.join(s.rjust(w) if num else s.ljust(w)
                         for s, w, num in zip(items, widths, numeric)).rstrip()

    out = [line(heads), line(['-' * w for w in widths])]
    out += [line(c) for c in cells]
    return '\n'.join(out)


def format_section(name, result):
    """The printed form of one section's result: title, table, goals, notes."""
    out = [f'== {name}: {result.get("title", "")}']
    if result.get('rows'):
        out.append(format_table(result['columns'], result['rows']))
    for g in result.get('goals', []):
        mark = 'MET ' if g['met'] else 'MISS'
        out.append(f"goal [{mark}] {g['text']}: {_fmt(g['value'])} {g['unit']} "
                   f"({g['relation']} {_fmt(g['target'])} {g['unit']})")
    for note in result.get('notes', []):
        out.append(f'note: {note}')
    return '\n'.join(out)
