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
  worker process or node died), collected with ``ray.wait`` as they finish. Each attempt
  writes a key into the cluster's key-value store (the head's GCS) as it starts, since Ray
  does not tell a driver that it retried a task (its state API needs the dashboard). A
  cluster left without a CPU (its worker nodes lost for good) cannot run the chunks still
  pending, which Ray would wait for forever: after ``NO_CPU_WAIT_S`` without one the sweep
  stops (SweepRunError). ``address`` is
  'auto' (the cluster of ``ray start`` on this machine), ``ray://host:10001`` or
  ``host:6379``, or None for a private local instance of ``workers`` CPUs (started and shut
  down here). Every node needs this repository at the same path and its .venv (``make
  venv-sweep``), so that the workers import the same code. ``fn`` runs a chunk instead of the
  sweep's ``run_chunk`` (a module-level function, so that workers import it by name).
- ``RayPool``: ``multiprocessing.Pool.map`` on ``run_ray`` (one task per item, results in
  item order, reruns counted per map), for loops that are not sweeps (the failure search).
"""
import concurrent.futures as cf
import functools
import multiprocessing as mp
import os
import time
import uuid

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


#: Namespace of the start records in the Ray cluster's key-value store (on its head, the GCS).
_KV_NAMESPACE = 'shipnav_sweep'


def _ray_task():
    import ray

    @ray.remote(num_cpus=1)
    def chunk_task(run_id, k, chunk, fn=None):
        # A key per attempt, written before the work so that an attempt lost with its worker
        # or node is counted. The store's put is a direct call to the head: a ray.get here (an
        # actor keeping count) would lend this task's CPU to another chunk while it waits.
        from ray.experimental import internal_kv
        try:
            internal_kv._internal_kv_put(f'{run_id}:{k}:{os.getpid()}:{time.time_ns()}', b'',
                                         namespace=_KV_NAMESPACE)
        except Exception:  # noqa: BLE001 (the count is lost, not the chunk)
            pass
        return (fn or run_chunk)(chunk)
    return chunk_task


def _ray_reruns(run_id):
    """Indices of the chunks of ``run_id`` that started more than once (their records are
    deleted), or None if the store cannot be read."""
    from ray.experimental import internal_kv
    try:
        keys = internal_kv._internal_kv_list(f'{run_id}:', namespace=_KV_NAMESPACE)
        internal_kv._internal_kv_del(f'{run_id}:', del_by_prefix=True, namespace=_KV_NAMESPACE)
    except Exception:  # noqa: BLE001 (e.g. a Ray client connection without the store)
        return None
    starts = {}
    for key in keys:
        k = int(key.decode().split(':')[1])
        starts[k] = starts.get(k, 0) + 1
    return sorted(k for k, n in starts.items() if n > 1)


def start_local_ray(num_cpus, attempts=2):
    """A private local Ray instance of ``num_cpus`` CPUs. On a loaded machine its raylet can
    miss Ray's fixed 30 s start-up wait (its metrics agent starts late): tried ``attempts``
    times; the last failure is raised. ``address='local'``: never the cluster a ``ray start`` on
    this machine (or another test) left running, which a bare ``ray.init()`` would join."""
    import ray
    for attempt in range(attempts):
        try:
            return ray.init(address='local', num_cpus=num_cpus, include_dashboard=False, log_to_driver=False,
                            configure_logging=False)
        except Exception:  # noqa: BLE001 (Ray raises a bare Exception for a slow start)
            ray.shutdown()
            if attempt == attempts - 1:
                raise


def run_ray(chunks, on_rows, address=None, workers=None, max_retries=DEFAULT_RETRIES, fn=None):
    import ray
    started = False
    if not ray.is_initialized():
        if address is None:
            start_local_ray(workers or os.cpu_count() or 1)
        else:
            ray.init(address=address, log_to_driver=False, configure_logging=False)
        started = True
    run_id, counted = uuid.uuid4().hex, False
    try:
        task = _ray_task().options(max_retries=max_retries)
        pending = [task.remote(run_id, k, c, fn) for k, c in enumerate(chunks)]
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
        counted = True
        return _ray_reruns(run_id)
    finally:
        if not counted:   # the sweep failed: its start records go all the same
            _ray_reruns(run_id)
        if started:
            ray.shutdown()


def _indexed(fn, chunk):
    """[(index, fn(item))] of a chunk of (index, item) pairs: a RayPool task."""
    return [(i, fn(item)) for i, item in chunk]


class RayPool:
    """``map(fn, items)`` as Ray tasks, one per item, through ``run_ray`` (Ray retries an item
    whose worker or node was lost, at most ``max_retries`` times); the results in item order.
    A context manager: Ray is started (``address`` None: a private local instance of
    ``workers`` CPUs) or joined on entry and shut down on exit, once for every map. ``reruns``
    holds, per map, the indices of the items that started more than once (None: the cluster's
    store could not be read); ``fn`` must be a module-level function."""

    def __init__(self, address=None, workers=None, max_retries=DEFAULT_RETRIES):
        self.address, self.workers, self.max_retries = address, workers, max_retries
        self.reruns = []

    def __enter__(self):
        import ray
        if self.address is None:
            start_local_ray(self.workers or os.cpu_count() or 1)
        else:
            ray.init(address=self.address, log_to_driver=False, configure_logging=False)
        return self

    def __exit__(self, *exc):
        import ray
        ray.shutdown()

    def map(self, fn, items):
        out = {}
        chunks = [[(i, item)] for i, item in enumerate(items)]
        self.reruns.append(run_ray(chunks, lambda rows: out.update(rows), self.address,
                                   self.workers, self.max_retries,
                                   fn=functools.partial(_indexed, fn)))
        return [out[i] for i in range(len(items))]
