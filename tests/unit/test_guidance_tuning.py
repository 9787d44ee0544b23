"""GA-tuned guidance (Lee 2004, Ch. 4): the box GA, the look-ahead law and its stability.

The GA is the route planner's (ship_planner.ga.minimize_box over ga.minimize); the closed loop
is the linear ship (nomoto1, Lee 2004 Table 2.2) with the gain table's PD and LOS guidance.
"""
import math

import numpy as np
import pytest

from ship_autopilot.gains import heading_loop_design
from ship_autopilot.guidance_tuning import (Case, ConstantLookahead, LookaheadLaw, gene_box,
                                            metrics, simulate, tune)
from ship_guidance.los import critical_lookahead
from ship_guidance.path import Line, Route
from ship_planner.fillets import fillet_polyline, segments_to_route
from ship_planner.ga import minimize_box
from ship_sim.models import make_model


def sphere(x):
    return np.sum((x - np.array([0.3, -2.0, 5.0])) ** 2, axis=1)


def rosenbrock(x):
    return (1.0 - x[:, 0]) ** 2 + 100.0 * (x[:, 1] - x[:, 0] ** 2) ** 2


def test_the_box_ga_finds_a_shifted_sphere_minimum():
    res = minimize_box(sphere, [-10.0] * 3, [10.0] * 3, population=40, generations=150, seed=1)
    assert np.allclose(res.x, [0.3, -2.0, 5.0], atol=0.02)
    assert res.cost < 1e-3


def test_the_box_ga_finds_rosenbrocks_valley_minimum():
    res = minimize_box(rosenbrock, [-2.0, -1.0], [2.0, 3.0], population=60, generations=400, seed=0,
                       stall_generations=400)
    assert np.allclose(res.x, [1.0, 1.0], atol=0.05)


def test_the_box_ga_is_deterministic_and_refuses_a_bad_box():
    a = minimize_box(sphere, [-10.0] * 3, [10.0] * 3, population=10, generations=5, seed=7)
    b = minimize_box(sphere, [-10.0] * 3, [10.0] * 3, population=10, generations=5, seed=7)
    assert np.array_equal(a.x, b.x) and a.history == b.history
    with pytest.raises(ValueError, match='upper > lower'):
        minimize_box(sphere, [0.0, 1.0], [1.0, 1.0])


def linear_ship_case(route, **kw):
    d = heading_loop_design('nomoto1')
    return Case('test', route, make_model('nomoto1'), d.gains['pd'], d.zeta, d.omega_n, **kw)


def small_case():
    pts = [(0.0, 0.0), (0.0, 1500.0), (1000.0, 2500.0)]
    return linear_ship_case(segments_to_route(fillet_polyline(pts, 600.0)), cost='coastal',
                            current_speed=0.75, start_cross_m=100.0, dt=2.0, t_max=800.0)


def test_tuning_is_deterministic_for_a_seed():
    case = small_case()
    law_a, res_a = tune(case, minimize_box, population=4, generations=2, seed=5)
    law_b, res_b = tune(case, minimize_box, population=4, generations=2, seed=5)
    assert law_a == law_b and res_a.history == res_b.history


def test_the_tuned_law_stays_above_the_stability_limit_at_its_speeds():
    case = small_case()
    law, _ = tune(case, minimize_box, population=4, generations=2, seed=2)
    errors = np.linspace(-3000.0, 3000.0, 601)
    for speed in (case.speed, 0.5 * case.speed, 1.2 * case.speed):   # the law scales with U
        limit = critical_lookahead(case.zeta, case.omega_n, speed)
        assert min(law(speed, e) for e in errors) > limit
        assert law.minimum(speed) > limit


def test_the_gene_box_starts_above_the_critical_time():
    case = small_case()
    lower, upper = gene_box(case)
    t_crit = 1.0 / (2.0 * case.zeta * case.omega_n)
    assert lower[0] > t_crit and lower[1] > t_crit and np.all(upper > lower)


def test_the_law_is_long_on_the_path_and_short_far_from_it():
    law = LookaheadLaw(t_min=20.0, t_max=60.0, e_scale=100.0)
    assert law(7.7, 0.0) == pytest.approx(7.7 * 60.0)
    assert law(7.7, 1000.0) == pytest.approx(7.7 * 20.0, rel=1e-6)
    assert law(7.7, 100.0) == pytest.approx(7.7 * (20.0 + 40.0 / math.e))


def test_the_closed_loop_is_stable_above_the_limit_and_not_below_it():
    """The in-process loop is the linear ship of the stability analysis: a constant look-ahead at
    twice the limit settles on a straight line, at half the limit it keeps oscillating."""
    case = linear_ship_case(Route([Line((0.0, 0.0), (0.0, 12000.0))]), start_cross_m=50.0,
                            dt=0.5, t_max=1500.0)
    d_crit = critical_lookahead(case.zeta, case.omega_n, case.speed)
    tail = slice(-400, None)                                       # the last 200 s
    stable = simulate(case, ConstantLookahead(2.0 * d_crit))
    unstable = simulate(case, ConstantLookahead(0.5 * d_crit))
    assert np.max(np.abs(stable['cross_track'][tail])) < 1.0
    assert np.max(np.abs(unstable['cross_track'][tail])) > 10.0


def test_plain_los_settles_downstream_in_a_cross_current_by_d_v_over_u():
    """Metrics of the loop against los.los_current_offset: e = d V / sqrt(U^2 - V^2)."""
    from ship_guidance.los import los_current_offset
    case = linear_ship_case(Route([Line((0.0, 0.0), (0.0, 20000.0))]), current_speed=0.75,
                            current_direction=0.0, dt=1.0, t_max=2000.0)
    run = simulate(case, ConstantLookahead(300.0))
    # current towards north pushes an eastbound ship to port: negative cross-track
    assert run['cross_track'][-1] == pytest.approx(-los_current_offset(300.0, 0.75, case.speed), rel=0.02)
    assert metrics(case, run)['finished'] is False
