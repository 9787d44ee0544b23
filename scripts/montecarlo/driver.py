"""Run a sweep: expand, chunk, hand the chunks to a backend, collect rows once each, report progress."""
import sys
import time

from . import backends
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
              episodes=None, progress=True, duration=None, where=None):
    """Every episode's row (sorted by episode index) and the run's figures.

    ``backend`` 'local' or 'ray'; ``episodes`` / ``duration`` override the file's samples per
    cell and episode length; ``chunk_size`` None = episodes.auto_chunk_size; ``where``
    {grid axis: value or list of values}: only those cells (episode indices and draws as in the
    whole sweep)."""
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
    n_workers = workers or os.cpu_count() or 1
    size = chunk_size or auto_chunk_size(len(eps), n_workers, eps[0]['duration_s'])
    chunks = episode_chunks(eps, size)
    rows = {}
    bar = Progress(len(eps)) if progress else None

    def on_rows(chunk_rows):
        new = [r for r in chunk_rows if r['episode'] not in rows]
        for r in new:
            rows[r['episode']] = r
        if bar:
            bar.update(len(new), vessel_steps(new))

    t0 = time.monotonic()
    if backend == 'local':
        backends.run_local(chunks, on_rows, workers=n_workers)
    elif backend == 'ray':
        backends.run_ray(chunks, on_rows, address=address, workers=workers)
    else:
        raise ValueError(f"backend {backend!r}; allowed: local, ray")
    wall = time.monotonic() - t0
    missing = sorted(set(e['episode'] for e in eps) - set(rows))
    if missing:
        raise backends.SweepRunError(f'{len(missing)} episodes without a result '
                                     f'(first {missing[0]})')
    out = [rows[k] for k in sorted(rows)]
    return out, {'episodes': len(out), 'chunks': len(chunks), 'chunk_size': size,
                 'workers': n_workers, 'backend': backend, 'wall_s': wall,
                 'episodes_per_s': len(out) / wall, 'vessel_steps_per_s':
                 vessel_steps(out) / wall}
