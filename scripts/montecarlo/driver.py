"""Run a sweep: expand, chunk, hand the chunks to a backend, collect rows once each, report progress."""
import sys
import time

from . import backends, results
from .episodes import auto_chunk_size, episode_chunks, vessel_steps, with_route_keys
from .spec import expand


class Progress:
    """One status line: episodes done, episodes/s, vessel-steps/s and the time left.
    Rewritten in place on a terminal; elsewhere a new line at most every ``every_s``."""

    def __init__(self, total, stream=None, every_s=10.0):
        self.total, self.done, self.steps = total, 0, 0
        self.stream = stream or sys.stderr
        self.tty = self.stream.isatty()
        self.every_s, self.t0, self.last = every_s, time.monotonic(), -1e9

    def update(self, episodes, steps):
        self.done += episodes
        self.steps += steps
        now = time.monotonic()
        if not self.tty and now - self.last < self.every_s and self.done < self.total:
            return
        self.last = now
        el = max(now - self.t0, 1e-9)
        rate = self.done / el
        left = (self.total - self.done) / rate if rate > 0 else float('inf')
        text = (f'sweep: {self.done}/{self.total} episodes ({100 * self.done / self.total:.0f} %)'
                f', {rate:.1f} episodes/s, {self.steps / el:,.0f} vessel-steps/s, '
                f'{_clock(el)} elapsed, {_clock(left)} left')
        self.stream.write(('\r' + text + ' ' * 4) if self.tty else text + '\n')
        if self.tty and self.done >= self.total:
            self.stream.write('\n')
        self.stream.flush()


def _clock(seconds):
    if seconds == float('inf'):
        return '?'
    s = int(round(seconds))
    return f'{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}'


def run_sweep(sweep, backend='local', workers=None, chunk_size=None, address=None,
              episodes=None, progress=True, duration=None, where=None, partial=None,
              resume=False):
    """Every episode's row (sorted by episode index) and the run's figures.

    ``backend`` 'local' or 'ray'; ``episodes`` / ``duration`` override the file's samples per
    cell and episode length; ``chunk_size`` None = episodes.auto_chunk_size; ``where``
    {grid axis: value or list of values}: only those cells (episode indices and draws as in the
    whole sweep). ``partial``: a file that gets each chunk's rows as they arrive
    (results.PartialRows); ``resume``: run only the episodes it lacks. A backend that fails
    raises SweepRunError naming the episodes without a row (those in ``partial`` are kept).
    The run's figures name the chunks that started more than once (``rerun_chunks``, their
    episodes in ``rerun_episodes``; None when the backend could not count), see rerun_line."""
    import os
    eps = expand(sweep, episodes)
    for axis, values in (where or {}).items():
        values = values if isinstance(values, list) else [values]
        if axis not in sweep.grid or not set(values) <= set(sweep.grid[axis]):
            from .spec import SweepError
            raise SweepError(f'--where {axis}={values}: not a grid axis value; grid: '
                             f'{sweep.grid}')
        eps = [e for e in eps if e[axis] in values]
    if duration is not None:
        eps = [dict(e, duration_s=float(duration)) for e in eps]
    if sweep.kind == 'route':
        eps = with_route_keys(eps, sweep.source)
    if backend not in ('local', 'ray'):
        raise ValueError(f"backend {backend!r}; allowed: local, ray")
    kept = None
    if partial is not None:
        kept = results.PartialRows(partial, results.episodes_fingerprint(eps), resume)
    rows = dict(kept.done) if kept else {}
    todo = [e for e in eps if e['episode'] not in rows]
    n_workers = workers or os.cpu_count() or 1
    size = chunk_size or auto_chunk_size(max(len(todo), 1), n_workers, eps[0]['duration_s'])
    chunks = episode_chunks(todo, size)
    bar = Progress(len(todo)) if progress and todo else None

    def on_rows(chunk_rows):
        new = [r for r in chunk_rows if r['episode'] not in rows]
        for r in new:
            rows[r['episode']] = r
        if kept and new:
            kept.add(new)
        if bar:
            bar.update(len(new), vessel_steps(new))

    t0 = time.monotonic()
    reruns = []
    try:
        if backend == 'local' and chunks:
            reruns = backends.run_local(chunks, on_rows, workers=n_workers)
        elif chunks:
            reruns = backends.run_ray(chunks, on_rows, address=address, workers=workers)
    except Exception as exc:  # noqa: BLE001 (any backend failure: say what is kept and lost)
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if not isinstance(exc, backends.SweepRunError):
            reason = f'{type(exc).__name__}: {reason}'
        raise backends.SweepRunError(_lost(reason, eps, rows, partial)) from None
    finally:
        if kept:
            kept.close()
    wall = max(time.monotonic() - t0, 1e-9)
    if len(rows) < len(eps):
        raise backends.SweepRunError(_lost('the backend returned early', eps, rows, partial))
    out = [rows[k] for k in sorted(rows)]
    ran = [r for r in out if r['episode'] in {e['episode'] for e in todo}]
    rerun = (None if reruns is None
             else sorted(e['episode'] for k in reruns for e in chunks[k]))
    return out, {'episodes': len(out), 'resumed_rows': len(out) - len(ran),
                 'chunks': len(chunks), 'chunk_size': size,
                 'rerun_chunks': None if reruns is None else len(reruns),
                 'rerun_episodes': None if rerun is None else results.episode_ranges(rerun),
                 'workers': n_workers, 'backend': backend, 'wall_s': wall,
                 'episodes_per_s': len(ran) / wall, 'vessel_steps_per_s':
                 vessel_steps(ran) / wall}


def _lost(reason, eps, rows, partial):
    """One line: why the sweep stopped, which episodes have no row, where the others are."""
    missing = sorted(e['episode'] for e in eps if e['episode'] not in rows)
    kept = (f'; the {len(rows)} finished rows are in {partial} (rerun with --resume)'
            if partial is not None and rows else '')
    return (f'{reason}; {len(missing)} of {len(eps)} episodes without a row: '
            f'{results.episode_ranges(missing)}{kept}')


def rerun_line(run):
    """One line on the chunks a lost worker or node made run again, or None if none did."""
    if run['rerun_chunks'] is None:
        return ("reruns: unknown (the cluster's key-value store could not be read); the table "
                'still has each row once')
    if not run['rerun_chunks']:
        return None
    return (f"reruns: {run['rerun_chunks']} of {run['chunks']} chunks ran again after a lost "
            f"worker process or node (episodes {run['rerun_episodes']}); each row is kept once")
