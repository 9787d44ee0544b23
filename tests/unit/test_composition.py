"""Composition as a function over the graph (ship_mission.composition), without processes: which
node specs share a container, what each member is told (the same ROS arguments as its own
process), and how the launcher's Starter maps start calls onto containers and loads."""
import dataclasses
import json
from pathlib import Path

import pytest

from ship_mission.composition import (CONTAINER, Starter, container_spec, containers,
                                      member_ros_args)
from ship_mission.graph import mission_graph
from ship_mission.launcher import check_scenario
from ship_mission.scenario import COMPOSE, ScenarioError, load_scenario

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ['flagship_mariner.yaml', 'head_on_mariner_2.yaml',
             'crossing_light_target_mariner.yaml', 'head_on_ais_mariner.yaml',
             'platoon_mariner_5.yaml']


def _graph(name, tmp_path, **options):
    sc = load_scenario(ROOT / 'scenarios' / name)
    check_scenario(sc)
    return mission_graph(dataclasses.replace(sc, **options), True, run_dir=tmp_path)


@pytest.mark.parametrize('name', SCENARIOS)
@pytest.mark.parametrize('mode', COMPOSE)
def test_every_node_spec_in_at_most_one_container(name, mode, tmp_path):
    graph = _graph(name, tmp_path, live_port=0)
    groups = containers(graph, mode)
    members = [m.label for c in groups for m in c.members]
    assert len(members) == len(set(members))
    packaged = [n.label for n in graph.nodes if n.package is not None]
    scripts = [n.label for n in graph.nodes if n.package is None]
    assert not set(scripts) & set(members)       # the recorder and the live view stay apart
    order = [n.label for n in graph.nodes]
    for c in groups:   # members keep the graph's start order
        idx = [order.index(m.label) for m in c.members]
        assert idx == sorted(idx)
    sims = [n.label for n in graph.simulators()]
    if mode == 'none':
        assert groups == []
    elif mode == 'all':
        assert len(groups) == 1 and members == packaged
        assert groups[0].node_name == f'/{CONTAINER}'
        assert [m.label for m in groups[0].deferred()] == sims
    else:
        assert [c.namespace for c in groups] == [n.namespace for n in graph.simulators()]
        for c in groups:
            assert {m.namespace for m in c.members} == {c.namespace}
            assert [m.label for m in c.deferred()] == [f'{c.namespace}/vessel_node']
            assert c.load_topic == f'/{c.namespace}/{CONTAINER}/_load'
        # every node of a vessel's namespace is in its container
        assert set(members) == {n for n in packaged
                                if graph.node(n).namespace in {c.namespace for c in groups}}


def test_member_gets_the_arguments_of_its_own_process(tmp_path):
    graph = _graph('head_on_mariner_2.yaml', tmp_path)
    (c,) = [c for c in containers(graph, 'vessel') if any(m.remaps for m in c.members)]
    spec = json.loads(container_spec(c, lambda n: tmp_path / f'{n.label}.yaml'))
    assert spec['namespace'] == c.namespace
    for m, node in zip(spec['members'], c.members):
        assert m['ros_args'] == member_ros_args(node, tmp_path / f'{node.label}.yaml')
        assert m['ros_args'][:3] == ['--ros-args', '-r', f'__ns:=/{node.namespace}']
        assert m['ros_args'][-len(node.remaps):] == node.remaps or not node.remaps
        assert m['deferred'] == (node.executable == 'vessel_node')


class _Group:
    """ProcessGroup stand-in: records what would be started."""

    def __init__(self):
        self.started = []

    def start(self, label, package, exe, args=()):
        proc = type('Proc', (), {'label': label})()
        self.started.append((label, package, exe, list(args), proc))
        return proc


@pytest.mark.parametrize('mode', ['vessel', 'all'])
def test_starter_starts_each_container_once_and_loads_the_simulators(mode, tmp_path):
    graph = _graph('platoon_mariner_5.yaml', tmp_path)
    (tmp_path / 'params').mkdir()
    group, own, loads = _Group(), [], []
    starter = Starter(graph, mode, tmp_path, group, own.append,
                      lambda n: tmp_path / f"{n.label.replace('/', '.')}.yaml")
    starter.publish_load = lambda topic, label: loads.append((topic, label))
    procs = {n.label: starter.start(n) for n in graph.nodes}
    assert own == [n for n in graph.nodes if n.package is None]    # the recorder
    assert [s[0] for s in group.started] == [c.label for c in starter.containers]
    assert all(s[1:3] == ('ship_mission', CONTAINER) for s in group.started)
    assert loads == [(starter.of[s.label].load_topic, s.label) for s in graph.simulators()]
    for label, pkg, exe, args, proc in group.started:
        spec = json.loads(Path(args[0]).read_text())
        assert [m['label'] for m in spec['members']] == \
            [m.label for m in starter.of[spec['members'][0]['label']].members]
    # a container ends the run of as many simulators as it holds
    total = sum(starter.simulators_in(s[4]) for s in group.started)
    assert total == len(graph.simulators())
    sim_proc = procs[graph.simulators()[0].label]
    assert starter.simulators_in(sim_proc) == (1 if mode == 'vessel' else 5)


def test_compose_key_is_checked(tmp_path):
    # the committed flagship, its route path made absolute (it is relative to the scenario)
    text = (ROOT / 'scenarios' / 'flagship_mariner.yaml').read_text().replace(
        'routes/', str(ROOT / 'scenarios' / 'routes') + '/')
    path = tmp_path / 'sc.yaml'
    path.write_text(text)
    assert load_scenario(path).compose == 'none'
    for mode in COMPOSE:
        path.write_text(text + f'\ncompose: {mode}\n')
        assert load_scenario(path).compose == mode
    path.write_text(path.read_text().replace('compose: all', 'compose: some'))
    with pytest.raises(ScenarioError, match='compose'):
        load_scenario(path)
