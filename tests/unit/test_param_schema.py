"""Every copy of a node's parameters agrees with its schema (ship_sim.param_schema).

- the nodes: each node class, built in-process, declares exactly the schema's parameters, with
  the schema's default, description, unit, range, choices and read-only flag in its rclpy
  descriptors; and no node module declares a parameter by hand;
- the config files: each committed config/<node>.yaml is what scripts/gen_param_files.py
  writes from the schema, every config file belongs to a schema, and its values are the
  defaults (or the schema's config_values) and pass the schema's own checks;
- the launcher: node_parameter_names is the schema's names plus rclpy's, and the pre-launch
  value check refuses what the node refuses.
"""
import ast
import importlib
import math
import socket
from pathlib import Path

import pytest
import yaml

import gen_param_files
from ship_mission.launcher import RCLPY_PARAMETERS, node_parameter_names
from ship_sim.param_schema import all_schemas, check_param, node_schema

REPO = Path(__file__).resolve().parents[2]
SCHEMAS = list(all_schemas())
IDS = [s.node for s in SCHEMAS]
# node executable -> (module, class)
NODE_CLASSES = {
    'vessel_node': ('ship_sim.vessel_node', 'VesselNode'),
    'traffic_node': ('ship_sim.traffic_node', 'TrafficNode'),
    'guidance_node': ('ship_guidance.guidance_node', 'GuidanceNode'),
    'follower_node': ('ship_guidance.follower_node', 'FollowerNode'),
    'ais_node': ('ship_guidance.ais_node', 'AisNode'),
    'colav_node': ('ship_guidance.colav_node', 'ColavRosNode'),
    'nav_display_node': ('ship_guidance.nav_display_node', 'NavDisplayNode'),
    'aivdm_out_node': ('ship_guidance.aivdm_out_node', 'AivdmOutNode'),
    'autopilot_node': ('ship_autopilot.autopilot_node', 'AutopilotNode'),
    'route_node': ('ship_planner.route_node', 'RouteNode'),
    'planner_node': ('ship_planner.planner_node', 'PlannerNode'),
    'tracker_node': ('ship_guidance.tracker_node', 'TrackerNode'),
}
# Start values some nodes need to be built at all (they refuse to start with no input); the
# UDP nodes get a free port each when the test runs (UDP_PORT is replaced).
UDP_PORT = object()
NEEDED = {
    'ais_node': {'udp_port': UDP_PORT},
    'tracker_node': {'udp_port': UDP_PORT},
    'aivdm_out_node': {'vessels': '[{"topic": "/v/odom", "mmsi": 123456789}]', 'udp': ''},
    'planner_node': {'chart_file': '/nonexistent.png', 'origin_lat_deg': 1.0,
                     'origin_lon_deg': 1.0, 'start_lat_deg': 1.0, 'start_lon_deg': 1.0,
                     'goal_lat_deg': 1.1, 'goal_lon_deg': 1.1},
}


def test_every_node_has_a_schema_and_every_config_file_one_node():
    assert sorted(IDS) == sorted(NODE_CLASSES)
    configs = sorted(REPO.glob('ros_ws/src/*/config/*.yaml'))
    assert configs == sorted(gen_param_files.config_path(s) for s in SCHEMAS)


@pytest.mark.parametrize('schema', SCHEMAS, ids=IDS)
def test_committed_config_file_is_the_generated_one(schema):
    path = gen_param_files.config_path(schema)
    assert path.read_text() == gen_param_files.config_text(schema), (
        f'{path.relative_to(REPO)} differs from its schema: run scripts/gen_param_files.py')


@pytest.mark.parametrize('schema', SCHEMAS, ids=IDS)
def test_config_values_are_the_defaults_and_pass_the_checks(schema):
    doc = yaml.safe_load(gen_param_files.config_path(schema).read_text())
    values = doc['/**']['ros__parameters']
    unset = {p.name for p in schema.params if p.is_list and not p.default}
    assert set(values) == (set(schema.names()) - unset) | (set(schema.config_values) - set(
        schema.names()))
    for p in schema.params:
        if p.name in unset:
            continue
        value = values[p.name]
        expected = schema.config_values.get(p.name, p.default)
        assert type(value) is type(expected)
        assert value == expected or (isinstance(value, float) and math.isnan(value)
                                     and math.isnan(expected))
        assert check_param(schema, p.name, value) is None


@pytest.mark.parametrize('schema', SCHEMAS, ids=IDS)
def test_launcher_names_are_the_schema(schema):
    assert node_parameter_names(schema.package, schema.node) == (
        set(schema.names()) | set(schema.renamed()) | set(RCLPY_PARAMETERS))


def test_node_modules_declare_nothing_by_hand():
    """Every declaration goes through NodeParameters.param/declare_schema (the schema): no
    node module calls declare() or rclpy's declare_parameter itself."""
    offenders = []
    for path in sorted(REPO.glob('ros_ws/src/*/*/*_node.py')) + [
            REPO / 'ros_ws/src/ship_sim/ship_sim/ros/waves.py']:
        for node in ast.walk(ast.parse(path.read_text())):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr in ('declare', 'declare_parameter', 'declare_parameters')):
                offenders.append(f'{path.name}:{node.lineno}')
    assert offenders == []


def _expected_description(p):
    text = p.description + (f' [{p.unit}]' if p.unit else '')
    if p.choices is not None:
        text += f"; allowed: {', '.join(str(c) for c in p.choices)}"
    return text


@pytest.fixture
def built_nodes(tmp_path, monkeypatch):
    """build(executable) -> the node class instance, built in-process in a global rclpy context
    (the node classes take none) on this process's leased domain, with NEEDED as start values."""
    import rclpy

    from conftest import _domain_id
    from ship_mission.processes import install_env
    # route_node finds its default route through the ament index of the install tree.
    monkeypatch.setenv('AMENT_PREFIX_PATH', install_env()['AMENT_PREFIX_PATH'])
    def free_udp_port():
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.bind(('127.0.0.1', 0))
            return s.getsockname()[1]
    needed = {n: {k: free_udp_port() if v is UDP_PORT else v for k, v in values.items()}
              for n, values in NEEDED.items()}
    params = tmp_path / 'needed.yaml'
    params.write_text(yaml.safe_dump({n: {'ros__parameters': v} for n, v in needed.items()}))
    rclpy.init(args=['--ros-args', '--params-file', str(params)], domain_id=_domain_id())
    nodes = []

    def build(executable):
        module, cls = NODE_CLASSES[executable]
        nodes.append(getattr(importlib.import_module(module), cls)())
        return nodes[-1]

    build.needed = needed
    yield build
    for node in nodes:
        node.destroy_node()
    rclpy.try_shutdown()


@pytest.mark.parametrize('schema', SCHEMAS, ids=IDS)
def test_node_declares_exactly_its_schema(schema, built_nodes):
    from rcl_interfaces.msg import ParameterType
    node = built_nodes(schema.node)
    assert set(node._parameters) == set(schema.names()) | set(RCLPY_PARAMETERS)
    given = built_nodes.needed.get(schema.node, {})
    for p in schema.params:
        d = node.describe_parameter(p.name)
        assert d.description == _expected_description(p), p.name
        assert d.read_only == p.read_only, p.name
        assert d.dynamic_typing == (p.is_list and not p.default), p.name
        fp, ir = list(d.floating_point_range), list(d.integer_range)
        if p.type == 'float' and (p.lo is not None or p.hi is not None):
            assert (fp[0].from_value, fp[0].to_value) == (
                -math.inf if p.lo is None else p.lo, math.inf if p.hi is None else p.hi), p.name
        elif p.type == 'int' and (p.lo is not None or p.hi is not None):
            assert (ir[0].from_value, ir[0].to_value) == (
                -2**63 if p.lo is None else p.lo, 2**63 - 1 if p.hi is None else p.hi), p.name
        else:
            assert fp == [] and ir == [], p.name
        value = node.get_parameter(p.name)
        if p.name in given:
            assert value.value == given[p.name]
            continue
        if p.is_list and not p.default:
            assert value.type_.value == ParameterType.PARAMETER_NOT_SET or value.value == []
            continue
        v = list(value.value) if p.is_list else value.value
        assert v == p.default or (isinstance(v, float) and math.isnan(v)
                                  and math.isnan(p.default)), p.name
        assert type(v if not p.is_list else v[0]) is p.kind, p.name


@pytest.mark.parametrize('package, executable, key, value, needle', [
    ('ship_sim', 'vessel_node', 'dt', 5.0, '[0.0001, 1.0]'),                 # range
    ('ship_sim', 'vessel_node', 'dt', 1, 'write 1.0'),                       # static type
    ('ship_sim', 'vessel_node', 'model', 'dinghy', "one of 'mariner'"),      # choices
    ('ship_sim', 'vessel_node', 'max_steps', 1.5, 'an integer'),
    ('ship_sim', 'traffic_node', 'targets', 'nope', 'JSON'),                  # named pure check
    ('ship_guidance', 'colav_node', 'speed_factors', [], 'non-empty list'),
    ('ship_planner', 'planner_node', 'start_lat_deg', 95.0, 'or nan'),
])
def test_prelaunch_check_refuses_in_one_line(package, executable, key, value, needle):
    bad = check_param(node_schema(package, executable), key, value)
    assert bad is not None and needle in bad and '\n' not in bad and repr(key) in bad


@pytest.mark.parametrize('package, executable, key, value', [
    ('ship_sim', 'vessel_node', 'dt', 0.05),
    ('ship_sim', 'vessel_node', 'initial_x', -3),              # an int for a float: refused
    ('ship_planner', 'planner_node', 'start_lat_deg', math.nan),
    ('ship_guidance', 'guidance_node', 'course_schedule_deg', [0.0, 90.0, 60.0, 120.0]),
])
def test_prelaunch_check_agrees_with_the_node(make_node, package, executable, key, value):
    """check_param refuses a value exactly when NodeParameters.param does (same message)."""
    from ship_sim.ros.params import NodeParameters, ParameterError
    schema = node_schema(package, executable)
    node, _ = make_node(**{key: value})
    p = NodeParameters(node, schema)
    try:
        p.param(key)
        node_says = None
    except ParameterError as exc:
        node_says = str(exc)
    ours = check_param(schema, key, value)
    assert (ours is None) == (node_says is None), (ours, node_says)


def test_a_deprecated_name_still_sets_the_parameter_with_a_warning(make_node):
    """U0 (renamed nominal_speed_mps) is taken for one release: the value reaches the new name,
    one warning names both, and the old key is no longer an unknown override."""
    from ship_sim.ros.params import NodeParameters, check_overrides
    from ship_sim.schema import VESSEL_NODE
    assert VESSEL_NODE.renamed() == {'U0': 'nominal_speed_mps', 'depth': 'water_depth_m'}
    node, _ = make_node(U0=6.5)
    warnings = []
    node.get_logger().warning = warnings.append   # the node's logger, read back here
    p = NodeParameters(node, VESSEL_NODE)
    assert p.param('nominal_speed_mps') == 6.5
    assert len(warnings) == 1 and "'U0'" in warnings[0] and "'nominal_speed_mps'" in warnings[0]
    check_overrides(node)                          # raises if 'U0' still counted as unknown
    assert check_param(VESSEL_NODE, 'nominal_speed_mps', 40.0) is not None   # same range


def test_scenario_keys_under_a_deprecated_name_are_checked_by_the_new_rules():
    from ship_mission.node_checks import section_problems
    assert section_problems('ship_sim', 'vessel_node', {'depth': 30.0}) == []
    [(key, bad)] = section_problems('ship_sim', 'vessel_node', {'depth': -1.0})
    assert key == 'depth' and "'water_depth_m'" in bad
