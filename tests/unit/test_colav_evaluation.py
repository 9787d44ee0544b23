"""The collision-avoidance evaluator (ship_guidance.colav_evaluation) on constructed tracks whose
answers follow by hand: straight legs at constant speed, instant course changes, hulls as
rectangles at given headings."""
import math

import numpy as np
import pytest

from ship_guidance.colav_evaluation import (EvaluationParams, ShipDimensions, Track,
                                            colregs_stage, distance_to_polyline, evaluate_run,
                                            evaluate_target, hull_contact, path_deviation,
                                            return_to_route, time_lost)

U = 6.0
T = np.arange(0.0, 2000.0 + 1e-9, 1.0)
P = EvaluationParams()
SHIP = ShipDimensions(160.0)            # beam 160 / 7 = 22.86 m


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
    r = evaluate_target(own, HEAD_ON, REF, SHIP)
    assert r['situation'] == 'head-on' and r['role'] == 'give-way'
    assert r['min_distance_m'] > P.r_min_m and not r['near_miss']
    assert r['manoeuvre_start_s'] == 300.0 and r['max_departure_deg'] == pytest.approx(40.0)
    assert r['penalties'] == {} and r['rule_score'] == 1.0 and r['safety_score'] == 1.0


def test_port_alteration_in_head_on_is_penalised_for_side_and_passing():
    own = turning(300.0, -40.0)
    r = evaluate_target(own, HEAD_ON, REF, SHIP)
    # passes starboard to starboard after a port turn: 0.4 + 0.6, nothing left
    assert set(r['penalties']) == {'not_starboard', 'starboard_to_starboard'}
    assert r['rule_score'] == 0.0


def test_small_late_alteration_is_neither_early_nor_apparent():
    # 15 deg to starboard 200 s before the meeting: late (< early_s) and not apparent (< 30 deg)
    own = turning(1000.0, 15.0)
    r = evaluate_target(own, HEAD_ON, REF, SHIP)
    assert set(r['penalties']) == {'late', 'not_apparent'}
    assert r['rule_score'] == pytest.approx(1.0 - P.gamma_late - P.gamma_na)


def still(n, e, heading_deg):
    """A ship lying at (n, e) with the given heading over the samples T[:3]."""
    t = T[:3]
    return Track.of(t, np.full(3, n), np.full(3, e), np.full(3, math.radians(heading_deg)),
                    np.zeros(3))


def test_hull_rectangles_touch_exactly_when_the_hand_geometry_says_so():
    b = SHIP.beam_m
    assert b == pytest.approx(160.0 / 7.0)
    own = still(0.0, 0.0, 0.0)
    # side by side on parallel headings: sides touch at a centre distance of one beam
    for gap, contact in ((b - 0.5, True), (b + 0.5, False)):
        hit, clearance = hull_contact(own, still(0.0, gap, 0.0), SHIP, SHIP)
        assert hit is contact and clearance == pytest.approx(max(gap - b, 0.0), abs=1e-9)
    # bow into the side of a ship heading 090 (its long axis across the own bow): contact at
    # half a length (own bow) plus half a beam (its side) ahead
    reach = 0.5 * SHIP.length_m + 0.5 * b
    for ahead, contact in ((reach - 0.5, True), (reach + 0.5, False)):
        hit, clearance = hull_contact(own, still(ahead, 0.0, 90.0), SHIP, SHIP)
        assert hit is contact and clearance == pytest.approx(max(ahead - reach, 0.0), abs=1e-9)
    # end to end on one heading: bow meets stern at one length; a 300 m tanker's hull ahead
    # of a 160 m ship reaches it at half the sum of the lengths
    tanker = ShipDimensions(300.0)
    assert hull_contact(own, still(229.0, 0.0, 0.0), SHIP, tanker)[0]
    assert not hull_contact(own, still(231.0, 0.0, 0.0), SHIP, tanker)[0]
    # the other hull on 045, centre x0 dead ahead: its long side is the line y = x - x0 +
    # (B/2) / sin45 (x ahead, y to port of the own bow), which the own bow corner (L/2, -B/2)
    # crosses at x0 = L/2 + B/2 + (B/2) / sin45 = 107.6 m; the hulls touch up to there
    x0 = 0.5 * SHIP.length_m + 0.5 * b + 0.5 * b / math.sin(math.radians(45.0))
    assert x0 == pytest.approx(107.59, abs=0.01)
    assert hull_contact(own, still(x0 - 0.5, 0.0, 45.0), SHIP, SHIP)[0]
    hit, clearance = hull_contact(own, still(x0 + 0.5, 0.0, 45.0), SHIP, SHIP)
    # the gap from that corner to the side, perpendicular to it: 0.5 sin45
    assert not hit and clearance == pytest.approx(0.5 * math.sin(math.radians(45.0)), abs=1e-9)


def test_the_hulls_touching_during_a_pass_is_a_collision_and_a_near_miss():
    # head-on, passing 20 m apart centre to centre: the beams (22.9 m) overlap
    r = evaluate_target(REF, straight(2 * U * 1200.0, 20.0, 180.0), REF, SHIP)
    assert r['collision'] and r['near_miss'] and r['below_safe']
    assert r['min_hull_clearance_m'] == 0.0
    assert r['safety_score'] == pytest.approx(1.0 - P.gamma_col - P.gamma_nm - P.gamma_min)


def test_near_miss_is_the_fujii_domain_abeam_and_ahead():
    # passing abeam at 1.6 L = 256 m is the domain's edge; the domain index is distance / 256
    abeam = P.domain_across * SHIP.length_m
    for offset in (0.95 * abeam, 1.05 * abeam, 700.0, 1000.0):
        r = evaluate_target(REF, straight(2 * U * 1200.0, offset, 180.0), REF, SHIP)
        assert r['min_distance_m'] == pytest.approx(offset, abs=1e-6)
        assert r['domain_index'] == pytest.approx(offset / abeam, rel=1e-9)
        assert r['near_miss'] is (offset < abeam) and not r['collision']
        assert r['below_safe'] is (offset < P.r_min_m)
        assert r['min_hull_clearance_m'] == pytest.approx(offset - SHIP.beam_m, abs=1e-6)
    # the domain reaches 4 L = 640 m ahead: a ship lying dead ahead at 600 m is inside it, at
    # 700 m outside, though both are closer than the abeam pass at 1000 m above
    for ahead in (600.0, 700.0):
        r = evaluate_target(still(0.0, 0.0, 0.0), still(ahead, 0.0, 90.0), still(0.0, 0.0, 0.0),
                            SHIP, situation='none')
        assert r['domain_index'] == pytest.approx(ahead / (P.domain_along * SHIP.length_m))
        assert r['near_miss'] is (ahead < P.domain_along * SHIP.length_m)


def test_a_longer_target_has_a_larger_domain_the_own_ship_can_violate():
    # a 300 m target passing abeam at 400 m: outside the own (160 m) domain (256 m abeam) but
    # the own ship is inside the target's (1.6 x 300 = 480 m)
    tgt = straight(2 * U * 1200.0, 400.0, 180.0)
    small = evaluate_target(REF, tgt, REF, SHIP)
    large = evaluate_target(REF, tgt, REF, SHIP, ShipDimensions(300.0))
    assert not small['near_miss'] and large['near_miss']
    assert large['domain_index'] == pytest.approx(400.0 / 480.0)


def test_crossing_give_way_passing_ahead_is_penalised_astern_is_not():
    # target from starboard on course 270, crossing the own track at (7200, 0) at t = 1200 s
    tgt = straight(U * 1200.0, U * 1200.0, 270.0)
    astern = evaluate_target(turning(300.0, 60.0), tgt, REF, SHIP)
    assert astern['situation'] == 'crossing-give-way' and astern['penalties'] == {}
    # a port turn that runs ahead of the target: wrong side and crossing ahead
    ahead = evaluate_target(turning(300.0, -60.0), tgt, REF, SHIP)
    assert {'not_starboard', 'crossing_ahead'} <= set(ahead['penalties'])


def test_colregs_stage_boundaries():
    four_lengths = P.colregs_4_lengths * SHIP.length_m
    for rng, stage in ((P.r_colregs_2_max_m + 0.1, 1), (P.r_colregs_2_max_m, 2),
                       (P.r_colregs_3_max_m + 0.1, 2), (P.r_colregs_3_max_m, 3),
                       (four_lengths + 0.1, 3), (four_lengths, 4), (0.0, 4)):
        assert colregs_stage(rng, SHIP) == stage, rng
    # stage 4 scales with the own ship: 4 x 300 m for a tanker
    assert colregs_stage(1000.0, ShipDimensions(300.0)) == 4 and colregs_stage(1000.0, SHIP) == 3


def test_stand_on_may_act_only_from_stage_three():
    # target from port on course 090 crossing at (7200, 0) at t = 1200 s: own ship stands on.
    # Range sqrt(2) U (1200 - t) reaches r_colregs_3_max = 3000 m at t = 846.4 s
    tgt = straight(U * 1200.0, -U * 1200.0, 90.0)
    t3 = 1200.0 - P.r_colregs_3_max_m / (math.sqrt(2.0) * U)
    assert t3 == pytest.approx(846.45, abs=0.01)
    held = evaluate_target(turning(850.0, 40.0), tgt, REF, SHIP)
    assert held['situation'] == 'crossing-stand-on' and held['role'] == 'stand-on'
    assert held['manoeuvre_stage'] == 3 and held['penalties'] == {}
    early = evaluate_target(turning(840.0, 40.0), tgt, REF, SHIP)
    assert early['manoeuvre_stage'] == 2 and set(early['penalties']) == {'not_holding'}
    assert early['manoeuvre_range_m'] == pytest.approx(math.sqrt(2.0) * U * 360.0)
    port = evaluate_target(turning(1000.0, -40.0), tgt, REF, SHIP)
    assert set(port['penalties']) == {'port_turn'}
    # holding into stage 4 (4 L = 640 m, reached at 1200 - 640 / (sqrt2 U) = 1124.6 s): Rule
    # 17(b) required action; a turn at 1120 s (range 679 m) is in time, at 1130 s (594 m) not
    assert 'not_acting' in evaluate_target(REF, tgt, REF, SHIP)['penalties']
    assert evaluate_target(turning(1120.0, 40.0), tgt, REF, SHIP)['penalties'] == {}
    assert set(evaluate_target(turning(1130.0, 40.0), tgt, REF, SHIP)['penalties']) == \
        {'not_acting'}
    # no duty where the unmanoeuvred pass clears both domains: overtaken on a parallel track
    # 300 m to starboard by a ship at 2 U, abeam at t = 500 s, inside 4 L = 640 m (stage 4)
    # for 2 x 565 m of relative track but never inside 1.6 L = 256 m abeam; 200 m off is
    for side, duty in ((300.0, False), (200.0, True)):
        r = evaluate_target(REF, straight(-3000.0, side, 0.0, speed=2.0 * U), REF, SHIP,
                            situation='being-overtaken')
        assert r['min_distance_m'] == pytest.approx(side) and r['t_min_s'] == 500.0
        assert r['min_distance_m'] < P.colregs_4_lengths * SHIP.length_m
        assert r['domain_index'] == pytest.approx(side / (P.domain_across * SHIP.length_m))
        assert ('not_acting' in r['penalties']) is duty
    # the window is the target's range, not the method: the same turn judged against a longer
    # own ship (stage 4 from 4 L) is still stage 3 at 1000 s (range 1697 m) for 160 m and
    # stage 4 for a 450 m ship
    late = turning(1000.0, 40.0)
    assert evaluate_target(late, tgt, REF, SHIP)['manoeuvre_stage'] == 3
    assert evaluate_target(late, tgt, REF, ShipDimensions(450.0))['manoeuvre_stage'] == 4


def legs(turns, t=T, speed=U):
    """A track from (0, 0) at ``speed`` whose course changes instantly: ``turns`` [(t_s,
    course_deg), ...] in time order, north before the first."""
    course = np.zeros(len(t))
    for at, c in turns:
        course[t >= at] = math.radians(c)
    dt = np.diff(t, prepend=t[0])
    prev = np.concatenate(([course[0]], course[:-1]))
    north = np.cumsum(speed * np.cos(prev) * dt)
    east = np.cumsum(speed * np.sin(prev) * dt)
    return Track.of(t, north, east, course, np.full(len(t), speed))


def test_return_to_route_on_a_dog_leg():
    # out at 040 for 200 s from t = 300 s (771 m to starboard), back at 320 for 200 s, then
    # north: the offset falls below the 200 m band 148 s into the leg back (771 - 200 m at
    # U sin40 = 3.86 m/s), i.e. at t = 648 s
    own = legs([(300.0, 40.0), (500.0, 320.0), (700.0, 0.0)])
    route = np.array([[0.0, 0.0], [20000.0, 0.0]])
    off = distance_to_polyline(own.p, route)
    assert off.max() == pytest.approx(U * 200.0 * math.sin(math.radians(40.0)), abs=1e-6)
    back = 500.0 + (U * 200.0 * math.sin(math.radians(40.0)) - P.route_band_m) / (
        U * math.sin(math.radians(40.0)))
    assert back == pytest.approx(648.1, abs=0.05)
    assert return_to_route(own, route, 500.0) == pytest.approx(back - 500.0, abs=1.0)
    # already back when counting starts: 0; a stay shorter than the dwell does not count
    assert return_to_route(own, route, 900.0) == 0.0
    short = EvaluationParams(route_dwell_s=T[-1] - 600.0)
    assert return_to_route(own, route, 500.0, short) is None
    # a dog-leg held to the end never returns
    assert return_to_route(turning(300.0, 40.0), route, 500.0) is None
    # evaluate_run counts from the last target's closest approach, on the reference's line
    run = evaluate_run(own, {'ho': straight(2 * U * 1200.0, 2000.0, 180.0)}, REF, SHIP)
    assert run['last_cpa_s'] == run['targets']['ho']['t_min_s']
    expected = return_to_route(own, REF.p[[0, -1]], run['last_cpa_s'])
    assert run['return_to_route_s'] == expected


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
    run = evaluate_run(own, {'ho': HEAD_ON, 'near': straight(2 * U * 1200.0, 3500.0, 180.0)}, REF,
                       SHIP)
    assert set(run['targets']) == {'ho', 'near'}
    assert run['collisions'] == 0
    assert run['min_distance_m'] == min(v['min_distance_m'] for v in run['targets'].values())
    scores = [v['rule_score'] for v in run['targets'].values() if v['role'] != 'none']
    assert run['rule_score'] == pytest.approx(np.mean(scores))
