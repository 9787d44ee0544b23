"""The live view as Foxglove's own client libraries see it: ``@foxglove/ws-protocol`` 0.8.0 (which
offers only the protocol's old subprotocol name) with ``@foxglove/rosmsg2-serialization``, in a
Node script (foxglove_npm_client.mjs) that subscribes every channel the moment it is advertised,
during a short lockstep run with --live. The packages (foxglove_npm/package.json and its lock
file) are installed with ``npm ci`` into ros_ws/build/foxglove_npm (git-ignored, reused while
the lock file is unchanged); the test is skipped, with the reason, where node or npm is missing
or the registry cannot be reached."""
import json
import re
import shutil
import socket
import subprocess
import time

import pytest
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from harness import REPO_ROOT, _die_with_parent

FLAGSHIP = REPO_ROOT / 'scenarios' / 'flagship_mariner.yaml'
CLIENT = REPO_ROOT / 'tests' / 'integration' / 'foxglove_npm_client.mjs'
PACKAGES = REPO_ROOT / 'tests' / 'integration' / 'foxglove_npm'
CACHE = REPO_ROOT / 'ros_ws' / 'build' / 'foxglove_npm'
ODOM, FIX, TF = '/vessel_0/odom', '/vessel_0/fix', '/tf'
DURATION_S = 120.0
WALL_TIMEOUT_S = 150.0
NPM_TIMEOUT_S = 180.0


def _npm_modules():
    """The installed packages' folder, or pytest.skip with why they cannot be had."""
    node, npm = shutil.which('node'), shutil.which('npm')
    if node is None or npm is None:
        pytest.skip('node and npm are needed for the official Foxglove client')
    lock = (PACKAGES / 'package-lock.json').read_text()
    if (CACHE / 'package-lock.json').exists() and (CACHE / 'node_modules').is_dir() \
            and (CACHE / 'package-lock.json').read_text() == lock:
        return CACHE
    shutil.rmtree(CACHE, ignore_errors=True)
    CACHE.mkdir(parents=True)
    for name in ('package.json', 'package-lock.json'):
        shutil.copy(PACKAGES / name, CACHE / name)
    try:
        done = subprocess.run([npm, 'ci', '--ignore-scripts', '--no-audit', '--no-fund'], cwd=CACHE,
                              capture_output=True, text=True, timeout=NPM_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        done = None
    if done is None or done.returncode != 0:
        shutil.rmtree(CACHE, ignore_errors=True)
        why = 'timed out' if done is None else (done.stderr.strip().splitlines() or ['?'])[-1]
        pytest.skip(f'npm could not install the Foxglove client packages: {why}')
    return CACHE


def _free_port():
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def _lines(text):
    return [json.loads(ln) for ln in text.splitlines() if ln.startswith('{')]


def _step0_wall_time(run_dir):
    """Wall time (s) at which the simulator published step 0, from its log line's stamp."""
    log = (run_dir / 'logs' / 'vessel_0.vessel_node.log').read_text()
    m = re.search(r'\[(\d+\.\d+)\] \[[^\]]*\]: lockstep: publishing step 0', log)
    assert m, log[-2000:]
    return float(m.group(1))


@pytest.mark.timeout(NPM_TIMEOUT_S + WALL_TIMEOUT_S + 120)
def test_the_official_foxglove_client_gets_every_channel_decoded_in_order_from_step_0(
        launch, tmp_path):
    modules = _npm_modules()
    port = _free_port()
    out_path = tmp_path / 'npm_client.jsonl'
    # The client first, retrying until the view serves: it is connected before step 0.
    with open(out_path, 'wb') as out:
        client = subprocess.Popen(['node', str(CLIENT), f'ws://127.0.0.1:{port}', str(modules),
                                   str(WALL_TIMEOUT_S + 10)], stdout=out,
                                  stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                  start_new_session=True, preexec_fn=_die_with_parent)
    try:
        # --live-nice 0: every channel must deliver however loaded the machine is (test_live_view
        # covers a starved view). 120 s of sim time: on a busy machine the view gets little CPU
        # and a 30 s run (3 s wall at 10x real time) could end before it has subscribed every
        # topic it may take only once step 0 is out.
        run = launch(FLAGSHIP, '--duration', DURATION_S, '--live', '--live-port', port,
                     '--live-nice', 0, '--wall-timeout', WALL_TIMEOUT_S)
        code = run.wait(WALL_TIMEOUT_S + 20.0)
        try:
            client.wait(20.0)   # the server closing ends it
        except subprocess.TimeoutExpired:
            client.terminate()
            client.wait(10.0)
    finally:
        if client.poll() is None:
            client.kill()
            client.wait()
    text = out_path.read_text(errors='replace')
    assert code == 0, run.report()
    lines = _lines(text)
    events = {}
    for ln in lines:
        events.setdefault(ln['event'], []).append(ln)
    assert 'refused' not in events, text[-2000:]
    # The client offers only the old name and is served under it.
    assert [o['subprotocol'] for o in events['open']] == ['foxglove.websocket.v1'], text[:2000]
    # No refusal reaches the client (a subscription right after an advertisement included).
    assert not [s for s in events.get('status', ()) if s['level'] >= 2], events['status']
    channels = {c['topic']: c for c in events['channel']}
    advertised = {a['topic'] for a in events['advertise']}
    assert set(channels) == advertised and {ODOM, FIX, TF, '/vessel_0/nav_markers',
                                            '/vessel_0/rudder_cmd', '/clock'} <= advertised
    for topic, c in channels.items():
        assert c['messages'] >= 1, (topic, c, run.report())
        assert c['decodeErrors'] == 0, (topic, c)
        assert c['backwards'] == 0, (topic, c)          # log time never goes back per channel
        assert 0 <= c['firstLogTime'] <= c['lastLogTime'] <= DURATION_S * 1e9, (topic, c)

    first = {f['topic']: f for f in events['first']}
    odom = first[ODOM]['message']
    stamp_ns = odom['header']['stamp']['sec'] * 10**9 + odom['header']['stamp']['nanosec']
    assert first[ODOM]['logTime'] == stamp_ns   # the log time is the message's own stamp
    assert odom['child_frame_id'] == 'vessel_0/base_link' and odom['header']['frame_id'] == 'map'
    lead = _step0_wall_time(run.run_dir()) - events['open'][0]['wallTime']
    print(f'npm client connected {lead:.2f} s before step 0; first odom at {stamp_ns} ns')
    if lead > 0:
        assert stamp_ns == 0, 'connected before step 0, but the first odom is not step 0'
    # /tf: decoded with the advertised protobuf descriptors, the odom's pose at its stamp.
    tf = first[TF]['message']['transforms']
    assert [(t['parent_frame_id'], t['child_frame_id']) for t in tf] == \
        [('map', 'vessel_0/base_link')]
    assert first[TF]['logTime'] == stamp_ns
    assert tf[0]['timestamp'] == {'seconds': stamp_ns // 10**9, 'nanos': stamp_ns % 10**9}
    pos = odom['pose']['pose']['position']
    assert (tf[0]['translation']['x'], tf[0]['translation']['y']) == (pos['x'], pos['y'])
    # fix: the flagship gives no origin, so the default sea area; what the client decoded is the
    # bag's fix of that stamp, to the bit.
    fix = first[FIX]['message']
    key = (fix['header']['stamp']['sec'], fix['header']['stamp']['nanosec'])
    store = get_typestore(Stores.ROS2_JAZZY)
    with Reader(run.run_dir() / 'bag') as reader:
        conns = [c for c in reader.connections if c.topic == FIX]
        bag_fix = {}
        for conn, _, data in reader.messages(connections=conns):
            m = store.deserialize_cdr(data, conn.msgtype)
            bag_fix[(m.header.stamp.sec, m.header.stamp.nanosec)] = (m.latitude, m.longitude)
    assert bag_fix[key] == (fix['latitude'], fix['longitude'])


def test_the_client_gets_no_data_from_a_server_that_is_not_there(tmp_path):
    """The client script itself: against a closed port it connects to nothing, prints no
    channel, and ends by its time limit (a test that would pass with a broken client cannot)."""
    modules = _npm_modules()
    port = _free_port()
    t0 = time.monotonic()
    done = subprocess.run(['node', str(CLIENT), f'ws://127.0.0.1:{port}', str(modules), '2'],
                          capture_output=True, text=True, timeout=60)
    events = [ln['event'] for ln in _lines(done.stdout)]
    assert done.returncode == 0 and events == ['end'], done.stdout + done.stderr
    assert time.monotonic() - t0 >= 2.0
