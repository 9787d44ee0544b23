"""Nodes alone (real processes, colcon install tree) and bad input files: route_node's route
files, every node's declared parameters, traffic_node's targets. (A whole run on a full disk is
in test_faults.py: it starts a graph.)

1. at start, a route file that is not UTF-8, a FIFO or a directory ends the node with exit code 2
   and one line naming route_file and the file, without blocking;
2. live reload: a running route_node refuses a runtime ``route_file`` change to such a file (the
   reason names it), and an edit of the watched file to bytes that are not UTF-8, to invalid
   YAML or to a FIFO is logged once and the last good route stays published (a late joiner gets
   it); the node stays up, a good edit is published again, and the node ends with exit code 0;
3. every parameter a node declares is in its package's config list, which the launcher's check
   (ship_mission.launcher.node_parameter_names) reads: the check never refuses a valid key (the
   unit tests check the other direction: every listed key is one of the file's keys);
4. traffic_node's ``targets`` parameter goes through the bounded loader (ship_sim.safe_load):
   deep nesting, a 5000-digit number or a target name that is no ROS name ends the node with
   exit code 2 and one line, not a traceback or a topic-name error.
"""
import os

import pytest
import yaml
from nav_msgs.msg import Path as PathMsg

from ship_mission.launcher import node_parameter_names
from ship_sim.ros.qos import LATCHED

NS = '/vessel_0'
GOOD = """\
name: {name}
source: integration test
frame: enu
waypoints: [[0, 0], [{x}, 0], [{x}, 1000]]
"""


def _lines(proc):
    return [line for line in proc.stderr().splitlines() if line.strip()]


def _replace(path, data):
    """Give ``path`` new contents at once (as an editor saving does), never a half-written file."""
    tmp = path.with_name(path.name + '.tmp')
    tmp.write_bytes(data)
    os.replace(tmp, path)


def _end_x(msg):
    return max(p.pose.position.x for p in msg.poses)


@pytest.mark.timeout(120)
@pytest.mark.parametrize('kind', ['latin1', 'fifo', 'directory'])
def test_route_node_refuses_a_bad_route_file_at_start_in_one_line(ros_graph, tmp_path, kind):
    path = tmp_path / 'route.yaml'
    if kind == 'latin1':
        path.write_bytes(GOOD.format(name='caf\xe9', x=1000).encode('latin-1'))
    elif kind == 'fifo':
        os.mkfifo(path)
    else:
        path.mkdir()
    proc = ros_graph.start('ship_planner', 'route_node', namespace=NS,
                           params={'route_file': str(path)})
    assert proc.wait(30.0) == 2, proc.report()
    lines = _lines(proc)
    assert len(lines) == 1, lines
    assert lines[0].startswith('route_node:') and 'route_file' in lines[0]
    assert str(path) in lines[0]
    assert 'Traceback' not in proc.output()


@pytest.mark.timeout(150)
def test_route_node_keeps_its_last_good_route_through_bad_files(ros_graph, tmp_path):
    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient

    route = tmp_path / 'route.yaml'
    route.write_text(GOOD.format(name='first', x=2000))
    latin1 = tmp_path / 'latin1.yaml'
    latin1.write_bytes(b'name: caf\xe9\n')
    fifo = tmp_path / 'fifo.yaml'
    os.mkfifo(fifo)
    node = ros_graph.start('ship_planner', 'route_node', namespace=NS,
                           params={'route_file': str(route), 'watch_period_s': 0.2})
    tn = ros_graph.test_node()
    first = tn.subscribe(f'{NS}/route', PathMsg, qos=LATCHED)
    assert tn.wait_for_message(first, timeout=20.0) is not None, node.report()
    assert _end_x(first[0]) == pytest.approx(2000.0)
    client = AsyncParameterClient(tn.node, f'{NS}/route_node')
    assert tn.spin_until(client.services_are_ready, timeout=15.0)

    def set_route_file(value):
        future = client.set_parameters([Parameter('route_file', value=str(value))])
        assert tn.spin_until(future.done, timeout=10.0), 'no answer to set_parameters'
        return future.result().results[0]

    def still_the_good_route(x):
        """A late joiner gets the last good route, and the node is still up."""
        assert node.returncode is None, node.report()
        late = tn.subscribe(f'{NS}/route', PathMsg, qos=LATCHED)
        msg = tn.wait_for_message(late, timeout=10.0)
        tn.unsubscribe(late)
        assert msg is not None and _end_x(msg) == pytest.approx(x)

    # 1. runtime parameter changes to bad files are refused with the file in the reason
    for bad in (latin1, fifo, tmp_path):
        result = set_route_file(bad)
        assert not result.successful and str(bad) in result.reason, result.reason
        still_the_good_route(2000.0)

    # 2. edits of the watched file: each refused once (logged), the last good route stays
    for n, bad in enumerate((b'name: caf\xe9\nsource: x\n', b'name: [unclosed\n',
                             GOOD.format(name='far', x=1e308).encode())):
        _replace(route, bad)
        assert node.wait_for_output(rf'(?s)(keeping the last valid route.*){{{n + 1}}}',
                                    timeout=10.0), node.report()
        still_the_good_route(2000.0)
    tn.spin_for(1.0)   # several watch periods: an unchanged bad file is not reported again
    assert node.output().count('keeping the last valid route') == 3
    route.unlink()
    os.mkfifo(route)
    assert node.wait_for_output(r'(?s)(keeping the last valid route.*){4}', timeout=10.0)
    assert 'not a regular file' in node.output()
    still_the_good_route(2000.0)

    # 3. a good edit is published again
    route.unlink()
    _replace(route, GOOD.format(name='second', x=3000).encode())
    assert tn.wait_for_message(first, timeout=10.0,
                               predicate=lambda m: _end_x(m) == pytest.approx(3000.0))
    assert 'Traceback' not in node.output()
    assert ros_graph.stop(node) == 0, node.report()


@pytest.mark.timeout(120)
@pytest.mark.parametrize('package, executable, params', [
    ('ship_sim', 'vessel_node', {}),
    ('ship_guidance', 'guidance_node', {}),
    ('ship_guidance', 'follower_node', {}),
    ('ship_autopilot', 'autopilot_node', {}),
    ('ship_planner', 'route_node', {}),
])
def test_the_launchers_parameter_lists_are_what_the_nodes_declare(ros_graph, package,
                                                                   executable, params):
    from rclpy.parameter_client import AsyncParameterClient
    node = ros_graph.start(package, executable, namespace=NS, params=params)
    tn = ros_graph.test_node()
    client = AsyncParameterClient(tn.node, f'{NS}/{executable}')
    assert tn.spin_until(client.services_are_ready, timeout=20.0), node.report()
    # A service reply can be lost when the request races the server's reply writer discovery
    # (seen under load): ask again, up to three times.
    for _ in range(3):
        future = client.list_parameters()
        if tn.spin_until(future.done, timeout=10.0):
            break
    assert future.done(), node.report()
    declared = set(future.result().result.names)
    assert declared <= node_parameter_names(package, executable)


@pytest.mark.timeout(120)
@pytest.mark.parametrize('targets, needle', [
    ('[' * 5000 + ']' * 5000, 'nested deeper than'),                       # was a RecursionError
    ('[{"name": "a", "x_m": ' + '9' * 5000 + ', "y_m": 0.0, "course_deg": 0.0, '
     '"speed_mps": 1.0}]', 'a number of 5000 characters'),                # was a ValueError
    ('[{"name": "ta\u00efget", "course_deg": 0.0, "speed_mps": 1.0}]',
     "'ta\u00efget' is not a ROS name"),                                   # was "Invalid topic name"
])
def test_traffic_node_refuses_unbounded_or_unnamable_targets_in_one_line(ros_graph, tmp_path,
                                                                         targets, needle):
    # A parameter file, as the launcher passes it: the JSON is one YAML string.
    params = tmp_path / 'traffic.yaml'
    params.write_text(yaml.safe_dump({'/**': {'ros__parameters': {'targets': targets}}},
                                     allow_unicode=True))
    proc = ros_graph.start('ship_sim', 'traffic_node', params_file=params)
    assert proc.wait(30.0) == 2, proc.report()
    lines = _lines(proc)
    assert len(lines) == 1 and lines[0].startswith('traffic_node:'), lines
    assert 'targets' in lines[0] and needle in lines[0], lines
    assert 'Traceback' not in proc.output()
