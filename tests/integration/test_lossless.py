"""A lockstep run's bag holds every step, and a repeated run gives the same record, under load.

The recorder takes part in the lockstep handshake (vessel_node ``lockstep_record_topic``): the
simulator never runs more than ``lockstep_record_window`` steps ahead of what the recorder has
taken, so no publisher queue (keep-last 100, /clock 10) can overwrite an unrecorded message,
however slow the recorder is made. Two busy loops (one per core) load the machine for the whole
test, which is how messages were lost before: bursts of 100 odom or 10 /clock steps.

For the flagship on its first two legs (one vessel, completed route) and a 3-vessel platoon
(duration-limited), run twice at the same time under load, once with a process per node and
once composed (ship_mission.composition: the flagship's nodes in its vessel's container, the
whole platoon in one):
- every step is in each bag: odom stamps are exactly k * dt for k = 0 .. last, /clock the
  same, and every per-step topic has one message per step (ship_mission.integrity finds nothing
  missing; the answer to the very last step may be in flight when the graph is stopped);
- the two runs' metrics are identical (but for the two that say how long the graph ran on
  after completion: the launcher's reaction time), and so is every message of every topic up to the
  shorter bag (the tail after completion depends on when the launcher heard route_complete);
  the bags' log times differ (the recorder's receive time), their messages do not.
"""
import json
import math
import subprocess
import sys

import numpy as np
import pytest
import yaml
from rosbags.highlevel import AnyReader

from ship_mission.bag import read_bag
from ship_mission.integrity import record_integrity

from harness import REPO_ROOT, _die_with_parent, start_pair
from test_launcher import Launch, _run_json

FLAGSHIP = REPO_ROOT / 'scenarios' / 'flagship_mariner.yaml'
PLATOON = REPO_ROOT / 'scenarios' / 'platoon_mariner_5.yaml'
#: Compose modes of the two runs: one with a process per node, one composed (per vessel for the
#: flagship, one container for the whole platoon), so each test checks the record of both
#: modes and that composing changes nothing in it.
COMPOSE_FLAGSHIP = ('none', 'vessel')
COMPOSE_PLATOON = ('none', 'all')
BUSY = 'import time\nend = time.monotonic() + 900\nwhile time.monotonic() < end:\n    pass\n'


@pytest.fixture
def busy_machine():
    """Two CPU-bound loops (the machine has two cores), ended at teardown or after 15 min."""
    procs = [subprocess.Popen([sys.executable, '-c', BUSY], preexec_fn=_die_with_parent)
             for _ in range(2)]
    try:
        yield procs
    finally:
        for p in procs:
            p.kill()
            p.wait(timeout=10)


def flagship_two_legs(tmp_path):
    """The flagship on the first two legs of its route (one fillet, ~4 km instead of ~8.7 km):
    the same graph, ended by route completion, in less than half the steps."""
    data = yaml.safe_load(FLAGSHIP.read_text())
    route_file = FLAGSHIP.parent / data['vessels']['vessel_0']['route']
    route = yaml.safe_load(route_file.read_text())
    route['name'] = 'flagship_two_legs'
    route['waypoints'] = route['waypoints'][:3]
    (tmp_path / 'route.yaml').write_text(yaml.safe_dump(route))
    data['name'] = 'lossless_flagship'
    data['vessels']['vessel_0']['route'] = str(tmp_path / 'route.yaml')
    path = tmp_path / 'flagship2.yaml'
    path.write_text(yaml.safe_dump(data))
    return path


def three_vessel_platoon(tmp_path):
    """The first three vessels of the 5-Mariner platoon, 150 s: every simulator reaches max_steps."""
    data = yaml.safe_load(PLATOON.read_text())
    data['name'] = 'lossless_platoon'
    data['duration_s'] = 150.0
    data['platoon']['route'] = str(PLATOON.parent / data['platoon']['route'])
    data['platoon']['vessels'] = data['platoon']['vessels'][:3]
    path = tmp_path / 'platoon3.yaml'
    path.write_text(yaml.safe_dump(data))
    return path


#: nav_display_node's frames. Their CDR carries alignment padding that the rmw's serializer
#: leaves as it finds it in memory (seen: the 3 bytes after a 1-byte string of a Marker differ
#: between two runs whose every field is equal), so they are compared after a round trip through
#: rosbags, which writes zeros there: every field, not the padding.
VIEW_TOPICS = ('/fix', '/nav_markers', '/heading')


def messages(bag):
    """{topic: [serialized message, ...]} in recording order (view topics with zero padding).

    ``/tf`` carries every vessel's transform in the order their odometry reached the recorder,
    which differs between runs where the vessels step independently (a platoon): it is keyed
    per child frame, ``/tf <child_frame_id>``, each vessel's transforms in order.
    """
    out = {}
    with AnyReader([bag]) as reader:
        for conn, _, raw in reader.messages():
            topic = conn.topic
            if topic.endswith(VIEW_TOPICS):
                raw = reader.typestore.serialize_cdr(reader.deserialize(raw, conn.msgtype),
                                                     conn.msgtype)
            elif topic == '/tf':
                topic = f'/tf {reader.deserialize(raw, conn.msgtype).transforms[0].child_frame_id}'
            out.setdefault(topic, []).append(bytes(raw))
    return out


def assert_every_step(bag, dt):
    data = read_bag(bag)
    report = record_integrity(data)
    assert report['complete'], json.dumps(report, indent=1)[:3000]
    for ns, v in data.vessels.items():
        k = v.t / dt
        assert np.allclose(k, np.round(k), atol=1e-6), ns
        assert np.array_equal(np.round(k), np.arange(len(k))), f'{ns}: odom steps not 0..{len(k) - 1}'
    k = data.clock / dt
    assert np.array_equal(np.round(k), np.arange(len(k))), '/clock steps not contiguous from 0'
    return data


def with_compose(path, mode):
    """A copy of scenario ``path`` with ``compose: mode`` (ship_mission.composition)."""
    data = yaml.safe_load(path.read_text())
    data['compose'] = mode
    out = path.with_name(f'{path.stem}_{mode}.yaml')
    out.write_text(yaml.safe_dump(data))
    return out


def run_twice(ros_graph, tmp_path, scenario, timeout, modes=('none', 'none')):
    """The scenario run twice at the same time (harness.start_pair: the second once the first
    is stepping, on a domain of its own), so each run is also loaded by the other graph; both
    launchers and their processes are ended whatever fails. ``modes``: each run's compose mode
    (a process per node, or containers: ship_mission.composition)."""
    launches = []

    def start(own_domain):
        k = len(launches)
        folder = tmp_path / f'run{k}'
        folder.mkdir()
        launches.append(Launch(ros_graph, folder, with_compose(scenario, modes[k]), [],
                               own_domain=own_domain))
        return launches[-1]

    runs = []
    try:
        for mode, launch in zip(modes, start_pair(start)):
            assert launch.wait(timeout) == 0, launch.report()
            run = (launch.runs / 'latest').resolve()
            procs = set(_run_json(run)['exit_codes'])
            assert any(p.endswith('component_container') for p in procs) == (mode != 'none'), \
                procs
            runs.append((run, json.loads((run / 'metrics.json').read_text())))
    finally:
        for launch in launches:
            launch.close()
    return runs


def compare(runs, dt):
    (run_a, met_a), (run_b, met_b) = runs
    for run in (run_a, run_b):
        assert_every_step(run / 'bag', dt)
    # Every vessel's metrics must match bit for bit; how long the graph ran on after completion
    # (the record's bag_end_s, tail_after_finish_s) is the launcher's reaction time.
    assert met_a['vessels'] == met_b['vessels']
    assert met_a.get('platoon') == met_b.get('platoon')
    msgs_a, msgs_b = messages(run_a / 'bag'), messages(run_b / 'bag')
    assert set(msgs_a) == set(msgs_b)
    # Also nav_display_node's frames (fix, nav_markers, heading), outside the lockstep: it reads
    # the simulator's odom_display, every frame kept for it however far it lags (qos DISPLAY).
    view = [t for t in msgs_a if t.endswith(VIEW_TOPICS)]
    assert len(view) == 3 * len(met_a['vessels']) and all(msgs_a[t] for t in view), view
    for topic in msgs_a:
        n = min(len(msgs_a[topic]), len(msgs_b[topic]))
        assert msgs_a[topic][:n] == msgs_b[topic][:n], topic
    return met_a


@pytest.mark.timeout(900)
def test_flagship_lossless_and_repeatable_under_load(ros_graph, tmp_path, busy_machine):
    dt = yaml.safe_load(FLAGSHIP.read_text())['dt_s']
    metrics = compare(run_twice(ros_graph, tmp_path, flagship_two_legs(tmp_path), timeout=400,
                                modes=COMPOSE_FLAGSHIP), dt)
    v = metrics['vessels']['/vessel_0']
    assert v['completion_cut'] == 'guidance' and math.isfinite(v['xte_rms_m'])


@pytest.mark.timeout(900)
def test_platoon_lossless_and_repeatable_under_load(ros_graph, tmp_path, busy_machine):
    scenario = three_vessel_platoon(tmp_path)
    metrics = compare(run_twice(ros_graph, tmp_path, scenario, timeout=400,
                                modes=COMPOSE_PLATOON), 0.1)
    assert len(metrics['vessels']) == 3
    # Ended by max_steps: each simulator stopped only once the recorder held its last step's
    # rudder_cmd, so the answer to the last step is never left in flight (it was, now and then,
    # and the two runs' metrics then differed by that one sample).
    counts = {t: c['count'] for t, c in metrics['topics'].items()}
    for ns in metrics['vessels']:
        assert counts[f'{ns}/rudder_cmd'] == counts[f'{ns}/odom'] == 1501, ns
