"""Where chunks of episodes run: local processes (the default) or Ray tasks on a cluster.

Both backends call ``on_rows(rows)`` as each chunk finishes (results streamed back to the
driver, in completion order) and return the indices of the chunks that started more than once
(reruns after a lost worker process or node; every start is counted where the chunk runs, so a
chunk that was queued but never started on a lost worker is not a rerun). The driver keys rows
by episode index, so a chunk that runs twice cannot duplicate rows, and the table is sorted by
episode index whatever the completion order.

- ``run_local``: a ``concurrent.futures.ProcessPoolExecutor`` of ``workers`` processes (default:
  every core). A worker that dies breaks the pool; the chunks without a result are submitted
  again to a new pool, at most ``max_retries`` times. Starts are counted in shared memory.
- ``run_ray``: one Ray task per chunk (``num_cpus=1``, ``max_retries``: Ray reruns a task whose
  worker process or node died), collected with ``ray.wait`` as they finish. Starts are counted
  by a small actor on the driver's node (``_Starts``), since Ray does not tell a driver that it
  retried a task (its state API needs the dashboard). A cluster left without a CPU (its worker
  nodes lost for good) cannot run the chunks still pending, which Ray would wait for forever:
  after ``NO_CPU_WAIT_S`` without one the sweep stops (SweepRunError). ``address`` is
  'auto' (the cluster of ``ray start`` on this machine), ``ray://host:10001`` or
  ``host:6379``, or None for a private local instance of ``workers`` CPUs (started and shut
  down here). Every node needs this repository at the same path and its .venv (``make
  venv-sweep``), so that the workers import the same code.
"""
import concurrent.futures as cf
import multiprocessing as mp
import os
import time

from .episodes import run_chunk

DEFAULT_RETRIES = 3
#: Seconds a Ray cluster may have no CPU at all before the sweep gives up on its pending chunks
#: (an autoscaling cluster starting a node needs minutes; a lost node is never coming back).
NO_CPU_WAIT_S = 300.0
#: Seconds between two looks at the cluster's CPUs while no chunk finishes.
_POLL_S = 2.0


class SweepRunError(RuntimeError):
    """A chunk failed for good (more lost workers than retries, or an error in the loop)."""


_STARTS = None   # a worker process's view of run_local's start counts


def _share_starts(starts):
    global _STARTS
    _STARTS = starts


def _counted_chunk(k, chunk):
    with _STARTS.get_lock():
        _STARTS[k] += 1
    return run_chunk(chunk)


def run_local(chunks, on_rows, workers=None, max_retries=DEFAULT_RETRIES):
    workers = workers or os.cpu_count() or 1
    todo = dict(enumerate(chunks))
    starts = mp.Array('i', len(chunks))
    for attempt in range(max_retries + 1):
        try:
            with cf.ProcessPoolExecutor(max_workers=min(workers, len(todo)),
                                        initializer=_share_starts, initargs=(starts,)) as pool:
                futures = {pool.submit(_counted_chunk, k, todo[k]): k for k in sorted(todo)}
                for fut in cf.as_completed(futures):
                    on_rows(fut.result())
                    del todo[futures[fut]]
            return [k for k, n in enumerate(starts) if n > 1]
        except cf.process.BrokenProcessPool:
            if attempt == max_retries:
                raise SweepRunError(f'a worker process died {attempt + 1} times; '
                                    f'{len(todo)} chunks not run') from None


def _ray_remotes():
    """(the chunk task, the start-counting actor class), defined once Ray is imported."""
    import ray

    @ray.remote(num_cpus=0)
    class _Starts:
        def __init__(self):
            self.starts = {}

        def start(self, k):
            self.starts[k] = self.starts.get(k, 0) + 1

        def reruns(self):
            return sorted(k for k, n in self.starts.items() if n > 1)

    @ray.remote(num_cpus=1)
    def chunk_task(k, chunk, starts):
        try:
            ray.get(starts.start.remote(k))   # before the work, so a lost attempt is counted
        except ray.exceptions.RayError:
            pass   # the count is lost, not the chunk
        return run_chunk(chunk)
    return chunk_task, _Starts


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
        from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy
        chunk_task, starts_actor = _ray_remotes()
        # On the driver's node, which lives as long as the driver (a soft affinity lets Ray put
        # it on another node, which may be the one that dies).
        here = NodeAffinitySchedulingStrategy(ray.get_runtime_context().get_node_id(),
                                              soft=False)
        starts = starts_actor.options(scheduling_strategy=here).remote()
        task = chunk_task.options(max_retries=max_retries)
        pending = [task.remote(k, c, starts) for k, c in enumerate(chunks)]
        no_cpu_since = None
        while pending:
            done, pending = ray.wait(pending, num_returns=1, timeout=_POLL_S)
            if not done:
                if ray.cluster_resources().get('CPU', 0) > 0:
                    no_cpu_since = None
                    continue
                no_cpu_since = no_cpu_since or time.monotonic()
                if time.monotonic() - no_cpu_since >= NO_CPU_WAIT_S:
                    raise SweepRunError(f'the Ray cluster has had no CPU for {NO_CPU_WAIT_S:g} '
                                        f's (its worker nodes are gone); {len(pending)} chunks '
                                        'not run')
                continue
            try:
                rows = ray.get(done[0])
            except ray.exceptions.RayError as exc:
                raise SweepRunError(f'a chunk failed on Ray: {type(exc).__name__}: '
                                    f'{str(exc).splitlines()[0]}') from None
            on_rows(rows)
        try:
            return ray.get(starts.reruns.remote(), timeout=60)
        except ray.exceptions.RayError:
            return None   # the counts were lost with the actor's node: reruns unknown
    finally:
        if started:
            ray.shutdown()
