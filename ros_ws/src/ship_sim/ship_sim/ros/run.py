"""The main() of every node in the project (shape of ros2/demos jazzy demo_nodes_py talker.py).

    def main(args=None):
        return run_node(MyNode, args=args)

run_node initialises rclpy, builds the node, spins it, treats Ctrl-C / SIGTERM as a normal end,
and always destroys the node and shuts rclpy down. Signals: rclpy's own handlers are not
installed (their shutdown of the context lands at any moment, also inside a callback under load,
whose next publish then fails and the EventsExecutor logs a FATAL traceback). run_node's
handlers only take note while the node spins, and the spin loop ends between two callbacks
(at most SPIN_TIMEOUT_S later when idle); before that, while rclpy starts or the node is built,
a signal ends the start at once (KeyboardInterrupt), the way the launcher handles its own.
Once the spin is over (also when the node ended by itself, e.g. a lockstep run at max_steps),
a signal is only noted: the process is already ending, and a KeyboardInterrupt raised in its
teardown would end it killed by the signal instead of with its exit code. When run_process
returns, SIGINT and SIGTERM are ignored: at interpreter exit Python puts back the default action
of every signal with a Python handler (death by the signal, exit -2 for SIGINT) but leaves an
ignored one ignored, and rclpy's and DDS's clean-up there can take a while.
Exit codes:

- 0: normal end (signal, or the node finished on its own, see ``finish``);
- 2: invalid parameter at start: ONE line on stderr, ``<executable>: <message>``, where the
  message (ship_sim.ros.params.ParameterError) names the parameter, the value and what is
  allowed; a parameter given (``-p``, ``--params-file``) that the node does not declare is
  refused the same way (ship_sim.ros.params.check_overrides, naming the closest declared one);
- 2: invalid ROS arguments (``-p model:=``, ``-p dt``, an unreadable or malformed
  ``--params-file``, ``-r __ns:="bad ns"``, unknown ``--ros-args`` flags) or a node rcl cannot
  create: ONE line, ``<executable>: invalid ROS arguments: <rcl's reason>``, no traceback. rcl
  also logs its own "Failed to parse global arguments" line on stderr before refusing: what
  ``rclpy.init`` and the node's construction write to stderr is held back, shown when they
  succeed and dropped when they end in one of these refusals;
- the node's own code: a node that ends itself calls ``finish(node, code)``.

Executor: EventsExecutor (rclpy.experimental, Jazzy) by default; it spins the lockstep
vessel/echo loop several times faster than SingleThreadedExecutor (numbers in
doc/results/performance.md).
The environment variable SHIPNAV_EXECUTOR=single|events overrides the choice, for benchmarks.
"""
import contextlib
import os
import re
import signal
import sys
import tempfile

import rclpy
from rclpy._rclpy_pybind11 import RCLError, UnknownROSArgsError
from rclpy.exceptions import NameValidationException
from rclpy.exceptions import ParameterException as RclpyParameterException
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor

from ship_sim.allocator import tune_allocator
from .params import ParameterError, check_overrides

EXECUTORS = ('events', 'single')
#: Longest wait of one spin_once: bounds how long a stop signal waits for an idle node.
SPIN_TIMEOUT_S = 0.1
#: Names of the stop signals received (SIGINT, SIGTERM) while the node spins.
_stop_signals = []
_spinning = False
#: Set once the spin is over: the teardown is not cut short by a signal.
_ending = False


def make_executor(kind=None, context=None):
    """An executor by name: 'events' (rclpy.experimental.EventsExecutor) or 'single'."""
    kind = kind or os.environ.get('SHIPNAV_EXECUTOR', 'events')
    if kind == 'events':
        from rclpy.experimental import EventsExecutor
        return EventsExecutor(context=context)
    if kind == 'single':
        return SingleThreadedExecutor(context=context)
    raise ValueError(f"executor {kind!r} is not allowed: one of {', '.join(EXECUTORS)}")


def finish(node, code=0):
    """End the spin of ``node`` from inside one of its callbacks; run_node returns ``code``.
    A node that shares its process and context with others (ship_mission.container sets its
    ``end_alone``) ends alone: the context stays up for the others."""
    node.exit_code = code
    end_alone = getattr(node, 'end_alone', None)
    if end_alone is not None:
        end_alone(code)
        return
    node.context.try_shutdown()


def stop_requested(node):
    """Whether the node should end: a stop signal came (noted, see the module docstring) or its
    context is shut down. A long callback (planner_node's planning) polls it to end early."""
    return bool(_stop_signals) or not node.context.ok()


def wait_for_acks(node, publishers, timeout_s=2.0):
    """Give reliable subscribers of ``publishers`` up to ``timeout_s`` each to acknowledge what
    was published, unless the context is shutting down (a signal that lands while we wait makes
    rcl refuse with "publisher's context is invalid": a normal end, not an error). None entries
    are skipped."""
    from rclpy.duration import Duration
    for pub in publishers:
        if pub is None or not node.context.ok() or _stop_signals:
            return
        try:
            pub.wait_for_all_acked(Duration(seconds=timeout_s))
        except RCLError:
            if node.context.ok():
                raise
            return


def spin(node, executor=None):
    """Spin ``node`` until its context shuts down (``finish``) or a stop signal came.

    The Jazzy (7.1.6) EventsExecutor's own spin() never runs timers and does not release the
    GIL while it waits (tested: a 10 ms timer never fires, other threads stall), while its
    spin_once() works, so we loop over spin_once. A stop signal is only noted by the handler
    (see the module docstring) and seen here between two callbacks: no callback is cut short
    and nothing publishes on a context that is gone.
    """
    ex = make_executor(executor, context=node.context)
    ex.add_node(node)
    ok = node.context.ok
    spin_once = ex.spin_once
    with spinning():
        while ok() and not _stop_signals:
            try:
                spin_once(timeout_sec=SPIN_TIMEOUT_S)
            except RCLError:
                # ``finish`` from inside a callback shuts the context down under a later
                # publish of the same callback: the normal end; anything else is a real error.
                if ok():
                    raise


@contextlib.contextmanager
def spinning():
    """While inside, a stop signal is only noted (``stop_signalled``), for a spin loop to see
    between two callbacks; outside, it ends the start at once (module docstring)."""
    global _spinning, _ending
    _spinning = True
    try:
        yield
    finally:
        _ending = True      # before the spin flag drops: no gap for a signal to raise in
        _spinning = False


def stop_signalled():
    """Whether a stop signal (SIGINT, SIGTERM) came: a spin loop's cue to end."""
    return bool(_stop_signals)


def _on_stop_signal(signum, frame):
    """SIGINT / SIGTERM: noted while spinning (``spin`` ends between callbacks); before that
    (rclpy starting, the node being built, e.g. blocked opening a file) the start ends now."""
    _stop_signals.append(signal.Signals(signum).name)
    if not (_spinning or _ending):
        raise KeyboardInterrupt(_stop_signals[-1])


def install_stop_handlers():
    """run_node's SIGINT and SIGTERM handlers (module docstring); rclpy's are not installed."""
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, _on_stop_signal)


#: rcl's source locations (``, at /project/src/rcl/arguments.c:352``) and empty reasons.
_RCL_NOISE = re.compile(r',? at \S+\.c:\d+|\s*Error: error not set,?|^failed to initialize rcl: ')


def rcl_reason(exc):
    """One line from an rclpy init / argument / node-creation exception: rcl's reason without
    its C source locations."""
    if isinstance(exc, UnknownROSArgsError):
        return f'unknown arguments {exc}'   # str() is the list of them
    text = ' '.join(str(exc).split())
    return _RCL_NOISE.sub('', text).strip(' .,') or type(exc).__name__


class _HeldStderr:
    """Hold back what goes to stderr (fd 2, where rcl and rclpy log) until ``release``: written
    out unchanged, or dropped when the step it covered ended in a one-line refusal."""

    def __init__(self):
        sys.stderr.flush()
        self._file = tempfile.TemporaryFile()
        self._saved = os.dup(2)
        os.dup2(self._file.fileno(), 2)

    def release(self, drop=False):
        if self._file is None:
            return
        sys.stderr.flush()
        os.dup2(self._saved, 2)
        os.close(self._saved)
        self._file.seek(0)
        text = self._file.read()
        self._file.close()
        self._file = None
        if text and not drop:
            os.write(2, text)


def _init(args):
    """rclpy.init; rcl logs 'Failed to parse global arguments' before it raises, that line is
    dropped (the caller prints the one line)."""
    from rclpy.signals import SignalHandlerOptions
    held = _HeldStderr()
    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except BaseException as exc:
        held.release(drop=isinstance(exc, (RCLError, UnknownROSArgsError)))
        raise
    held.release()


def build_node(node_factory):
    """The node, built and its parameters checked (check_overrides). rcl's and rclpy's errors
    of node creation become ParameterError; on any ParameterError the node's log output of its
    construction is dropped, so the refusal stays one line."""
    held = _HeldStderr()
    node = None
    try:
        try:
            node = node_factory()
        except (RCLError, NameValidationException) as exc:
            raise ParameterError(None, message=f'invalid ROS arguments: {rcl_reason(exc)}') \
                from None
        except RclpyParameterException as exc:
            # A parameter rclpy itself declares (use_sim_time) with a value of the wrong type.
            raise ParameterError(None, message=f'invalid parameter: {exc}') from None
        check_overrides(node)
    except BaseException as exc:
        if node is not None:
            node.destroy_node()
        held.release(drop=isinstance(exc, ParameterError))
        raise
    held.release()
    return node


def run_process(build, spin_it, destroy, exit_code, *, args=None, prog=None):
    """The frame of every node process (run_node; ship_mission.container's main): rclpy
    started, ``obj = build()`` built and ``spin_it(obj)`` spun, ``destroy(obj)`` and rclpy shut
    down on every way out; the exit codes of the module docstring, ``exit_code(obj)`` when it
    ends by itself. A ParameterError from ``build`` is the one line ``<prog>: <message>``."""
    global _ending
    tune_allocator()   # every node's hot loop (waves, SB-MPC) without mmap churn
    if prog is None:
        prog = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else 'node'
    install_stop_handlers()
    try:
        _init(args)
    except (RCLError, UnknownROSArgsError) as exc:
        print(f'{prog}: invalid ROS arguments: {rcl_reason(exc)}', file=sys.stderr, flush=True)
        rclpy.try_shutdown()
        ignore_stop_signals()
        return 2
    except KeyboardInterrupt:
        rclpy.try_shutdown()
        ignore_stop_signals()
        return 0
    obj = None
    code = 0
    try:
        obj = build()
        spin_it(obj)
    except ParameterError as exc:
        print(f'{prog}: {exc}', file=sys.stderr, flush=True)
        code = 2
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        _ending = True
        if obj is not None:
            destroy(obj)
        rclpy.try_shutdown()
        ignore_stop_signals()
    if obj is not None:
        code = exit_code(obj) or code
    return code


def ignore_stop_signals():
    """SIGINT and SIGTERM ignored from now on: the process is ending with its own code (module
    docstring); a stop signal in the interpreter's exit would otherwise kill it."""
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_IGN)


def run_node(node_factory, *, args=None, executor=None):
    """Build the node with ``node_factory()``, spin it until shutdown; return the exit code."""
    return run_process(lambda: build_node(node_factory), lambda node: spin(node, executor),
                       lambda node: node.destroy_node(),
                       lambda node: getattr(node, 'exit_code', 0), args=args)
