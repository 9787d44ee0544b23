"""ais_node as a real process under hostile input (issue 24).

1. A flood of multi-sentence first parts that never complete (100,000 datagrams over UDP, with
   every key a sender can make: talker, channel, sequence id, and ids outside 0-9): the node's
   resident memory grows by less than RSS_GROWTH_BOUND_KB and its `ais_counts` keep coming.
2. A FIFO as the replay file is refused in one line with exit code 2, without waiting for a
   writer.
3. SIGINT during a flood of valid position reports of 5000 ships: exit code 0, no traceback or
   FATAL line, and the new targets are logged in a few summary lines, not one line each.
"""
import os
import signal
import socket
import time
from functools import reduce

import pyais
import pytest
from std_msgs.msg import UInt64MultiArray

from ship_guidance.ais import MAX_PENDING_FRAGMENTS
from ship_guidance.ais_node import LOG_PERIOD_S
from ship_sim.geodetic import ned_to_geodetic

ORIGIN = (34.86, 128.73)
#: What 100 pending messages (the store's bound, a few kB) plus the allocator's and the DDS
#: layer's churn under a flood may cost: the unbounded store grew 187 MB for 200k first parts,
#: about 0.9 kB each, so 100k kept would be ~90 MB.
RSS_GROWTH_BOUND_KB = 20_000
#: ais_counts is published every PERIOD_S; a gap of this many periods means the node starved.
PERIOD_S = 0.5
MAX_GAP_S = 4 * PERIOD_S


def checksum(body):
    return '%02X' % reduce(lambda a, c: a ^ ord(c), body, 0)


def first_part(i):
    """The first of two parts of a message 5 whose second part never comes: keys cycle over
    talkers, channels and ids 0-9; every 10th has an id outside 0-9 (a fresh one each time)."""
    talker = ('AI', 'AB', 'BS', 'SA')[i % 4]
    channel = chr(ord('A') + (i // 4) % 26)
    seq = str(i % 10) if i % 10 else str(10 + i)
    body = f'{talker}VDM,2,1,{seq},{channel},5{"0" * 59},0'
    return f'!{body}*{checksum(body)}\r\n'.encode()


def rss_kb(pid):
    with open(f'/proc/{pid}/status') as f:
        for line in f:
            if line.startswith('VmRSS:'):
                return int(line.split()[1])
    raise AssertionError(f'no VmRSS for pid {pid}')


def counts(msg):
    return dict(zip(msg.layout.dim[0].label.split(','), msg.data))


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def start_udp_node(ros_graph):
    port = free_udp_port()
    node = ros_graph.start('ship_guidance', 'ais_node', params={
        'use_sim_time': False, 'udp_port': port, 'origin_lat_deg': ORIGIN[0],
        'origin_lon_deg': ORIGIN[1], 'publish_period_s': PERIOD_S})
    assert node.wait_for_output(f'UDP 127.0.0.1:{port}', timeout=20.0)
    return node, port


@pytest.mark.timeout(60)
def test_fragment_flood_keeps_memory_bounded_and_counts_coming(ros_graph):
    node, port = start_udp_node(ros_graph)
    tn = ros_graph.test_node()
    stats = tn.subscribe('/ais_counts', UInt64MultiArray)
    assert tn.wait_for_message(stats, timeout=20.0) is not None
    tn.spin_for(1.0)
    rss0 = rss_kb(node.pid)
    n = 100_000
    t_start = time.monotonic()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for i in range(n):
            s.sendto(first_part(i), ('127.0.0.1', port))
            if i % 2000 == 1999:      # let the node (and the test node) run in between
                tn.spin_for(0.05)
    t_end = time.monotonic()
    tn.spin_for(2 * PERIOD_S)
    rss1 = rss_kb(node.pid)
    during = [t for t in stats.times if t_start <= t <= t_end + 2 * PERIOD_S]
    print(f'flood of {n} first parts in {t_end - t_start:.1f} s: RSS {rss0} -> {rss1} kB, '
          f'{len(during)} ais_counts meanwhile; last {counts(stats.last)}')
    assert rss1 - rss0 < RSS_GROWTH_BOUND_KB
    gaps = [b - a for a, b in zip([t_start] + during, during + [t_end + 2 * PERIOD_S])]
    assert max(gaps) < MAX_GAP_S
    c = counts(stats.last)
    assert c['pending_fragments'] <= MAX_PENDING_FRAGMENTS
    # Many more first parts were taken in than the store holds: the bound did the work.
    assert c['fragment'] + c['malformed'] > 10 * MAX_PENDING_FRAGMENTS
    assert c['decoded'] == 0 and node.returncode is None
    assert ros_graph.stop(node) == 0


@pytest.mark.timeout(30)
def test_a_fifo_as_replay_file_is_refused_in_one_line(ros_graph, tmp_path):
    fifo = tmp_path / 'ais.fifo'
    os.mkfifo(fifo)
    node = ros_graph.start('ship_guidance', 'ais_node', params={'file': str(fifo)})
    assert node.wait(timeout=20.0) == 2
    err = node.stderr().strip()
    assert err.count('\n') == 0 and 'FIFO' in err and "'file'" in err, err
    # Nobody opened it for reading: a non-blocking writer finds no reader.
    with pytest.raises(OSError):
        os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)


def position(mmsi, north, east):
    lat, lon = ned_to_geodetic(north, east, *ORIGIN)
    return pyais.encode_dict(dict(type=1, msg_type=1, mmsi=mmsi, lat=lat, lon=lon, speed=5.0,
                                  course=90.0, heading=511), talker_id='AI',
                             sentence_type='VDM')[0]


@pytest.mark.timeout(60)
def test_sigint_under_a_flood_of_5000_ships_ends_cleanly(ros_graph):
    node, port = start_udp_node(ros_graph)
    ships = [(position(257000000 + i, 100.0 * (i % 100), 100.0 * (i // 100)) + '\r\n').encode()
             for i in range(5000)]
    tn = ros_graph.test_node()
    stats = tn.subscribe('/ais_counts', UInt64MultiArray)
    assert tn.wait_for_message(stats, timeout=20.0) is not None
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        t0 = time.monotonic()
        i = 0
        while time.monotonic() - t0 < 6.0:
            s.sendto(ships[i % len(ships)], ('127.0.0.1', port))
            i += 1
            if i % 1000 == 0:
                tn.spin_once(0.0)
        assert counts(stats.last)['targets'] > 1000          # the node was busy publishing
        node.popen.send_signal(signal.SIGINT)
        t_sig = time.monotonic()
        while node.returncode is None and time.monotonic() - t_sig < 10.0:
            s.sendto(ships[i % len(ships)], ('127.0.0.1', port))   # the flood goes on
            i += 1
    assert node.wait(timeout=5.0) == 0
    out = node.output()
    for needle in ('Traceback', 'FATAL', 'Exception', 'context is invalid'):
        assert needle not in out, out[-2000:]
    # One summary line per LOG_PERIOD_S at most (plus the first), however many ships came.
    tracked = [line for line in out.splitlines() if line.endswith(' tracked')]
    assert 1 <= len(tracked) <= (time.monotonic() - t0) / LOG_PERIOD_S + 2
    assert any('more tracked' in line for line in tracked)
