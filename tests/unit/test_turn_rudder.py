"""Turning circles from a rudder angle (Lee 2004, Ch. 4, Figs. 4.4-4.6, eq. 4.24).

The route option turn_rudder_deg + turn_model rounds each corner with the model's steady turn
at that rudder. The radius is checked against an independent long run of the simulator with
the rudder held (a least-squares circle through the settled track), P_in / P_out against the
tangent-circle geometry, and the LOS point on the circle against its definition.
"""
import math

import numpy as np
import pytest

from ship_guidance.guidance import Guidance
from ship_guidance.los import circle_los_point
from ship_guidance.path import Arc, Line
from ship_planner.fillets import rudder_turn_radius
from ship_planner.route_data import RouteError
from ship_planner.yaml_route_reader import parse_route_yaml
from ship_sim.models import make_model
from ship_sim.simulator import VesselSimulator

ROUTE = """
name: t
source: test
frame: enu
turn_rudder_deg: {rudder}
turn_model: {model}
start: [0, 0]
legs:
  - {{course_deg: 0, length_m: 4000}}
  - {{course_deg: 90, length_m: 4000}}
  - {{course_deg: 30, length_m: 4000}}
"""


def fit_circle(north, east):
    """Algebraic least-squares circle (Kasa): (centre north, centre east, radius)."""
    a = np.column_stack([north, east, np.ones_like(north)])
    b = north ** 2 + east ** 2
    (p, q, c), *_ = np.linalg.lstsq(a, b, rcond=None)
    cn, ce = p / 2.0, q / 2.0
    return cn, ce, math.sqrt(c + cn ** 2 + ce ** 2)


def simulated_radius(model_name, rudder_deg, starboard, t_total, t_fit):
    """Radius of the circle the simulator's track settles on with the rudder held."""
    model = make_model(model_name)
    sim = VesselSimulator(model, dt=0.5)
    cmd = math.radians(-rudder_deg if starboard else rudder_deg)   # + turns to port
    n_total, n_fit = int(t_total / 0.5), int(t_fit / 0.5)
    track = []
    for k in range(n_total):
        sim.step(cmd)
        if k >= n_total - n_fit:
            track.append(sim.pose_ned()[:2])
    track = np.array(track)
    cn, ce, r = fit_circle(track[:, 0], track[:, 1])
    spread = np.hypot(track[:, 0] - cn, track[:, 1] - ce)
    assert spread.max() - spread.min() < 0.01 * r, 'the track has not settled on a circle'
    return r


@pytest.mark.parametrize('model, rudder, t_total', [('mariner', 10.0, 2500.0),
                                                    ('tanker', 5.0, 6000.0)])
def test_the_route_radius_is_the_simulated_steady_turn_within_1_percent(model, rudder, t_total):
    plan = parse_route_yaml(ROUTE.format(rudder=rudder, model=model))
    arcs = [leg for leg in plan.route.legs if isinstance(leg, Arc)]
    assert [a.clockwise for a in arcs] == [True, False]          # 90 deg stbd, then 60 deg port
    for arc in arcs:
        r_sim = simulated_radius(model, rudder, arc.clockwise, t_total, 1000.0)
        assert arc.radius == pytest.approx(r_sim, rel=0.01)


def test_a_linear_ship_turns_on_u_over_k_delta():
    """Nomoto's first-order model: steady r = K delta, so R = U / (K delta) exactly."""
    m = make_model('nomoto1')
    r = rudder_turn_radius('nomoto1', 10.0, True)
    assert r == pytest.approx(m.U / (m.K * math.radians(10.0)), rel=1e-4)


def test_a_larger_rudder_turns_tighter_and_the_hull_asymmetry_shows():
    r10, r20 = rudder_turn_radius('mariner', 10.0, True), rudder_turn_radius('mariner', 20.0, True)
    assert r20 < r10
    # The MSS Mariner needs rudder to hold a straight course, so its two turns differ.
    assert rudder_turn_radius('mariner', 10.0, False) != pytest.approx(r10, rel=0.01)


def test_p_in_and_p_out_are_tangent_points_of_the_legs():
    plan = parse_route_yaml(ROUTE.format(rudder=15.0, model='mariner'))
    legs = plan.route.legs
    assert [type(leg).__name__ for leg in legs] == ['Line', 'Arc', 'Line', 'Arc', 'Line']
    for i in (1, 3):
        before, arc, after = legs[i - 1], legs[i], legs[i + 1]
        assert isinstance(before, Line) and isinstance(after, Line)
        c = np.asarray(arc.center)
        for p_t, line in ((arc.start, before), (arc.end, after)):
            p_t = np.asarray(p_t)
            u = np.asarray(line.end) - np.asarray(line.start)
            u = u / np.hypot(*u)
            assert np.hypot(*(p_t - c)) == pytest.approx(arc.radius, abs=1e-6)   # on the circle
            assert abs(np.dot(p_t - c, u)) < 1e-6 * arc.radius                   # radius normal to the leg
        assert np.allclose(before.end, arc.start) and np.allclose(arc.end, after.start)
        # P_in and P_out lie the same distance R tan(|Delta|/2) from the waypoint.
        u_in = np.asarray(before.end) - np.asarray(before.start)
        u_out = np.asarray(after.end) - np.asarray(after.start)
        delta = abs(math.remainder(math.atan2(u_out[1], u_out[0]) - math.atan2(u_in[1], u_in[0]),
                                   2 * math.pi))
        t = arc.radius * math.tan(delta / 2)
        wp = np.asarray(arc.start) + t * u_in / np.hypot(*u_in)
        assert np.allclose(np.asarray(arc.end) - t * u_out / np.hypot(*u_out), wp, atol=1e-6)


def test_a_corner_radius_given_by_hand_still_wins():
    text = ROUTE.format(rudder=15.0, model='mariner').replace(
        '{course_deg: 0, length_m: 4000}', '{course_deg: 0, length_m: 4000, fillet_radius_m: 300}')
    arcs = [leg for leg in parse_route_yaml(text).route.legs if isinstance(leg, Arc)]
    assert arcs[0].radius == pytest.approx(300.0)
    assert arcs[1].radius == pytest.approx(rudder_turn_radius('mariner', 15.0, False))


@pytest.mark.parametrize('keys, words', [
    ('turn_model: mariner\n', 'needs turn_rudder_deg'),
    ('turn_rudder_deg: 15\nturn_model: mariner\nfillet_radius_m: 500\n', 'cannot go with fillet_radius_m'),
    ('turn_rudder_deg: 50\nturn_model: mariner\n', 'must be in (0, 40] deg'),
    ('turn_rudder_deg: 15\nturn_model: boat\n', 'turn_model must be one of'),
])
def test_bad_turn_keys_are_refused_with_the_line(keys, words):
    text = ROUTE.format(rudder=15.0, model='mariner').replace(
        'turn_rudder_deg: 15.0\nturn_model: mariner\n', keys)
    with pytest.raises(RouteError) as exc:
        parse_route_yaml(text)
    assert words in str(exc.value) and '<string>:' in str(exc.value), str(exc.value)


def test_the_los_point_runs_one_lookahead_of_arc_ahead():
    c, r, d = (100.0, -50.0), 400.0, 120.0
    for clockwise in (True, False):
        phi = 0.7
        pos = (c[0] + r * math.cos(phi), c[1] + r * math.sin(phi))
        pn, pe = circle_los_point(c, r, clockwise, *pos, d)
        assert math.hypot(pn - c[0], pe - c[1]) == pytest.approx(r)
        ahead = math.atan2(pe - c[1], pn - c[0]) - phi
        assert ahead == pytest.approx(d / r if clockwise else -d / r)


def test_arc_los_point_leads_the_tangent_by_half_the_angle_on_the_circle():
    """On the circle the bearing of P_LOS is the tangent plus d / (2R) towards the turn."""
    arc = Arc((0.0, 0.0), (500.0, 500.0), (0.0, 500.0), True)     # north-east quarter, starboard
    from ship_guidance.path import Route
    route = Route([Line((-1000.0, 0.0), (0.0, 0.0)), arc])
    d = 100.0
    g = Guidance(route, law='los', lookahead=d, arc_los_point=True)
    phi = math.radians(-70.0)                                    # 20 deg into the arc
    pos = (arc.center[0] + 500.0 * math.cos(phi), arc.center[1] + 500.0 * math.sin(phi))
    g.reset(s=1000.0 + 500.0 * math.radians(20.0))
    out = g.update(*pos)
    tangent = phi + math.pi / 2
    assert math.remainder(out.heading_cmd - tangent, 2 * math.pi) == pytest.approx(d / 1000.0)
    with pytest.raises(ValueError, match='arc_los_point'):
        Guidance(route, law='ilos', lookahead=d, arc_los_point=True)
