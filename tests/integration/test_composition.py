"""Composed runs (ship_mission.composition, run_mission --compose): several nodes per process.

- the record stays lossless and the lockstep run deterministic: the flagship composed in one
  container gives, under load, the very record of the same run with a process per node, and the
  3-vessel platoon the same with a container per vessel and with one for all (the helpers of
  test_lossless: every step in each bag, identical metrics, every message equal);
- every member is a node of its own, as in a process of its own: its name and namespace in the
  graph, its parameters (the launcher's parameter file) over its parameter services;
- killing a container fails the run as killing a node process does: exit 1 naming it, every
  other process stopped, nothing left behind.
"""
import json
import os
import signal
import time

import pytest
import yaml

from test_launcher import SCENARIO, Launch, _run_json, run_processes
from test_lossless import (busy_machine, compare, flagship_two_legs,  # noqa: F401 (fixture)
                           three_vessel_platoon)


def _with_compose(path, mode):
    data = yaml.safe_load(path.read_text())
    data['compose'] = mode
    out = path.with_name(f'{path.stem}_{mode}.yaml')
    out.write_text(yaml.safe_dump(data))
    return out


def run_modes(ros_graph, tmp_path, scenario, modes, timeout):
    """One run of ``scenario`` per compose mode: [(run folder, metrics)]."""
    runs = []
    for mode in modes:
        folder = tmp_path / f'run_{mode}'
        folder.mkdir()
        launch = Launch(ros_graph, folder, _with_compose(scenario, mode), [])
        try:
            assert launch.wait(timeout) == 0, launch.report()
        finally:
            launch.close()
        run = (launch.runs / 'latest').resolve()
        procs = set(_run_json(run)['exit_codes'])
        assert any(p.endswith('component_container') for p in procs) == (mode != 'none'), procs
        runs.append((run, json.loads((run / 'metrics.json').read_text())))
    return runs


@pytest.mark.timeout(900)
@pytest.mark.usefixtures('busy_machine')
def test_flagship_composed_records_the_same_run_under_load(ros_graph, tmp_path):
    dt = yaml.safe_load(flagship_two_legs(tmp_path).read_text())['dt_s']
    compare(run_modes(ros_graph, tmp_path, flagship_two_legs(tmp_path), ['none', 'all'], 400), dt)


@pytest.mark.timeout(900)
@pytest.mark.usefixtures('busy_machine')
def test_platoon_composed_per_vessel_and_in_one_records_the_same_run_under_load(
        ros_graph, tmp_path):
    runs = run_modes(ros_graph, tmp_path, three_vessel_platoon(tmp_path), ['vessel', 'all'], 400)
    metrics = compare(runs, 0.1)
    assert len(metrics['vessels']) == 3
    counts = {t: c['count'] for t, c in metrics['topics'].items()}
    for ns in metrics['vessels']:   # ended by max_steps: every step and its answer recorded
        assert counts[f'{ns}/rudder_cmd'] == counts[f'{ns}/odom'] == 1501, ns


def _call(tn, future, timeout=10.0):
    assert tn.spin_until(future.done, timeout=timeout)
    return future.result()


@pytest.mark.timeout(120)
def test_members_are_nodes_with_their_own_names_and_parameters(ros_graph, launch):
    from rclpy.parameter import parameter_value_to_python
    from rclpy.parameter_client import AsyncParameterClient
    run = launch(SCENARIO, '--compose', 'all', '--duration', 10000, '--wall-timeout', 100)
    assert run.wait_for_log('component_container', 'publishing step 0', timeout=60.0), \
        run.report()
    params_dir = run.run_dir() / 'params'
    files = sorted(params_dir.glob('vessel_0.*.yaml'))
    expected = {f.name.split('.')[1]: yaml.safe_load(f.read_text())['/**']['ros__parameters']
                for f in files}
    assert set(expected) == {'route_node', 'guidance_node', 'autopilot_node', 'vessel_node'}
    tn = ros_graph.test_node()
    assert tn.spin_until(lambda: {('vessel_0', n) for n in expected} | {('', 'component_container')}
                         <= {(ns.strip('/'), n) for n, ns
                             in tn.node.get_node_names_and_namespaces()}, timeout=20.0)
    for exe, params in expected.items():
        client = AsyncParameterClient(tn.node, f'/vessel_0/{exe}')
        assert tn.spin_until(client.services_are_ready, timeout=20.0), exe
        names = set(_call(tn, client.list_parameters()).result.names)
        assert set(params) <= names, (exe, sorted(set(params) - names))
        order = sorted(params)
        values = [parameter_value_to_python(v)
                  for v in _call(tn, client.get_parameters(order)).values]
        got = {k: list(v) if isinstance(v, (list, tuple)) or type(v).__name__ == 'array'
               else v for k, v in zip(order, values)}
        assert got == params, exe
    # a parameter of one member is not another's: each has its own (vessel_node's model)
    other = AsyncParameterClient(tn.node, '/vessel_0/guidance_node')
    assert 'model' not in set(_call(tn, other.list_parameters()).result.names)


@pytest.mark.timeout(120)
def test_killing_a_container_stops_every_process_and_fails(launch):
    run = launch(SCENARIO, '--compose', 'vessel', '--duration', 10000, '--wall-timeout', 100)
    assert run.wait_for_log('vessel_0.component_container', 'publishing step 0', timeout=60.0), \
        run.report()
    time.sleep(1.0)   # mid-run
    procs = [(pid, argv) for pid, argv in run_processes(str(run.runs)) if pid != run.popen.pid]
    pid = next(pid for pid, argv in procs if any('component_container' in a for a in argv))
    assert len(procs) == 2, procs   # the container and the recorder
    os.kill(pid, signal.SIGKILL)
    assert run.wait(30.0) == 1, run.report()
    err = run.stderr()
    assert 'vessel_0/component_container' in err and 'FAILED' in err, err
    assert run_processes(str(run.runs)) == [], 'processes of the run outlived the launcher'
    info = _run_json(run.run_dir())
    assert info['outcome'] == 'failed' and info['sim_time_s'] > 0.0
    codes = info['exit_codes']
    assert codes.pop('vessel_0/component_container') == -signal.SIGKILL
    assert codes == {'recorder': 0}
