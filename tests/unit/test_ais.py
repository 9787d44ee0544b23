"""AIS tracker (ship_guidance.ais): real sentences of every used type, round trips of our own
simulated states through pyais.encode, every bad-input reason, dead reckoning and staleness.

Real sentences: tests/data/ais/ (from the pyais repository, see tests/data/README.md); the
expected values are those pyais's own tests assert for the same sentences, and physical facts
(e.g. EVER DIADEM is a 295 m container ship).
"""
import math
from functools import reduce
from pathlib import Path

import numpy as np
import pyais
import pytest

from ship_guidance.ais import (BAD_REASONS, FRAGMENT_TIMEOUT_S, KNOT, MAX_PENDING_FRAGMENTS,
                               STALE_AFTER_S, AisTracker, TargetState, dead_reckon)
from ship_sim.geodetic import geodetic_to_ned, ned_to_geodetic
from ship_sim.simulator import VesselSimulator

DATA = Path(__file__).resolve().parents[1] / 'data' / 'ais'
ORIGIN = (34.86, 128.73)          # scenarios/routes/busan_passage.yaml
SF = (37.80, -122.34)             # San Francisco Bay, where most pyais samples come from
RES_DEG = 1.0 / 600000.0          # AIS position resolution: 1/10000 minute
RES_M = 1852.0 / 10000.0          # ... in metres of latitude (one arc minute ~ 1852 m)


def checksum(body):
    return '%02X' % reduce(lambda a, c: a ^ ord(c), body, 0)


def sentence(payload, fill=0, talker='AIVDM', n=1, k=1, seq='', channel='A'):
    """A sentence with a correct checksum around any payload."""
    body = f'{talker},{n},{k},{seq},{channel},{payload},{fill}'
    return f'!{body}*{checksum(body)}'


def feed_file(tracker, path, t0=0.0, dt=1.0):
    lines = [s for s in path.read_text().splitlines() if s.strip()]
    for i, line in enumerate(lines):
        tracker.feed(line, t0 + i * dt)
    return lines


@pytest.fixture(scope='module')
def samples():
    tr = AisTracker(*SF)
    feed_file(tr, DATA / 'pyais_samples.nmea', dt=0.0)
    return tr


def test_every_supported_type_decodes_from_real_sentences(samples):
    assert samples.decoded == {1: 2, 2: 1, 3: 1, 5: 1, 18: 2, 19: 1, 24: 3}
    # The only bad line is the proprietary $PGHP sentence of the aishub sample.
    assert {k: v for k, v in samples.bad.items() if v} == {'malformed': 1}
    assert samples.ignored == {}


def test_class_a_position_reports(samples):
    t = samples.tracks[366053209]                        # message 1, pyais test_msg_type_1_a
    assert (t.lat, t.lon) == (37.802118, -122.341618)
    assert t.sog == 0.0 and math.degrees(t.cog) == pytest.approx(219.3)
    assert math.degrees(t.heading) == pytest.approx(1.0) and t.klass == 'A'
    t = samples.tracks[538090443]                        # message 1, test_msg_type_1_c
    assert t.sog == pytest.approx(10.9 * KNOT) and math.degrees(t.cog) == pytest.approx(87.0)
    t = samples.tracks[218069000]                        # message 2 (test_file_stream.py)
    assert t.klass == 'A' and -90 < t.lat < 90 and t.sog > 0.0
    t = samples.tracks[367581220]                        # message 3, test_msg_type_3: moored
    assert round(t.lat, 4) == 37.8107 and round(t.lon, 4) == -122.3343
    assert t.sog == pytest.approx(0.1 * KNOT) and math.degrees(t.cog) == pytest.approx(254.2)
    assert math.degrees(t.heading) == pytest.approx(217.0)


def test_static_data_two_sentence_message_5(samples):
    t = samples.tracks[351759000]                        # test_msg_type_5, two sentences
    assert t.name == 'EVER DIADEM' and t.ship_type == 70            # cargo
    # An Evergreen D-class container ship: 295 m x 32 m (to_bow 225 + to_stern 70, 1 + 31).
    assert (t.length, t.beam) == (295.0, 32.0)
    assert t.t is None and samples.state(351759000, 0.0) is None    # no position yet


def test_class_b_messages_18_19_24(samples):
    t = samples.tracks[367430530]                        # 18 twice: AIVDM then AIVDO
    assert t.sog == pytest.approx(67.8 * KNOT) and math.degrees(t.cog) == pytest.approx(10.1)
    assert t.heading is None and t.klass == 'B' and t.reports == 2
    t = samples.tracks[367059850]                        # 19, test_msg_type_19
    assert t.name == 'CAPT.J.RIMES' and t.ship_type == 70 and t.lat == 29.543695
    assert t.sog == pytest.approx(8.7 * KNOT) and (t.length, t.beam) == (26.0, 8.0)
    assert t.heading is None                             # 511: not available
    t = samples.tracks[244270489]                        # 24 A + B (real capture)
    assert t.name == 'SY-LUNDE' and t.ship_type == 36 and t.length == 12.0    # sailing yacht
    assert samples.tracks[338091445].ship_type == 37     # 24 B, pleasure craft


def test_positions_in_the_local_plane(samples):
    t = samples.tracks[366053209]
    north, east = geodetic_to_ned(t.lat, t.lon, *SF)
    assert (t.north, t.east) == (north, east)
    # 0.002118 deg of latitude north of the origin: 0.1271 arc minutes, ~235 m.
    assert t.north == pytest.approx(0.002118 * 60 * 1852.0, rel=5e-3)
    s = samples.state(366053209, 0.0)
    assert isinstance(s, TargetState) and s.psi == t.heading      # true heading when given
    s = samples.state(367430530, 0.0)                 # class B, heading 511
    assert s.psi == s.cog                                         # else the COG


def test_real_capture_is_counted_and_never_raises():
    """The first 120 lines of pyais's nmea_data_sample.txt: every line ends up in exactly one
    counter; the empty payloads of the capture are 'truncated'."""
    tr = AisTracker(37.5, 22.0)                          # the capture is from Greece
    lines = feed_file(tr, DATA / 'nmea_data_sample_head.txt')
    empty = sum(1 for s in lines if s.split(',')[5] == '')
    first_parts = sum(1 for s in lines if s.split(',')[1:3] == ['2', '1'])
    assert tr.bad['truncated'] == empty > 0
    # Their second parts come after the excerpt: those begun more than FRAGMENT_TIMEOUT_S
    # before the last line (fed 1 s apart) are dropped as 'fragment', the others still wait.
    last_first = max(i for i, s in enumerate(lines) if s.split(',')[1:3] == ['2', '1'])
    assert first_parts == 3 and len(lines) - 1 - last_first <= FRAGMENT_TIMEOUT_S
    assert 1 <= tr.pending_fragments < first_parts
    assert tr.bad['fragment'] == first_parts - tr.pending_fragments
    total = sum(tr.decoded.values()) + sum(tr.bad.values()) + sum(tr.ignored.values())
    assert total - tr.bad['velocity_not_available'] + tr.pending_fragments == len(lines)
    assert tr.decoded.keys() <= {1, 3, 18, 24}
    assert len(tr.targets(len(lines))) > 10


# -- round trip: our own simulated states -> pyais.encode -> tracker --------------------------

def simulated_states():
    """A Mariner turning at 10 deg rudder (ship_sim), sampled every 10 s for 300 s."""
    sim = VesselSimulator('mariner', dt=0.1, north=4000.0, east=-3000.0, psi=0.3)
    out = []
    for _ in range(31):
        t, n, e, psi, u, v, _r = sim.nav_state()
        out.append((t, n, e, psi, math.hypot(u, v), psi + math.atan2(v, u)))
        sim.run(math.radians(10.0), 100)
    return out


@pytest.mark.parametrize('msg_type', [1, 2, 3, 18, 19])
def test_round_trip_of_simulated_states(msg_type):
    tr = AisTracker(*ORIGIN)
    mmsi = 257000123
    for t, n, e, psi, sog, cog in simulated_states():
        lat, lon = ned_to_geodetic(n, e, *ORIGIN)
        sog_kn, cog_deg = sog / KNOT, math.degrees(cog) % 360.0
        hdg = round(math.degrees(psi) % 360.0) % 360
        data = dict(type=msg_type, msg_type=msg_type, mmsi=mmsi, lat=lat, lon=lon,
                    speed=sog_kn, course=cog_deg, heading=hdg, shipname='OWN TEST')
        for s in pyais.encode_dict(data, talker_id='AI', sentence_type='VDM'):
            assert tr.feed(s, t) == mmsi
        tk = tr.tracks[mmsi]
        assert abs(tk.lat - lat) <= RES_DEG and abs(tk.lon - lon) <= RES_DEG
        assert abs(tk.north - n) <= RES_M + 1e-6
        assert abs(tk.east - e) <= RES_M * math.cos(math.radians(lat)) + 1e-6
        assert abs(tk.sog / KNOT - sog_kn) <= 0.1 + 1e-9
        dc = (math.degrees(tk.cog) - cog_deg + 180.0) % 360.0 - 180.0
        assert abs(dc) <= 0.1 + 1e-9
        assert round(math.degrees(tk.heading)) % 360 == hdg
    assert sum(tr.bad.values()) == 0 and tr.decoded[msg_type] == 31


def test_round_trip_of_static_data():
    tr = AisTracker(*ORIGIN)
    dims = dict(to_bow=120, to_stern=40, to_port=10, to_starboard=13)
    for kind, extra in ((5, dict(shipname='MARINER')), (24, dict(partno=0, shipname='MARINER')),
                        (24, dict(partno=1, ship_type=70)), (19, dict(shipname='MARINER'))):
        mmsi = 257000000 + kind * 10 + extra.get('partno', 0)
        data = dict(type=kind, msg_type=kind, mmsi=mmsi, lat=34.9, lon=128.8, **dims, **extra)
        data.setdefault('ship_type', 70)
        for s in pyais.encode_dict(data, talker_id='AI', sentence_type='VDM'):
            tr.feed(s, 0.0)
        tk = tr.tracks[mmsi]
        if kind == 24 and extra['partno'] == 0:          # part A: the name only
            assert tk.name == 'MARINER' and tk.ship_type is None and tk.length is None
            continue
        assert tk.ship_type == 70 and tk.name in ('MARINER', None)
        assert (tk.length, tk.beam) == (160.0, 23.0)
    assert sum(tr.bad.values()) == 0 and tr.decoded == {5: 1, 24: 2, 19: 1}


# -- bad input ---------------------------------------------------------------------------------

GOOD = '!AIVDM,1,1,,B,15M67FC000G?ufbE`FepT@3n00Sa,0*5C'


def encoded(**kw):
    data = dict(type=1, msg_type=1, mmsi=257000001, lat=34.9, lon=128.8, speed=10.0, course=90.0)
    data.update(kw)
    return pyais.encode_dict(data, talker_id='AI', sentence_type='VDM')[0]


BAD = {
    'malformed': ['', 'garbage', '$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,,,,*47',
                  '!AIVDM,1,1,,B,15M67FC000G?ufbE`FepT@3n00Sa'],
    'checksum': [GOOD[:-1] + 'D', GOOD.replace('15M67', '15M68')],
    'truncated': [sentence('15M67FC000G?ufbE`Fep'), sentence(''), sentence('H52KMeDU65')],
    'fragment': [sentence('88888888880', fill=2, n=2, k=2, seq='1')],
    'unknown_type': [sentence('05M67FC000G?ufbE`FepT@3n00Sa'),
                     sentence('w5M67FC000G?ufbE`FepT@3n00Sa')],
    'bad_mmsi': [encoded(mmsi=0)],
    'position_not_available': [encoded(lat=91.0, lon=181.0), encoded(lat=91.0)],
    'velocity_not_available': [encoded(speed=102.3), encoded(course=360.0)],
}


@pytest.mark.parametrize('reason', BAD_REASONS)
def test_bad_sentences_are_counted_by_reason(reason):
    tr = AisTracker(*ORIGIN)
    for line in BAD[reason]:
        tr.feed(line, 0.0)
    assert tr.bad == {r: (len(BAD[reason]) if r == reason else 0) for r in BAD_REASONS}
    assert tr.last_bad[0] == reason
    if reason == 'velocity_not_available':
        s = tr.state(257000001, 100.0)                  # placed, held (velocity unknown)
        n, e = geodetic_to_ned(34.9, 128.8, *ORIGIN)
        assert s.sog == 0.0 and abs(s.north - n) < RES_M and abs(s.east - e) < RES_M
    elif reason != 'malformed':
        assert tr.targets(0.0) == []


def test_fragments_out_of_order_and_interleaved():
    five = pyais.encode_dict(dict(type=5, mmsi=257000005, shipname='ONE', to_bow=10,
                                  to_stern=5, to_port=2, to_starboard=2), seq_id=3,
                             talker_id='AI', sentence_type='VDM')
    other = pyais.encode_dict(dict(type=5, mmsi=257000006, shipname='TWO'), seq_id=4,
                              radio_channel='B', talker_id='AI', sentence_type='VDM')
    assert len(five) == 2
    tr = AisTracker(*ORIGIN)
    tr.feed(five[1], 0.0)                                # second part first: orphan
    tr.feed(five[0], 0.0)
    tr.feed(other[0], 0.0)                               # another message in between
    tr.feed(five[1], 0.0)
    tr.feed(other[1], 0.0)
    assert tr.bad['fragment'] == 1 and tr.decoded == {5: 2}
    assert tr.tracks[257000005].length == 15.0 and tr.tracks[257000006].name == 'TWO'
    tr.feed(five[0], 1.0)                                # a first part never completed ...
    tr.feed(five[0], 2.0)                                # ... is replaced and counted
    assert tr.bad['fragment'] == 2


def test_unfinished_fragments_expire_by_age():
    five = pyais.encode_dict(dict(type=5, mmsi=257000005, shipname='LATE'), seq_id=3,
                             talker_id='AI', sentence_type='VDM')
    tr = AisTracker(*ORIGIN)
    tr.feed(five[0], 10.0)
    tr.prune(10.0 + FRAGMENT_TIMEOUT_S)                  # still within the timeout: waits
    assert tr.pending_fragments == 1 and tr.bad['fragment'] == 0
    tr.feed(five[1], 10.0 + FRAGMENT_TIMEOUT_S)          # and completes
    assert tr.decoded == {5: 1} and tr.pending_fragments == 0
    tr.feed(five[0], 20.0)
    tr.prune(20.0 + 1.01 * FRAGMENT_TIMEOUT_S)           # expired, with no further input
    assert tr.pending_fragments == 0 and tr.bad['fragment'] == 1
    tr.feed(five[1], 20.0 + 1.01 * FRAGMENT_TIMEOUT_S)   # its late second part is an orphan
    assert tr.bad['fragment'] == 2 and tr.decoded == {5: 1}


def test_a_flood_of_first_parts_is_bounded_and_counted():
    """First parts with every key a sender can make (talker, channel, id) never complete: the
    store stays at MAX_PENDING_FRAGMENTS and every first part beyond it is counted; the newest
    ones are kept, so a message that does complete still assembles."""
    tr = AisTracker(*ORIGIN)
    talkers = ('AIVDM', 'ABVDM', 'ADVDM', 'ANVDM', 'ARVDM', 'ASVDM', 'ATVDM', 'AXVDM', 'BSVDM',
               'SAVDM')
    n = 0
    for talker in talkers:
        for channel in 'AB12':
            for seq in range(10):
                tr.feed(sentence('5' + '0' * 59, n=2, k=1, seq=str(seq), talker=talker,
                                 channel=channel), 0.0)
                n += 1
    assert n > MAX_PENDING_FRAGMENTS
    assert tr.pending_fragments == MAX_PENDING_FRAGMENTS
    assert tr.bad['fragment'] == n - MAX_PENDING_FRAGMENTS
    assert sum(tr.bad.values()) == tr.bad['fragment']
    five = pyais.encode_dict(dict(type=5, mmsi=257000007, shipname='THROUGH'), seq_id=7,
                             talker_id='AI', sentence_type='VDM')
    for part in five:
        tr.feed(part, 0.0)
    assert tr.tracks[257000007].name == 'THROUGH'
    assert tr.pending_fragments <= MAX_PENDING_FRAGMENTS


@pytest.mark.parametrize('seq', ['10', '12345', '-1'])
def test_a_sequence_id_outside_0_to_9_is_malformed(seq):
    tr = AisTracker(*ORIGIN)
    tr.feed(sentence('5' + '0' * 59, n=2, k=1, seq=seq), 0.0)
    assert tr.pending_fragments == 0 and tr.bad['malformed'] == 1


def test_random_damage_never_raises():
    rng = np.random.default_rng(13)
    lines = (DATA / 'pyais_samples.nmea').read_text().splitlines()
    tr = AisTracker(*SF)
    for i in range(2000):
        s = bytearray(lines[i % len(lines)].encode())
        op = i % 4
        if op == 0:
            s = s[:rng.integers(0, len(s))]
        elif op == 1:
            s[rng.integers(0, len(s))] = rng.integers(0, 256)
        elif op == 2:
            s = bytes(rng.integers(0, 256, rng.integers(0, 90), dtype=np.uint8))
        else:
            s = s.replace(b',', b'', 1)
        tr.feed(bytes(s), float(i))
    assert sum(tr.bad.values()) > 1000


# -- dead reckoning and staleness --------------------------------------------------------------

def test_dead_reckoning_matches_the_next_report_of_a_straight_run():
    """A ship on a straight line at 14 kn, course 30 deg: the first report dead-reckoned 60 s
    equals the second report within AIS resolution (position, and 0.05 kn of SOG rounding)."""
    tr = AisTracker(*ORIGIN)
    sog, cog = 14.0 * KNOT, math.radians(30.0)
    n0, e0 = 1500.0, -800.0
    reports = []
    for t in (0.0, 60.0):
        n, e = n0 + sog * t * math.cos(cog), e0 + sog * t * math.sin(cog)
        lat, lon = ned_to_geodetic(n, e, *ORIGIN)
        reports.append((t, n, e, encoded(mmsi=257000777, lat=lat, lon=lon, speed=14.0,
                                         course=30.0)))
    tr.feed(reports[0][3], 0.0)
    s = tr.state(257000777, 60.0)
    tol = 2 * RES_M + 0.05 * KNOT * 60.0
    assert math.hypot(s.north - reports[1][1], s.east - reports[1][2]) <= tol
    assert s.age == 60.0 and s.sog == pytest.approx(sog)
    # The closed form, at any time: p(t) = p0 + SOG t (cos COG, sin COG).
    tk = tr.tracks[257000777]
    for t in (0.0, 13.7, 359.0):
        s = tr.state(257000777, t)
        assert (s.north, s.east) == pytest.approx(
            (tk.north + sog * t * math.cos(cog), tk.east + sog * t * math.sin(cog)), abs=1e-9)
    assert dead_reckon(0.0, 0.0, 2.0, math.pi / 2, 10.0) == pytest.approx((0.0, 20.0))


def test_a_class_a_ship_at_anchor_is_kept_between_its_3_minute_reports():
    assert STALE_AFTER_S >= 2 * 180.0                    # ITU-R M.1371: 3 min at anchor
    tr = AisTracker(*ORIGIN)
    anchored = encoded(mmsi=257000900, speed=0.0, course=0.0, status=1)
    for k in range(6):                                   # reports at 0, 180, ..., 900 s
        tr.feed(anchored, 180.0 * k)
        for t in np.arange(180.0 * k, 180.0 * (k + 1), 10.0):
            assert [s.mmsi for s in tr.targets(float(t))] == [257000900]
    last = 900.0
    assert [s.mmsi for s in tr.targets(last + STALE_AFTER_S)] == [257000900]
    assert tr.targets(last + STALE_AFTER_S + 1e-3) == [] and 257000900 not in tr.tracks


def test_static_data_alone_does_not_keep_a_stale_position_alive():
    tr = AisTracker(*ORIGIN, stale_after_s=60.0)
    tr.feed(encoded(mmsi=257000901), 0.0)
    for s in pyais.encode_dict(dict(type=5, mmsi=257000901, shipname='X'), talker_id='AI',
                               sentence_type='VDM'):
        tr.feed(s, 50.0)
    assert tr.targets(61.0) == [] and 257000901 in tr.tracks        # position stale
    tr.prune(111.0)
    assert 257000901 not in tr.tracks                               # static data stale too
    with pytest.raises(ValueError):
        AisTracker(*ORIGIN, stale_after_s=0.0)


def test_replay_file_format():
    from ship_guidance.ais import parse_replay
    lines = ['# comment', '', '12.5 !AIVDM,1,1,,A,x,0*00', '!AIVDM,1,1,,A,y,0*00',
             '!AIVDM,1,1,,A,z,0*00', '3 !AIVDM,1,1,,A,w,0*00']
    got = parse_replay(lines, rate_hz=2.0, offset_s=100.0)
    assert got == [(100.0, '!AIVDM,1,1,,A,y,0*00'), (100.5, '!AIVDM,1,1,,A,z,0*00'),
                   (103.0, '!AIVDM,1,1,,A,w,0*00'), (112.5, '!AIVDM,1,1,,A,x,0*00')]
    with pytest.raises(ValueError):
        parse_replay(lines, rate_hz=0.0)


def test_replay_feeds_the_parts_of_a_message_together_at_any_rate():
    """Untimed lines at 0.01 Hz (100 s apart): the second part of a message 5 keeps the time of
    its first, so it is assembled instead of expiring, and the next line gets the next slot."""
    from ship_guidance.ais import parse_replay
    five = pyais.encode_dict(dict(type=5, mmsi=257000005, shipname='SLOW'), seq_id=1,
                             talker_id='AI', sentence_type='VDM')
    position = pyais.encode_dict(dict(type=1, mmsi=257000001, lat=34.9, lon=128.8, speed=1.0,
                                      course=0.0), talker_id='AI', sentence_type='VDM')[0]
    got = parse_replay([*five, position], rate_hz=0.01)
    assert [t for t, _ in got] == [0.0, 0.0, 100.0]
    tr = AisTracker(*ORIGIN)
    for t, line in got:
        tr.feed(line, t)
    assert tr.decoded == {5: 1, 1: 1} and tr.tracks[257000005].name == 'SLOW'
    assert tr.bad['fragment'] == 0
