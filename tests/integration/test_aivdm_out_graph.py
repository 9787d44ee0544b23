"""AIVDM/AIVDO out on the graph (aivdm_out_node through the launcher): a lockstep run of a Mariner
(own ship, AIVDO) with a class A and a class B light target, received on a local UDP socket as a
chart plotter would, and the same sentences in the run folder's file.

Checked: the message types of each vessel (1 + 5 for class A, 18 + 24 A/B for class B; AIVDO
only for the own ship), the MMSIs of the scenario, and the intervals between position reports
(from their UTC-second field, whole seconds) within the ITU-R M.1371-5 interval of each speed
+-10 % slot selection and one second of rounding. Losses are off (loss_probability 0), so
every report of the run is there."""
import math
import socket

import pyais
import pytest
import yaml

from ship_guidance.ais import KNOT
from ship_guidance.ais_sensor import SLOT_SELECTION, report_interval

from harness import REPO_ROOT, _reached_duration

DURATION_S = 70.0
U = 7.7175                                   # m/s = 15 kn: class A 6 s
MMSI = {'vessel_0': 257000100, 'target_1': 257000200, 'target_2': 257000300}
SPEED = {'vessel_0': U, 'target_1': U, 'target_2': 4.0}    # target_2: class B, 7.8 kn: 30 s
KLASS = {'vessel_0': 'A', 'target_1': 'A', 'target_2': 'B'}


def scenario_file(tmp_path, port):
    scenario = {
        'name': 'aivdm_out_graph', 'duration_s': DURATION_S, 'stepping': 'lockstep',
        'dt_s': 0.1, 'record': False, 'display': False,
        'vessels': {'vessel_0': {
            'model': 'mariner', 'route': str(REPO_ROOT / 'scenarios/routes/head_on_east.yaml'),
            'speed_mps': U, 'guidance': {'law': 'los', 'lookahead_m': 800.0},
            'autopilot': {'controller': 'pd'}}},
        'traffic': {
            'target_1': {'light': {'x_m': 3000.0, 'y_m': 2000.0, 'course_deg': 270.0,
                                   'speed_mps': U}},
            'target_2': {'light': {'x_m': 1000.0, 'y_m': -1500.0, 'course_deg': 45.0,
                                   'speed_mps': SPEED['target_2']}}},
        'aivdm_out': {'udp': f'127.0.0.1:{port}', 'file': 'aivdm.nmea', 'mmsi': MMSI,
                      'origin': {'lat_deg': 63.44, 'lon_deg': 10.40}, 'loss_probability': 0,
                      'static': {'target_2': {'class': 'B', 'name': 'Yacht', 'ship_type': 37}}},
    }
    path = tmp_path / 'aivdm_out_graph.yaml'
    path.write_text(yaml.safe_dump(scenario))
    return path


@pytest.mark.timeout(300)
def test_udp_stream_has_the_types_mmsis_and_intervals(launch, tmp_path):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.bind(('127.0.0.1', 0))
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
        run = _reached_duration(launch(scenario_file(tmp_path, sock.getsockname()[1]),
                                       '--wall-timeout', 200, '--duration', DURATION_S), 200)
        sock.setblocking(False)
        datagrams = []
        while True:
            try:
                datagrams.append(sock.recv(65536).decode('ascii'))
            except BlockingIOError:
                break
    finally:
        sock.close()
    lines = [ln for d in datagrams for ln in d.split('\r\n') if ln]
    assert lines, 'nothing received on UDP'
    assert (run / 'aivdm.nmea').read_text().split() == lines    # the file has the same
    node_log = (run / 'logs' / 'aivdm.aivdm_out_node.log').read_text()    # says if samples went missing
    by_mmsi = {}
    for d in datagrams:
        sentences = [ln for ln in d.split('\r\n') if ln]
        msg = pyais.decode(*sentences)
        by_mmsi.setdefault(msg.mmsi, []).append((sentences[0][:6], msg))
    assert set(by_mmsi) == set(MMSI.values())
    for ns, mmsi in MMSI.items():
        msgs = by_mmsi[mmsi]
        talkers = {talker for talker, _ in msgs}
        assert talkers == ({'!AIVDO'} if ns == 'vessel_0' else {'!AIVDM'})
        types = {(m.msg_type, getattr(m, 'partno', None)) for _, m in msgs}
        if KLASS[ns] == 'A':
            assert types == {(1, None), (5, None)}
        else:
            assert types == {(18, None), (24, 0), (24, 1)}
        nominal = report_interval(KLASS[ns], SPEED[ns] / KNOT)
        seconds = [m.second for _, m in msgs if m.msg_type in (1, 18)]
        gaps = [(b - a) % 60 for a, b in zip(seconds, seconds[1:])]
        # the node may miss the first steps while the graph comes up: at most one interval
        expected = (DURATION_S - nominal * (1 + SLOT_SELECTION)) / (nominal * (1 + SLOT_SELECTION))
        assert len(seconds) >= math.floor(expected), f'{ns}: seconds {seconds}'
        assert all(nominal * (1 - SLOT_SELECTION) - 1 <= g <= nominal * (1 + SLOT_SELECTION) + 1
                   for g in gaps), (f'{ns}: seconds {seconds}, gaps {gaps}; node log:\n'
                                    + node_log)
