"""Where the fields of a serialized nav_msgs/Odometry lie, for reading them without deserialising.

Two readers use this layout: ``conversions.odometry_to_ned`` (one message on a node's hot path,
with ``struct``) and ``ros_ws/src/ship_mission/ship_mission/bag.py`` (thousands of bag messages at once, with numpy).
The offset functions take plain ints or numpy integer arrays alike. No rclpy import here, so the
bag tools can use it without a ROS installation.

Encoding (OMG XCDR version 1, little endian, as rmw_fastrtps sends ROS 2 messages and rosbag2
stores them): a 4-byte encapsulation header 00 01 00 00, then the fields in declaration order,
each primitive aligned to its size counted from the end of that header, strings as a uint32
length (terminating NUL included) followed by the bytes. Offsets below are from the end of the
header:

    header.stamp        int32 sec @0, uint32 nanosec @4
    header.frame_id     uint32 length @8, chars
    child_frame_id      aligned to 4: uint32 length, chars
    pose.pose           aligned to 8: position x y z, orientation x y z w (7 float64)
    pose.covariance     36 float64
    twist.twist         linear x y z, angular x y z (6 float64)
    twist.covariance    36 float64
"""

#: Encapsulation identifier of XCDR1 little endian (the first two bytes of the message).
XCDR1_LE = b'\x00\x01'
HEADER_BYTES = 4
FRAME_ID_AT = 8
POSE_BYTES = 7 * 8
COVARIANCE_BYTES = 36 * 8
TWIST_BYTES = 6 * 8
#: Offsets relative to the pose's start.
TWIST_FROM_POSE = POSE_BYTES + COVARIANCE_BYTES
END_FROM_POSE = TWIST_FROM_POSE + TWIST_BYTES + COVARIANCE_BYTES


def align(offset, size):
    """``offset`` rounded up to a multiple of ``size`` (int or numpy integer array)."""
    return (offset + size - 1) // size * size


def child_frame_at(frame_id_length):
    """Offset of child_frame_id's length word, given header.frame_id's length word (NUL incl.)."""
    return align(FRAME_ID_AT + 4 + frame_id_length, 4)


def pose_at(child_at, child_frame_length):
    """Offset of pose.pose, given child_frame_id's offset and its length word."""
    return align(child_at + 4 + child_frame_length, 8)
