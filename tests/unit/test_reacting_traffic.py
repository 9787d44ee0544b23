"""Target behaviours (ship_guidance.reacting_traffic) on hand-built geometries: each trigger,
the breach it makes, and two reciprocal ships meeting head-on."""
import math

import numpy as np
import pytest

from ship_guidance import colregs
from ship_guidance.colav import ShipState
from ship_guidance.colav_methods import make_colav
from ship_guidance.colav_params import ColavParams
from ship_guidance.own_ship_prediction import OwnShipModel
from ship_guidance.reacting_traffic import (PORT_TURN_DEG, TRIGGER_RANGE_M, ReactingTraffic,
                                            applies, los_course)
from ship_sim.frames import wrap_angle
from ship_sim.light_traffic import make_traffic

U = 6.0
SHIP = OwnShipModel(has_shaft=False)


def _target(name, north, east, course_deg, speed=U):
    # the scenario form: ENU (x east, y north), course clockwise from north
    return {'name': name, 'x_m': east, 'y_m': north, 'course_deg': course_deg, 'speed_mps': speed}


def _straight(own, dt):
    if own is None:
        return None
    return ShipState(own.north + own.speed * math.cos(own.course) * dt,
                     own.east + own.speed * math.sin(own.course) * dt, own.course, own.speed)


def _run(traffic, own, t_end, dt=1.0):
    """Step ``traffic`` beside an own ship on a straight line; per step (t, own, states)."""
    out = []
    t = 0.0
    while t <= t_end:
        out.append((t, own, traffic.state(t)))
        traffic.step(t, own, dt)
        own = _straight(own, dt)
        t += dt
    return out


def _crossing(own_side):
    """Target 'a' heading west 2500 m east of the origin; the own ship heading north from
    2500 m south of the origin (own_side 'port': on a's port side, a stands on) or from 2500 m
    north heading south (on a's starboard side, a gives way); both meet at the origin."""
    light = make_traffic([_target('a', 0.0, 2500.0, 270.0)])
    own = (ShipState(-2500.0, 0.0, 0.0, U) if own_side == 'port'
           else ShipState(2500.0, 0.0, math.pi, U))
    return ReactingTraffic(light, {'a': 'turns_to_port'}, SHIP), own


def test_turns_to_port_turns_to_port_only_once_stand_on_within_its_trigger_range():
    traffic, own = _crossing('port')
    rows = _run(traffic, own, 400.0)
    courses = np.array([s[2][0] for _, _, s in rows])
    ranges = np.array([math.hypot(s[0][0] - o.north, s[1][0] - o.east) for _, o, s in rows])
    t = np.array([r[0] for r in rows])
    assert ranges[0] > TRIGGER_RANGE_M          # the geometry starts outside the trigger
    t_fire, other = traffic.triggered['a']
    assert other == 'own_ship'
    # it fires at the first step inside the trigger range, not before
    first_inside = t[np.argmax(ranges < TRIGGER_RANGE_M)]
    assert t_fire == first_inside
    before = courses[t <= t_fire]
    assert np.all(before == courses[0])          # course held (stand-on) until then
    alteration = np.degrees(wrap_angle(courses - courses[0]))
    assert np.all(alteration <= 0.0)              # never to starboard
    assert alteration[-1] == pytest.approx(-PORT_TURN_DEG, abs=1.0)   # the port turn, held


@pytest.mark.parametrize('geometry', ['give-way', 'head-on'])
def test_turns_to_port_holds_its_course_when_it_is_not_the_stand_on_ship(geometry):
    if geometry == 'give-way':
        traffic, own = _crossing('starboard')
    else:
        traffic = ReactingTraffic(make_traffic([_target('a', 5000.0, 0.0, 180.0)]),
                                  {'a': 'turns_to_port'}, SHIP)
        own = ShipState(0.0, 0.0, 0.0, U)
    rows = _run(traffic, own, 400.0)
    assert not traffic.triggered
    assert all(s[2][0] == rows[0][2][2][0] for _, _, s in rows)


def test_no_alteration_never_changes_course_or_speed_and_moves_as_a_light_target():
    targets = [_target('a', 3000.0, 0.0, 180.0), _target('b', 0.0, 2500.0, 270.0)]
    light = make_traffic(targets)
    traffic = ReactingTraffic(make_traffic(targets), {'a': 'no_alteration',
                                                      'b': 'no_alteration'}, SHIP)
    for t, _, (n, e, c, s) in _run(traffic, ShipState(0.0, 0.0, 0.0, U), 600.0):
        ln, le, lc, ls = light.state(t)
        assert (n.tolist(), e.tolist(), c.tolist(), s.tolist()) == \
            (ln.tolist(), le.tolist(), lc.tolist(), ls.tolist())
    assert not traffic.reacting


def test_the_behaviours_apply_where_the_targets_role_calls_for_them():
    # seen from the own ship: a crossing-give-way target stands on, so it may turn to port
    assert applies('turns_to_port', 'crossing-give-way')
    assert not applies('turns_to_port', 'crossing-stand-on')
    assert applies('no_alteration', 'head-on') and applies('no_alteration', 'crossing-stand-on')
    assert not applies('no_alteration', 'crossing-give-way')
    assert all(applies(b, s) for b in ('straight', 'reciprocal') for s in colregs.SITUATIONS[1:])
    with pytest.raises(ValueError, match='unknown'):
        applies('zigzag', 'head-on')


def test_los_course_steers_back_to_the_track_from_either_side():
    assert los_course(0.0, 0.0, 0.0, 0.0, 0.0, 1000.0) == 0.0
    assert los_course(0.0, 1000.0, 0.0, 0.0, 0.0, 1000.0) == pytest.approx(-math.pi / 4)
    assert los_course(0.0, -1000.0, 0.0, 0.0, 0.0, 1000.0) == pytest.approx(math.pi / 4)


def test_unknown_behaviour_or_target_is_refused():
    light = make_traffic([_target('a', 0.0, 0.0, 0.0)])
    with pytest.raises(ValueError, match='unknown'):
        ReactingTraffic(light, {'a': 'zigzag'}, SHIP)
    with pytest.raises(ValueError, match='unknown targets'):
        ReactingTraffic(light, {'b': 'straight'}, SHIP)
    with pytest.raises(ValueError, match='colav_factory'):
        ReactingTraffic(light, {'a': 'reciprocal'}, SHIP)


def test_two_reciprocal_sbmpc_ships_meeting_head_on_pass_port_to_port_beyond_a_near_miss():
    params = ColavParams()
    light = make_traffic([_target('a', 0.0, 0.0, 0.0), _target('b', 7000.0, 0.0, 180.0)])
    traffic = ReactingTraffic(light, {'a': 'reciprocal', 'b': 'reciprocal'}, SHIP,
                              colav_factory=lambda: make_colav('sbmpc', params, SHIP),
                              decision_period_s=5.0)
    rows = _run(traffic, None, 1000.0, dt=2.0)
    p = np.array([[[s[0][i], s[1][i]] for i in range(2)] for _, _, s in rows])   # (N, 2, 2)
    c = np.array([s[2] for _, _, s in rows])
    rng = np.hypot(*(p[:, 1] - p[:, 0]).T)
    k = int(np.argmin(rng))
    assert 0 < k < len(rows) - 1                  # they met within the run
    assert rng[k] > params.near_miss_m, rng[k]
    # port to port: at the closest point each sees the other on its port side
    for me, other in ((0, 1), (1, 0)):
        beta = colregs.relative_bearing(p[k, me], c[k, me], p[k, other])
        assert math.pi < beta < 2.0 * math.pi, math.degrees(beta)
    # each one's first alteration is to starboard (Rule 14; the way back to its track later
    # is to port)
    alteration = np.degrees(wrap_angle(c - c[0]))
    for i in range(2):
        first = alteration[np.argmax(np.abs(alteration[:, i]) > 1.0), i]
        assert first > 1.0, alteration[:, i]
