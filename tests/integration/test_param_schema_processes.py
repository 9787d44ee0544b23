"""The installed nodes, as processes, declare exactly their parameter schema.

Each node is started from the install tree with its defaults; the test lists its parameters
through rclpy's parameter services and compares names, descriptors (description with unit and
choices, read-only flag, range) and values with the schema (ship_sim.param_schema).
"""
import math

import pytest

from ship_sim.param_schema import RCLPY_PARAMETERS, node_schema

NS = '/schema_test'


def _expected_description(p):
    text = p.description + (f' [{p.unit}]' if p.unit else '')
    if p.choices is not None:
        text += f"; allowed: {', '.join(str(c) for c in p.choices)}"
    return text


def _call(tn, future, timeout=10.0):
    assert tn.spin_until(future.done, timeout=timeout)
    return future.result()


@pytest.mark.timeout(90)
@pytest.mark.parametrize('package, executable', [('ship_sim', 'vessel_node'),
                                                 ('ship_guidance', 'colav_node')])
def test_running_node_declares_its_schema(ros_graph, package, executable):
    from rclpy.parameter import parameter_value_to_python
    from rclpy.parameter_client import AsyncParameterClient
    schema = node_schema(package, executable)
    proc = ros_graph.start(package, executable, namespace=NS)
    tn = ros_graph.test_node()
    client = AsyncParameterClient(tn.node, f'{NS}/{executable}')
    assert tn.spin_until(lambda: client.services_are_ready(), timeout=20.0), proc.report()
    names = set(_call(tn, client.list_parameters()).result.names)
    assert names == set(schema.names()) | set(RCLPY_PARAMETERS)
    order = schema.names()
    descriptors = _call(tn, client.describe_parameters(order)).descriptors
    values = [parameter_value_to_python(v)
              for v in _call(tn, client.get_parameters(order)).values]
    for p, d, value in zip(schema.params, descriptors, values):
        assert d.name == p.name
        assert d.description == _expected_description(p), p.name
        assert d.read_only == p.read_only, p.name
        ranges = [(r.from_value, r.to_value) for r in
                  list(d.floating_point_range) + list(d.integer_range)]
        if p.type in ('float', 'int') and (p.lo is not None or p.hi is not None):
            inf = math.inf if p.type == 'float' else 2**63
            assert ranges == [(-inf if p.lo is None else p.lo,
                               (inf if p.type == 'float' else inf - 1) if p.hi is None
                               else p.hi)], p.name
        else:
            assert ranges == [], p.name
        if p.is_list:
            value = list(value)
        assert value == p.default, p.name
    assert proc.returncode is None, proc.report()
    assert ros_graph.stop(proc) == 0
