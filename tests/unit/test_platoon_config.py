"""Platoon scenarios (ship_mission.platoon): parsing, refusals, per-vessel node parameters, the
stability checks, and the platoon part of the analysis (ship_mission.report, ship_mission.metrics).
No ROS graph is started.

- the shipped 5-vessel scenario wires a string: follower_node with the predecessor's odom, the
  lockstep settings, one more odom subscriber per follower of a vessel, one clock master;
- a string of five mixed models: each follower's stability check gets its own autopilot design
  (gain table) and speed (model trim), compared with the gain table file and the simulator;
- bad platoons are refused before anything starts, naming the vessel and the key (and
  run_mission.py exits 2 with that one line);
- the look-ahead limits: U / (2 zeta omega_n) for LOS, (U + 4 zeta^2 sigma) / (2 zeta omega_n)
  for an ILOS leader, times the margin (hand-computed); the amplification warning at
  4 zeta U / omega_n;
- analysis: string ratios and gap statistics by hand; a synthetic bag whose follower lags the
  master clock, lost messages and a lagging recorder: the follower's messages are timed by its
  own steps, every record ends at its vessel's completion, the gap at the predecessor's.
"""
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from ship_mission import metrics
from ship_mission.launcher import check_scenario, node_parameters, vessel_nodes
from ship_mission.platoon import autopilot_design, follow_lookahead
from ship_mission.scenario import ScenarioError, load_scenario
from ship_autopilot.gains import nomoto_gains
from ship_autopilot.pd import pd_gains
from ship_guidance.node_defaults import FOLLOWER_DEFAULTS, GUIDANCE_DEFAULTS
from ship_sim.models import make_model

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / 'scenarios' / 'platoon_mariner_5.yaml'
ROUTE = ROOT / 'scenarios' / 'routes' / 'platoon_curve.yaml'
GAINS = yaml.safe_load((ROOT / 'ros_ws/src/ship_autopilot/ship_autopilot/data/'
                        'autopilot_gains.yaml').read_text())['models']
MARINER_U = 7.7175


def write(tmp_path, platoon, name='platoon.yaml', **top):
    data = {'name': 'test_platoon', 'duration_s': 100.0, 'stepping': 'lockstep', 'dt_s': 0.1,
            'lockstep_timeout_s': 10.0, **top, 'platoon': platoon}
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def string(n=3, **extra):
    """A plain string of n Mariners on the test route, 400 m apart."""
    vessels = [{'namespace': f'vessel_{i}', 'model': 'mariner',
                'start': {'along_m': 400.0 * (n - 1 - i)}} for i in range(n)]
    return {'route': str(ROUTE), 'spacing_m': 400.0, 'vessels': vessels, **extra}


def refused(path, *parts):
    """load_scenario + check_scenario must raise one line naming the file and every part."""
    with pytest.raises(ScenarioError) as exc:
        check_scenario(load_scenario(path))
    text = str(exc.value)
    assert '\n' not in text and str(path) in text, text
    for part in parts:
        assert part in text, (part, text)
    return text


# -- the shipped scenario ---------------------------------------------------------------------

def test_shipped_scenario_wires_a_five_vessel_string():
    sc = load_scenario(SCENARIO)
    check_scenario(sc)
    assert [s.namespace for s in sc.vessels] == [f'vessel_{i}' for i in range(5)]
    assert sc.platoon.warnings == []
    assert sc.platoon.predecessor_wait_s < sc.lockstep_timeout_s
    for i, spec in enumerate(sc.vessels):
        params, _ = node_parameters(sc, spec, i, record=True)
        v = params['vessel_node']
        assert v['clock_master'] is (i == 0)
        assert v['stepping_mode'] == 'lockstep'
        # own guidance/follower + autopilot + recorder, + the next vessel's follower, + the
        # predecessor's simulator (it keeps within lockstep_follower_window steps of this odom)
        assert len(v['lockstep_odom_readers']) == 3 + int(i < 4) + int(i > 0)
        assert v['lockstep_follower_odom_topics'] == ('' if i == 4 else f'/vessel_{i + 1}/odom')
        assert v['current_speed'] == 0.5 and v['current_direction_deg'] == 90.0
        exes = [exe for exe, _ in vessel_nodes(spec)]
        if i == 0:
            assert spec.predecessor is None and 'follower_node' not in params
            assert exes == ['route_node', 'guidance_node', 'autopilot_node']
            assert params['guidance_node']['law'] == 'ilos'
        else:
            assert exes == ['route_node', 'follower_node', 'autopilot_node']
            f = params['follower_node']
            assert f['predecessor_odom_topic'] == f'/vessel_{i - 1}/odom'
            assert f['stepping_mode'] == 'lockstep' and f['spacing_m'] == 400.0
            # the k-th follower outwaits the (k-1)-th: k x the platoon's wait
            assert f['predecessor_wait_s'] == i * sc.platoon.predecessor_wait_s
            assert f['predecessor_wait_s'] < sc.lockstep_timeout_s
            assert f['min_lookahead_m'] == 400.0 and f['max_lookahead_m'] == 600.0
            # the node's own check gets the autopilot design of the scenario
            assert (f['autopilot_zeta'], f['autopilot_omega_n'], f['speed']) == (
                0.8, 0.12, pytest.approx(MARINER_U, abs=1e-3))
        assert params['route_node']['route_file'] == str(ROUTE.resolve())


def test_shipped_scenario_lookahead_at_the_gap_clears_the_amplification_bound():
    # 4 zeta U / omega_n = 4 * 0.8 * 7.7175 / 0.12 = 205.8 m (hand); the scenario asks for
    # 1.5 x that and steers with at least 400 m.
    sc = load_scenario(SCENARIO)
    for spec in sc.vessels[1:]:
        assert follow_lookahead(spec) == 400.0
        assert follow_lookahead(spec) > sc.platoon.stability_margin * 4 * 0.8 * MARINER_U / 0.12


# -- mixed models, other shapes ---------------------------------------------------------------

def test_five_mixed_models_get_their_own_autopilot_design_and_speed(tmp_path):
    models = ['mariner', 'tanker', 'container', 'nomoto1', 'mariner']
    pl = string(5)
    for v, m in zip(pl['vessels'], models):
        v['model'] = m
    pl['vessels'][0]['guidance'] = {'law': 'los', 'lookahead_m': 600.0}
    for v in pl['vessels'][1:]:
        v['guidance'] = {'min_lookahead_m': 600.0, 'lookahead_m': 600.0}
    pl['spacing_m'] = 800.0
    sc = load_scenario(write(tmp_path, pl))
    check_scenario(sc)
    for i, spec in enumerate(sc.vessels):
        params, _ = node_parameters(sc, spec, i, record=False)
        assert params['vessel_node']['model'] == models[i]
        assert params['autopilot_node']['vessel_model'] == models[i]
        # guidance + autopilot (no recorder), + the next follower, + the predecessor's gate
        assert len(params['vessel_node']['lockstep_odom_readers']) == 2 + int(i < 4) + int(i > 0)
        if i == 0:
            continue
        f = params['follower_node']
        model = make_model(models[i])
        assert f['autopilot_zeta'] == GAINS[models[i]]['zeta']
        assert f['autopilot_omega_n'] == GAINS[models[i]]['omega_n']
        assert f['speed'] == pytest.approx(float(model.surge_speed(model.initial_state())))


def test_default_waits_grow_with_the_depth_and_stay_below_the_simulator_timeout(tmp_path):
    sc = load_scenario(write(tmp_path, string(4)))   # depths 0..3, lockstep_timeout_s 10
    waits = [node_parameters(sc, s, i, True)[0].get('follower_node', {}).get('predecessor_wait_s')
             for i, s in enumerate(sc.vessels)]
    assert waits == [None, 10 / 6, 2 * 10 / 6, 3 * 10 / 6]   # deepest: half the timeout


def test_a_tree_counts_every_follower_of_a_vessel(tmp_path):
    pl = string(3)
    pl['vessels'][2]['predecessor'] = 'vessel_0'   # vessel_0 leads two followers
    sc = load_scenario(write(tmp_path, pl))
    check_scenario(sc)
    subs = [len(node_parameters(sc, s, i, True)[0]['vessel_node']['lockstep_odom_readers'])
            for i, s in enumerate(sc.vessels)]
    assert subs == [5, 4, 4]   # followers: + the predecessor's simulator's gate
    f2 = node_parameters(sc, sc.vessels[2], 2, True)[0]['follower_node']
    assert f2['predecessor_odom_topic'] == '/vessel_0/odom'


def test_a_second_leader_follows_the_route(tmp_path):
    pl = string(3)
    pl['vessels'][2]['predecessor'] = None
    sc = load_scenario(write(tmp_path, pl))
    check_scenario(sc)
    assert sc.vessels[2].predecessor is None
    params, _ = node_parameters(sc, sc.vessels[2], 2, True)
    assert 'guidance_node' in params and 'follower_node' not in params
    assert not params['vessel_node']['clock_master']


def test_per_vessel_current_replaces_the_platoon_current(tmp_path):
    pl = string(2, current={'speed_mps': 0.5, 'direction_deg': 90.0})
    pl['vessels'][1]['current'] = {'speed_mps': 0.2, 'direction_deg': 180.0}
    sc = load_scenario(write(tmp_path, pl))
    v0 = node_parameters(sc, sc.vessels[0], 0, True)[0]['vessel_node']
    v1 = node_parameters(sc, sc.vessels[1], 1, True)[0]['vessel_node']
    assert (v0['current_speed'], v0['current_direction_deg']) == (0.5, 90.0)
    assert (v1['current_speed'], v1['current_direction_deg']) == (0.2, 180.0)


# -- refusals ---------------------------------------------------------------------------------

def test_unknown_predecessor_is_refused_naming_the_vessel(tmp_path):
    pl = string(3)
    pl['vessels'][2]['predecessor'] = 'vessel_9'
    refused(write(tmp_path, pl), 'platoon.vessels[2] (vessel_2).predecessor', 'vessel_9')


def test_cycle_is_refused_naming_it(tmp_path):
    pl = string(3)
    pl['vessels'][0]['predecessor'] = 'vessel_2'   # 0 <- 2 <- 1 <- 0: no leader
    text = refused(write(tmp_path, pl), 'vessel_0', 'cycle')
    assert 'vessel_0 -> vessel_2 -> vessel_1 -> vessel_0' in text


def test_following_itself_is_refused(tmp_path):
    pl = string(2)
    pl['vessels'][1]['predecessor'] = 'vessel_1'
    refused(write(tmp_path, pl), 'platoon.vessels[1] (vessel_1).predecessor', 'itself')


def test_two_vessels_in_one_namespace_are_refused(tmp_path):
    pl = string(3)
    pl['vessels'][2]['namespace'] = 'vessel_1'
    refused(write(tmp_path, pl), 'platoon.vessels[2].namespace', 'vessel_1',
            'platoon.vessels[1]')


@pytest.mark.parametrize('case, parts', [
    ('route', ('platoon.vessels[1] (vessel_1).route', 'share platoon.route')),
    ('leader_spacing', ('platoon.vessels[0] (vessel_0).spacing_m',)),
    ('glue', ('platoon.vessels[1] (vessel_1).guidance.predecessor_odom_topic', 'launcher')),
    ('no_spacing', ('platoon.vessels[1] (vessel_1).spacing_m',)),
    ('wait', ('platoon.predecessor_wait_s', 'lockstep_timeout_s')),
    ('both', ('platoon', 'not both')),
    ('model', ('platoon.vessels[1] (vessel_1).model', 'titanic')),
])
def test_bad_platoon_keys_are_refused(tmp_path, case, parts):
    pl, top = string(2), {}
    if case == 'route':
        pl['vessels'][1]['route'] = str(ROUTE)
    elif case == 'leader_spacing':
        pl['vessels'][0]['spacing_m'] = 300.0
    elif case == 'glue':
        pl['vessels'][1]['guidance'] = {'predecessor_odom_topic': '/x/odom'}
    elif case == 'no_spacing':
        del pl['spacing_m']
    elif case == 'wait':   # depth 1 x 10 s is not below lockstep_timeout_s 10 s
        pl['predecessor_wait_s'] = 10.0
    elif case == 'both':
        top['vessels'] = {'vessel_0': {'model': 'mariner', 'route': str(ROUTE)}}
    elif case == 'model':
        pl['vessels'][1]['model'] = 'titanic'
    refused(write(tmp_path, pl, **top), *parts)


# -- stability limits -------------------------------------------------------------------------

# Mariner with the PD of omega_n 0.12 rad/s, zeta 0.8: U / (2 zeta omega_n) = 40.195 m (hand).
LIMIT = MARINER_U / (2 * 0.8 * 0.12)
AUTOPILOT = {'controller': 'pd', 'omega_n': 0.12, 'zeta': 0.8}


def _limit_case(tmp_path, follower_min, leader=None, margin=1.0, allow=False):
    pl = string(2, stability_margin=margin, allow_unstable=allow)
    for v in pl['vessels']:
        v['autopilot'] = dict(AUTOPILOT)
        v['speed_mps'] = MARINER_U
    pl['vessels'][0]['guidance'] = leader or {'law': 'los', 'lookahead_m': 300.0}
    pl['vessels'][1]['guidance'] = {'min_lookahead_m': follower_min, 'lookahead_m': 300.0}
    return write(tmp_path, pl)


def test_follower_lookahead_below_the_limit_is_refused_above_it_accepted(tmp_path):
    text = refused(_limit_case(tmp_path, 0.95 * LIMIT),
                   'platoon.vessels[1] (vessel_1).guidance.min_lookahead_m', 'allow_unstable')
    assert f'{LIMIT:.1f} m' in text
    check_scenario(load_scenario(_limit_case(tmp_path, 1.05 * LIMIT)))


def test_margin_scales_the_limit(tmp_path):
    check_scenario(load_scenario(_limit_case(tmp_path, 1.2 * LIMIT, margin=1.0)))
    refused(_limit_case(tmp_path, 1.2 * LIMIT, margin=1.5), 'vessel_1', 'min_lookahead_m')


def test_allow_unstable_accepts_and_tells_the_node(tmp_path):
    sc = load_scenario(_limit_case(tmp_path, 0.5 * LIMIT, allow=True))
    check_scenario(sc)
    assert node_parameters(sc, sc.vessels[1], 1, True)[0]['follower_node']['allow_unstable']


def test_follower_with_integral_action_uses_the_integral_limit(tmp_path):
    # The follower node refuses min_lookahead below (U + 4 zeta^2 sigma) / (2 zeta omega_n);
    # the launcher must refuse the same scenario before starting anything.
    sigma = 2.0
    ilos = (MARINER_U + 4 * 0.8 ** 2 * sigma) / (2 * 0.8 * 0.12)
    d = 0.5 * (LIMIT + ilos)   # above the LOS limit, below the integral one
    path = _limit_case(tmp_path, d)
    pl = yaml.safe_load(path.read_text())
    pl['platoon']['vessels'][1]['guidance']['integral_gain'] = sigma
    path.write_text(yaml.safe_dump(pl))
    refused(path, 'platoon.vessels[1] (vessel_1).guidance.min_lookahead_m', f'{ilos:.1f} m')
    check_scenario(load_scenario(_limit_case(tmp_path, d)))   # without integral action: fine


def test_a_followers_guidance_is_checked_by_follower_nodes_own_ranges(tmp_path):
    # follower_node takes integral_gain 0 (no integral action: Angelopoulos's law), which
    # guidance_node's ILOS gain refuses; the check must apply the follower's schema, and the
    # variant scenario that runs that law must pass it
    pl = string(2)
    pl['vessels'][1]['guidance'] = {'aim': 'predecessor', 'integral_gain': 0.0}
    check_scenario(load_scenario(write(tmp_path, pl)))
    pl['vessels'][1]['guidance'] = {'integral_gain': -1.0}
    refused(write(tmp_path, pl), 'platoon.vessels[1] (vessel_1).guidance.integral_gain',
            '[0.0, 100.0]')
    check_scenario(load_scenario(ROOT / 'scenarios' / 'platoon_mariner_5_predecessor.yaml'))


def test_ilos_leader_uses_the_integral_limit(tmp_path):
    # (U + 4 zeta^2 sigma) / (2 zeta omega_n) with sigma 0.5 m/s = 46.86 m (hand)
    ilos = (MARINER_U + 4 * 0.8 ** 2 * 0.5) / (2 * 0.8 * 0.12)
    d = 0.5 * (LIMIT + ilos)   # above the LOS limit, below the ILOS one
    refused(_limit_case(tmp_path, 300.0, leader={'law': 'ilos', 'lookahead_m': d,
                                                 'integral_gain': 0.5}),
            'platoon.vessels[0] (vessel_0).guidance.lookahead_m', f'{ilos:.1f} m')
    check_scenario(load_scenario(_limit_case(tmp_path, 300.0, leader={
        'law': 'los', 'lookahead_m': d})))


def test_amplification_warning_names_the_vessel(tmp_path):
    pl = string(2, spacing_m=150.0)
    for v in pl['vessels']:
        v['autopilot'] = dict(AUTOPILOT)
        v['speed_mps'] = MARINER_U
    pl['vessels'][1]['guidance'] = {'min_lookahead_m': 100.0, 'lookahead_m': 300.0}
    sc = load_scenario(write(tmp_path, pl))
    check_scenario(sc)
    assert len(sc.platoon.warnings) == 1 and 'vessel_1' in sc.platoon.warnings[0]
    assert f'{4 * 0.8 * MARINER_U / 0.12:.1f} m' in sc.platoon.warnings[0]
    pl['spacing_m'] = 250.0
    sc = load_scenario(write(tmp_path, pl))
    check_scenario(sc)
    assert sc.platoon.warnings == []


def test_pd_gains_are_read_back_as_their_design():
    nm = nomoto_gains('mariner')
    k1, k2 = pd_gains(nm['a'], nm['b'], omega_n=0.1, zeta=0.9)
    zeta, omega_n, source = autopilot_design('mariner', {'controller': 'pd', 'k1': k1, 'k2': k2})
    assert (zeta, omega_n, source) == (pytest.approx(0.9), pytest.approx(0.1), 'k1, k2')
    assert autopilot_design('tanker', {'controller': 'fuzzy_pid'})[:2] == (
        GAINS['tanker']['zeta'], GAINS['tanker']['omega_n'])


def test_node_defaults_used_by_the_check_match_the_node_configs():
    cfg = ROOT / 'ros_ws' / 'src' / 'ship_guidance' / 'config'
    guidance = yaml.safe_load((cfg / 'guidance.yaml').read_text())['/**']['ros__parameters']
    follower = yaml.safe_load((cfg / 'follower.yaml').read_text())['/**']['ros__parameters']
    assert {k: guidance[k] for k in GUIDANCE_DEFAULTS} == GUIDANCE_DEFAULTS
    assert {k: follower[k] for k in FOLLOWER_DEFAULTS} == FOLLOWER_DEFAULTS


@pytest.mark.parametrize('case', ['cycle', 'unstable'])
def test_run_mission_exits_2_with_one_line(tmp_path, case):
    if case == 'cycle':
        pl = string(3)
        pl['vessels'][0]['predecessor'] = 'vessel_1'
        path, key = write(tmp_path, pl), 'vessel_0'
    else:
        path, key = _limit_case(tmp_path, 0.5 * LIMIT), 'vessel_1'
    out = subprocess.run([sys.executable, str(ROOT / 'scripts' / 'run_mission.py'), str(path),
                          '--runs', str(tmp_path / 'runs')], capture_output=True, text=True,
                         timeout=120)
    lines = [ln for ln in out.stderr.splitlines() if ln.strip()]
    assert out.returncode == 2, out.stderr
    assert len(lines) == 1 and key in lines[0] and str(path) in lines[0], lines
    assert not (tmp_path / 'runs').exists()


# -- analysis ---------------------------------------------------------------------------------

def test_string_ratios_and_gap_stats_by_hand():
    preds = {'a': None, 'b': 'a', 'c': 'b', 'd': 'c'}
    r = metrics.string_ratios({'a': 2.0, 'b': 3.0, 'c': 1.5, 'd': None}, preds)
    assert r == {'b': 1.5, 'c': 0.5, 'd': None}
    t = np.arange(6.0)
    g = metrics.gap_error_stats(t, [9.0, 9.0, 3.0, -4.0, np.nan, 0.0], t_from=2.0)
    assert g['gap_error_rms_m'] == pytest.approx(math.sqrt((9 + 16 + 0) / 3))
    assert g['gap_error_mean_m'] == pytest.approx(-1 / 3)
    assert g['gap_error_max_abs_m'] == 4.0
    assert (g['gap_error_samples'], g['gap_error_undefined_samples']) == (3, 1)


def _synthetic_platoon_bag(path):
    """Leader /vessel_0 (clock master) and follower /vessel_1 running behind it, 400 steps of
    0.1 s each, wall-clock log times. The follower's cross_track_error and gap_error carry their
    own step index k as value (so their true time is k / 10); the recorder lost follower odom
    steps 200-219 and cross-track steps 100-149, and logged cross-track steps 150-199 in one
    burst (their log times alone would put them all at step 174.5). Finish flags from step 250
    (leader) and 300 (follower). Returns the leader's xte by step (truth)."""
    pytest.importorskip('rclpy')
    from nav_msgs.msg import Odometry
    from rclpy.serialization import serialize_message
    from rosgraph_msgs.msg import Clock
    from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension
    from ship_mission.recorder import BagWriter, reliable_qos

    n, ms = 400, 1_000_000
    lead_xte = 5.0 * np.sin(np.arange(n) / 30.0)
    log = []   # (log ns, topic, message)

    def odom(k):
        m = Odometry()
        m.header.stamp.sec, m.header.stamp.nanosec = divmod(k * 100 * ms, 1000 * ms)
        m.header.frame_id = 'map'
        m.pose.pose.position.y = 7.7 * k * 0.1
        m.pose.pose.orientation.w = 1.0
        return m

    def progress(k, done):
        p = Float64MultiArray(data=[0.0, 0.0, 0.0, 1.0 if done else 0.0])
        p.layout.dim = [MultiArrayDimension(label='s_m,remaining_m,leg,finished', size=4,
                                            stride=1)]
        return p

    for k in range(n):
        t0, t1 = k * ms, 100 * ms + 3 * k * ms   # the follower lags in wall time
        c = Clock()
        c.clock.sec, c.clock.nanosec = divmod(k * 100 * ms, 1000 * ms)
        log += [(t0, '/clock', c), (t0, '/vessel_0/odom', odom(k)),
                (t0 + 1, '/vessel_0/cross_track_error', Float64(data=float(lead_xte[k]))),
                (t0 + 1, '/vessel_0/progress', progress(k, k >= 250))]
        if not 200 <= k < 220:
            log.append((t1, '/vessel_1/odom', odom(k)))
        if not 100 <= k < 200:
            log.append((t1 + 1, '/vessel_1/cross_track_error', Float64(data=float(k))))
        if 150 <= k < 200:   # one burst, logged half-way through those steps (174.5)
            log.append((100 * ms + 3 * 174 * ms + 3 * ms // 2, '/vessel_1/cross_track_error',
                        Float64(data=float(k))))
        log += [(t1 + 1, '/vessel_1/gap_error', Float64(data=float(k))),
                (t1 + 1, '/vessel_1/progress', progress(k, k >= 300))]
    log.sort(key=lambda e: e[0])
    types = {'/clock': 'rosgraph_msgs/msg/Clock', 'odom': 'nav_msgs/msg/Odometry',
             'progress': 'std_msgs/msg/Float64MultiArray'}
    with BagWriter(path, custom_data={'mission.time_source': 'wall'}) as w:
        conns = {}
        for t_ns, topic, msg in log:
            if topic not in conns:
                kind = types.get(topic) or types.get(topic.rsplit('/', 1)[1],
                                                     'std_msgs/msg/Float64')
                conns[topic] = w.add_topic(topic, kind, [reliable_qos()])
            w.write(conns[topic], t_ns, serialize_message(msg))
    return lead_xte


def test_platoon_analysis_times_follower_topics_by_its_own_steps(tmp_path):
    from ship_mission.report import analyse_bag
    lead_xte = _synthetic_platoon_bag(tmp_path / 'bag')
    m = analyse_bag(tmp_path / 'bag', tmp_path, settle_s=5.0, make_pngs=True,
                    platoon={'/vessel_0': None, '/vessel_1': '/vessel_0'})
    from ship_mission import bag as bagmod
    # what the analysis saw, re-read the same way: every follower message at its own step
    data = bagmod.read_bag(tmp_path / 'bag')
    from ship_mission.report import prepare_records
    gaps, ends, _ = prepare_records(tmp_path / 'bag', data, {'/vessel_0': None,
                                                             '/vessel_1': '/vessel_0'})
    assert ends == {'/vessel_0': (25.0, 'guidance'), '/vessel_1': (30.0, 'guidance')}
    xte = data.vessels['/vessel_1'].cross_track_error
    np.testing.assert_allclose(xte.t, xte.v / 10.0, atol=1e-9)
    assert xte.t[-1] == pytest.approx(30.0)              # ends at its own finish (step 300)
    assert data.vessels['/vessel_1'].t[-1] == pytest.approx(30.0)
    assert data.vessels['/vessel_0'].t[-1] == pytest.approx(25.0)
    g = gaps['/vessel_1']
    np.testing.assert_allclose(g.t, g.v / 10.0, atol=1e-9)
    assert g.t[-1] == pytest.approx(25.0)                # the predecessor's finish
    # metrics: gap after settling = steps 50..250; peaks after settling, up to each finish
    row = m['platoon']['/vessel_1']
    steps = np.arange(50, 251, dtype=float)
    assert row['gap_error_mean_m'] == pytest.approx(steps.mean())
    assert row['gap_error_samples'] == steps.size
    lead_peak = np.max(np.abs(lead_xte[50:251]))
    assert m['platoon']['/vessel_0']['xte_peak_m'] == pytest.approx(lead_peak)
    assert row['xte_peak_m'] == 300.0
    assert row['string_peak_ratio'] == pytest.approx(300.0 / lead_peak)
    assert row['time_to_complete_s'] == pytest.approx(30.0)
    assert {'gap_error.png', 'platoon_string.png'} <= set(m['plots'])
