"""The collision-avoidance evaluator (ship_guidance.colav_evaluation) on constructed tracks whose
answers follow by hand: straight legs at constant speed, instant course changes."""
import math

import numpy as np
import pytest

from ship_guidance.colav_evaluation import (EvaluationParams, Track, evaluate_run,
                                            evaluate_target, path_deviation, time_lost)

U = 6.0
T = np.arange(0.0, 2000.0 + 1e-9, 1.0)
P = EvaluationParams()


def straight(n0, e0, course_deg, speed=U, t=T):
    c = math.radians(course_deg)
    return Track.of(t, n0 + speed * math.cos(c) * t, e0 + speed * math.sin(c) * t,
                    np.full(len(t), c), np.full(len(t), speed))


def turning(at_s, new_course_deg, speed=U, t=T, n0=0.0, e0=0.0):
    """North at ``speed`` from (n0, e0), then from ``at_s`` on ``new_course_deg`` (instantly)."""
    c = math.radians(new_course_deg)
    after = np.maximum(t - at_s, 0.0)
    before = np.minimum(t, at_s)
    return Track.of(t, n0 + speed * before + speed * math.cos(c) * after,
                    e0 + speed * math.sin(c) * after,
                    np.where(t < at_s, 0.0, c), np.full(len(t), speed))


REF = straight(0.0, 0.0, 0.0)
HEAD_ON = straight(2 * U * 1200.0, 0.0, 180.0)          # meets the reference at t = 1200 s


def test_compliant_starboard_alteration_in_head_on_scores_full_marks():
    own = turning(300.0, 40.0)
    r = evaluate_target(own, HEAD_ON, REF)
    assert r['situation'] == 'head-on' and r['role'] == 'give-way'
    assert r['min_distance_m'] > P.r_min_m and not r['near_miss']
    assert r['manoeuvre_start_s'] == 300.0 and r['max_departure_deg'] == pytest.approx(40.0)
    assert r['penalties'] == {} and r['rule_score'] == 1.0 and r['safety_score'] == 1.0


def test_port_alteration_in_head_on_is_penalised_for_side_and_passing():
    own = turning(300.0, -40.0)
    r = evaluate_target(own, HEAD_ON, REF)
    # passes starboard to starboard after a port turn: 0.4 + 0.6, nothing left
    assert set(r['penalties']) == {'not_starboard', 'starboard_to_starboard'}
    assert r['rule_score'] == 0.0


def test_small_late_alteration_is_neither_early_nor_apparent():
    # 15 deg to starboard 200 s before the meeting: late (< early_s) and not apparent (< 30 deg)
    own = turning(1000.0, 15.0)
    r = evaluate_target(own, HEAD_ON, REF)
    assert set(r['penalties']) == {'late', 'not_apparent'}
    assert r['rule_score'] == pytest.approx(1.0 - P.gamma_late - P.gamma_na)


def test_near_miss_and_collision_flags_follow_the_radii():
    for offset, flags in ((300.0, (False, True, True)), (100.0, (True, True, True)),
                          (700.0, (False, False, True)), (1000.0, (False, False, False))):
        tgt = straight(2 * U * 1200.0, offset, 180.0)
        r = evaluate_target(REF, tgt, REF)
        assert r['min_distance_m'] == pytest.approx(offset, abs=1e-6)
        assert (r['collision'], r['near_miss'], r['below_safe']) == flags
        assert r['safety_score'] == pytest.approx(1.0 - P.gamma_col * flags[0]
                                                  - P.gamma_nm * flags[1] - P.gamma_min * flags[2])


def test_crossing_give_way_passing_ahead_is_penalised_astern_is_not():
    # target from starboard on course 270, crossing the own track at (7200, 0) at t = 1200 s
    tgt = straight(U * 1200.0, U * 1200.0, 270.0)
    astern = evaluate_target(turning(300.0, 60.0), tgt, REF)
    assert astern['situation'] == 'crossing-give-way' and astern['penalties'] == {}
    # a port turn that runs ahead of the target: wrong side and crossing ahead
    ahead = evaluate_target(turning(300.0, -60.0), tgt, REF)
    assert {'not_starboard', 'crossing_ahead'} <= set(ahead['penalties'])


def test_stand_on_holds_until_the_last_window():
    # target from port on course 090 crossing at (7200, 0) at t = 1200 s: own ship stands on
    tgt = straight(U * 1200.0, -U * 1200.0, 90.0)
    held = evaluate_target(turning(1000.0, 40.0), tgt, REF)
    assert held['situation'] == 'crossing-stand-on' and held['role'] == 'stand-on'
    assert held['penalties'] == {}
    early = evaluate_target(turning(300.0, 40.0), tgt, REF)
    assert set(early['penalties']) == {'not_holding'}
    port = evaluate_target(turning(1000.0, -40.0), tgt, REF)
    assert set(port['penalties']) == {'port_turn'}
    # a run may widen the window to its ship's Rule 17(b) moment, never narrow it
    at_800 = turning(800.0, 40.0)
    assert set(evaluate_target(at_800, tgt, REF)['penalties']) == {'not_holding'}
    assert evaluate_target(at_800, tgt, REF, stand_on_window_s=450.0)['penalties'] == {}
    assert evaluate_target(turning(1000.0, 40.0), tgt, REF,
                           stand_on_window_s=10.0)['penalties'] == {}
    run = evaluate_run(at_800, {'ts': tgt}, REF, stand_on_windows={'ts': 450.0})
    assert run['targets']['ts']['stand_on_window_s'] == 450.0 and run['rule_score'] == 1.0


def test_path_deviation_and_time_lost():
    # a parallel track 500 m to starboard: deviation 500 m, no time lost
    side = straight(0.0, 500.0, 0.0)
    assert path_deviation(side, REF) == pytest.approx(500.0)
    assert time_lost(side, REF) == pytest.approx(0.0, abs=1e-9)
    # half speed for the whole run: at the end it is where the reference was at t / 2
    slow = straight(0.0, 0.0, 0.0, speed=U / 2)
    assert time_lost(slow, REF) == pytest.approx(T[-1] / 2)
    # a 40 deg dog-leg held to the end: progress U cos40 per s after the turn
    own = turning(300.0, 40.0)
    lost = (T[-1] - 300.0) * (1.0 - math.cos(math.radians(40.0)))
    assert time_lost(own, REF) == pytest.approx(lost, rel=1e-9)
    assert path_deviation(own, REF) == pytest.approx(U * (T[-1] - 300.0) * math.sin(math.radians(40.0)))


def test_run_summary_counts_and_mean_score():
    own = turning(300.0, 40.0)
    run = evaluate_run(own, {'ho': HEAD_ON, 'near': straight(2 * U * 1200.0, 3500.0, 180.0)}, REF)
    assert set(run['targets']) == {'ho', 'near'}
    assert run['collisions'] == 0
    assert run['min_distance_m'] == min(v['min_distance_m'] for v in run['targets'].values())
    scores = [v['rule_score'] for v in run['targets'].values() if v['role'] != 'none']
    assert run['rule_score'] == pytest.approx(np.mean(scores))
