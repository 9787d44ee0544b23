"""QoS profiles shared by every node (doc/design.md), so publishers and subscribers always match.

- STREAM: odom, rudder, rudder_cmd, heading_cmd, cross_track_error, progress. Reliable so that
  lockstep pairing by sequence never loses a message; keep-last depth far above the one or two
  messages ever in flight per topic in lockstep.
- LATCHED: route (and other state that late joiners must get): reliable + transient_local,
  depth 1, on both ends (a mismatch fails silently in DDS).
- DISPLAY: odom_display (vessel_node's every n-th odom, nav_display_node's input). Reliable +
  transient_local with DISPLAY_DEPTH messages kept: a display that subscribes late or falls
  behind still gets every frame from step 0 (its frames are then the same on every run), and
  nobody waits for it (keep-last never blocks the publisher).
- CLOCK (vessel_node's /clock as clock master) and CLOCK_STEPS (nodes that act on every /clock
  step: traffic_node, ais_node with publish_on_clock): reliable + transient_local. In lockstep
  such a node must hear step 0, but a new publisher and an existing subscription match whenever
  discovery gets to it, which can be after step 0 has gone out on a loaded machine; a
  transient_local subscription that matches late gets the steps it missed from the publisher's
  history. rclpy's own (best-effort, volatile) /clock subscriptions match CLOCK as before; a
  CLOCK_STEPS subscription needs a transient_local /clock publisher.
- RECORD_ACK: the recorder's per-vessel acknowledgements (ship_mission.recorder -> vessel_node in
  lockstep). Reliable + transient_local: the recorder sends its first one as soon as it has
  matched the simulator's publishers, which can be before the simulator's subscription has
  matched the recorder's; volatile, that first one was lost, nothing else came before step 0
  and the simulator waited its whole lockstep_start_timeout (30 s). The values are cumulative,
  so the ones a late subscription gets from the history do no harm.
"""
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

STREAM = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                    reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)


def stream_with_depth(depth):
    """STREAM with a deeper keep-last queue, for a subscriber fed faster than it may take
    messages (the depth does not take part in QoS matching)."""
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=int(depth),
                      reliability=STREAM.reliability, durability=STREAM.durability)


#: STREAM kept for late joiners (transient_local): a link between two of our own nodes that no
#: one gates on, where a subscription matched after the first messages went out would lose them
#: and pair every later message with the wrong step (guidance's heading_cmd -> colav_node's
#: heading_ref). A transient_local publisher also serves volatile subscriptions (the autopilot,
#: `ros2 topic echo`); a transient_local subscription needs a transient_local publisher.
STREAM_KEPT = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=STREAM.depth,
                         reliability=STREAM.reliability,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)

LATCHED = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                     reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)

#: Frames odom_display keeps for a late or slow display: 500 s of sim time at 2 frames per second.
DISPLAY_DEPTH = 1000

DISPLAY = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=DISPLAY_DEPTH,
                     reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)

#: Clock steps kept on both ends of /clock: 100 s of sim time at dt 0.1 s. traffic_node and a
#: lockstep ais_node act on every step but nobody waits for them when no colav_node listens, so
#: while one is descheduled on a loaded machine the simulator runs on. Reliable keep-last drops
#: the oldest unacknowledged sample once the writer's history is full: at depth 10 (0.15 s of
#: wall time at 7x real time) traffic_node skipped steps under test load and its targets' odometry
#: jumped. Clock messages are a few bytes; a late transient_local joiner replays what is kept.
CLOCK_DEPTH = 1000

CLOCK = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=CLOCK_DEPTH,
                   reliability=ReliabilityPolicy.RELIABLE,
                   durability=DurabilityPolicy.TRANSIENT_LOCAL)

CLOCK_STEPS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=CLOCK_DEPTH,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)

#: The graph's readiness announcements (ship_sim.ros.readiness.READY_TOPIC): reliable +
#: transient_local, so a late subscriber still gets each node's one announcement, and deep: the
#: topic has no key, so a subscription keeps one history for every writer, and with depth 1 an
#: announcement arriving before the previous one was taken replaced it (seen: the launcher
#: missed traffic_node's because ais_node's came right after).
READY = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                   reliability=ReliabilityPolicy.RELIABLE,
                   durability=DurabilityPolicy.TRANSIENT_LOCAL)

RECORD_ACK = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                        reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.TRANSIENT_LOCAL)
