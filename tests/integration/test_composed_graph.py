"""Composed runs (ship_mission.composition, run_mission --compose): several nodes per process.

- the record stays lossless and the lockstep run deterministic: test_lossless runs the flagship
  and the 3-vessel platoon once with a process per node and once composed, at the same time
  under load, and finds every step in each bag and the same metrics and messages;
- every member is a node of its own, as in a process of its own: its name and namespace in the
  graph, its parameters (the launcher's parameter file) over its parameter services;
- killing a container fails the run as killing a node process does: exit 1 naming it, every
  other process stopped, nothing left behind.
"""
import os
import signal
import time

import pytest
import yaml

from test_launcher import SCENARIO, _run_json, run_processes


def _call(tn, future, timeout=10.0):
    assert tn.spin_until(future.done, timeout=timeout)
    return future.result()


@pytest.mark.timeout(120)
def test_members_are_nodes_with_their_own_names_and_parameters(ros_graph, launch):
    from rclpy.parameter import parameter_value_to_python
    from rclpy.parameter_client import AsyncParameterClient
    # realtime: the graph stays up while the test reads it (in lockstep this short scenario can
    # finish within seconds on an idle machine)
    run = launch(SCENARIO, '--compose', 'all', '--stepping', 'realtime', '--duration', 10000,
                 '--wall-timeout', 100)
    assert run.wait_for_log('component_container', 'clock master', timeout=60.0), \
        run.report()
    params_dir = run.run_dir() / 'params'
    files = sorted(params_dir.glob('vessel_0.*.yaml'))
    expected = {f.name.split('.')[1]: yaml.safe_load(f.read_text())['/**']['ros__parameters']
                for f in files}
    assert set(expected) == {'route_node', 'guidance_node', 'autopilot_node', 'vessel_node'}
    tn = ros_graph.test_node()
    wanted = {('vessel_0', n) for n in expected} | {('', 'component_container')}

    def listed():
        return {(ns.strip('/'), n) for n, ns in tn.node.get_node_names_and_namespaces()}
    assert tn.spin_until(lambda: wanted <= listed(), timeout=20.0), (sorted(wanted - listed()),
                                                                    sorted(listed()))
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
