"""QoS profiles shared by every node (DESIGN.md), so publishers and subscribers always match.

- STREAM: odom, rudder, rudder_cmd, heading_cmd, cross_track_error, progress. Reliable so that
  lockstep pairing by sequence never loses a message; keep-last depth far above the one or two
  messages ever in flight per topic in lockstep.
- LATCHED: route (and other state that late joiners must get): reliable + transient_local,
  depth 1, on both ends (a mismatch fails silently in DDS).
"""
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

STREAM = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                    reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)

LATCHED = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                     reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
