"""ship_mission.bag_recovery: a bag whose recorder was killed, or whose file was cut short, is read
back up to its torn end, and its integrity report says what is lost, never "complete"."""
import math
import os
import shutil
import struct

import pytest
from mcap.reader import make_reader
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from rosbags.highlevel import AnyReader

from ship_mission.bag import read_bag, read_custom_data
from ship_mission.bag_check import cross_check
from ship_mission.bag_recovery import RecoveryError, needs_recovery, recover_bag, scan
from ship_mission.integrity import record_integrity, summary_line
from ship_mission.recorder import COMPRESSIONS, BagWriter

FLOAT64 = 'std_msgs/msg/Float64'


def float64(x):
    return b'\x00\x01\x00\x00' + struct.pack('<d', x)


def killed_bag(tmp_path, n=5000, flush_every=1000, compression='zstd'):
    """A bag as a SIGKILLed recorder leaves it: flushed chunks, no summary, no metadata.yaml."""
    bag = tmp_path / 'bag'
    w = BagWriter(bag, custom_data={'mission.time_source': 'wall'}, compression=compression)
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


@pytest.mark.parametrize('compression', COMPRESSIONS)
def test_every_flushed_message_comes_back_in_order(tmp_path, compression):
    bag, _ = killed_bag(tmp_path, n=5000, flush_every=1000, compression=compression)
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
    assert cross_check(bag)['compressions'] == {'' if compression == 'none' else compression}


def test_a_torn_last_chunk_is_dropped_and_the_rest_kept(tmp_path):
    bag, sizes = killed_bag(tmp_path, n=3000, flush_every=1000)
    mcap = next(bag.glob('*.mcap'))
    data = mcap.read_bytes()
    mcap.write_bytes(data[:sizes[2] + 100])   # the kill tore the third chunk
    schemas, channels, messages, _stop = scan(mcap)
    assert len(messages) == 2000 and len(channels) == 2
    recover_bag(bag)
    with AnyReader([bag]) as reader:
        assert sum(c.msgcount for c in reader.connections) == 2000


def test_not_an_mcap_file(tmp_path):
    (tmp_path / 'bag').mkdir()
    (tmp_path / 'bag' / 'bag.mcap').write_bytes(b'garbage')
    with pytest.raises(RecoveryError, match='not an MCAP file'):
        recover_bag(tmp_path / 'bag')


STEPS = 3000
STEP_NS = 100_000_000
PER_STEP = ('/clock', '/vessel_0/odom', '/vessel_0/rudder', '/vessel_0/rudder_cmd')


def odometry(t_ns, x):
    o = Odometry()
    o.header.stamp.sec, o.header.stamp.nanosec = divmod(t_ns, 10**9)
    o.header.frame_id, o.child_frame_id = 'map', 'vessel_0/base_link'
    o.pose.pose.position.x, o.pose.pose.orientation.w = x, 1.0
    return serialize_message(o)


@pytest.fixture(scope='module')
def recorded(tmp_path_factory):
    """A complete lockstep-like bag (zstd chunks, flushed every 150 steps as the recorder's
    periodic flush does) -> its directory."""
    bag = tmp_path_factory.mktemp('rec') / 'bag'
    with BagWriter(bag, custom_data={'mission.time_source': 'sim'}) as w:
        clock = w.add_topic('/clock', 'rosgraph_msgs/msg/Clock')
        odom = w.add_topic('/vessel_0/odom', 'nav_msgs/msg/Odometry')
        rudder = w.add_topic('/vessel_0/rudder', FLOAT64)
        cmd = w.add_topic('/vessel_0/rudder_cmd', FLOAT64)
        for k in range(STEPS):
            t = k * STEP_NS
            w.write(clock, t, b'\x00\x01\x00\x00' + struct.pack('<iI', *divmod(t, 10**9)))
            w.write(odom, t, odometry(t, 0.77 * k))
            w.write(rudder, t, float64(math.sin(k / 40)))
            w.write(cmd, t, float64(math.sin(k / 40 + 0.1)))
            if k % 150 == 149:
                w.flush()
    return bag


def steps_before(mcap_path, cut):
    """Steps whose chunk lies wholly before byte ``cut``, from the complete file's own chunk
    index (each step is in one chunk: the flushes fall between steps)."""
    with open(mcap_path, 'rb') as f:
        chunks = make_reader(f).get_summary().chunk_indexes
    ends = [c.message_end_time for c in chunks if c.chunk_start_offset + c.chunk_length <= cut]
    return max(ends) // STEP_NS + 1 if ends else 0


def cut_copy(recorded, tmp_path, fraction, keep_metadata):
    bag = tmp_path / 'bag'
    shutil.copytree(recorded, bag)
    mcap = bag / 'bag.mcap'
    data = mcap.read_bytes()
    cut = int(len(data) * fraction)
    mcap.write_bytes(data[:cut])
    if not keep_metadata:
        (bag / 'metadata.yaml').unlink()
    return bag, steps_before(recorded / 'bag.mcap', cut)


def test_a_complete_bag_needs_no_recovery(recorded):
    assert not needs_recovery(recorded)
    assert cross_check(recorded)['problems'] == []


@pytest.mark.parametrize('fraction', [0.3, 0.55, 0.9])
@pytest.mark.parametrize('keep_metadata', [True, False], ids=['with metadata.yaml', 'without'])
def test_a_cut_bag_is_recovered_and_says_exactly_what_is_lost(recorded, tmp_path, fraction, keep_metadata):
    bag, kept = cut_copy(recorded, tmp_path, fraction, keep_metadata)
    assert 0 < kept < STEPS
    assert needs_recovery(bag)   # with metadata.yaml too: its summary is gone (issue 24)
    data = read_bag(bag)
    v = data.vessels['/vessel_0']
    assert len(v.t) == kept and len(v.rudder.t) == kept and len(data.clock) == kept
    assert v.t[-1] == pytest.approx((kept - 1) * STEP_NS / 1e9)
    assert cross_check(bag)['problems'] == []   # the rewritten bag reads in both readers
    report = record_integrity(data)
    line = summary_line(report)
    assert not report['complete'] and 'record complete' not in line
    assert 'INCOMPLETE' in line and f'ends at {(kept - 1) * 0.1:.1f} s' in line
    assert report['recovered']['end_s'] == pytest.approx((kept - 1) * STEP_NS / 1e9)
    if keep_metadata:
        assert report['recovered']['lost'] == {t: [kept, STEPS - kept] for t in PER_STEP}
        assert report['recovered']['lost_steps'] == {'/vessel_0': STEPS - kept}
        assert report['missing'] == len(PER_STEP) * (STEPS - kept)
        assert f'/vessel_0 {STEPS - kept} odom steps' in line
        assert f'/vessel_0/odom {STEPS - kept} of {STEPS}' in data.recovered
    else:
        assert report['recovered']['lost'] is None and 'not known' in line
        assert 'not known' in data.recovered
    # read again later (replay_bag): still recovered, still incomplete
    again = read_bag(bag)
    assert again.recovered == data.recovered
    assert summary_line(record_integrity(again)) == line
