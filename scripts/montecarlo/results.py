"""The sweep's table (CSV) and its summary with confidence intervals.

Table: one row per episode, sorted by episode index; the columns are the episode's identity
(episode, cell, sample, seed), its parameters (varied first) and the metrics
(episodes.METRICS). Floats are written with 10 significant digits, so the file is the same
byte for byte whenever the episodes' results are.

Summary: per grid cell (one value of every grid axis), per metric, the mean with a 95 %
Student-t confidence interval (mean +- t_{0.975, n-1} s / sqrt(n)), the median and the 95th
percentile; the 0/1 columns (completion; collision, near miss, below r_min of an encounter) as
proportions with a 95 % Wilson score interval (Wilson 1927), which stays inside [0, 1] when
every episode completes (or none collides). Route following: metrics of episodes that did not
complete are left out of the other means (n says how many remain). The columns of each sweep
kind (spec.Sweep.kind) are in KINDS.
"""
import csv
import hashlib
import io
import json
import math
import os
from dataclasses import dataclass

import numpy as np
from scipy import stats

from . import encounters
from .episodes import METRICS
from .spec import SweepError

ID_COLUMNS = ('episode', 'cell', 'sample', 'seed')
CI_LEVEL = 0.95


@dataclass(frozen=True)
class Kind:
    """The table and summary columns of a sweep kind."""
    metrics: tuple       # metric columns, in table order
    proportions: tuple   # 0/1 columns: Wilson intervals
    gate: str            # a proportion: the other metrics are over its rows = 1 (None: all)
    shown: tuple         # summary.md's columns


KINDS = {
    'route': Kind(METRICS, ('completed',), 'completed',
                  ('reward', 'rms_e_m', 'max_abs_e_m', 'rudder_rate_deg_s', 'completed')),
    'encounter': Kind(encounters.METRICS, encounters.PROPORTIONS, None,
                      ('min_distance_m', 'collision', 'near_miss', 'below_r_min', 'rule_score',
                       'path_deviation_m', 'time_lost_s')),
}


def _cell(value):
    if isinstance(value, float):
        return 'nan' if math.isnan(value) else f'{value:.10g}'
    return str(value)


def table_text(rows, param_columns, metrics=METRICS):
    """The CSV text of ``rows`` (dicts), sorted by episode index."""
    cols = list(ID_COLUMNS) + list(param_columns) + list(metrics)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator='\n')
    w.writerow(cols)
    for row in sorted(rows, key=lambda r: r['episode']):
        w.writerow([_cell(row[c]) for c in cols])
    return buf.getvalue()


def read_table(path):
    """Rows of a table written by ``table_text`` (numbers as floats, names as str)."""
    out = []
    with open(path, newline='') as f:
        for row in csv.DictReader(f):
            out.append({k: _parse(v) for k, v in row.items()})
    return out


def _parse(text):
    try:
        return float(text)
    except ValueError:
        return text


def t_interval(values, level=CI_LEVEL):
    """(mean, low, high) of the Student-t interval; (mean, nan, nan) for fewer than 2 values."""
    x = np.asarray(values, dtype=float)
    n = x.size
    if n == 0:
        return math.nan, math.nan, math.nan
    mean = float(x.mean())
    if n < 2:
        return mean, math.nan, math.nan
    half = float(stats.t.ppf(0.5 + level / 2, n - 1) * x.std(ddof=1) / math.sqrt(n))
    return mean, mean - half, mean + half


def wilson_interval(successes, n, level=CI_LEVEL):
    """(proportion, low, high) of the Wilson score interval."""
    if n == 0:
        return math.nan, math.nan, math.nan
    z = float(stats.norm.ppf(0.5 + level / 2))
    p = successes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return p, max(0.0, centre - half), min(1.0, centre + half)


def summarise(rows, group_by, kind=KINDS['route']):
    """Per group (a tuple of ``group_by`` values, in first-seen episode order):
    {metric: {'n', 'mean', 'low', 'high', 'median', 'p95'}} for the metrics of ``kind``."""
    groups = {}
    for row in sorted(rows, key=lambda r: r['episode']):
        groups.setdefault(tuple(row[g] for g in group_by), []).append(row)
    out = {}
    for key, members in groups.items():
        done = [r for r in members if kind.gate is None or r[kind.gate] == 1]
        entry = {}
        for m in kind.proportions:
            p, lo, hi = wilson_interval(sum(int(r[m]) for r in members), len(members))
            entry[m] = {'n': len(members), 'mean': p, 'low': lo, 'high': hi,
                        'median': math.nan, 'p95': math.nan}
        for m in kind.metrics:
            if m in kind.proportions:
                continue
            v = np.array([r[m] for r in done], dtype=float)
            mean, lo, hi = t_interval(v)
            entry[m] = {'n': int(v.size), 'mean': mean, 'low': lo, 'high': hi,
                        'median': float(np.median(v)) if v.size else math.nan,
                        'p95': float(np.percentile(v, 95)) if v.size else math.nan}
        out[key] = entry
    return out


def summary_rows(summary, group_by, kind=KINDS['route']):
    """(header, rows) of the summary: per group its grid values, n and 'mean [low, high]' per
    metric of ``kind.shown`` (text cells; summary.md and index.html show the same)."""
    metrics = kind.shown
    header = list(group_by) + ['n'] + list(metrics)
    rows = []
    for key, entry in summary.items():
        cells = [_cell(k) for k in key] + [str(entry[kind.proportions[0]]['n'])]
        for m in metrics:
            s = entry[m]
            fmt = ('{:.3f}' if m in kind.proportions or m == 'rule_score' else '{:.1f}'
                   if abs(s['mean']) >= 10 else '{:.2f}')
            cells.append(f'{fmt.format(s["mean"])} [{fmt.format(s["low"])}, '
                         f'{fmt.format(s["high"])}]' if not math.isnan(s['low'])
                         else fmt.format(s['mean']))
        rows.append(cells)
    return header, rows


def summary_caption(kind=KINDS['route']):
    """What the summary's cells are."""
    over = 'over completed episodes' if kind.gate == 'completed' else 'over every episode'
    return (f'Mean [{CI_LEVEL:.0%} CI] per group: Student-t for the metrics, Wilson for '
            f'{", ".join(kind.proportions)} (proportions); metrics {over}.')


def summary_markdown(summary, group_by, kind=KINDS['route']):
    """A Markdown table: one line per group, 'mean [low, high]' per metric of ``kind.shown``."""
    header, rows = summary_rows(summary, group_by, kind)
    lines = [summary_caption(kind), '', '| ' + ' | '.join(header) + ' |',
             '|' + '---|' * len(group_by) + '---:|' * (len(kind.shown) + 1)]
    lines += ['| ' + ' | '.join(cells) + ' |' for cells in rows]
    return '\n'.join(lines) + '\n'


# -- rows kept while the sweep runs -------------------------------------------------------------

PARTIAL_NAME = 'results.partial.jsonl'


def episodes_fingerprint(episodes):
    """A short hash of the episodes to run (parameters, seeds, durations): a partial file is
    only resumed by the sweep that wrote it."""
    text = json.dumps(episodes, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


class PartialRows:
    """The rows of a running sweep, appended to ``path`` as each chunk finishes (JSON lines,
    which keep every float exactly, so a resumed table equals an uninterrupted one), so a
    backend that dies (a Ray raylet, the machine) loses only the chunks still running.

    The first line names the episodes' fingerprint. ``resume``: the rows already in ``path``
    are ``done`` (a last line cut by a crash is dropped) and new rows are appended; a missing
    file or one of another sweep is a SweepError. Otherwise ``path`` starts empty."""

    #: What differs when a partial file is another run's (the refusal names it).
    OTHER = 'another sweep (the file, --episodes, --duration or --where differ)'

    def __init__(self, path, fingerprint, resume=False, other=OTHER):
        self.path, self.done = path, {}
        if resume:
            self.done = self._read(path, fingerprint, other)
            self._file = open(path, 'a')
        else:
            self._file = open(path, 'w')
            self._write([{'partial_of': fingerprint}])

    @staticmethod
    def _read(path, fingerprint, other):
        try:
            lines = path.read_text().splitlines()
        except FileNotFoundError:
            raise SweepError(f'--resume: nothing to resume, no {path}') from None
        try:
            head = json.loads(lines[0]) if lines else {}
        except ValueError:
            head = {}
        if head.get('partial_of') != fingerprint:
            raise SweepError(f'--resume: {path} was written by {other}; run without --resume')
        done = {}
        for i, line in enumerate(lines[1:], 2):
            try:
                row = json.loads(line)
            except ValueError:
                if i == len(lines):   # cut short by the crash that stopped the sweep
                    break
                raise SweepError(f'--resume: {path} line {i} is not a row') from None
            done[row['episode']] = row
        return done

    def _write(self, records):
        self._file.write(''.join(json.dumps(r) + '\n' for r in records))
        self._file.flush()
        os.fsync(self._file.fileno())

    def add(self, rows):
        self._write(rows)

    def close(self):
        self._file.close()


def episode_ranges(indices):
    """'3-5, 9, 12-13' for sorted episode indices."""
    parts, start = [], None
    for i, k in enumerate(indices):
        if start is None:
            start = k
        if i + 1 == len(indices) or indices[i + 1] != k + 1:
            parts.append(f'{start}' if start == k else f'{start}-{k}')
            start = None
    return ', '.join(parts)
