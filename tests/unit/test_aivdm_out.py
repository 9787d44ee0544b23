"""AIVDM/AIVDO out (ship_guidance.aivdm_out): every message type round-trips through pyais and
through an independent decoder (gpsd's gpsdecode) to the true state within the encoding's
resolution (position 1/10000 arc minute, SOG 0.1 kn, COG 0.1 deg, heading 1 deg)."""
import json
import math
import shutil
import subprocess

import numpy as np
import pyais
import pytest

from ship_guidance.ais import KNOT
from ship_guidance.ais_sensor import STATIC_INTERVAL_S, SensorConfig, Truth, antenna_position
from ship_guidance.aivdm_out import AivdmOut, VesselInfo
from ship_sim.geodetic import ned_to_geodetic

ORIGIN = (63.44, 10.40)
RES_DEG = 1.0 / 600000.0          # 1/10000 arc minute
NOISELESS = SensorConfig(loss_probability=0.0, position_sigma_m=0.0, sog_sigma_kn=0.0,
                         cog_sigma_deg=0.0, heading_sigma_deg=0.0)
OWN = VesselInfo(257000100, 'A', own=True, name='Own mariner', callsign='LAOW1', ship_type=70,
                 length_m=171.8, beam_m=23.2, antenna_x_m=-40.0, antenna_y_m=1.5)
CARGO = VesselInfo(257000200, 'A', name='Tanker target', callsign='LATK2', ship_type=80,
                   length_m=320.0, beam_m=47.2, antenna_x_m=-120.0)
YACHT = VesselInfo(257000300, 'B', name='Yacht', callsign='LB3', ship_type=37, length_m=12.0,
                   beam_m=4.0)
SAILER = VesselInfo(257000400, 'SO', name='Ferry', ship_type=60, length_m=60.0, beam_m=12.0)
VESSELS = (OWN, CARGO, YACHT, SAILER)


def truth_of(info, t):
    """A state per vessel: different speeds and courses, the cargo ship turning."""
    k = VESSELS.index(info)
    sog = (7.7, 9.0, 3.0, 10.0)[k]
    psi = math.radians((10.0, 250.0, 123.4, 359.0)[k]) + (0.004 * t if k == 1 else 0.0)
    return Truth(t, 1000.0 * k + sog * t * math.cos(psi), -500.0 * k + sog * t * math.sin(psi),
                 psi, sog, psi, 0.004 if k == 1 else 0.0)


@pytest.fixture(scope='module')
def stream():
    """[(t_received, sentences, truth at the report's send time, info)] of 400 s."""
    out = AivdmOut(*ORIGIN, NOISELESS)
    for info in VESSELS:
        out.add(info)
    got = []
    for t in np.arange(0.0, 400.0, 0.1):
        for info in VESSELS:
            truth = truth_of(info, t)
            got += [(tr, lines, truth, info) for tr, lines in out.step(info.mmsi, truth)]
    return got


def antenna_latlon(truth, info):
    n, e = antenna_position(truth.north, truth.east, truth.psi, info.antenna_x_m,
                            info.antenna_y_m)
    return ned_to_geodetic(n, e, *ORIGIN)


def check_position(msg, truth, info, pos_tol_deg=RES_DEG, sog_tol=0.05, cog_tol=0.05):
    lat, lon = antenna_latlon(truth, info)
    assert abs(msg['lat'] - lat) <= pos_tol_deg + 1e-12
    assert abs(msg['lon'] - lon) <= pos_tol_deg + 1e-12
    assert abs(msg['speed'] - truth.sog / KNOT) <= sog_tol + 1e-9
    dcog = (msg['course'] - math.degrees(truth.cog) + 180.0) % 360.0 - 180.0
    assert abs(dcog) <= cog_tol + 1e-9
    dhdg = (msg['heading'] - math.degrees(truth.psi) + 180.0) % 360.0 - 180.0
    assert abs(dhdg) <= 0.5 + 1e-9


def check_static(msg, info):
    assert msg['shipname'] == info.name.upper()
    assert msg['ship_type'] == info.ship_type
    assert msg['to_bow'] + msg['to_stern'] == pytest.approx(info.length_m, abs=1.0)
    assert msg['to_port'] + msg['to_starboard'] == pytest.approx(info.beam_m, abs=1.0)
    # the antenna's place on the hull: x = (stern - bow) / 2, y = (port - starboard) / 2
    assert (msg['to_stern'] - msg['to_bow']) / 2 == pytest.approx(info.antenna_x_m, abs=1.0)
    assert (msg['to_port'] - msg['to_starboard']) / 2 == pytest.approx(info.antenna_y_m, abs=1.0)


def test_every_message_type_round_trips_through_pyais(stream):
    seen = set()
    for _, lines, truth, info in stream:
        assert all(ln.startswith('!AIVDO' if info.own else '!AIVDM') for ln in lines)
        msg = pyais.decode(*lines).asdict()
        assert msg['mmsi'] == info.mmsi
        t = msg['msg_type']
        seen.add((t, msg.get('partno')))
        if t in (1, 2, 3, 18):
            assert (t == 18) == (info.klass != 'A')
            assert (t == 3) == (info is CARGO)         # the turning one, at its course-change rate
            check_position(msg, truth, info)
            assert msg['second'] == int(truth.t) % 60
            if t == 18:
                assert msg['cs'] == (info.klass == 'B')
            else:
                assert msg['turn'] == pytest.approx(math.degrees(truth.rot) * 60.0, rel=0.1)
        elif t == 5:
            assert len(lines) == 2 and info.klass == 'A'
            check_static(msg, info)
            assert msg['callsign'] == info.callsign
        elif t == 24:
            assert info.klass != 'A'
            if msg['partno'] == 0:
                assert msg['shipname'] == info.name.upper()
            else:
                check_static({**msg, 'shipname': info.name.upper()}, info)
                assert msg['callsign'] == info.callsign.upper()
    assert seen == {(1, None), (3, None), (5, None), (18, None), (24, 0), (24, 1)}


def test_static_data_every_six_minutes(stream):
    """Message 5 / 24 with the first report, then again after 360 s (and not before)."""
    for info in VESSELS:
        times = [tr for tr, lines, _, i in stream
                 if i is info and pyais.decode(*lines).msg_type in (5, 24)]
        first = min(tr for tr, _, _, i in stream if i is info)
        assert times[0] == first
        gaps = np.diff(sorted(set(times)))
        assert len(gaps) >= 1 and gaps.min() >= STATIC_INTERVAL_S


@pytest.mark.skipif(shutil.which('gpsdecode') is None,
                    reason='gpsdecode (Debian gpsd-clients) not installed')
def test_gpsdecode_reads_the_truth(stream):
    """gpsd's decoder, independent of pyais, reads the same positions (it prints 6 decimals:
    +0.5e-6 deg), SOG, COG, heading, names and dimensions."""
    text = '\n'.join(ln for _, lines, _, _ in stream for ln in lines) + '\n'
    res = subprocess.run(['gpsdecode', '-j'], input=text, capture_output=True, text=True,
                         timeout=60, check=True)
    decoded = [json.loads(ln) for ln in res.stdout.splitlines() if ln.strip()]
    positions = [(truth, info) for _, lines, truth, info in stream
                 if pyais.decode(*lines).msg_type in (1, 3, 18)]
    pos = [d for d in decoded if d['type'] in (1, 3, 18)]
    assert len(pos) == len(positions) > 50
    for d, (truth, info) in zip(pos, positions):
        assert d['mmsi'] == info.mmsi
        check_position(d, truth, info, pos_tol_deg=RES_DEG + 0.5e-6)
    statics = {d['mmsi']: d for d in decoded if d['type'] in (5, 24)}
    for info in VESSELS:
        d = statics[info.mmsi]
        check_static({**d, 'ship_type': d['shiptype']}, info)
        assert d['callsign'] == info.callsign.upper()


def test_bad_vessel_refused_at_add():
    out = AivdmOut(*ORIGIN)
    with pytest.raises(ValueError, match='class'):
        out.add(VesselInfo(257000500, 'C'))
    with pytest.raises(ValueError, match='MMSI'):
        out.add(VesselInfo(0))
    out.add(VesselInfo(257000500))
    with pytest.raises(ValueError, match='twice'):
        out.add(VesselInfo(257000500))
