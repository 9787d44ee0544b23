"""The three per-odom outputs every guidance-type node publishes (guidance_node, follower_node).

Exactly one message on each of these topics per odom message, so lockstep consumers pair by
sequence (doc/design.md); QoS ship_sim.ros.qos.STREAM, heading_cmd STREAM_KEPT (colav_node's
heading_ref subscription must get step 0's command however late it matched):
  heading_cmd        std_msgs/Float64  ENU yaw command (rad)
  cross_track_error  std_msgs/Float64  m, positive when the vessel is to starboard of the path
  progress           std_msgs/Float64MultiArray  [s (m), distance remaining (m), leg index,
                     finished (0/1), path angle (ENU yaw, rad), curvature (1/m, + = port turn)]
The messages are made once and reused. ``publish_route`` converts a guidance.GuidanceOutput
(NED) into these; ``repeat`` sends the previous values again (an odom that had to be refused
still gets its answer, so the pairing holds).
"""
import math

from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension

from ship_sim.frames import psi_to_yaw
from ship_sim.ros.held_start import held_publisher
from ship_sim.ros.qos import STREAM, STREAM_KEPT

PROGRESS_LABELS = ('s_m', 'remaining_m', 'leg', 'finished', 'path_yaw_rad', 'curvature_1pm')


def progress_values(out):
    """GuidanceOutput (NED) -> the progress array (ENU path yaw, curvature + = port turn)."""
    return [out.s, out.distance_remaining, float(out.leg_index), float(out.finished),
            float(psi_to_yaw(out.path_angle)), -out.curvature]


class GuidancePublishers:
    """Publishers and reused messages of heading_cmd, cross_track_error and progress."""

    def __init__(self, node, qos=STREAM, readers=('',)):
        # readers (lockstep, from the graph): heading_cmd's first messages wait until the node
        # that pairs them (the autopilot, or colav_node on heading_ref) and the recorder matched
        self.pub_heading = held_publisher(
            node, node.create_publisher(Float64, 'heading_cmd', STREAM_KEPT if qos is STREAM else qos),
            readers)
        self.pub_xte = node.create_publisher(Float64, 'cross_track_error', qos)
        self.pub_progress = node.create_publisher(Float64MultiArray, 'progress', qos)
        self.m_heading, self.m_xte = Float64(), Float64()
        self.m_progress = Float64MultiArray()
        self.m_progress.layout.dim = [MultiArrayDimension(label=','.join(PROGRESS_LABELS),
                                                          size=len(PROGRESS_LABELS), stride=1)]

    def publish(self, yaw_cmd, xte, progress):
        """Publish an ENU yaw command (rad; a non-finite one becomes 0), cross-track (m) and
        the progress array."""
        self.m_heading.data = yaw_cmd if math.isfinite(yaw_cmd) else 0.0
        self.m_xte.data = xte
        self.m_progress.data = list(progress)
        self.pub_heading.publish(self.m_heading)
        self.pub_xte.publish(self.m_xte)
        self.pub_progress.publish(self.m_progress)

    def publish_route(self, out, heading_cmd=None):
        """Publish from a GuidanceOutput; ``heading_cmd`` (NED, rad) overrides its command."""
        psi_c = out.heading_cmd if heading_cmd is None else heading_cmd
        self.publish(float(psi_to_yaw(psi_c)), out.cross_track, progress_values(out))

    def repeat(self):
        """Send the previous values again."""
        self.publish(self.m_heading.data, self.m_xte.data, self.m_progress.data)
