"""mission.recorder.BagWriter writes bags as Jazzy's rosbag2 does, and fails cleanly."""
import errno
import struct

import pytest
import yaml
from rosbags.highlevel import AnyReader

from mission.recorder import BagWriter

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
    mcap = next(bag.glob('*.mcap')).read_bytes()
    # channel metadata map: ... 'topic_type_hash' -> the same hash (in the chunk and the summary)
    assert mcap.count(b'topic_type_hash') == 2 and mcap.count(digest.encode()) >= 2
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
