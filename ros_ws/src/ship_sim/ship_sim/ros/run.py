"""The main() of every node in the project (shape of ros2/demos jazzy demo_nodes_py talker.py).

    def main(args=None):
        return run_node(MyNode, args=args)

run_node initialises rclpy, builds the node, spins it, treats Ctrl-C / SIGTERM (rclpy's signal
handler shuts the context down; KeyboardInterrupt, ExternalShutdownException) as a normal end,
and always destroys the node and shuts rclpy down. Exit codes:

- 0: normal end (signal, or the node finished on its own, see ``finish``);
- 2: invalid parameter at start: ONE line on stderr, ``<executable>: <message>``, where the
  message (ship_sim.ros.params.ParameterError) names the parameter, the value and what is
  allowed;
- the node's own code: a node that ends itself calls ``finish(node, code)``.

Executor: EventsExecutor (rclpy.experimental, Jazzy) by default; it spins the lockstep
vessel/echo loop about three times faster than SingleThreadedExecutor (numbers in
ship_sim.vessel_node's docstring).
The environment variable SHIPNAV_EXECUTOR=single|events overrides the choice, for benchmarks.
"""
import os
import signal
import sys

import rclpy
from rclpy._rclpy_pybind11 import RCLError
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor

from .params import ParameterError

EXECUTORS = ('events', 'single')


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
    """End the spin of ``node`` from inside one of its callbacks; run_node returns ``code``."""
    node.exit_code = code
    node.context.try_shutdown()


def spin(node, executor=None):
    """Spin ``node`` until its context shuts down.

    The Jazzy (7.1.6) EventsExecutor's own spin() never runs timers and does not release the
    GIL while it waits (tested: a 10 ms timer never fires, other threads stall), while its
    spin_once() works, so we loop over spin_once. The timeout only bounds how long a wait may
    last; shutdown (signal, ``finish``) wakes the executor at once.
    """
    ex = make_executor(executor, context=node.context)
    ex.add_node(node)
    ok = node.context.ok
    spin_once = ex.spin_once
    while ok():
        try:
            spin_once(timeout_sec=1.0)
        except RCLError:
            # A shutdown (signal) that lands inside a callback invalidates the context under
            # a publish; that is the normal end, anything else is a real error.
            if ok():
                raise


def _ignore_signal(signum, frame):
    pass


def run_node(node_factory, *, args=None, executor=None):
    """Build the node with ``node_factory()``, spin it until shutdown; return the exit code."""
    prog = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else 'node'
    # Ctrl-C: rclpy's signal handler (installed by init, chaining to this one) shuts the
    # context down, which ends the spin loop. Without this no-op, Python would also raise
    # KeyboardInterrupt in whatever callback runs at that moment, and the EventsExecutor
    # reports that as a FATAL callback exception. Must be set before rclpy.init.
    signal.signal(signal.SIGINT, _ignore_signal)
    rclpy.init(args=args)
    node = None
    code = 0
    try:
        node = node_factory()
        spin(node, executor)
    except ParameterError as exc:
        print(f'{prog}: {exc}', file=sys.stderr, flush=True)
        code = 2
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    if node is not None:
        code = getattr(node, 'exit_code', 0) or code
    return code
