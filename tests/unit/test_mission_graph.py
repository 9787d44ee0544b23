"""The graph a scenario makes, as data (ship_mission.graph): built for committed scenarios
without starting a process, its structure checked against what the scenario says, and every
subscriber count a lockstep publisher waits for checked against the wiring parameters that
make those subscriptions."""
import dataclasses
import json
from pathlib import Path

import pytest

from ship_mission.graph import AIS_TARGETS, COLAV_REMAP, mission_graph
from ship_mission.launcher import check_scenario
from ship_mission.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ['flagship_mariner.yaml', 'head_on_mariner_2.yaml',
             'crossing_light_target_mariner.yaml', 'head_on_ais_mariner.yaml',
             'platoon_mariner_5.yaml']


def _scenario(name, **options):
    sc = load_scenario(ROOT / 'scenarios' / name)
    check_scenario(sc)
    return dataclasses.replace(sc, **options)


def _names(graph, labels):
    """The full ROS names of the node specs ``labels``, sorted."""
    return sorted(graph.node(label).full_name for label in labels)


def _followers_of_topic(graph, topic):
    """The node specs that follow ``topic`` by what their parameters and arguments say (not by
    the graph's own ``counted``): the way the nodes themselves subscribe."""
    labels = []
    for n in graph.nodes:
        p = n.parameters
        own = n.namespace is not None and topic == f'/{n.namespace}/odom'
        if n.executable in ('guidance_node', 'autopilot_node') and own:
            labels.append(n.label)
        elif n.executable == 'follower_node' and (own or p['predecessor_odom_topic'] == topic):
            labels.append(n.label)
        elif n.executable == 'colav_node' and (own or topic in p['target_topics']):
            labels.append(n.label)
        elif n.executable == 'vessel_node' and topic in p.get(
                'lockstep_follower_odom_topics', '').split(','):
            labels.append(n.label)
        elif n.executable == 'recorder':   # the recorder takes every topic
            labels.append(n.label)
        elif n.executable == 'live_view' and topic in n.argv[n.argv.index('--early') + 1:]:
            labels.append(n.label)
        elif n.executable == 'aivdm_out_node' and topic in [
                v['topic'] for v in json.loads(p['vessels'])]:
            labels.append(n.label)
    return labels


@pytest.mark.parametrize('name', SCENARIOS)
@pytest.mark.parametrize('record', [True, False])
@pytest.mark.parametrize('live', [None, 0])
def test_graph_of_a_scenario_follows_from_it(name, record, live, tmp_path):
    sc = _scenario(name, live_port=live)
    graph = mission_graph(sc, record, run_dir=tmp_path / 'run')
    assert not (tmp_path / 'run').exists()           # data only: nothing written
    labels = [n.label for n in graph.nodes]
    assert len(labels) == len(set(labels))
    for spec in sc.vessels:
        ns = [n.executable for n in graph.nodes if n.namespace == spec.namespace]
        steering = 'guidance_node' if spec.predecessor is None else 'follower_node'
        expected = ['route_node', steering, 'autopilot_node', 'vessel_node']
        if spec.colav_params is not None:
            expected.append('colav_node')
        if sc.display is not None:
            expected.append('nav_display_node')
        assert sorted(ns) == sorted(expected)
        if spec.colav_params is not None:   # guidance feeds colav_node, not the autopilot
            assert graph.node(f'{spec.namespace}/guidance_node').remaps == COLAV_REMAP
    # the simulators come last, after everything that must hear their step 0
    n_sim = len(sc.vessels)
    assert [n.executable for n in graph.nodes[-n_sim:]] == ['vessel_node'] * n_sim
    assert ('recorder' in labels) == bool(record)
    assert ('live_view' in labels) == (live is not None)
    assert ('traffic/traffic_node' in labels) == bool(sc.light)
    assert ('ais/ais_node' in labels) == (sc.ais is not None)
    for sim in graph.simulators():
        topic = f'/{sim.namespace}/odom'
        assert sorted(sim.parameters['lockstep_odom_readers']) == _names(
            graph, _followers_of_topic(graph, topic)), topic
        assert sim.parameters['lockstep_record_topic'] == ('record_ack' if record else '')
    if sc.light:
        topic = f"/{sc.light[0]['name']}/odom"
        assert sorted(graph.node('traffic/traffic_node').parameters['wait_readers']) == _names(
            graph, _followers_of_topic(graph, topic))
    if sc.ais is not None:
        colav = [n for n in graph.nodes if n.executable == 'colav_node'
                 and n.parameters.get('targets_topic') == AIS_TARGETS]
        assert len(graph.node('ais/ais_node').parameters['wait_readers']) == (
            len(colav) + int(bool(record)))


@pytest.mark.parametrize('name', SCENARIOS)
def test_realtime_graph_waits_for_no_target_subscribers(name):
    sc = _scenario(name, stepping='realtime')
    graph = mission_graph(sc, True)
    if sc.light:
        assert graph.node('traffic/traffic_node').parameters['wait_readers'] == ['']
    if sc.ais is not None:
        assert 'wait_readers' not in graph.node('ais/ais_node').parameters
    # the simulators' readers do not depend on the stepping (a realtime one waits for no one)
    lockstep = mission_graph(dataclasses.replace(sc, stepping='lockstep'), True)
    assert ([s.parameters['lockstep_odom_readers'] for s in graph.simulators()]
            == [s.parameters['lockstep_odom_readers'] for s in lockstep.simulators()])


def test_a_new_subscriber_is_counted_where_it_is_declared():
    sc = _scenario('head_on_mariner_2.yaml')
    base = mission_graph(sc, True)
    with_aivdm = mission_graph(dataclasses.replace(sc, aivdm_out={'file': 'out.nmea'}), True)
    for sim in base.simulators():
        other = with_aivdm.node(sim.label)
        assert (sorted(other.parameters['lockstep_odom_readers'])
                == sorted(sim.parameters['lockstep_odom_readers'] + ['/aivdm_out_node']))
