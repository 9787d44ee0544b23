"""mission.bag_recovery: a bag whose recorder was killed is read back up to its torn end."""
import os
import shutil
import struct

import pytest
from rosbags.highlevel import AnyReader

from mission.bag import read_custom_data
from mission.bag_recovery import RecoveryError, needs_recovery, recover_bag, scan
from mission.recorder import BagWriter

FLOAT64 = 'std_msgs/msg/Float64'


def float64(x):
    return b'\x00\x01\x00\x00' + struct.pack('<d', x)


def killed_bag(tmp_path, n=5000, flush_every=1000):
    """A bag as a SIGKILLed recorder leaves it: flushed chunks, no summary, no metadata.yaml."""
    bag = tmp_path / 'bag'
    w = BagWriter(bag, custom_data={'mission.time_source': 'wall'})
    a = w.add_topic('/a', FLOAT64)
    w.add_topic('/b', 'nav_msgs/msg/Odometry')   # declared, never written
    sizes = []
    for i in range(n):
        w.write(a, i * 1000, float64(float(i)))
        if (i + 1) % flush_every == 0:
            sizes.append(w._writer.storage.bio.tell())   # file size after each flushed chunk
            w.flush()
    w._writer.storage.bio.flush()   # what the OS has when the process dies
    mcap = next(bag.glob('*.mcap'))
    shutil.copy(mcap, tmp_path / 'copy.mcap')   # the file as it is on disk at the kill
    w.close()
    os.replace(tmp_path / 'copy.mcap', mcap)
    (bag / 'metadata.yaml').unlink()
    return bag, sizes


def test_every_flushed_message_comes_back_in_order(tmp_path):
    bag, _ = killed_bag(tmp_path, n=5000, flush_every=1000)
    assert needs_recovery(bag)
    line = recover_bag(bag)
    assert 'recovered' in line and '5000 messages' in line
    assert not needs_recovery(bag)
    with AnyReader([bag]) as reader:
        got = [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages()]
        topics = {c.topic: c.msgtype for c in reader.connections}
    assert [g[2] for g in got] == [float64(float(i)) for i in range(5000)]
    assert [g[1] for g in got] == [i * 1000 for i in range(5000)]
    assert topics == {'/a': FLOAT64, '/b': 'nav_msgs/msg/Odometry'}  # types and empty topics too
    assert read_custom_data(bag)['mission.time_source'] == 'wall'
    assert any(p.name.endswith('.mcap.partial') for p in bag.iterdir())


def test_a_torn_last_chunk_is_dropped_and_the_rest_kept(tmp_path):
    bag, sizes = killed_bag(tmp_path, n=3000, flush_every=1000)
    mcap = next(bag.glob('*.mcap'))
    data = mcap.read_bytes()
    mcap.write_bytes(data[:sizes[2] + 100])   # the kill tore the third chunk
    schemas, channels, messages = scan(mcap)
    assert len(messages) == 2000 and len(channels) == 2
    recover_bag(bag)
    with AnyReader([bag]) as reader:
        assert sum(c.msgcount for c in reader.connections) == 2000


def test_not_an_mcap_file(tmp_path):
    (tmp_path / 'bag').mkdir()
    (tmp_path / 'bag' / 'bag.mcap').write_bytes(b'garbage')
    with pytest.raises(RecoveryError, match='not an MCAP file'):
        recover_bag(tmp_path / 'bag')
