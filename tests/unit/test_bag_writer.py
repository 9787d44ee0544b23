"""ship_mission.recorder.BagWriter writes bags as Jazzy's rosbag2 does, and fails cleanly."""
import errno
import struct

import math

import pytest
import yaml
from builtin_interfaces.msg import Time
from mcap.records import Channel
from mcap.stream_reader import StreamReader
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore
from sensor_msgs.msg import NavSatFix
from std_msgs.msg import Float64
from visualization_msgs.msg import Marker, MarkerArray

from ship_mission.bag_check import cross_check
from ship_mission.recorder import (COMPRESSIONS, TF_TYPE, BagWriter, header_stamp_at, odometry_to_tf,
                              stamp_ns)

FLOAT64 = 'std_msgs/msg/Float64'


def float64(x):
    return b'\x00\x01\x00\x00' + struct.pack('<d', x)


def test_metadata_and_mcap_channels_carry_distro_and_type_hash(tmp_path):
    bag = tmp_path / 'bag'
    with BagWriter(bag) as w:
        conn = w.add_topic('/x', FLOAT64)
        for i in range(3):
            w.write(conn, i, float64(i))
    info = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert info['ros_distro'] == 'jazzy'
    digest = info['topics_with_message_count'][0]['topic_metadata']['type_description_hash']
    assert digest.startswith('RIHS01_') and len(digest) == 7 + 64
    # channel metadata map: ... 'topic_type_hash' -> the same hash (in the chunk and the summary)
    with open(next(bag.glob('*.mcap')), 'rb') as f:
        channels = [r for r in StreamReader(f).records if isinstance(r, Channel)]
    assert [c.metadata.get('topic_type_hash') for c in channels] == [digest, digest]
    with AnyReader([bag]) as reader:   # readers that do not know the key still read the bag
        assert [c.msgcount for c in reader.connections] == [3]


def test_a_write_error_stops_writing_and_is_kept(tmp_path):
    w = BagWriter(tmp_path / 'bag')
    conn = w.add_topic('/x', FLOAT64)
    w.write(conn, 0, float64(0.0))

    def full(*_):
        raise OSError(errno.ENOSPC, 'No space left on device')
    w._writer.write = full
    w.write(conn, 1, float64(1.0))
    w.write(conn, 2, float64(2.0))   # ignored: writing stopped at the first error
    assert w.error.errno == errno.ENOSPC
    w.close()                         # no exception
    assert w.closed and w.error.errno == errno.ENOSPC
    assert w.counts() == {'/x': 1}


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_both_storages_close(tmp_path, storage):
    with BagWriter(tmp_path / 'bag', storage=storage) as w:
        w.write(w.add_topic('/x', FLOAT64), 5, float64(1.5))
    assert yaml.safe_load((tmp_path / 'bag' / 'metadata.yaml').read_text())[
        'rosbag2_bagfile_information']['ros_distro'] == 'jazzy'


TS = get_typestore(Stores.ROS2_JAZZY)


def time_of(ns):
    return Time(sec=ns // 10**9, nanosec=ns % 10**9)


def odometry(ns, x, y, yaw, child='vessel_0/base_link'):
    """A serialized Odometry as the simulator sends it (rclpy's serializer, not rosbags')."""
    o = Odometry()
    o.header.stamp, o.header.frame_id, o.child_frame_id = time_of(ns), 'map', child
    o.pose.pose.position.x, o.pose.pose.position.y = x, y
    o.pose.pose.orientation.z, o.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    o.twist.twist.linear.x = 7.0
    return serialize_message(o)


def markers(ns, n):
    array = MarkerArray()
    for i in range(n):
        m = Marker(id=i)
        m.header.stamp, m.header.frame_id = time_of(ns), 'map'
        array.markers.append(m)
    return serialize_message(array)


def fix(ns):
    f = NavSatFix()
    f.header.stamp, f.latitude, f.longitude = time_of(ns), 59.9, 10.7
    return serialize_message(f)


@pytest.mark.parametrize('msgtype, data, expected', [
    ('nav_msgs/msg/Odometry', odometry(12_300_000_000, 1.0, 2.0, 0.3), 12_300_000_000),
    ('sensor_msgs/msg/NavSatFix', fix(4_500_000_001), 4_500_000_001),
    ('visualization_msgs/msg/MarkerArray', markers(7_000_000_000, 3), 7_000_000_000),
    ('visualization_msgs/msg/MarkerArray', markers(7_000_000_000, 0), None),   # nothing stamped
    ('std_msgs/msg/Float64', serialize_message(Float64(data=3.5)), None),       # no header
    ('nav_msgs/msg/Odometry', odometry(0, 1.0, 2.0, 0.3), 0),                   # step 0 of sim time
])
def test_header_stamps_are_found_where_the_type_has_them(msgtype, data, expected):
    assert stamp_ns(data, header_stamp_at(TS, msgtype)) == expected


def test_tf_from_odometry_carries_its_frames_stamp_and_pose():
    yaw = 0.7
    tf = TS.deserialize_cdr(odometry_to_tf(TS, odometry(3_200_000_000, 120.5, -40.25, yaw)), TF_TYPE)
    assert len(tf.transforms) == 1
    t = tf.transforms[0]
    assert (t.header.frame_id, t.child_frame_id) == ('map', 'vessel_0/base_link')
    assert (t.header.stamp.sec, t.header.stamp.nanosec) == (3, 200_000_000)
    assert (t.transform.translation.x, t.transform.translation.y) == (120.5, -40.25)
    q = t.transform.rotation
    assert math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y ** 2 + q.z ** 2)) == pytest.approx(yaw, abs=1e-12)
    assert header_stamp_at(TS, TF_TYPE) == 8   # a /tf message is logged at its transform's stamp


def write_sample(bag, compression, steps=3000):
    """A small recording: odom, its /tf, rudder, markers every 5th step; returns the counts."""
    with BagWriter(bag, compression=compression) as w:
        odom = w.add_topic('/vessel_0/odom', 'nav_msgs/msg/Odometry')
        tf = w.add_topic('/tf', TF_TYPE)
        rudder = w.add_topic('/vessel_0/rudder', FLOAT64)
        marks = w.add_topic('/vessel_0/nav_markers', 'visualization_msgs/msg/MarkerArray')
        for k in range(steps):
            t = (k + 1) * 100_000_000
            data = odometry(t, 7.0 * k * 0.1, 30.0 * math.sin(k / 300), k / 1000)
            w.write(odom, t, data)
            w.write(tf, t, odometry_to_tf(w.typestore, data))
            w.write(rudder, t, float64(0.01 * math.sin(k / 50)))
            if k % 5 == 0:
                w.write(marks, t, markers(t, 2))
            if k % 700 == 699:
                w.flush()   # several chunks, as the recorder's periodic flush makes
        return w.counts()


@pytest.mark.parametrize('compression', COMPRESSIONS)
def test_two_independent_readers_decode_every_message_of_each_compression(tmp_path, compression):
    counts = write_sample(tmp_path / 'bag', compression)
    check = cross_check(tmp_path / 'bag')
    assert check['problems'] == []
    assert check['metadata'] == counts and sum(counts.values()) > 0
    assert check['compressions'] == {'' if compression == 'none' else compression}
    info = yaml.safe_load((tmp_path / 'bag' / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    # rosbag2 Jazzy's metadata for MCAP chunk compression: no file or message compression
    assert (info['compression_format'], info['compression_mode']) == ('', '')
    tf = next(t for t in info['topics_with_message_count'] if t['topic_metadata']['name'] == '/tf')
    assert tf['topic_metadata']['type'] == TF_TYPE
    assert tf['topic_metadata']['type_description_hash'] == TS.hash_rihs01(TF_TYPE)


def test_compressed_chunks_are_smaller_and_zstd_is_the_default(tmp_path):
    sizes = {}
    for c in COMPRESSIONS:
        write_sample(tmp_path / c, c)
        sizes[c] = (tmp_path / c / f'{c}.mcap').stat().st_size
    assert sizes['zstd'] < sizes['lz4'] < sizes['none']
    with BagWriter(tmp_path / 'default') as w:
        assert w.compression == 'zstd'


def test_an_unknown_compression_is_refused(tmp_path):
    with pytest.raises(ValueError, match='compression must be one of none, lz4, zstd'):
        BagWriter(tmp_path / 'bag', compression='gzip')
