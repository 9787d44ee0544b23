"""Parametric curves (ship_guidance.curves): the sampled Route stays within 1 mm of the analytic
curve (sine, spline), circles are exact, and the YAML `curve` form builds the same routes."""
import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.interpolate import CubicSpline

from ship_guidance import curves
from ship_planner.yaml_route_reader import parse_route_yaml

TOL_M = 1e-3          # stated tolerance of a sampled curve route: 1 mm (step 10 m, ship-sized curves)

A, LAM, LENGTH = 500.0, 4000.0, 8000.0
K = 2 * math.pi / LAM


@pytest.fixture(scope='module')
def sine():
    return curves.sine_route(LENGTH, A, LAM, step_m=10.0)


def test_sine_route_stays_on_the_analytic_curve(sine):
    s = np.linspace(0.0, sine.length, 40001)
    north, east, angle = sine.point_at(s)
    # The base line runs north, so the curve is east = A sin(k north); the east offset bounds the distance.
    assert np.max(np.abs(east - A * np.sin(K * north))) < TOL_M
    # Tangent arcs have constant curvature over a step h, so their heading drifts from the curve's by
    # about |dkappa/ds| h^2 / 6 ~ A k^3 h^2 / 6 = 3e-5 rad here before the next sample resets it.
    assert np.max(np.abs(angle - np.arctan2(A * K * np.cos(K * north), 1.0))) < 1e-4
    analytic_length = quad(lambda x: math.hypot(1.0, A * K * math.cos(K * x)), 0.0, LENGTH, limit=200)[0]
    assert sine.length == pytest.approx(analytic_length, abs=TOL_M)
    assert tuple(sine.start) == pytest.approx((0.0, 0.0)) and tuple(sine.end) == pytest.approx((LENGTH, 0.0), abs=1e-9)


def test_sine_sampling_step_and_smallest_radius(sine):
    assert np.max(sine.leg_lengths) <= 10.0 + 1e-9
    r_min = LAM ** 2 / (4 * math.pi ** 2 * A)               # 810.6 m at the crests
    assert 1.0 / np.max(np.abs(sine.curvatures)) == pytest.approx(r_min, rel=1e-3)


def test_sine_offset_is_to_starboard_of_the_base_course():
    route = curves.sine_route(2000.0, 100.0, 2000.0, step_m=5.0, start=(50.0, -20.0), course=math.pi / 2)
    north, east, _ = route.point_at(np.linspace(0.0, route.length, 20001))
    # Base line east from (50, -20); a quarter wavelength on, the curve is A to starboard (south).
    assert north.min() == pytest.approx(50.0 - 100.0, abs=0.01)
    assert east[np.argmin(north)] == pytest.approx(-20.0 + 500.0, abs=1.0)


def test_spline_route_follows_the_spline_and_its_points():
    pts = np.array([[0, 0], [1500, 300], [2800, 1200], [4300, 1000], [5500, 0]], float)
    route = curves.spline_route(pts, step_m=10.0)
    chord = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))))
    ref = CubicSpline(chord, pts, bc_type='natural', axis=0)(np.linspace(0.0, chord[-1], 600))
    s_hint, worst = 0.0, 0.0
    for n, e in ref:
        p = route.project(n, e, s_hint=s_hint, window=200.0)
        s_hint, worst = p.s, max(worst, p.distance)
    assert worst < TOL_M
    for n, e in pts:
        assert route.project(n, e).distance < TOL_M


def test_circle_route_is_exact():
    route = curves.circle_route((100.0, 200.0), 800.0, math.radians(30.0), 2 * math.pi, clockwise=True)
    assert len(route.legs) == 4 and all(leg.kind == 'arc' for leg in route.legs)
    assert route.length == pytest.approx(2 * math.pi * 800.0)
    assert tuple(route.end) == pytest.approx(tuple(route.start))
    assert tuple(route.start) == pytest.approx((100.0 + 800.0 * math.cos(math.radians(30)),
                                                200.0 + 800.0 * math.sin(math.radians(30))))
    assert route.legs[0].start_angle == pytest.approx(math.radians(120.0))   # bearing + 90 deg when clockwise
    ccw = curves.circle_route((0.0, 0.0), 500.0, 0.0, math.radians(100.0), clockwise=False)
    assert len(ccw.legs) == 2 and ccw.legs[0].start_angle == pytest.approx(-math.pi / 2)
    assert tuple(ccw.end) == pytest.approx((500.0 * math.cos(math.radians(-100)), 500.0 * math.sin(math.radians(-100))))


@pytest.mark.parametrize('call', [
    lambda: curves.sine_samples(1000.0, 100.0, 500.0, step_m=0.0),
    lambda: curves.sine_samples(-1.0, 100.0, 500.0),
    lambda: curves.spline_samples([[0, 0], [0, 0], [1, 1]]),
    lambda: curves.circle_segments((0, 0), 0.0, 0.0, 1.0, True),
])
def test_bad_curve_parameters_are_refused(call):
    with pytest.raises(ValueError):
        call()


def test_yaml_curve_forms():
    head = 'name: c\nsource: unit test\nframe: enu\n'
    sine = parse_route_yaml(head + 'curve: {type: sine, length_m: 8000, amplitude_m: 500, wavelength_m: 4000}\n')
    assert sine.route.length == pytest.approx(curves.sine_route(LENGTH, A, LAM).length, rel=1e-12)
    circle = parse_route_yaml(head + 'curve: {type: circle, center: [0, 1000], radius_m: 1000, '
                                     'start_bearing_deg: 180, sweep_deg: 360, direction: clockwise}\n')
    assert circle.route.length == pytest.approx(2000 * math.pi)
    assert tuple(circle.route.start) == pytest.approx((0.0, 0.0), abs=1e-9)      # 1000 m south of (north 1000)
    spline = parse_route_yaml(head + 'curve: {type: spline, points: [[0, 0], [300, 1500], [1200, 2800]], step_m: 5}\n')
    assert np.max(spline.route.leg_lengths) <= 5.0 + 1e-9
    assert tuple(spline.route.end) == pytest.approx((2800.0, 1200.0))          # ENU [1200, 2800] in NED
