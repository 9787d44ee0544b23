"""Where chunks of episodes run: local processes (the default) or Ray tasks on a cluster.

Both backends call ``on_rows(rows)`` as each chunk finishes (results streamed back to the
driver, in completion order) and return nothing else: the driver keys rows by episode index, so
a chunk that runs twice (a retry after a lost worker) cannot duplicate rows, and the table is
sorted by episode index whatever the completion order.

- ``run_local``: a ``concurrent.futures.ProcessPoolExecutor`` of ``workers`` processes (default:
  every core). A worker that dies breaks the pool; the chunks without a result are submitted
  again to a new pool, at most ``max_retries`` times.
- ``run_ray``: one Ray task per chunk (``num_cpus=1``, ``max_retries``: Ray reruns a task whose
  worker process or node died), collected with ``ray.wait`` as they finish. ``address`` is
  'auto' (the cluster of ``ray start`` on this machine), ``ray://host:10001`` or
  ``host:6379``, or None for a private local instance of ``workers`` CPUs (started and shut
  down here). Every node needs this repository at the same path and its .venv (``make
  venv-sweep``), so that the workers import the same code.
"""
import concurrent.futures as cf
import os

from .episodes import run_chunk

DEFAULT_RETRIES = 3


class SweepRunError(RuntimeError):
    """A chunk failed for good (more lost workers than retries, or an error in the loop)."""


def run_local(chunks, on_rows, workers=None, max_retries=DEFAULT_RETRIES):
    workers = workers or os.cpu_count() or 1
    todo = dict(enumerate(chunks))
    for attempt in range(max_retries + 1):
        try:
            with cf.ProcessPoolExecutor(max_workers=min(workers, len(todo))) as pool:
                futures = {pool.submit(run_chunk, todo[k]): k for k in sorted(todo)}
                for fut in cf.as_completed(futures):
                    on_rows(fut.result())
                    del todo[futures[fut]]
            return
        except cf.process.BrokenProcessPool:
            if attempt == max_retries:
                raise SweepRunError(f'a worker process died {attempt + 1} times; '
                                    f'{len(todo)} chunks not run') from None


def _ray_task():
    import ray

    @ray.remote(num_cpus=1)
    def chunk_task(chunk):
        return run_chunk(chunk)
    return chunk_task


def start_local_ray(num_cpus, attempts=2):
    """A private local Ray instance of ``num_cpus`` CPUs. On a loaded machine its raylet can
    miss Ray's fixed 30 s start-up wait (its metrics agent starts late): tried ``attempts``
    times; the last failure is raised."""
    import ray
    for attempt in range(attempts):
        try:
            return ray.init(num_cpus=num_cpus, include_dashboard=False, log_to_driver=False,
                            configure_logging=False)
        except Exception:  # noqa: BLE001 (Ray raises a bare Exception for a slow start)
            ray.shutdown()
            if attempt == attempts - 1:
                raise


def run_ray(chunks, on_rows, address=None, workers=None, max_retries=DEFAULT_RETRIES):
    import ray
    started = False
    if not ray.is_initialized():
        if address is None:
            start_local_ray(workers or os.cpu_count() or 1)
        else:
            ray.init(address=address, log_to_driver=False, configure_logging=False)
        started = True
    try:
        task = _ray_task().options(max_retries=max_retries)
        pending = [task.remote(c) for c in chunks]
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            try:
                rows = ray.get(done[0])
            except ray.exceptions.RayError as exc:
                raise SweepRunError(f'a chunk failed on Ray: {type(exc).__name__}: '
                                    f'{str(exc).splitlines()[0]}') from None
            on_rows(rows)
    finally:
        if started:
            ray.shutdown()
