"""Bad input to the nodes, at the level of the shared helpers (no node processes; those are in
tests/integration/test_node_input_processes.py):

- run_node's one-line reason from rcl's errors, and check_overrides refusing an undeclared
  parameter with the closest declared one;
- routes: non-physical coordinates and too many poses refused with one line, the raw-bytes
  decoder equal to the message decoder, a large allowed route decoded well within the
  lockstep timeout;
- the odometry gate: non-finite, non-physical and jumping samples refused and counted, a
  normal track untouched, a real move followed after CONFIRM_SAMPLES agreeing samples;
- tanker and container astern commands stay inside the models' domains.
"""
import math
import struct

import numpy as np
import pytest
from builtin_interfaces.msg import Time
from rclpy.serialization import serialize_message

from ship_guidance.path import MAX_COORDINATE_M, Line, Route
from ship_guidance.ros import path_msgs
from ship_guidance.ros.odom_gate import CONFIRM_SAMPLES, JUMP_MARGIN_M, OdomGate
from ship_guidance.ros.path_msgs import (MAX_ROUTE_POSES, accept_route, path_msg_to_route,
                                         route_to_path_msg)
from ship_sim.ros.params import ParameterError, check_overrides
from ship_sim.ros.run import rcl_reason
from ship_sim.simulator import VesselSimulator

#: The vessel node's lockstep timeout default (s): a route must be decoded well within it.


# -- run_node / parameters ----------------------------------------------------------------------

def test_rcl_reason_is_one_line_without_c_source_locations():
    from rclpy._rclpy_pybind11 import RCLError, UnknownROSArgsError
    exc = RCLError("failed to initialize rcl: Couldn't parse parameter override rule: "
                   "'-p model:='. Error: error not set, at /project/src/rcl/arguments.c:352")
    assert rcl_reason(exc) == "Couldn't parse parameter override rule: '-p model:='"
    exc = RCLError("failed to initialize rcl: Couldn't parse params file: '--params-file "
                   "/x.yaml'. Error: Error opening YAML file, at /project/src/parser.c:271, at "
                   "/project/src/rcl/arguments.c:415")
    text = rcl_reason(exc)
    assert '\n' not in text and '.c:' not in text and 'Error opening YAML file' in text
    assert '--foo' in rcl_reason(UnknownROSArgsError(['--foo']))


def test_undeclared_parameter_is_refused_naming_the_closest_declared_one(make_node):
    node, p = make_node(lookahed_m=3.0, dt=0.2)
    p.declare('lookahead_m', 500.0, 'look-ahead', lo=1e-3)
    p.declare('dt', 0.1, 'step', lo=1e-3, hi=1.0)
    with pytest.raises(ParameterError) as err:
        check_overrides(node)
    text = str(err.value)
    assert '\n' not in text
    assert "'lookahed_m'" in text and "did you mean 'lookahead_m'" in text


def test_declared_and_rclpy_parameters_pass_the_override_check(make_node):
    node, p = make_node(dt=0.2, use_sim_time=True)
    p.declare('dt', 0.1, 'step', lo=1e-3, hi=1.0)
    check_overrides(node)   # use_sim_time is rclpy's own: declared, accepted
    node, p = make_node(zzz_unrelated=1.0)
    with pytest.raises(ParameterError, match="'zzz_unrelated' is not a parameter") as err:
        check_overrides(node)
    assert 'did you mean' not in str(err.value)   # nothing close: no guess


# -- routes -------------------------------------------------------------------------------------

class Log:
    def __init__(self):
        self.lines = []

    def error(self, text):
        self.lines.append(text)


def _route_msg(route, frame_id='map'):
    return route_to_path_msg(route, Time(), frame_id=frame_id)


@pytest.mark.parametrize('far', [1e308, -1e308, 2.0 * MAX_COORDINATE_M])
def test_route_with_non_physical_coordinates_is_refused_in_one_line(far):
    msg = _route_msg(Route([Line((0.0, 0.0), (100.0, 0.0))]))
    msg.poses[1].pose.position.x = far
    log = Log()
    for form in (msg, serialize_message(msg)):
        assert accept_route(form, log) is None
    assert len(log.lines) == 2 and log.lines[0] == log.lines[1]
    assert '\n' not in log.lines[0] and 'keeping the previous route' in log.lines[0]
    assert 'from the origin' in log.lines[0]


def test_route_within_the_coordinate_bound_is_accepted():
    edge = 0.9 * MAX_COORDINATE_M
    route = path_msg_to_route(_route_msg(Route([Line((edge, edge), (edge + 100.0, edge))])))
    assert route.length == pytest.approx(100.0)


def _serialized_with_count(count):
    """A serialized Path whose pose count word says ``count``: the refusal must come from the
    count alone, before any pose is read (the bytes behind it are those of 2 poses)."""
    data = bytearray(serialize_message(_route_msg(Route([Line((0.0, 0.0), (10.0, 0.0))]))))
    frame_len = struct.unpack_from('<I', data, 4 + 8)[0]
    at = 4 + (8 + 4 + frame_len + 3) // 4 * 4
    assert struct.unpack_from('<I', data, at)[0] == 2
    struct.pack_into('<I', data, at, count)
    return bytes(data)


def test_too_many_poses_are_refused_at_once_from_the_count():
    log = Log()
    # the bytes hold 2 poses behind a count of 200000: only a refusal from the count alone passes
    assert accept_route(_serialized_with_count(200_000), log) is None
    assert len(log.lines) == 1 and f'at most {MAX_ROUTE_POSES}' in log.lines[0]
    assert '200000 poses' in log.lines[0]
    # The message form too (a node given a deserialised Path).
    msg = _route_msg(Route.polyline(np.column_stack([np.arange(MAX_ROUTE_POSES + 1.0),
                                                     np.zeros(MAX_ROUTE_POSES + 1)])))
    assert accept_route(msg, log) is None and 'at most' in log.lines[-1]


def _large_route():
    # ~MAX_ROUTE_POSES poses: a sampled sine as tangent arcs (split by the encoder at 25 m).
    s = np.linspace(0.0, 25.0 * 9000, 9000)
    return Route.from_curve(s, 300.0 * np.sin(s / 3000.0))


def test_raw_bytes_decode_of_a_large_route_equals_message_decode():
    msg = _route_msg(_large_route())
    assert 0.8 * MAX_ROUTE_POSES < len(msg.poses) <= MAX_ROUTE_POSES
    data = serialize_message(msg)
    assert path_msgs._cdr_path_fields(data) is not None   # read with numpy, not rclpy
    from_bytes = path_msg_to_route(data)
    from_msg = path_msg_to_route(msg)
    assert len(from_bytes.legs) == len(from_msg.legs)
    for a, b in zip(from_bytes.legs, from_msg.legs):
        assert a.kind == b.kind
        np.testing.assert_array_equal(a.start, b.start)
        np.testing.assert_array_equal(a.end, b.end)


def test_raw_decode_falls_back_to_rclpy_for_unequal_pose_frame_ids():
    msg = _route_msg(Route([Line((0.0, 0.0), (100.0, 0.0)), Line((100.0, 0.0), (100.0, 50.0))]))
    from std_msgs.msg import Header
    msg.poses[1].header = Header(frame_id='a_longer_frame_name')   # the encoder shares one
    data = serialize_message(msg)
    assert path_msgs._cdr_path_fields(data) is None
    assert path_msg_to_route(data).length == pytest.approx(150.0)


def test_wrong_frame_is_refused_from_bytes_too():
    log = Log()
    data = serialize_message(_route_msg(Route([Line((0.0, 0.0), (100.0, 0.0))]), 'odom'))
    assert accept_route(data, log) is None
    assert log.lines == ["route refused: route frame_id is 'odom', expected 'map'; keeping the "
                         'previous route']


# -- odometry gate --------------------------------------------------------------------------------

def test_gate_accepts_a_normal_track_and_only_consistent_samples_count_as_consistent():
    gate = OdomGate(50.0)
    assert gate.check(0.0, 0.0, 0.0) is None and not gate.consistent   # first: no reference
    for k in range(1, 100):
        assert gate.check(0.1 * k, 8.0 * 0.1 * k, 0.0, 0.0, 8.0, 0.0, 0.0) is None
        assert gate.consistent and not gate.re_anchored
    assert gate.n_refused == 0


@pytest.mark.parametrize('north, east, psi, why', [
    (math.nan, 0.0, 0.0, 'non-finite'),
    (0.0, 0.0, math.inf, 'non-finite'),
    (1e308, 0.0, 0.0, 'beyond'),
    (-1e308, 1e308, 0.0, 'beyond'),
    (1e6, 0.0, 0.0, 'jump'),
])
def test_gate_refuses_an_outlier_counts_it_and_keeps_the_reference(north, east, psi, why):
    gate = OdomGate(50.0)
    assert gate.check(0.0, 0.0, 0.0, 0.0) is None
    reason = gate.check(0.1, north, east, psi)
    assert reason is not None and why in reason and '\n' not in reason
    assert gate.n_refused == 1 and gate.last == (0.0, 0.0, 0.0)
    # The next normal sample is accepted against the kept reference.
    assert gate.check(0.2, 1.6, 0.0, 0.0) is None and gate.consistent


def test_gate_bound_is_speed_times_dt_plus_margin():
    gate = OdomGate(50.0)
    gate.check(0.0, 0.0, 0.0)
    limit = 50.0 * 1.0 + JUMP_MARGIN_M
    assert gate.check(1.0, limit * 1.001, 0.0) is not None
    assert gate.check(1.0, limit * 0.999, 0.0) is None


def test_gate_follows_a_real_move_after_agreeing_samples():
    gate = OdomGate(50.0)
    gate.check(0.0, 0.0, 0.0)
    for k in range(1, CONFIRM_SAMPLES):
        assert gate.check(0.1 * k, 5e5, 0.0) is not None
    assert gate.check(0.1 * CONFIRM_SAMPLES, 5e5, 0.0) is None
    assert gate.re_anchored and not gate.consistent
    assert gate.check(0.1 * CONFIRM_SAMPLES + 0.1, 5e5 + 0.8, 0.0) is None and gate.consistent


def test_gate_restarts_when_time_goes_back():
    gate = OdomGate(50.0)
    gate.check(100.0, 0.0, 0.0)
    assert gate.check(0.0, 1000.0, 0.0) is None and not gate.consistent


# -- astern shaft commands --------------------------------------------------------------------------

@pytest.mark.parametrize('model, shaft, seconds_before', [('tanker', -80.0, 34.6),
                                                          ('container', -160.0, 4.3)])
def test_astern_shaft_command_stays_in_the_model_domain(model, shaft, seconds_before):
    """Before the lower limits, these left the domain after ``seconds_before`` s; run for 300 s
    (several times that, and 6 shaft time constants of the tanker), with the rudder over."""
    sim = VesselSimulator(model, dt=0.1)
    lo = sim.model.shaft_min
    assert lo >= 0.0
    for _ in range(3000):
        sim.step(0.1, shaft)
    state = sim.state
    assert np.all(np.isfinite(state))
    assert state[sim.model.IU] > 0.0                 # still going ahead, slower
    assert lo <= state[sim.model.IN] <= sim.model.shaft_nominal
    assert sim.shaft_command == lo                   # the command was saturated, not refused
