"""Light traffic targets (ship_sim.light_traffic): closed-form tracks, refusals."""
import json
import math

import numpy as np
import pytest

from ship_sim.light_traffic import LightTraffic, constant_legs, make_traffic, parse_targets, \
    waypoint_legs


def test_constant_course_and_speed_is_the_straight_line_at_any_time():
    # Course 060 deg at 5 m/s from (north 100, east -50): after t s the target is 5 t m along
    # the course; exact at a large time too (closed form, nothing accumulates).
    traffic = LightTraffic(['a'], [constant_legs(100.0, -50.0, math.radians(60.0), 5.0)])
    for t in (0.0, 0.1, 7.3, 1e5):
        n, e, c, s = traffic.state(t)
        assert n[0] == pytest.approx(100.0 + 5.0 * t * math.cos(math.radians(60.0)), abs=1e-9)
        assert e[0] == pytest.approx(-50.0 + 5.0 * t * math.sin(math.radians(60.0)), abs=1e-9)
        assert c[0] == pytest.approx(math.radians(60.0))
        assert s[0] == pytest.approx(5.0)


def test_waypoints_are_piecewise_linear_in_time_and_hit_each_point_at_its_time():
    legs = waypoint_legs([10.0, 20.0, 40.0], [0.0, 100.0, 100.0], [0.0, 0.0, 200.0])
    traffic = LightTraffic(['w'], [legs])
    for t, n_ok, e_ok in ((10.0, 0.0, 0.0), (20.0, 100.0, 0.0), (40.0, 100.0, 200.0),
                          (15.0, 50.0, 0.0), (30.0, 100.0, 100.0)):
        n, e, _, _ = traffic.state(t)
        assert (n[0], e[0]) == pytest.approx((n_ok, e_ok), abs=1e-9)
    # first leg: north at 10 m/s; second: east at 10 m/s; after the end it keeps going east,
    # before the start it moves on the first leg's velocity
    _, _, c, s = traffic.state(12.0)
    assert (c[0], s[0]) == pytest.approx((0.0, 10.0))
    n, e, c, s = traffic.state(50.0)
    assert (n[0], e[0], c[0], s[0]) == pytest.approx((100.0, 300.0, math.pi / 2, 10.0))
    n, e, _, _ = traffic.state(0.0)
    assert (n[0], e[0]) == pytest.approx((-100.0, 0.0))


def test_several_targets_of_both_kinds_at_once():
    traffic = make_traffic([
        {'name': 'c', 'x_m': 10.0, 'y_m': 20.0, 'course_deg': 270.0, 'speed_mps': 2.0},
        {'name': 'w', 'waypoints': [[0, 0, 0], [10, 30, 40], [20, 30, 40], [30, 30, 0]]}])
    n, e, c, s = traffic.state(5.0)
    # ENU input: x east, y north. Target c heads west (270 deg) at 2 m/s.
    assert n == pytest.approx([20.0, 20.0])
    assert e == pytest.approx([10.0 - 10.0, 15.0])
    assert c == pytest.approx([-math.pi / 2, math.atan2(30.0, 40.0)])
    assert s == pytest.approx([2.0, 5.0])
    # the rest leg (10..20 s) keeps the course of the leg before, at zero speed
    _, _, c, s = traffic.state(15.0)
    assert (c[1], s[1]) == pytest.approx((math.atan2(30.0, 40.0), 0.0))
    _, _, c, _ = traffic.state(25.0)
    assert c[1] == pytest.approx(-math.pi)   # due south, wrapped into [-pi, pi)


@pytest.mark.parametrize('targets, needle', [
    ([{'name': 'a', 'waypoints': [[0, 0, 0], [0, 1, 1]]}], 'increase strictly'),
    ([{'name': 'a', 'waypoints': [[5, 0, 0], [4, 1, 1]]}], 'increase strictly'),
    ([{'name': 'a', 'waypoints': [[0, 0, 0]]}], 'at least two'),
    ([{'name': 'a', 'waypoints': [[0, 0], [1, 1]]}], '[t_s, x_m, y_m]'),
    ([{'name': 'a', 'waypoints': [[0, 0, 0], [1, float('nan'), 1]]}], 'finite'),
    ([{'name': 'a', 'course_deg': float('inf'), 'speed_mps': 1.0}], 'finite'),
    ([{'name': 'a', 'course_deg': 0.0, 'speed_mps': -1.0}], 'in [0, 50]'),
    ([{'name': 'a', 'course_deg': 0.0, 'speed_mps': 1e300}], 'in [0, 50]'),
    ([{'name': 'a', 'course_deg': 0.0, 'speed_mps': 50.001}], 'in [0, 50]'),
    ([{'name': 'a', 'x_m': 1e300, 'course_deg': 0.0, 'speed_mps': 1.0}], 'at most 1e.07 m'),
    ([{'name': 'a', 'y_m': -1.0001e7, 'course_deg': 0.0, 'speed_mps': 1.0}], 'at most 1e.07 m'),
    ([{'name': 'a', 'waypoints': [[0, 0, 0], [10, 0, 1e300]]}], 'at most 1e.07 m'),
    # 1000 m in 10 s is 100 m/s: a leg no ship sails.
    ([{'name': 'a', 'waypoints': [[0, 0, 0], [10, 0, 1000]]}], 'leg 1 .* at most 50 m/s'),
    ([{'name': 'a', 'course_deg': 0.0, 'speed_mps': True}], 'a number'),
    ([{'name': 'a', 'course_deg': 0.0}], 'give either'),
    ([{'name': 'a', 'course_deg': 0.0, 'speed_mps': 1.0, 'waypoints': []}], 'give either'),
    ([{'name': 'a/b', 'course_deg': 0.0, 'speed_mps': 1.0}], "'a/b' is not a ROS name"),
    # isidentifier() accepts these; ROS refuses them in a topic name
    ([{'name': 'ta\u00efget', 'course_deg': 0.0, 'speed_mps': 1.0}], "'ta\u00efget' is not a ROS name"),
    ([{'name': '\u03a9', 'course_deg': 0.0, 'speed_mps': 1.0}], "'\u03a9' is not a ROS name"),
    ([{'name': '1a', 'course_deg': 0.0, 'speed_mps': 1.0}], "'1a' is not a ROS name"),
    ([{'name': 'a', 'course_deg': 0, 'speed_mps': 1}] * 2, 'distinct'),
    ({'name': 'a'}, 'a list'),
])
def test_bad_targets_are_refused_with_the_reason(targets, needle):
    with pytest.raises(ValueError, match='.*' + needle.replace('[', r'\[').replace(']', r'\]')):
        make_traffic(targets)


def test_targets_at_the_bounds_are_accepted():
    t = make_traffic([{'name': 'fast', 'x_m': -1e7, 'y_m': 1e7, 'course_deg': 0.0,
                       'speed_mps': 50.0},
                      {'name': 'legs', 'waypoints': [[0, 0, 0], [20, 0, 1000], [30, 0, 1000]]}])
    _, _, _, speed = t.state(5.0)
    assert speed == pytest.approx([50.0, 50.0])        # 1000 m in 20 s: exactly the bound


def test_parameter_text_is_json_and_nan_is_refused():
    text = json.dumps([{'name': 't', 'x_m': 1.0, 'y_m': 2.0, 'course_deg': 90.0,
                        'speed_mps': 3.0}])
    n, e, _, _ = parse_targets(text).state(1.0)
    assert (n[0], e[0]) == pytest.approx((2.0, 4.0))
    with pytest.raises(ValueError, match='finite'):
        parse_targets('[{"name": "t", "course_deg": NaN, "speed_mps": 1}]')
    with pytest.raises(ValueError, match='not valid JSON'):
        parse_targets('[{')
    with pytest.raises(ValueError, match='finite'):
        LightTraffic(['a'], [constant_legs(0, 0, 0, 1)]).state(float('nan'))


def test_state_is_vectorised_and_exact_at_repeated_calls():
    # The same time gives the same bits however often and in whatever order it is asked.
    traffic = make_traffic([{'name': f't{i}', 'x_m': i, 'y_m': -i, 'course_deg': 10.0 * i,
                             'speed_mps': 1.0 + i} for i in range(5)])
    a = traffic.state(123.4)
    traffic.state(1.0)
    b = traffic.state(123.4)
    for x, y in zip(a, b):
        assert x.shape == (5,) and np.array_equal(x, y)


def test_a_target_at_rest_keeps_its_given_course():
    traffic = make_traffic([{'name': 'r', 'x_m': 5.0, 'y_m': 6.0, 'course_deg': 135.0,
                             'speed_mps': 0.0}])
    n, e, c, s = traffic.state(1000.0)
    assert (n[0], e[0], c[0], s[0]) == pytest.approx((6.0, 5.0, math.radians(135.0), 0.0))
