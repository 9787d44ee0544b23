"""The Imazu benchmark's end of a run (imazu.runner.RunEnd) on constructed states, and the
turn-back encounter closed loop with SB-MPC on the MSS tanker, judged by the evaluator."""
import math
import tempfile

import pytest

from imazu.cases import turn_back_case
from imazu.evaluate import evaluate
from imazu.runner import LIMIT_S, RunEnd, case_scenario, run_scenario, write_scenario

from ship_guidance.colav import ShipState, Target
from ship_guidance.colav_evaluation import EvaluationParams

P = EvaluationParams()
U = 6.0


def _end():
    return RunEnd(0.0, 0.0, 0.0, P.route_band_m, P.route_dwell_s)


def test_a_run_ends_once_every_target_has_passed_and_the_ship_stayed_on_its_route():
    end = _end()
    ahead = Target(2000.0, 0.0, math.pi, U, name='closing')     # head-on, still closing
    astern = Target(-2000.0, 0.0, math.pi, U, name='passed')    # behind, opening
    on_route = ShipState(5000.0, 150.0, 0.0, U)
    off_route = ShipState(5000.0, 250.0, 0.0, U)
    assert end.cross_track(5000.0, 150.0) == pytest.approx(150.0)
    assert not end.done(0.0, on_route, [astern, ahead])        # one target still closing
    assert not end.done(1.0, off_route, [astern])              # outside the band
    # inside the band with every target passed from t = 2 s: done after the dwell, not before
    assert not end.done(2.0, on_route, [astern])
    assert not end.done(2.0 + P.route_dwell_s - 1.0, on_route, [astern])
    assert end.done(2.0 + P.route_dwell_s, on_route, [astern])
    # leaving the band restarts the dwell
    end = _end()
    assert not end.done(0.0, on_route, [astern])
    assert not end.done(30.0, off_route, [astern])
    assert not end.done(31.0, on_route, [astern])
    assert not end.done(31.0 + P.route_dwell_s - 1.0, on_route, [astern])
    assert end.done(31.0 + P.route_dwell_s, on_route, [astern])


def _turn_back_run(ship='tanker'):
    case = turn_back_case()
    with tempfile.TemporaryDirectory() as tmp:
        ref = run_scenario(write_scenario(*case_scenario(
            0, {'own': case['own'], 'targets': []}, ship, None, LIMIT_S), f'{tmp}/ref'))
        res = run_scenario(write_scenario(*case_scenario(0, case, ship, 'sbmpc', LIMIT_S),
                                          f'{tmp}/run'), end=RunEnd.of_case(case))
    return res, evaluate(res, ref, case, ship)


def test_turning_back_to_the_route_keeps_the_still_closing_target_outside_its_domain():
    # the specification: the own ship gives way to ts2, then returns to its route without
    # bringing ts1 (still closing) inside either ship's domain, and the run ends with every
    # target passed and the ship back on its route before the limit
    res, run = _turn_back_run()
    assert res.end == 'clear' and run['return_to_route_s'] is not None
    assert run['collisions'] == 0
    ts1 = run['targets']['ts1']
    assert ts1['t_min_s'] > run['targets']['ts2']['t_min_s']    # met after the give-way
    assert not ts1['near_miss'], (ts1['min_distance_m'], ts1['domain_index'])
