"""Scenario parsing and launcher wiring of collision avoidance: a vessel's `colav:` block and
the `traffic:` section (ship_mission.scenario, ship_mission.launcher)."""
from pathlib import Path

import pytest

from ship_mission.launcher import (COLAV_REMAP, check_scenario, node_parameters, node_remaps,
                              vessel_nodes)
from ship_mission.scenario import ScenarioError, load_scenario

ROOT = Path(__file__).resolve().parents[2]
HEAD_ON = ROOT / 'scenarios' / 'head_on_mariner_2.yaml'



def test_head_on_scenario_wires_colav_between_guidance_and_autopilot():
    sc = load_scenario(HEAD_ON)
    check_scenario(sc)
    own, tgt = sc.vessels
    assert (own.namespace, own.traffic, tgt.namespace, tgt.traffic) == \
        ('vessel_0', False, 'target_0', True)
    assert ('colav_node', 'ship_guidance') in vessel_nodes(own)
    assert ('colav_node', 'ship_guidance') not in vessel_nodes(tgt)
    assert node_remaps(own, 'guidance_node') == COLAV_REMAP
    assert node_remaps(own, 'autopilot_node') == [] and node_remaps(tgt, 'guidance_node') == []
    p_own, _ = node_parameters(sc, own, 0, record=True)
    p_tgt, _ = node_parameters(sc, tgt, 1, record=True)
    assert p_own['colav_node']['target_topics'] == ['/target_0/odom']
    assert p_own['colav_node']['method'] == 'sbmpc'
    assert p_own['colav_node']['pairing'] == 'sequence'
    assert 'colav_node' not in p_tgt
    # own odom: guidance, autopilot, its colav_node, the recorder, the target's gate
    assert p_own['vessel_node']['lockstep_odom_readers'] == [
        '/vessel_0/guidance_node', '/vessel_0/autopilot_node', '/vessel_0/colav_node',
        '/mission_recorder', '/target_0/vessel_node']
    # target odom: the own colav_node, guidance, autopilot, recorder
    assert sorted(p_tgt['vessel_node']['lockstep_odom_readers']) == [
        '/mission_recorder', '/target_0/autopilot_node', '/target_0/guidance_node',
        '/vessel_0/colav_node']
    assert p_tgt['vessel_node']['lockstep_follower_odom_topics'] == '/vessel_0/odom'
    assert 'lockstep_follower_odom_topics' not in p_own['vessel_node']
    # without a recorder: the others
    assert '/mission_recorder' not in node_parameters(sc, own, 0, record=False)[0][
        'vessel_node']['lockstep_odom_readers']


def test_realtime_traffic_is_not_gated(scenario_variant):
    sc = load_scenario(scenario_variant(HEAD_ON, lambda d: d.update(stepping='realtime')))
    p_tgt, _ = node_parameters(sc, sc.vessels[1], 1, record=True)
    assert 'lockstep_follower_odom_topics' not in p_tgt['vessel_node']
    p_own, _ = node_parameters(sc, sc.vessels[0], 0, record=True)
    assert p_own['colav_node']['pairing'] == 'latest'


def _colav_in_traffic(d):
    d['traffic']['target_0']['colav'] = {}


def _unknown_traffic_key(d):
    d['traffic']['target_0']['colour'] = 'red'


def _clash(d):
    d['traffic']['vessel_0'] = d['traffic'].pop('target_0')


def _traffic_not_mapping(d):
    d['traffic'] = ['target_0']


def _colav_not_mapping(d):
    d['vessels']['vessel_0']['colav'] = 'sbmpc'


@pytest.mark.parametrize('change, key', [
    (_colav_in_traffic, 'traffic.target_0.colav'),
    (_unknown_traffic_key, 'traffic.target_0.colour'),
    (_clash, 'traffic.vessel_0'),
    (_traffic_not_mapping, 'traffic'),
    (_colav_not_mapping, 'vessels.vessel_0.colav'),
])
def test_bad_traffic_or_colav_blocks_are_refused_naming_the_key(scenario_variant, change, key):
    with pytest.raises(ScenarioError, match=f': {key}: '):
        load_scenario(scenario_variant(HEAD_ON, change))


def test_unknown_colav_parameter_is_refused_with_the_closest_name(scenario_variant):
    sc = load_scenario(scenario_variant(HEAD_ON, lambda d: d['vessels']['vessel_0']['colav'].update(
        d_saf_m=500.0)))
    with pytest.raises(ScenarioError, match=r'vessels\.vessel_0\.colav\.d_saf_m: colav_node has '
                       r'no parameter .*did you mean "d_safe_m"'):
        check_scenario(sc)


def test_traffic_parameters_are_checked_like_vessels(scenario_variant):
    sc = load_scenario(scenario_variant(HEAD_ON, lambda d: d['traffic']['target_0']['guidance'].update(
        lookahed_m=1.0)))
    with pytest.raises(ScenarioError, match=r'traffic\.target_0\.guidance\.lookahed_m'):
        check_scenario(sc)


def test_traffic_beside_a_platoon_is_refused(scenario_variant):
    def change(d):
        d['platoon'] = {}
        del d['vessels']
    with pytest.raises(ScenarioError, match=': (platoon|traffic)'):
        load_scenario(scenario_variant(HEAD_ON, change))


def test_realtime_simulator_waits_for_the_nodes_that_follow_its_odom():
    """Realtime: a vessel's simulator starts only once its guidance (subscribed after the route
    came), autopilot and colav_node follow its odom; a node that never does is warned about."""
    from types import SimpleNamespace

    from ship_mission.launcher import wait_for_odom_subscribers
    sc = load_scenario(HEAD_ON)
    own = sc.vessels[0]
    joined = []   # subscribers of /vessel_0/odom appear one per spin

    class Monitor:
        node = SimpleNamespace(get_subscriptions_info_by_topic=lambda topic: [
            SimpleNamespace(node_name=n, node_namespace=ns) for n, ns in joined])

        def spin(self, seconds):
            pending = [('guidance_node', '/vessel_0'), ('autopilot_node', '/target_0'),
                       ('autopilot_node', '/vessel_0'), ('colav_node', '/vessel_0')]
            if len(joined) < len(pending):
                joined.append(pending[len(joined)])

    group = SimpleNamespace(failed=lambda: [])
    said = []
    wait_for_odom_subscribers(Monitor(), own, group, said.append)
    assert len(joined) == 4 and said == []     # waited for all three of its own namespace
    joined[:] = [('guidance_node', '/vessel_0')]

    class Stuck(Monitor):
        def spin(self, seconds):
            pass
    wait_for_odom_subscribers(Stuck(), own, group, said.append, timeout_s=0.05)
    assert len(said) == 1 and '/vessel_0/autopilot_node, /vessel_0/colav_node not' in said[0]
