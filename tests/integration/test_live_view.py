"""The live view (run_mission.py --live) as a viewer sees it: a Foxglove WebSocket client that
subscribes every channel, decodes odom and rudder_cmd with the schemas the server advertised,
and finds exactly what the bag recorded (test_live_view_npm: the official npm client)."""
import socket

import numpy as np
import yaml
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from harness import REPO_ROOT
from ship_mission.foxglove_client import FoxgloveClient

FLAGSHIP = REPO_ROOT / 'scenarios' / 'flagship_mariner.yaml'
ODOM, RUDDER_CMD = '/vessel_0/odom', '/vessel_0/rudder_cmd'
DURATION_S = 60.0
WALL_TIMEOUT_S = 150.0


def _free_port():
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def _decoder(channel):
    """A deserializer built from nothing but the advertised channel (schema text and name)."""
    assert channel['encoding'] == 'cdr' and channel['schemaEncoding'] == 'ros2msg', channel
    name = channel['schemaName']
    store = get_typestore(Stores.EMPTY)
    store.register(get_types_from_msg(channel['schema'], name))
    return lambda data: store.deserialize_cdr(data, name)


def _bag_messages(bag, topics):
    out = {t: [] for t in topics}
    with Reader(bag) as reader:
        conns = [c for c in reader.connections if c.topic in topics]
        for conn, log_time, data in reader.messages(connections=conns):
            out[conn.topic].append((log_time, bytes(data)))
    return out


def test_a_foxglove_client_receives_what_the_bag_records(launch):
    port = _free_port()
    # --live-nice 0: the view keeps up however loaded the test machine is (at the default
    # priority a busy machine may starve it; the next test covers that case).
    run = launch(FLAGSHIP, '--duration', DURATION_S, '--live', '--live-port', port,
                 '--live-nice', 0, '--wall-timeout', WALL_TIMEOUT_S)
    client = FoxgloveClient(f'ws://127.0.0.1:{port}', connect_timeout_s=60.0)
    try:
        code = run.wait(WALL_TIMEOUT_S + 20.0)
    finally:
        client.close()
    assert code == 0, run.report()
    assert f'live view: ws://127.0.0.1:{port}' in run.stdout(), run.report()
    assert client.error is None or 'connection ended' in client.error, client.error
    assert client.server_info is not None
    assert {ODOM, RUDDER_CMD, '/tf', '/clock', '/vessel_0/fix', '/vessel_0/nav_markers'} \
        <= set(client.channels)
    for topic in client.channels:   # every channel delivers, its log time never going back
        times = [t for t, _ in client.messages.get(topic, ())]
        assert times and all(np.diff(times) >= 0), (topic, times[:20], run.report())
    assert client.channels['/tf']['schemaName'] == 'foxglove.FrameTransforms'
    assert client.channels[ODOM]['schemaName'] == 'nav_msgs/msg/Odometry'
    assert client.channels[RUDDER_CMD]['schemaName'] == 'std_msgs/msg/Float64'
    # The run lasts DURATION_S / 0.1 = 600 steps; the bridge subscribes once step 0 is out and
    # may lose messages (best effort), but a client connected through the run sees most of them.
    assert client.count(ODOM) >= 50 and client.count(RUDDER_CMD) >= 50, \
        (client.count(ODOM), client.count(RUDDER_CMD), run.report())

    bag = _bag_messages(run.run_dir() / 'bag', {ODOM, RUDDER_CMD})
    # odom: every message received is byte for byte the bag's message of the same stamp, and
    # decodes (with the advertised schema alone) to the same values.
    odom = _decoder(client.channels[ODOM])
    bag_odom = {}
    for _, data in bag[ODOM]:
        m = odom(data)
        bag_odom[(m.header.stamp.sec, m.header.stamp.nanosec)] = data
    _check_display_topics(run.run_dir() / 'bag', odom)
    stamps = []
    for log_time, data in client.messages[ODOM]:
        m = odom(data)
        key = (m.header.stamp.sec, m.header.stamp.nanosec)
        assert key in bag_odom, f'odom stamped {key} is not in the bag'
        assert data == bag_odom[key]
        ref = odom(bag_odom[key])
        assert (m.pose.pose.position.x, m.pose.pose.position.y) == \
            (ref.pose.pose.position.x, ref.pose.pose.position.y)
        assert m.child_frame_id == 'vessel_0/base_link'
        stamps.append(m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec)
        # Log time: the message's own stamp (the sim time it describes).
        assert log_time == m.header.stamp.sec * 10**9 + m.header.stamp.nanosec
    assert np.all(np.diff(stamps) > 0), 'odom out of order'
    # rudder_cmd has no stamp: what was received is the bag's sequence with some messages
    # possibly left out (an ordered subsequence), values decoded from the advertised schema.
    cmd = _decoder(client.channels[RUDDER_CMD])
    got = [cmd(d).data for _, d in client.messages[RUDDER_CMD]]
    ref = [cmd(d).data for _, d in bag[RUDDER_CMD]]
    it = iter(ref)
    assert all(any(v == r for r in it) for v in got), 'rudder_cmd is not a subsequence of the bag'
    assert np.all(np.abs(got) <= np.radians(40.0) + 1e-12)   # the Mariner's rudder limit


def _check_display_topics(bag, odom):
    """nav_display_node in the bag: display_rate_hz (2) fixes per sim second, one at every
    display period from step 0 on (the simulator's odom_display keeps every frame for the
    display; the last ones may be cut by the end of the run), each at the WGS-84 point of the
    odom of its stamp (flagship: no origin given, so the default sea area)."""
    from ship_guidance.nav_display import (DEFAULT_DISPLAY_RATE_HZ, DEFAULT_ORIGIN_DEG,
                                           enu_to_geodetic)
    store = get_typestore(Stores.ROS2_JAZZY)
    fixes = _bag_messages(bag, {'/vessel_0/fix'})['/vessel_0/fix']
    assert 0 < len(fixes) <= DEFAULT_DISPLAY_RATE_HZ * DURATION_S + 1
    stamps = [store.deserialize_cdr(d, 'sensor_msgs/msg/NavSatFix').header.stamp for _, d in fixes]
    k = np.array([s.sec + 1e-9 * s.nanosec for s in stamps]) * DEFAULT_DISPLAY_RATE_HZ
    assert np.allclose(k, np.arange(len(k)), atol=1e-6), k[:20]
    # Every frame has the hull; the trail comes when it gains a point, the route in the first
    # frame and every route_period_s (the node's defaults, in its config file).
    params = yaml.safe_load((REPO_ROOT / 'ros_ws' / 'src' / 'ship_guidance' / 'config' /
                             'nav_display.yaml').read_text())['/**']['ros__parameters']
    frames = _bag_messages(bag, {'/vessel_0/nav_markers'})['/vessel_0/nav_markers']
    assert abs(len(frames) - len(fixes)) <= 1   # the run's end may cut one of a pair
    per_trail = round(params['trail_period_s'] * DEFAULT_DISPLAY_RATE_HZ)
    per_route = round(params['route_period_s'] * DEFAULT_DISPLAY_RATE_HZ)
    for i, (_, data) in enumerate(frames):
        ns = {m.ns for m in store.deserialize_cdr(data, 'visualization_msgs/msg/MarkerArray').markers}
        want = {'hull', 'hull_fill', 'label'} | ({'trail'} if i % per_trail == 0 and i else set())
        assert ns == want | ({'route'} if i % per_route == 0 else set()), (i, ns)
    poses = {}
    for _, data in _bag_messages(bag, {ODOM})[ODOM]:
        m = odom(data)
        poses[(m.header.stamp.sec, m.header.stamp.nanosec)] = m.pose.pose.position
    for _, data in fixes:
        f = store.deserialize_cdr(data, 'sensor_msgs/msg/NavSatFix')
        p = poses[(f.header.stamp.sec, f.header.stamp.nanosec)]
        assert (f.latitude, f.longitude) == enu_to_geodetic(p.x, p.y, *DEFAULT_ORIGIN_DEG)
        assert f.header.frame_id == 'vessel_0/base_link'


def test_a_slow_client_on_every_topic_never_holds_the_lockstep_run_back(launch):
    """A client that reads one frame every 50 ms (far below the run's ~100 messages per sim
    second at several times real time): the run still takes every step without a lockstep
    timeout, the bag is complete, and the bridge reports what it forwarded and lost."""
    port = _free_port()
    run = launch(FLAGSHIP, '--duration', DURATION_S, '--live', '--live-port', port,
                 '--wall-timeout', WALL_TIMEOUT_S)
    client = FoxgloveClient(f'ws://127.0.0.1:{port}', connect_timeout_s=60.0, read_delay_s=0.05)
    try:
        code = run.wait(WALL_TIMEOUT_S + 20.0)
    finally:
        client.close()
    assert code == 0, run.report()
    assert 'record complete' in run.stdout(), run.report()
    logs = run.run_dir() / 'logs'
    vessel = (logs / 'vessel_0.vessel_node.log').read_text()
    assert '0 lockstep timeouts' in vessel and '(deterministic run)' in vessel, vessel[-2000:]
    assert len(client.channels) >= 10, sorted(client.channels)   # every topic advertised
    view = (logs / 'live_view.log').read_text()
    assert 'messages forwarded' in view and 'lost before the bridge' in view, view
