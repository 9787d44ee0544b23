"""Bag round trip: messages built with rclpy classes, serialized by rclpy, written through the
recorder's BagWriter, read back with ship_mission.bag and compared exactly; metadata.yaml; errors;
replay_bag.py end to end."""
import json
import math

import numpy as np
import pytest
import yaml

pytest.importorskip('rclpy')
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry, Path as PathMsg
from rclpy.serialization import serialize_message
from rosbags.typesys import Stores, get_typestore
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension

from ship_mission import bag as bagmod
from ship_mission.recorder import BagWriter, reliable_qos

NS = 1_000_000_000
FINISH_INDEX = 150  # progress 'finished' flag set from this message on


def _odom(t_ns, x, y, yaw, u, v, r, child):
    m = Odometry()
    m.header.stamp.sec, m.header.stamp.nanosec = divmod(t_ns, NS)
    m.header.frame_id = 'map'
    m.child_frame_id = child
    m.pose.pose.position.x, m.pose.pose.position.y = x, y
    m.pose.pose.orientation.z, m.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    m.twist.twist.linear.x, m.twist.twist.linear.y, m.twist.twist.angular.z = u, v, r
    return m


def _path(points, yaws):
    p = PathMsg()
    p.header.frame_id = 'map'
    p.header.stamp.sec = 1
    for (x, y), yaw in zip(points, yaws):
        ps = PoseStamped()
        ps.header.frame_id = 'map'
        ps.pose.position.x, ps.pose.position.y = x, y
        ps.pose.orientation.z, ps.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        p.poses.append(ps)
    return p


@pytest.fixture(scope='module')
def synthetic(tmp_path_factory):
    """A two-vessel bag with random values; returns (bag path, the values written)."""
    rng = np.random.default_rng(7)
    n = 300
    path = tmp_path_factory.mktemp('bags') / 'run' / 'bag'
    truth = {}
    # Per-vessel rudder limits as the launcher stores them (a mixed platoon has several).
    meta = {'mission.time_source': 'sim', 'mission.rudder_limit_rad/vessel_0': '0.6',
            'mission.rudder_limit_rad/vessel_1': '0.35'}
    with BagWriter(path, custom_data=meta) as w:
        clock = w.add_topic('/clock', 'rosgraph_msgs/msg/Clock', [reliable_qos()])
        conns = {}
        for ns in ('/vessel_0', '/vessel_1'):
            for rel, ty in (('odom', 'nav_msgs/msg/Odometry'), ('rudder', 'std_msgs/msg/Float64'),
                            ('rudder_cmd', 'std_msgs/msg/Float64'), ('heading_cmd', 'std_msgs/msg/Float64'),
                            ('cross_track_error', 'std_msgs/msg/Float64'),
                            ('progress', 'std_msgs/msg/Float64MultiArray')):
                conns[f'{ns}/{rel}'] = w.add_topic(f'{ns}/{rel}', ty, [reliable_qos()])
            conns[f'{ns}/route'] = w.add_topic(f'{ns}/route', 'nav_msgs/msg/Path', [reliable_qos(1, True)])
        for ns in ('/vessel_0', '/vessel_1'):
            tv = truth[ns] = {}
            tv['t_ns'] = np.cumsum(rng.integers(1, 3 * NS // 10, n))  # irregular stamps, exact ns
            for k in ('x', 'y', 'u', 'v', 'r', 'rudder', 'rudder_cmd', 'heading_cmd', 'cross_track_error'):
                tv[k] = rng.normal(0.0, 100.0, n)
            tv['yaw'] = rng.uniform(-3.0, 3.0, n)
            tv['progress'] = rng.normal(size=(n, 3))
            tv['progress'][:, 2] = np.arange(n) >= FINISH_INDEX  # the 'finished' flag
            pts = rng.normal(0, 500, (6, 2))
            tv['route'] = (pts, rng.uniform(-3.0, 3.0, 6))
            w.write(conns[f'{ns}/route'], 0, serialize_message(_path(pts[:3], tv['route'][1][:3])))  # replaced later
            for i in range(n):
                t_ns = int(tv['t_ns'][i])
                # frame ids of varying length exercise the CDR alignment of the fast decoder
                child = f'{ns[1:]}/base_link' + 'x' * (i % 9)
                w.write(conns[f'{ns}/odom'], t_ns, serialize_message(
                    _odom(t_ns, tv['x'][i], tv['y'][i], tv['yaw'][i], tv['u'][i], tv['v'][i], tv['r'][i], child)))
                for k in ('rudder', 'rudder_cmd', 'heading_cmd', 'cross_track_error'):
                    w.write(conns[f'{ns}/{k}'], t_ns, serialize_message(Float64(data=float(tv[k][i]))))
                prog = Float64MultiArray(data=[float(v) for v in tv['progress'][i]])
                prog.layout.dim = [MultiArrayDimension(label='s_m,remaining_m,finished', size=3, stride=3)]
                w.write(conns[f'{ns}/progress'], t_ns, serialize_message(prog))
                if ns == '/vessel_0':
                    c = Clock()
                    c.clock.sec, c.clock.nanosec = divmod(t_ns, NS)
                    w.write(clock, t_ns, serialize_message(c))
            w.write(conns[f'{ns}/route'], int(tv['t_ns'][-1]), serialize_message(_path(pts, tv['route'][1])))
        counts = w.counts()
    return path, truth, counts


def test_round_trip_values_are_exact(synthetic):
    path, truth, _ = synthetic
    data = bagmod.read_bag(path)
    assert sorted(data.vessels) == ['/vessel_0', '/vessel_1']
    for ns, tv in truth.items():
        v = data.vessels[ns]
        assert v.missing == []
        np.testing.assert_array_equal(v.t, tv['t_ns'] / 1e9)
        for k in ('x', 'y', 'u', 'v', 'r'):
            np.testing.assert_array_equal(getattr(v, k), tv[k])
        np.testing.assert_allclose(v.yaw, tv['yaw'], rtol=0, atol=1e-12)  # through a quaternion
        for k in ('rudder', 'rudder_cmd', 'heading_cmd', 'cross_track_error'):
            series = getattr(v, k)
            np.testing.assert_array_equal(series.v, tv[k])
            np.testing.assert_array_equal(series.t, tv['t_ns'] / 1e9)  # log time (sim)
        np.testing.assert_array_equal(v.progress.v, tv['progress'])
        assert v.progress_labels == ['s_m', 'remaining_m', 'finished']
        pts, yaws = tv['route']
        assert v.route is not None and len(v.route.x) == 6  # the latest Path wins
        np.testing.assert_array_equal(np.c_[v.route.x, v.route.y], pts)
        np.testing.assert_allclose(v.route.yaw, yaws, rtol=0, atol=1e-12)


def test_fast_odometry_decoder_matches_rosbags_deserialisation():
    ts = get_typestore(Stores.ROS2_JAZZY)
    msgs = [serialize_message(_odom(i * 123456789 + 5, 1.5 * i, -2.0 * i, 0.1 * i, 3.0, -0.5, 0.01 * i,
                                    'b' * (i % 13))) for i in range(40)]
    fast = bagmod.decode_odometry(msgs)
    for i, raw in enumerate(msgs):
        m = ts.deserialize_cdr(raw, 'nav_msgs/msg/Odometry')
        assert fast['t'][i] == (m.header.stamp.sec * NS + m.header.stamp.nanosec) / 1e9
        assert fast['x'][i] == m.pose.pose.position.x and fast['y'][i] == m.pose.pose.position.y
        assert fast['qz'][i] == m.pose.pose.orientation.z and fast['qw'][i] == m.pose.pose.orientation.w
        assert fast['u'][i] == m.twist.twist.linear.x and fast['v'][i] == m.twist.twist.linear.y
        assert fast['r'][i] == m.twist.twist.angular.z


def test_metadata_yaml_lists_topics_counts_qos_and_hashes(synthetic):
    path, truth, counts = synthetic
    meta = yaml.safe_load((path / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert meta['version'] >= 9 and meta['storage_identifier'] == 'mcap'
    topics = {t['topic_metadata']['name']: t for t in meta['topics_with_message_count']}
    n = len(truth['/vessel_0']['t_ns'])
    assert topics['/vessel_0/odom']['message_count'] == n
    assert topics['/vessel_1/rudder_cmd']['message_count'] == n
    assert topics['/vessel_0/route']['message_count'] == 2
    assert topics['/clock']['message_count'] == n
    assert meta['message_count'] == sum(counts.values())
    route = topics['/vessel_1/route']['topic_metadata']
    assert route['type'] == 'nav_msgs/msg/Path' and route['serialization_format'] == 'cdr'
    assert route['offered_qos_profiles'][0]['durability'] == 'transient_local'
    assert route['offered_qos_profiles'][0]['reliability'] == 'reliable'
    assert route['type_description_hash'].startswith('RIHS01_')
    assert meta['custom_data']['mission.time_source'] == 'sim'


def test_wall_clock_bag_is_mapped_to_sim_time(tmp_path):
    wall0 = 1_700_000_000 * NS
    with BagWriter(tmp_path / 'bag', custom_data={'mission.time_source': 'wall'}) as w:
        clock = w.add_topic('/clock', 'rosgraph_msgs/msg/Clock')
        odom = w.add_topic('/odom', 'nav_msgs/msg/Odometry')
        rud = w.add_topic('/rudder', 'std_msgs/msg/Float64')
        for i in range(11):  # sim runs 2x faster than the wall clock
            sim_ns, wall_ns = i * NS, wall0 + i * NS // 2
            c = Clock()
            c.clock.sec, c.clock.nanosec = divmod(sim_ns, NS)
            w.write(clock, wall_ns, serialize_message(c))
            w.write(odom, wall_ns, serialize_message(_odom(sim_ns, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 'base_link')))
            w.write(rud, wall_ns + NS // 4, serialize_message(Float64(data=float(i))))
    v = bagmod.read_bag(tmp_path / 'bag', pair_by_sequence=False).vessels['/']  # root namespace
    assert v.timing['rudder'] == 'log time'
    np.testing.assert_allclose(v.rudder.t[:10], np.arange(10) + 0.5)
    np.testing.assert_array_equal(v.t, np.arange(11.0))


def test_errors_name_the_problem(tmp_path):
    with pytest.raises(bagmod.BagError, match='no such file'):
        bagmod.read_bag(tmp_path / 'nope')
    (tmp_path / 'plain').mkdir()
    with pytest.raises(bagmod.BagError, match='not a rosbag2 bag'):
        bagmod.read_bag(tmp_path / 'plain')
    with BagWriter(tmp_path / 'noodom') as w:
        w.write(w.add_topic('/x', 'std_msgs/msg/Float64'), 0, serialize_message(Float64(data=1.0)))
    with pytest.raises(bagmod.BagError, match='no nav_msgs/Odometry'):
        bagmod.read_bag(tmp_path / 'noodom')


def test_replay_bag_writes_metrics_and_plots(synthetic, tmp_path):
    import replay_bag  # scripts/replay_bag.py
    path, truth, _ = synthetic
    out = tmp_path / 'out'
    assert replay_bag.main([str(path), '--out', str(out), '--settle', '5', '--rudder-limit-deg', '35']) == 0
    result = json.loads((out / 'metrics.json').read_text())
    v0 = result['vessels']['/vessel_0']
    assert v0['settle_s'] == pytest.approx(5.0)
    e = truth['/vessel_0']['cross_track_error']
    t = truth['/vessel_0']['t_ns'] / 1e9
    # Statistics run from the settling time to the guidance's finish flag, not to the bag's end.
    window = (t >= t[0] + 5.0) & (t <= t[FINISH_INDEX])
    assert v0['xte_rms_m'] == pytest.approx(math.sqrt(np.mean(e[window] ** 2)))
    assert v0['rudder_limit_rad'] == pytest.approx(math.radians(35))
    assert v0['completion_source'] == 'guidance' and v0['completion_cut'] == 'guidance'
    assert v0['time_to_complete_s'] == pytest.approx(t[FINISH_INDEX] - t[0])
    rec0 = result['record']['vessels']['/vessel_0']
    assert rec0['tail_after_finish_s'] == pytest.approx(t[-1] - t[FINISH_INDEX])
    assert rec0['bag_end_s'] == pytest.approx(t[-1] - t[0])
    assert 'tail_after_finish_s' not in v0 and 'bag_end_s' not in v0
    assert v0['remaining_at_end_m'] == truth['/vessel_0']['progress'][FINISH_INDEX, 1]
    for name in ('track.png', 'cross_track_error.png', 'heading.png', 'rudder.png'):
        assert (out / name).stat().st_size > 10_000
    assert replay_bag.main([str(tmp_path / 'missing_bag')]) == 2


def test_each_vessel_gets_its_own_stored_rudder_limit(synthetic, tmp_path):
    from ship_mission.report import analyse_bag
    path, _, _ = synthetic
    result = analyse_bag(path, tmp_path, make_pngs=False)
    assert result['vessels']['/vessel_0']['rudder_limit_rad'] == pytest.approx(0.6)
    assert result['vessels']['/vessel_1']['rudder_limit_rad'] == pytest.approx(0.35)


def test_the_plots_get_the_settle_window_metrics_json_has(synthetic, tmp_path, monkeypatch):
    """ship_mission.report hands the plots (shaded settling windows) the settle_s it writes to
    metrics.json, per vessel: one home for the window (tests/unit/test_report_plots.py checks
    that the plots shade exactly what they are given)."""
    from ship_mission import plots
    from ship_mission.report import analyse_bag
    seen, real = {}, plots.make_plots

    def spy(vessels, out, limits, settle, **kw):
        seen['settle'] = settle
        return real(vessels, out, limits, settle, **kw)
    monkeypatch.setattr(plots, 'make_plots', spy)
    result = analyse_bag(synthetic[0], tmp_path, html=False)
    assert seen['settle'] == {ns: v['settle_s'] for ns, v in result['vessels'].items()}
    assert len(seen['settle']) == 2 and all(v > 0 for v in seen['settle'].values())
    from ship_mission.metric_info import VESSEL   # and each key the vessels get has its description
    assert set().union(*result['vessels'].values()) <= set(VESSEL)


def test_unstamped_topics_pair_with_odom_by_sequence_when_counts_match(tmp_path):
    # the recorder fell behind and /clock got ahead of the rudder queue: steps 3 and 4 were logged
    # at the clock of step 5 (as seen in a loaded run; log times never decrease, ties keep their
    # write order); another topic lost a message and keeps its log times
    with BagWriter(tmp_path / 'bag') as w:
        odom = w.add_topic('/v/odom', 'nav_msgs/msg/Odometry')
        rud = w.add_topic('/v/rudder', 'std_msgs/msg/Float64')
        xte = w.add_topic('/v/cross_track_error', 'std_msgs/msg/Float64')
        lagged = {3: 5, 4: 5}
        for k in range(8):
            w.write(odom, k * NS, serialize_message(_odom(k * NS, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 'v/base_link')))
            w.write(rud, lagged.get(k, k) * NS, serialize_message(Float64(data=float(k))))
            if k != 5:
                w.write(xte, k * NS, serialize_message(Float64(data=float(k))))
    v = bagmod.read_bag(tmp_path / 'bag').vessels['/v']
    assert v.timing == {'rudder': 'odom sequence', 'cross_track_error': 'log time'}
    np.testing.assert_array_equal(v.rudder.t, np.arange(8.0))
    np.testing.assert_array_equal(v.rudder.v, np.arange(8.0))
    np.testing.assert_array_equal(v.cross_track_error.t, [0, 1, 2, 3, 4, 6, 7])
