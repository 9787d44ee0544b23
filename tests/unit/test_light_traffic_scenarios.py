"""Light targets in a scenario's `traffic:` section (ship_mission.scenario, ship_mission.launcher)
and how the analysis tells them from vessels (ship_mission.report)."""
import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from ship_mission.launcher import check_scenario, node_parameters, record_ack_args, traffic_parameters
from ship_mission.report import VESSEL_TOPICS, traffic_tracks
from ship_mission.scenario import TARGETS_KEY, ScenarioError, load_scenario, target_record

from ship_sim.light_traffic import parse_targets

ROOT = Path(__file__).resolve().parents[2]
CROSSING = ROOT / 'scenarios' / 'crossing_light_target_mariner.yaml'



def test_light_target_is_not_a_vessel_and_joins_colav_targets_and_the_record_ack():
    sc = load_scenario(CROSSING)
    check_scenario(sc)
    assert [s.namespace for s in sc.vessels] == ['vessel_0']
    assert [t['name'] for t in sc.light] == ['target_1']
    params, _ = node_parameters(sc, sc.vessels[0], 0, record=True)
    assert params['colav_node']['target_topics'] == ['/target_1/odom']
    ack = record_ack_args(sc)
    assert ack[0] == '--ack' and ack[1].endswith(',/target_1/odom')
    # traffic_node gets the same list as JSON, which it parses into the same track
    tp = traffic_parameters(sc)
    assert tp['use_sim_time'] is True
    assert json.loads(tp['targets']) == sc.light
    n, e, c, s = parse_targets(tp['targets']).state(300.0)
    # the scenario's claim: left alone, the target reaches the own route (y = 0) at t = 300 s
    assert (n[0], e[0], c[0], s[0]) == pytest.approx((0.0, 2315.25, 0.0, 7.7175), abs=1e-9)


def test_waypoint_light_targets_mix_with_full_traffic_vessels(scenario_variant):
    def change(d):
        d['traffic']['target_2'] = {'light': {'waypoints': [[0, 100, 0], [60, 100, 600]]}}
        d['traffic']['target_3'] = {'model': 'mariner', 'route': 'routes/head_on_east.yaml'}
    sc = load_scenario(scenario_variant(CROSSING, change))
    assert [t['name'] for t in sc.light] == ['target_1', 'target_2']
    assert [(s.namespace, s.traffic) for s in sc.vessels] == [('vessel_0', False),
                                                               ('target_3', True)]
    params, _ = node_parameters(sc, sc.vessels[0], 0, record=True)
    assert params['colav_node']['target_topics'] == ['/target_3/odom', '/target_1/odom',
                                                     '/target_2/odom']
    # the loader records each target's kind, and the launcher stores that record in the bag
    assert sc.targets == {'target_1': 'light', 'target_2': 'light', 'target_3': 'full'}
    assert json.loads(target_record(sc)) == {'light': ['/target_1', '/target_2'],
                                             'full': ['/target_3'], 'ais': False}


def test_scenarios_without_traffic_or_with_ais_record_so():
    flagship = load_scenario(ROOT / 'scenarios' / 'flagship_mariner.yaml')
    assert flagship.targets == {}
    assert json.loads(target_record(flagship)) == {'light': [], 'full': [], 'ais': False}
    ais = load_scenario(ROOT / 'scenarios' / 'head_on_ais_mariner.yaml')
    assert ais.targets == {'target_wp': 'light'}
    assert json.loads(target_record(ais))['ais'] is True


def _bag_data(custom_data, **missing):
    """A stand-in for ship_mission.bag.BagData: namespaces with their missing topics."""
    return SimpleNamespace(custom_data=custom_data, topics={},
                           vessels={ns: SimpleNamespace(missing=m) for ns, m in missing.items()})


def test_the_analysis_takes_the_light_targets_from_the_record_not_the_topics():
    only_odom = list(VESSEL_TOPICS)
    # /target_1 recorded with odometry only but a full vessel by the record (its other topics
    # excluded from the bag, say): a vessel; /target_2 a light target by the record
    data = _bag_data({TARGETS_KEY: json.dumps({'light': ['/target_2'], 'full': ['/target_1'],
                                               'ais': False})},
                     **{'/vessel_0': [], '/target_1': only_odom, '/target_2': only_odom})
    assert {name: source for name, (source, _) in traffic_tracks('unused', data).items()} == \
        {'/target_2': 'light'}
    # a bag without the record (not the launcher's): the namespaces with odometry only
    data.custom_data = {}
    assert sorted(traffic_tracks('unused', data)) == ['/target_1', '/target_2']


@pytest.mark.parametrize('light, key', [
    ({'x_m': 0.0, 'course_deg': 0.0}, 'traffic.target_1.light: .*give either'),
    ({'course_deg': 0.0, 'speed_mps': 1.0, 'colour': 'red'}, r'traffic\.target_1\.light\.colour'),
    ({'waypoints': [[0, 0, 0], [0, 10, 0]]}, 'traffic.target_1.light: .*increase strictly'),
    ({'course_deg': '.nan', 'speed_mps': 1.0}, 'traffic.target_1.light: .*'),
    ([1, 2], r'traffic\.target_1\.light: a mapping'),
])
def test_bad_light_targets_are_refused_naming_the_key(scenario_variant, light, key):
    with pytest.raises(ScenarioError, match=key):
        load_scenario(scenario_variant(CROSSING, lambda d: d['traffic'].update({'target_1':
                                                                       {'light': light}})))


def test_a_light_entry_takes_no_vessel_keys(scenario_variant):
    def change(d):
        d['traffic']['target_1']['model'] = 'mariner'
    with pytest.raises(ScenarioError, match=r'traffic\.target_1\.model: unknown key'):
        load_scenario(scenario_variant(CROSSING, change))


def test_a_light_target_may_carry_a_closed_form_behaviour(scenario_variant):
    sc = load_scenario(scenario_variant(CROSSING, lambda d: d['traffic']['target_1']['light']
                                        .update({'behaviour': 'no_alteration'})))
    assert sc.light[0]['behaviour'] == 'no_alteration'
    # traffic_node's parameter takes it, and the target moves as without it
    tp = traffic_parameters(sc)
    assert parse_targets(tp['targets']).state(300.0) == \
        parse_targets(json.dumps([{k: v for k, v in sc.light[0].items() if k != 'behaviour'}])
                      ).state(300.0)


@pytest.mark.parametrize('behaviour, why', [
    ('zigzag', "behaviour 'zigzag' unknown; one of straight, reciprocal"),
    ('reciprocal', "behaviour 'reciprocal' needs the other ships' states"),
    ('turns_to_port', "behaviour 'turns_to_port' needs the other ships' states"),
])
def test_a_behaviour_the_graph_cannot_move_is_refused_in_one_line(scenario_variant, behaviour,
                                                                  why):
    with pytest.raises(ScenarioError, match=r'traffic\.target_1\.light: ' + why) as info:
        load_scenario(scenario_variant(CROSSING, lambda d: d['traffic']['target_1']['light']
                                       .update({'behaviour': behaviour})))
    assert '\n' not in str(info.value)
