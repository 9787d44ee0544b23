"""The live bridge and a latched topic that subscribers named before its publisher existed.

Discovery lists a topic as soon as any endpoint names it: guidance subscribing to a vessel's
route makes the route a channel before the route node has started. A client that listens to
that channel then must still get the route the route node latches once, on its start: the
bridge may subscribe only once the topic has a publisher, with the QoS that publisher offers
(a volatile subscription made earlier would match the publisher only after its one message)."""
import time

import rclpy
from nav_msgs.msg import Path
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor

from ship_mission.foxglove_client import FoxgloveClient
from ship_mission.live_bridge import LiveBridge
from ship_mission.live_front import SubprotocolFront
from ship_sim.ros.qos import LATCHED

TOPIC = '/vessel_0/route'
TIMEOUT_S = 20.0


def _spin_until(executor, predicate, timeout):
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            return False
        executor.spin_once(timeout_sec=0.05)
    return True


def test_a_client_listening_before_the_route_node_starts_gets_the_latched_route(ros_graph):
    import foxglove
    tn = ros_graph.test_node(executor='single')
    tn.subscribe(TOPIC, Path, qos=LATCHED)          # guidance, before the route node
    context = foxglove.Context()
    server = foxglove.start_server(name='test', host='127.0.0.1', port=0,
                                   supported_encodings=['cdr'], context=context)
    # The client reaches the server through the live view's front, as every viewer does (the
    # sdk alone can refuse a subscription sent right after an advertisement: live_front).
    front = SubprotocolFront('127.0.0.1', 0, f'ws://127.0.0.1:{server.port}')
    bridge = LiveBridge(tn.node, context)
    bridge.server = server
    client = FoxgloveClient(f'ws://127.0.0.1:{front.port}', topics=[TOPIC],
                            connect_timeout_s=TIMEOUT_S)
    route_ctx = None
    try:
        assert _spin_until(tn.executor, lambda: TOPIC in bridge.channels
                           and bridge.channels[TOPIC][0].has_sinks(), TIMEOUT_S), \
            f'the client never subscribed {TOPIC}: advertised {sorted(bridge.channels)}'
        tn.spin_for(1.0)   # ten bridge updates with the client listening and no publisher
        # The route node: its own participant, publishing once, right after it starts.
        route_ctx = Context()
        rclpy.init(context=route_ctx, domain_id=ros_graph.domain_id)
        route_node = rclpy.create_node('route', context=route_ctx)
        route = Path()
        route.header.frame_id = 'map'
        route_node.create_publisher(Path, TOPIC, LATCHED).publish(route)
        route_exec = SingleThreadedExecutor(context=route_ctx)
        route_exec.add_node(route_node)

        def got_it():
            route_exec.spin_once(timeout_sec=0.0)
            return client.count(TOPIC) >= 1
        assert _spin_until(tn.executor, got_it, TIMEOUT_S), \
            f'no route reached the client in {TIMEOUT_S} s ({bridge.summary()})'
    finally:
        client.close()
        front.close()
        server.stop()
        if route_ctx is not None:
            route_ctx.try_shutdown()
