"""The figure-eight rudder statistics of scripts/run_seed_scenarios.py (Simakis 1992 Fig. 29).

steady_turn_rudder must be the rudder the vehicle model needs for a steady turn of a given
radius: for the NPS AUV II (linear sway/yaw, Simakis 1992 eqs. 2.8-2.9) the steady state of
v' = a11 v + a12 r + b1 delta, r' = a21 v + a22 r + b2 delta gives
r / delta = (a21 b1 - a11 b2) / (a11 a22 - a12 a21) (non-dimensional), with r' = L / R for a
circle of radius R travelled at the speed V = sqrt(u^2 + v^2) (r' = r L / U, U = u here).
The claim check is tested on hand-made legs: it can fail both ways."""
import math

import numpy as np
import pytest

import run_seed_scenarios as rs
from ship_sim.models import make_model
from ship_sim.models.nps_auv2 import nondimensional_matrices


def analytic_steady_rudder(radius_lengths):
    """|rudder| (rad) of the linear model's steady turn on a circle of radius_lengths L."""
    a11, a12, a21, a22, b1, b2 = nondimensional_matrices()
    gain = (a21 * b1 - a11 * b2) / (a11 * a22 - a12 * a21)      # steady r' per rad of rudder
    k = -(a12 * b2 - a22 * b1) / (a11 * b2 - a21 * b1)          # steady v' / r'
    # R / L = sqrt(1 + v'^2) / r' with v' = k r'  ->  r' = 1 / sqrt((R/L)^2 - k^2)
    r = 1.0 / math.sqrt(radius_lengths ** 2 - k ** 2)
    return abs(r / gain)


@pytest.mark.parametrize('radius_lengths, clockwise', [(5.0, True), (5.0, False), (10.0, True)])
def test_steady_turn_rudder_equals_the_linear_model_steady_state(radius_lengths, clockwise):
    model = make_model('nps_auv2')
    length = 0.3048 * 7.3
    # 60 s is 40 yaw time constants of the vehicle (Nomoto T = 1.5 s at 1 m/s)
    got = rs.steady_turn_rudder(model, radius_lengths * length, clockwise, model.rudder_max,
                                t_end=60.0)
    want = analytic_steady_rudder(radius_lengths)
    assert abs(got) == pytest.approx(want, rel=0.01)
    # unified sign: a clockwise (starboard) turn needs a negative rudder
    assert math.copysign(1.0, got) == (-1.0 if clockwise else 1.0)


def test_steady_turn_rudder_none_when_the_limit_turns_wider():
    model = make_model('nps_auv2')
    # the tightest steady circle is at the limit: ~ L / (0.4 x r'/rad) ~ 1.3 L
    assert rs.steady_turn_rudder(model, 0.5 * 0.3048 * 7.3, True, model.rudder_max,
                                 t_end=60.0) is None


def _leg(kind, mean, mx, steady):
    return {'kind': kind, 'rudder_mean_abs_rad': mean, 'rudder_max_abs_rad': mx,
            'steady_turn_rudder_rad': steady, 'curvature_1pm': 0.0, 'leg': 0}


def test_figure_eight_claim_needs_arcs_near_their_steady_turn_and_below_the_corner():
    line = _leg('line', 0.1, 0.4, 0.0)
    good = [line, _leg('arc', 0.11, 0.3, -0.1), _leg('arc', 0.09, 0.2, 0.1)]
    assert rs.figure_eight_arc_claim(good)[1] is True
    too_much = [line, _leg('arc', 0.2, 0.3, -0.1)]            # twice what the curve needs
    assert rs.figure_eight_arc_claim(too_much)[1] is False
    above_corner = [line, _leg('arc', 0.1, 0.45, -0.1)]
    assert rs.figure_eight_arc_claim(above_corner)[1] is False
    assert rs.figure_eight_arc_claim(None)[1] is None
    assert rs.figure_eight_arc_claim([line, _leg('arc', 0.1, 0.2, None)])[1] is None
    assert np.isclose(rs.ARC_RUDDER_RTOL, 0.25)
