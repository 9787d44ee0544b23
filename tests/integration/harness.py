"""Integration-test harness: real node processes from the colcon install tree, a test node.

The shape of ros2/examples' launch_testing examples (start processes, wait for topics or output
lines with timeouts, check while they run, check exit codes after shutdown), written as plain
pytest fixtures because there is no launch_testing wheel here:

- every test gets its own ROS_DOMAIN_ID (1..101, never 0, unique among this user's graphs
  through a lock file per id, starting at an offset from the pid) and Fast DDS on the loopback
  interface only (ship_mission.processes.LOOPBACK_PROFILE, unicast discovery on 127.0.0.1), so
  parallel tests and other graphs never see each other;
- nodes run as ``ros2 run`` would run them: ``ros_ws/install/<pkg>/lib/<pkg>/<exe>`` with the
  environment ``install/setup.bash`` would set (AMENT_PREFIX_PATH, PYTHONPATH, ... computed
  here from colcon's .dsv hook files, not by sourcing bash), arguments
  ``--ros-args -r __ns:=/vessel_0 -p name:=value ...``; stdout and stderr go to files;
- a test rclpy node (own Context on the test's domain) publishes and subscribes, with
  deadline-based helpers (spin_until, wait_for_message, wait_for_subscribers);
- teardown ALWAYS ends every process it started: SIGINT, then SIGTERM, then SIGKILL of the
  process group, each after a timeout; it records exit codes and prints each process's exit
  code and stderr tail (pytest shows them when a test fails). Children also get SIGTERM from
  the kernel if the test process dies (PR_SET_PDEATHSIG), so nothing is orphaned.

Usage (fixture ``ros_graph`` from conftest.py)::

    def test_x(ros_graph):
        sim = ros_graph.start('ship_sim', 'vessel_node', namespace='/vessel_0',
                              params={'model': 'mariner', 'speedup': 20.0})
        tn = ros_graph.test_node()
        odom = tn.subscribe('/vessel_0/odom', Odometry)
        assert tn.wait_for_message(odom, timeout=10.0) is not None
        assert ros_graph.stop(sim) == 0
"""
import json
import os
import re
import signal
import subprocess
import time
from pathlib import Path

import rclpy
import yaml
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor

from ship_mission.encounter import colav_messages
from ship_mission.processes import die_with_parent, executable, format_param
from ship_sim.ros.qos import STREAM

REPO_ROOT = Path(__file__).resolve().parents[2]
INSTALL = REPO_ROOT / 'ros_ws' / 'install'

# Teardown timeouts (s): SIGINT (normal end), then SIGTERM, then SIGKILL.
SIGINT_TIMEOUT = 5.0
SIGTERM_TIMEOUT = 3.0


# -- environment of the install tree --------------------------------------------------------

# install_env, executable and format_param live in ros_ws/src/ship_mission/ship_mission/processes.py (one place
# for the launcher, the benchmarks and the tests).


# -- domain ids ---------------------------------------------------------------------------------

# DomainLease (an exclusive ROS_DOMAIN_ID per test) is ship_mission.domain's, shared with the
# launcher, the seed-scenario batch and the benchmarks.


# -- node processes ------------------------------------------------------------------------------

_die_with_parent = die_with_parent  # SIGTERM when the test process dies (even by SIGKILL)


class NodeProcess:
    """One node executable started from the install tree; output in <label>.out / .err."""

    def __init__(self, package, name, *, env, log_dir, label, namespace=None, node_name=None,
                 params=None, params_file=None, remaps=None, extra_args=()):
        self.package, self.name, self.label = package, name, label
        self.cmd = [str(executable(package, name)), '--ros-args']
        if namespace:
            self.cmd += ['-r', f'__ns:={namespace}']
        if node_name:
            self.cmd += ['-r', f'__node:={node_name}']
        for src, dst in (remaps or {}).items():
            self.cmd += ['-r', f'{src}:={dst}']
        if params_file:
            self.cmd += ['--params-file', str(params_file)]
        for key, value in (params or {}).items():
            self.cmd += ['-p', f'{key}:={format_param(value)}']
        self.cmd += list(extra_args)
        self.out_path = Path(log_dir) / f'{label}.out'
        self.err_path = Path(log_dir) / f'{label}.err'
        with open(self.out_path, 'wb') as out, open(self.err_path, 'wb') as err:
            self.popen = subprocess.Popen(self.cmd, stdout=out, stderr=err, env=env,
                                          stdin=subprocess.DEVNULL, start_new_session=True,
                                          preexec_fn=_die_with_parent)
        self.started = time.monotonic()
        self.stopped_by = None   # None (exited by itself), 'SIGINT', 'SIGTERM' or 'SIGKILL'

    @property
    def pid(self):
        return self.popen.pid

    @property
    def returncode(self):
        return self.popen.poll()

    def stdout(self):
        return self.out_path.read_text(errors='replace')

    def stderr(self):
        return self.err_path.read_text(errors='replace')

    def output(self):
        return self.stdout() + self.stderr()

    def wait(self, timeout):
        """Exit code, or None if still running after ``timeout`` s."""
        try:
            return self.popen.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            return None

    def wait_for_output(self, pattern, timeout, stream='both'):
        """The first regex match in the output within ``timeout`` s, else None."""
        rx = re.compile(pattern)
        deadline = time.monotonic() + timeout
        read = {'both': self.output, 'stdout': self.stdout, 'stderr': self.stderr}[stream]
        while True:
            m = rx.search(read())
            if m or time.monotonic() > deadline:
                return m
            if self.returncode is not None:
                return rx.search(read())
            time.sleep(0.05)

    def stop(self, sigint_timeout=SIGINT_TIMEOUT, sigterm_timeout=SIGTERM_TIMEOUT):
        """End the process: SIGINT, then SIGTERM, then SIGKILL (group). Returns the exit code."""
        return stop_processes([self], sigint_timeout, sigterm_timeout)[0]

    def report(self, tail=15):
        lines = self.stderr().splitlines()[-tail:]
        how = f' (after {self.stopped_by})' if self.stopped_by else ''
        text = [f'--- {self.label}: pid {self.pid}, exit code {self.returncode}{how}',
                '    ' + ' '.join(self.cmd)]
        text += ['    | ' + line for line in lines]
        return '\n'.join(text)


def stop_processes(procs, sigint_timeout=SIGINT_TIMEOUT, sigterm_timeout=SIGTERM_TIMEOUT):
    """End NodeProcesses together: SIGINT to every one still running, then SIGTERM to those
    still running ``sigint_timeout`` s later, then SIGKILL of their groups after
    ``sigterm_timeout`` s more. Returns their exit codes, in order.

    Each signal goes to all before any is waited for: a node takes about a second to shut down
    under load, so a graph ended one node at a time takes seconds per node."""
    procs = list(procs)
    running = [p for p in procs if p.popen.poll() is None]
    for sig, timeout in ((signal.SIGINT, sigint_timeout), (signal.SIGTERM, sigterm_timeout)):
        signalled = []
        for p in running:
            try:
                p.popen.send_signal(sig)
                signalled.append(p)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + timeout
        for p in signalled:
            if p.wait(max(0.0, deadline - time.monotonic())) is not None:
                p.stopped_by = sig.name
        running = [p for p in running if p.popen.poll() is None]
        if not running:
            break
    for p in running:
        try:
            os.killpg(p.popen.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        p.stopped_by = 'SIGKILL'
        p.popen.wait()
    return [p.popen.returncode for p in procs]


# -- the test node -------------------------------------------------------------------------------

class Inbox:
    """Messages received on one subscription, with their wall receive times (monotonic)."""

    def __init__(self):
        self.messages = []
        self.times = []

    def __len__(self):
        return len(self.messages)

    def __getitem__(self, i):
        return self.messages[i]

    @property
    def last(self):
        return self.messages[-1] if self.messages else None

    def _add(self, msg):
        self.messages.append(msg)
        self.times.append(time.monotonic())


class TestNode:
    """An rclpy node in the test process, on the test's domain, spun on demand with deadlines."""

    def __init__(self, domain_id, name='test_node', executor='events'):
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain_id)
        self.node = rclpy.create_node(name, context=self.context)
        if executor == 'events':
            from rclpy.experimental import EventsExecutor
            self.executor = EventsExecutor(context=self.context)
        else:
            self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def subscribe(self, topic, msg_type, qos=STREAM, callback=None):
        """Subscribe; returns an Inbox that fills while spinning. ``callback(msg)`` too."""
        inbox = Inbox()

        def on_msg(msg):
            inbox._add(msg)
            if callback is not None:
                callback(msg)

        inbox.subscription = self.node.create_subscription(msg_type, topic, on_msg, qos)
        return inbox

    def unsubscribe(self, inbox):
        """Stop receiving on ``inbox`` (its messages stay)."""
        self.node.destroy_subscription(inbox.subscription)

    def publisher(self, topic, msg_type, qos=STREAM):
        return self.node.create_publisher(msg_type, topic, qos)

    def spin_once(self, timeout=0.05):
        self.executor.spin_once(timeout_sec=timeout)

    def spin_for(self, seconds):
        deadline = time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0.0:
            self.executor.spin_once(timeout_sec=min(left, 0.1))

    def spin_until(self, predicate, timeout, poll=0.1):
        """Spin until ``predicate()`` is true (returns True) or ``timeout`` s pass (False)."""
        deadline = time.monotonic() + timeout
        while not predicate():
            left = deadline - time.monotonic()
            if left <= 0.0:
                return False
            self.executor.spin_once(timeout_sec=min(left, poll))
        return True

    def wait_for_message(self, inbox, timeout, predicate=None, count=1):
        """The first message (after the ``count``-th) in ``inbox`` satisfying ``predicate``.

        Looks at messages already received too. None if none within ``timeout`` s.
        """
        state = {'i': 0}

        def found():
            msgs = inbox.messages
            while state['i'] < len(msgs):
                m = msgs[state['i']]
                state['i'] += 1
                if state['i'] >= count and (predicate is None or predicate(m)):
                    state['hit'] = m
                    return True
            return False

        return state['hit'] if self.spin_until(found, timeout) else None

    def wait_for_subscribers(self, publisher, n=1, timeout=10.0):
        return self.spin_until(lambda: publisher.get_subscription_count() >= n, timeout)

    def wait_for_publishers(self, inbox, n=1, timeout=10.0):
        return self.spin_until(lambda: inbox.subscription.get_publisher_count() >= n, timeout)

    def close(self):
        try:
            self.executor.shutdown()
        except Exception:  # noqa: BLE001 - teardown must go on
            pass
        self.node.destroy_node()
        self.context.try_shutdown()


# -- the graph of one test -----------------------------------------------------------------------

class RosGraph:
    """Processes and the test node of one test, on one domain; ``close`` ends everything."""

    def __init__(self, log_dir, domain_id, env):
        self.log_dir = Path(log_dir)
        self.domain_id = domain_id
        self.env = env
        self.processes = []
        self._test_node = None
        self._counts = {}

    def start(self, package, name, **kw):
        """Start ``package``'s executable ``name`` (see NodeProcess for the keywords; ``env``
        replaces the graph's environment for this process)."""
        n = self._counts[name] = self._counts.get(name, 0) + 1
        label = kw.pop('label', None) or (name if n == 1 else f'{name}_{n}')
        env = kw.pop('env', self.env)
        proc = NodeProcess(package, name, env=env, log_dir=self.log_dir, label=label, **kw)
        self.processes.append(proc)
        return proc

    def test_node(self, name='test_node', executor='events'):
        """The test's rclpy node (created on first use)."""
        if self._test_node is None:
            self._test_node = TestNode(self.domain_id, name, executor)
        return self._test_node

    def stop(self, proc, **kw):
        """Stop one process (SIGINT -> SIGTERM -> SIGKILL); its exit code."""
        return proc.stop(**kw)

    def stop_all(self):
        """Stop every process started, all at once (stop_processes; signalled newest first);
        {label: exit code}."""
        procs = self.processes[::-1]
        return dict(zip((p.label for p in procs), stop_processes(procs)))

    def report(self):
        return '\n'.join(p.report() for p in self.processes)

    def close(self):
        try:
            self.stop_all()
        finally:
            if self._test_node is not None:
                self._test_node.close()
                self._test_node = None
            if self.processes:
                print(f'\n[ros_graph domain {self.domain_id}, logs in {self.log_dir}]')
                print(self.report())


def run_to_duration(launch, scenario, wall_timeout_s=150.0):
    """Run ``scenario`` through the launcher (the ``launch`` fixture) to its duration, asserting
    a clean exit and that outcome; returns the run folder."""
    return _reached_duration(launch(scenario, '--wall-timeout', wall_timeout_s), wall_timeout_s)


def _reached_duration(run, wall_timeout_s):
    """The run folder of a started launch, once it exited cleanly at its duration."""
    assert run.wait(wall_timeout_s + 20.0) == 0, run.report()
    run_dir = run.run_dir()
    info = yaml.safe_load((run_dir / 'run.json').read_text())
    assert info['outcome'] == 'duration reached', info
    return run_dir


def run_complete(launch, scenario, duration_s, wall_timeout_s=240.0):
    """Run a lockstep ``scenario`` once through the launcher to ``duration_s`` and assert a
    clean exit at the duration and a complete record; returns (run folder, its metrics)."""
    return _completed(launch(scenario, *_duration_args(duration_s, wall_timeout_s)),
                      wall_timeout_s)


def _duration_args(duration_s, wall_timeout_s):
    return ('--wall-timeout', wall_timeout_s, '--duration', duration_s)


def _completed(run, wall_timeout_s):
    """(run folder, metrics) of a started launch, once it exited cleanly at its duration with a
    complete record."""
    folder = _reached_duration(run, wall_timeout_s)
    metrics = json.loads((folder / 'metrics.json').read_text())
    assert metrics['record']['complete'], metrics['record']
    return folder, metrics


#: A launcher's progress line once its sim clock has moved (ship_mission.console.progress_line).
_STEPPING = re.compile(r'^\s*t = +([0-9.]+) /', re.MULTILINE)


def wait_until_stepping(run, timeout):
    """Return once the launch ``run`` reports sim time past 0 (every node of its graph started
    and the lockstep under way), or it has exited, or ``timeout`` s passed (the caller's own
    checks of ``run`` then say what went wrong)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and run.popen.poll() is None:
        if any(float(t) > 0.0 for t in _STEPPING.findall(run.stdout())):
            return
        time.sleep(0.2)


def start_pair(start, timeout=120.0):
    """Two runs of one graph at the same time: ``start(own_domain)`` starts a launch (on the
    test's leased domain, then on one the second launcher leases itself); the second starts once
    the first is stepping. Returns both launches.

    A lockstep run is bound by message latency, not by CPU, so two at once take much less than
    two in turn, and the repeat is then made under the load of the other graph. The start-ups
    do not overlap: both graphs coming up at once once lost a light target's step-0 odom (colav
    then decided without it after 10 s, a known start-up race, doc/known_limits.md), which the
    repeat check must not trip on."""
    first = start(False)
    wait_until_stepping(first, timeout)
    return first, start(True)


def run_twice_complete(launch, scenario, duration_s, wall_timeout_s=240.0, colav_ns=None):
    """Run a lockstep ``scenario`` twice through the launcher (``start_pair``: at the same
    time, on two domains), each to ``duration_s`` (the launcher's ``--duration``), and assert
    what a repeat needs: both exits clean at the duration, both records complete, the two runs'
    ``vessels`` and ``traffic`` metrics equal and, with ``colav_ns``, that vessel's heading_cmd /
    colav_targets / colav_decision messages equal byte for byte. Returns (run folders, the
    first run's metrics, the first run's colav messages or None). Both launches are ended at
    the ``launch`` fixture's teardown, whatever fails."""
    args = _duration_args(duration_s, wall_timeout_s)
    pair = start_pair(lambda own_domain: launch(scenario, *args, own_domain=own_domain))
    runs, metrics = zip(*(_completed(run, wall_timeout_s) for run in pair))
    assert metrics[0]['vessels'] == metrics[1]['vessels']
    assert metrics[0].get('traffic') == metrics[1].get('traffic')
    if colav_ns is None:
        return runs, metrics[0], None
    msgs = [colav_messages(run / 'bag', colav_ns) for run in runs]
    for topic in ('heading_cmd', 'colav_targets', 'colav_decision'):
        assert msgs[0][topic] == msgs[1][topic], topic
    return runs, metrics[0], msgs[0]


def answer_each_odom(tn, namespace, command):
    """A lockstep controller in the test node: every odom of ``namespace`` is answered with a
    rudder_cmd of ``command(k)`` for its step k (the k-th odom, 0-based). Returns (odom Inbox,
    the rudder_cmd publisher)."""
    from nav_msgs.msg import Odometry
    from std_msgs.msg import Float64

    cmd = tn.publisher(f'{namespace}/rudder_cmd', Float64)
    out = Float64()

    def answer(msg):
        out.data = command(len(odom) - 1)   # this odom is step len(odom) - 1
        cmd.publish(out)

    odom = tn.subscribe(f'{namespace}/odom', Odometry, callback=answer)
    return odom, cmd
