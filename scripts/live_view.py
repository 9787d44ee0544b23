#!/usr/bin/env python3
"""Serve a running graph's topics to Foxglove / Lichtblick: `scripts/live_view.py [--port N]`.

A Foxglove WebSocket server (foxglove-sdk) on 127.0.0.1 (``--host`` to change) that advertises
every topic of the graph in this ROS_DOMAIN_ID (or the ``--topics`` given) with its ROS 2
schema and forwards the CDR messages untouched (ship_mission.live_bridge), plus ``/tf`` from every
vessel's odom. Clients reach it through ship_mission.live_front, which also accepts the protocol's
old subprotocol name ``foxglove.websocket.v1`` (older Foxglove and Lichtblick releases, the
``@foxglove/ws-protocol`` client). Open it in Foxglove or
Lichtblick with "Open connection" -> "Foxglove WebSocket" -> ws://127.0.0.1:8765, then import
the layout scripts/live_view_layout.json. `scripts/run_mission.py --live` starts it with the
run. Once serving it runs at a low CPU priority (``--nice``): on a busy machine the graph goes
first and the view loses messages instead (counted). Prints ``live view: ws://HOST:PORT`` once
serving, a status line every ``--status-period`` seconds while clients listen, and the totals
at exit. Exit code 0 on Ctrl-C / SIGTERM, 2 for
bad options, 1 if the port cannot be bound.
"""
import argparse
import os
import sys
import time

from ship_mission.live_bridge import LiveBridge
from ship_mission.live_front import SubprotocolFront
from ship_mission.recorder import DEFAULT_EXCLUDE


def lower_priority(n):
    """Nice this process by ``n``. With the kernel's autogroup scheduling (on by default) a
    nice value only ranks a process within its session, and the launcher starts every process
    in its own session, so the session's autogroup is niced too when this process leads it (a
    shell's session, when started by hand, is left alone)."""
    os.nice(n)
    if os.getsid(0) == os.getpid():
        try:
            with open('/proc/self/autogroup', 'w') as f:
                f.write(str(n))
        except OSError:
            pass


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--port', type=int, default=8765, help='TCP port (0: any free one)')
    ap.add_argument('--host', default='127.0.0.1', help='address to bind (default 127.0.0.1)')
    ap.add_argument('--topics', nargs='*', default=None, help='absolute topic names (default: '
                    'every topic discovered)')
    ap.add_argument('--exclude', default=DEFAULT_EXCLUDE, help='regex of topics not to serve')
    ap.add_argument('--depth', type=int, default=10, help='queue depth of each subscription')
    ap.add_argument('--backlog', type=int, default=256, help='messages queued per client (the '
                    'oldest is dropped when a client reads too slowly)')
    ap.add_argument('--wait-ready', nargs='*', default=[], metavar='TOPIC',
                    help='latched std_msgs/Bool topics that must all be true before anything '
                         'is subscribed (the launcher: every vessel\'s ready)')
    ap.add_argument('--early', nargs='*', default=[], metavar='TOPIC',
                    help='topics subscribed before --wait-ready is true: once a client listens, '
                         'else 1 s after they appear (the launcher, in lockstep: every vessel\'s '
                         'odom, whose simulator waits for the view too)')
    ap.add_argument('--status-period', type=float, default=10.0, help='s between status lines')
    ap.add_argument('--nice', type=int, default=10, help='CPU niceness added once serving '
                    '(default 10: the graph first; a starved bridge loses messages, counted)')
    args, ros_argv = ap.parse_known_args(argv)
    if not 0 <= args.port <= 65535:
        ap.error(f'--port must be in 0..65535, got {args.port}')
    if args.depth < 1 or args.backlog < 1:
        ap.error('--depth and --backlog must be >= 1')

    import foxglove
    import rclpy
    from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor

    context = foxglove.Context()
    # The sdk's server on a free loopback port, behind the front that clients reach
    # (ship_mission.live_front: the protocol's old name, subscriptions right after an advertisement).
    try:
        server = foxglove.start_server(name='shipnav', host='127.0.0.1', port=0,
                                       capabilities=[foxglove.Capability.Time],
                                       supported_encodings=['cdr'], context=context,
                                       message_backlog_size=args.backlog)
        front = SubprotocolFront(args.host, args.port, f'ws://127.0.0.1:{server.port}')
    except Exception as exc:  # noqa: BLE001 - the sdk raises its own error types
        print(f'live_view: cannot serve on {args.host}:{args.port}: {exc}', file=sys.stderr)
        return 1
    rclpy.init(args=[sys.argv[0], *ros_argv])
    node = rclpy.create_node('live_view')
    bridge = LiveBridge(node, context, topics=args.topics, exclude=args.exclude,
                        depth=args.depth, wait_ready=args.wait_ready, early=args.early)
    bridge.server = server
    lower_priority(max(0, args.nice))   # after the start-up, which would crawl at a low priority
    print(f'live view: ws://{args.host}:{front.port}', flush=True)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    last_status, last_line = time.monotonic(), None
    try:
        while rclpy.ok():
            executor.spin_once(timeout_sec=0.1)
            now = time.monotonic()
            if now - last_status >= args.status_period:
                last_status = now
                line = bridge.summary()
                if line != last_line and bridge.subs:
                    print(f'live view: {line}', flush=True)
                last_line = line
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        print(f'live view: {bridge.summary()}', flush=True)
        front.close()
        server.stop()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
