"""Sweeps and the failure search on a multi-node Ray cluster that loses a node mid-run (issue 30
item 3).

Each test starts a real cluster in the test process (``ray.cluster_utils.Cluster``: a head of
no CPU, which only coordinates as on a real cluster, and worker nodes of one CPU, each its own
raylet and worker processes), runs scripts/sweep.py against its address and removes a worker
node (every process of it killed) while that node runs a chunk: the node is chosen by the title
Ray gives a worker process while it runs a task (``ray::chunk_task``). The cluster is always
shut down, even on failure; Ray needs no ROS domain.

- Two worker nodes, one removed: Ray reruns its chunk on the other, the table equals the same
  sweep's on one local process byte for byte, and the run names the one chunk that ran again
  (a line and run.json).
- One worker node, removed for good: no CPU is left for the pending chunks, the sweep stops
  with one line naming the missing episodes and --resume and keeps the finished rows; with a
  new node, --resume completes the same table.
- The failure search (scripts/failure_search.py --ray) on two worker nodes, one removed while
  it runs a simulation: Ray reruns that simulation on the other, the results equal the search's
  on one local process, and the run names the one simulation that ran again.
- Two worker nodes and no retries (the backend's max_retries set to 0): the removed node's
  chunk fails for good, the sweep stops with one line, keeps the finished rows, and --resume
  on the node left completes the same table.
"""
import json
import os
import threading
import time

import pytest

import failure_search
import sweep as sweep_cli
from montecarlo import backends, results

pytestmark = [pytest.mark.integration, pytest.mark.timeout(150)]

SWEEP = ('name: cluster\nseed: 3\nepisodes: 4\nbase: {model: mariner, duration_s: 120}\n'
         'vary: {controller: [los, ilos], start_cross_m: {uniform: [-80, 80]}}\n')
N_EPISODES = 8
OPTS = ['--chunk', '1', '--no-plots']


@pytest.fixture(scope='module')
def sweep_file(tmp_path_factory):
    """The sweep file and its table on one local process (the reference)."""
    folder = tmp_path_factory.mktemp('cluster_sweep')
    path = folder / 'cluster.yaml'
    path.write_text(SWEEP)
    assert sweep_cli.main([str(path), '--out', str(folder / 'local'), '--workers', '1',
                           *OPTS]) == 0
    return path, (folder / 'local' / 'results.csv').read_text()


@pytest.fixture
def cluster(monkeypatch):
    """cluster(workers) -> a running Cluster: a head of 0 CPU and ``workers`` nodes of 1 CPU;
    shut down (every node's processes) after the test, whatever happened."""
    pytest.importorskip('ray', reason='ray is not installed (make venv-sweep)')
    import ray
    from ray.cluster_utils import Cluster
    made = []

    def start(workers):
        # Ray starts its worker processes at niceness 15: beside the suite's other tests (at 0)
        # a chunk then ran some 40 times slower than alone and a worker's first chunk took a
        # minute. Its raylets read this at start.
        monkeypatch.setenv('RAY_worker_niceness', '0')
        try:
            made.append(Cluster(initialize_head=True, head_node_args={'num_cpus': 0}))
            for _ in range(workers):
                made[-1].add_node(num_cpus=1)
            made[-1].wait_for_nodes()
        except Exception as exc:  # noqa: BLE001 (any start failure is a reason to skip)
            pytest.skip(f'a Ray cluster cannot start here: {type(exc).__name__}: '
                        f'{str(exc).splitlines()[0] if str(exc) else ""}')
        return made[-1]

    try:
        yield start
    finally:
        ray.shutdown()   # a driver the sweep left connected (it disconnects itself normally)
        for c in made:
            c.shutdown()


def _chunks_running(node):
    """How many of ``node``'s worker processes run a sweep chunk (Ray titles a worker process
    'ray::<task name>' while it runs that task, 'ray::IDLE' otherwise)."""
    from ray._private import ray_constants
    procs = node.all_processes.get(ray_constants.PROCESS_TYPE_RAYLET)
    if not procs:
        return 0
    raylet, n = procs[0].process.pid, 0
    for pid in filter(str.isdigit, os.listdir('/proc')):
        try:
            with open(f'/proc/{pid}/stat') as f:
                parent = int(f.read().rsplit(')', 1)[1].split()[1])
            if parent == raylet:
                with open(f'/proc/{pid}/cmdline') as f:
                    n += f.read().startswith('ray::chunk_task')
        except (OSError, ValueError, IndexError):
            continue   # a process that ended while we looked
    return n


def _rows(partial):
    try:
        return max(len(partial.read_text().splitlines()) - 1, 0)
    except FileNotFoundError:
        return 0


class NodeRemover(threading.Thread):
    """Removes the first of ``nodes`` seen running a chunk once ``partial`` holds a row (so
    finished rows and pending chunks both exist, and the workers have started); with
    ``partial`` None, once ``ready()`` says so. ``rows_before`` is what the file held,
    ``most_at_once`` the most chunks seen running at once on one node until then."""

    def __init__(self, cluster, nodes, partial, ready=None):
        super().__init__(daemon=True)
        self.cluster, self.nodes, self.partial = cluster, nodes, partial
        self.ready = ready or (lambda: _rows(partial) >= 1)
        self.finished = threading.Event()   # set by the test once the run returned
        self.removed, self.rows_before, self.error, self.most_at_once = None, None, None, 0

    def stop(self):
        """Stop looking (the run is over) and wait for the thread."""
        self.finished.set()
        self.join(timeout=5)

    def run(self):
        try:
            while not self.finished.is_set() and self.removed is None:
                running = [_chunks_running(node) for node in self.nodes]
                self.most_at_once = max(self.most_at_once, *running)
                if self.ready():
                    for node, n in zip(self.nodes, running):
                        if n:
                            self.rows_before = self.partial and _rows(self.partial)
                            self.cluster.remove_node(node)
                            self.removed = node
                            return
                time.sleep(0.05)
        except Exception as exc:  # noqa: BLE001 (reported by the test, not lost in a thread)
            self.error = exc


def test_a_node_removed_mid_sweep_costs_a_rerun_not_a_row(cluster, sweep_file, tmp_path,
                                                          capsys):
    path, local_table = sweep_file
    c = cluster(2)
    out = tmp_path / 'ray'
    remover = NodeRemover(c, list(c.worker_nodes), out / results.PARTIAL_NAME)
    remover.start()
    t0 = time.monotonic()
    code = sweep_cli.main([str(path), '--out', str(out), '--ray', c.address, *OPTS])
    wall = time.monotonic() - t0
    remover.stop()
    printed = capsys.readouterr()
    assert remover.error is None, remover.error
    assert remover.removed is not None, 'no worker node was seen running a chunk'
    assert 1 <= remover.rows_before < N_EPISODES          # removed mid-run
    assert code == 0, printed.err
    assert len(c.worker_nodes) == 1
    assert (out / 'results.csv').read_text() == local_table      # byte for byte, nothing lost
    run = json.loads((out / 'run.json').read_text())
    # A node of one CPU runs one chunk at a time (a task that waited on Ray inside would lend
    # its CPU to a second one), so the removed node took one chunk with it: that one reran.
    assert remover.most_at_once == 1
    assert run['rerun_chunks'] == 1 and run['chunks'] == N_EPISODES
    lines = [ln for ln in printed.out.splitlines() if ln.startswith('reruns:')]
    assert len(lines) == 1 and f'1 of {N_EPISODES} chunks ran again' in lines[0]
    assert f"(episodes {run['rerun_episodes']})" in lines[0]
    print(f'cluster sweep with a node removed: {wall:.1f} s, {lines[0]}')


def test_a_node_lost_for_good_keeps_the_rows_and_resume_completes(cluster, sweep_file,
                                                                  tmp_path, capsys,
                                                                  monkeypatch):
    path, local_table = sweep_file
    monkeypatch.setattr(backends, 'NO_CPU_WAIT_S', 3.0)   # the real default waits minutes
    c = cluster(1)
    out = tmp_path / 'ray'
    partial = out / results.PARTIAL_NAME
    remover = NodeRemover(c, list(c.worker_nodes), partial)
    remover.start()
    code = sweep_cli.main([str(path), '--out', str(out), '--ray', c.address, *OPTS])
    remover.stop()
    printed = capsys.readouterr()
    assert remover.error is None, remover.error
    assert remover.removed is not None, 'no worker node was seen running a chunk'
    assert code == 1, printed.err
    errors = [ln for ln in printed.err.splitlines() if ln.startswith('error')]
    assert len(errors) == 1 and 'Traceback' not in printed.err
    kept = sorted(json.loads(ln)['episode'] for ln in partial.read_text().splitlines()[1:])
    assert len(kept) == _rows(partial) >= remover.rows_before
    missing = [k for k in range(N_EPISODES) if k not in kept]
    assert missing and 'no CPU' in errors[0] and '--resume' in errors[0]
    assert (f'{len(missing)} of {N_EPISODES} episodes without a row: '
            f'{results.episode_ranges(missing)}') in errors[0]
    assert not (out / 'results.csv').exists()

    c.add_node(num_cpus=1)   # a new node: the same sweep resumes the missing episodes only
    c.wait_for_nodes()
    code = sweep_cli.main([str(path), '--out', str(out), '--ray', c.address, '--resume', *OPTS])
    printed = capsys.readouterr()
    assert code == 0, printed.err
    run = json.loads((out / 'run.json').read_text())
    assert run['resumed_rows'] == len(kept) and run['chunks'] == len(missing)
    assert (out / 'results.csv').read_text() == local_table
    assert not partial.exists()
    print(f'cluster sweep, its only worker node removed: {errors[0]}')


def test_a_chunk_whose_retries_all_fail_stops_the_sweep_in_one_line(cluster, sweep_file,
                                                                    tmp_path, capsys,
                                                                    monkeypatch):
    path, local_table = sweep_file
    real = backends.run_ray

    def no_retries(chunks, on_rows, **kw):   # the node's death is then the chunk's last attempt
        return real(chunks, on_rows, **kw, max_retries=0)
    monkeypatch.setattr(backends, 'run_ray', no_retries)
    c = cluster(2)
    out = tmp_path / 'ray'
    partial = out / results.PARTIAL_NAME
    remover = NodeRemover(c, list(c.worker_nodes), partial)
    remover.start()
    code = sweep_cli.main([str(path), '--out', str(out), '--ray', c.address, *OPTS])
    remover.stop()
    printed = capsys.readouterr()
    assert remover.error is None, remover.error
    assert remover.removed is not None, 'no worker node was seen running a chunk'
    assert code == 1, printed.err
    errors = [ln for ln in printed.err.splitlines() if ln.startswith('error')]
    assert len(errors) == 1 and 'Traceback' not in printed.err
    kept = sorted(json.loads(ln)['episode'] for ln in partial.read_text().splitlines()[1:])
    missing = [k for k in range(N_EPISODES) if k not in kept]
    assert len(kept) >= remover.rows_before and missing
    assert 'a chunk failed on Ray' in errors[0] and '--resume' in errors[0]
    assert (f'{len(missing)} of {N_EPISODES} episodes without a row: '
            f'{results.episode_ranges(missing)}') in errors[0]

    monkeypatch.setattr(backends, 'run_ray', real)   # the remaining node finishes the sweep
    code = sweep_cli.main([str(path), '--out', str(out), '--ray', c.address, '--resume', *OPTS])
    printed = capsys.readouterr()
    assert code == 0, printed.err
    assert json.loads((out / 'run.json').read_text())['resumed_rows'] == len(kept)
    assert (out / 'results.csv').read_text() == local_table
    print(f'cluster sweep, a chunk without retries on a removed node: {errors[0]}')


#: A failure search of two generations of two simulations (the Mariner with VO, short
#: encounters): two Ray tasks at a time on two nodes of one CPU.
SEARCH = ['--ship', 'mariner', '--method', 'vo', '--budget', '4', '--generation', '2',
          '--seed', '3', '--samplers', 'cross_entropy']


def _search_results(folder):
    """The results file's samplers without what depends on the machine (wall time) and on the
    backend (reruns)."""
    data = json.loads((folder / 'failure_search.json').read_text())
    return {name: {k: v for k, v in s.items() if k not in ('wall_s_mean', 'reran_sims')}
            for name, s in data['samplers'].items()}, data


def _starts_recorded(at_least):
    """Whether the cluster's key-value store holds ``at_least`` task starts (the backend's
    records, one written as each task begins, deleted as each map ends): a task removed with
    its node before it wrote one would be retried as its first counted start. False before the
    search has joined the cluster."""
    def ready():
        try:
            from ray.experimental import internal_kv
            return len(internal_kv._internal_kv_list('', namespace=backends._KV_NAMESPACE)) \
                >= at_least
        except Exception:  # noqa: BLE001 (not connected yet)
            return False
    return ready


def test_a_failure_search_with_a_node_removed_reruns_a_simulation_not_a_result(cluster,
                                                                               tmp_path,
                                                                               capsys):
    assert failure_search.main([*SEARCH, '--out', str(tmp_path / 'local')]) == 0
    local, _ = _search_results(tmp_path / 'local')
    c = cluster(2)
    # both simulations of a generation started (a worker's first task imports the package
    # before it records its start: under load that can take seconds)
    remover = NodeRemover(c, list(c.worker_nodes), None, ready=_starts_recorded(2))
    remover.start()
    code = failure_search.main([*SEARCH, '--ray', c.address, '--out', str(tmp_path / 'ray')])
    remover.stop()
    printed = capsys.readouterr()
    assert remover.error is None, remover.error
    assert remover.removed is not None, 'no worker node was seen running a simulation'
    assert code == 0, printed.err
    assert len(c.worker_nodes) == 1
    on_ray, data = _search_results(tmp_path / 'ray')
    assert on_ray == local                       # every simulation's result, nothing lost
    reran = data['samplers']['cross_entropy']['reran_sims']
    assert remover.most_at_once == 1 and len(reran) == 1
    lines = [ln for ln in printed.out.splitlines() if 'ran again' in ln]
    assert len(lines) == 1 and f'(sims {reran})' in lines[0]
    print(f'failure search with a node removed: {lines[0]}')
