#!/usr/bin/env python3
"""Bare three-hop relay, the middleware floor of the lockstep loop (section ``lockstep``).

    relay_nodes.py sim --steps N   odom (nav_msgs/Odometry) out, rudder_cmd (Float64) in
    relay_nodes.py guidance        odom in -> heading_cmd (Float64) out
    relay_nodes.py autopilot       heading_cmd in -> rudder_cmd (Float64) out
    (plus --raw, and --ros-args, e.g. -r __ns:=/relay)

The lockstep graph's critical path with empty callbacks: the same message types, the same QoS
(ship_sim.ros.qos.STREAM) and the same executor and main loop (ship_sim.ros.run.run_node) as
vessel_node -> guidance_node -> autopilot_node -> vessel_node, and the same stepping rule as
the vessel node in lockstep: step 0 goes out once odom has a subscriber and rudder_cmd a
publisher (plus the vessel node's START_GRACE_S), each rudder_cmd releases the next odom, and
the run ends after step N is published (N round trips). The relays do no work: the sim relay
only writes the step's stamp into one reused Odometry; the others republish one reused Float64.
With ``--raw`` every subscription is created with raw=True, so nothing received is turned into
Python message objects (the true floor: an empty callback needs no content); without it rclpy
deserialises each message before the empty callback runs.

The sim relay prints one line ``RELAY_RESULT {json}`` at the end: steps, stepping_s (wall time,
time.monotonic, from publishing step 0 to publishing step N), t_step0_unix (time.time() when
step 0 went out, to measure start-up against) and startup_s (process start to step 0).
"""
import json
import sys
import time

T_PROCESS = time.monotonic()


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    role = argv[0] if argv else ''
    if role not in ('sim', 'guidance', 'autopilot'):
        print('usage: relay_nodes.py sim|guidance|autopilot [--steps N] [--ros-args ...]',
              file=sys.stderr)
        return 2
    steps = 1000
    if '--steps' in argv:
        steps = int(argv[argv.index('--steps') + 1])
    raw = '--raw' in argv

    from nav_msgs.msg import Odometry
    from rclpy.clock import Clock, ClockType
    from rclpy.node import Node
    from std_msgs.msg import Float64

    from ship_sim.ros.qos import STREAM
    from ship_sim.ros.run import finish, run_node
    from ship_sim.pacing import START_GRACE_S

    class SimRelay(Node):
        def __init__(self):
            super().__init__('relay_sim')
            self.pub = self.create_publisher(Odometry, 'odom', STREAM)
            self.sub = self.create_subscription(Float64, 'rudder_cmd', self.on_cmd, STREAM,
                                                raw=raw)
            self.msg = Odometry()
            self.k = 0
            self.matched_at = None
            self.t0 = None
            self.watch = self.create_timer(0.05, self.on_watch,
                                           clock=Clock(clock_type=ClockType.STEADY_TIME))

        def on_watch(self):
            if self.t0 is not None:
                return
            now = time.monotonic()
            if (self.matched_at is None and self.pub.get_subscription_count() > 0
                    and self.sub.get_publisher_count() > 0):
                self.matched_at = now
            if self.matched_at is not None and now - self.matched_at >= START_GRACE_S:
                self.destroy_timer(self.watch)
                self.t0_unix = time.time()
                self.t0 = time.monotonic()
                self.publish()
                print('RELAY_STEP0', flush=True)

        def publish(self):
            stamp = self.msg.header.stamp
            stamp.sec, stamp.nanosec = divmod(self.k * 100_000_000, 1_000_000_000)
            self.pub.publish(self.msg)

        def on_cmd(self, msg):
            if self.t0 is None:
                return
            self.k += 1
            self.publish()
            if self.k >= steps:
                wall = time.monotonic() - self.t0
                print('RELAY_RESULT ' + json.dumps({
                    'steps': self.k, 'stepping_s': wall, 't_step0_unix': self.t0_unix,
                    'startup_s': self.t0 - T_PROCESS}), flush=True)
                finish(self, 0)

    class Hop(Node):
        def __init__(self, name, in_type, in_topic, out_topic):
            super().__init__(name)
            self.out = Float64()
            self.pub = self.create_publisher(Float64, out_topic, STREAM)
            self.create_subscription(in_type, in_topic, self.on_msg, STREAM, raw=raw)

        def on_msg(self, msg):
            self.pub.publish(self.out)

    factories = {
        'sim': SimRelay,
        'guidance': lambda: Hop('relay_guidance', Odometry, 'odom', 'heading_cmd'),
        'autopilot': lambda: Hop('relay_autopilot', Float64, 'heading_cmd', 'rudder_cmd'),
    }
    ros_args = [a for a in argv[argv.index('--ros-args'):]] if '--ros-args' in argv else []
    return run_node(factories[role], args=[sys.argv[0], *ros_args])


if __name__ == '__main__':
    sys.exit(main())
