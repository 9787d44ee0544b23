"""run_seed_scenarios' Lee 2004 claims (tanker course changes, the thesis's PD gains, current)
on hand-made rows: each verdict follows the numbers, and a missing run gives n/a."""
import math

import run_seed_scenarios as rs


def _row(**metrics):
    return {'metrics': metrics}


def _claims(rows, word):
    return [c for c in rs.claim_checks(rows) if word in c[0]]


def test_tanker_course_change_claim_follows_the_steady_errors():
    rows = {'course_tanker_30_pd_004': _row(steady_error_rad=math.radians(0.25)),
            'course_tanker_30_fuzzy_004': _row(steady_error_rad=math.radians(-0.01)),
            'course_tanker_45_pd_004': _row(steady_error_rad=math.radians(0.25)),
            'course_tanker_45_fuzzy_004': _row(steady_error_rad=math.radians(0.4)),
            'course_tanker_60_pd_004': _row(steady_error_rad=math.radians(0.25))}
    verdicts = [v for _, v, _ in _claims(rows, 'tanker, depth 1000 m')]
    assert verdicts == [True, False, None]


def test_thesis_pd_claim_needs_every_angle_within_the_tolerance():
    rows = {f'course_mariner_{a}_pd_thesisgains_004': _row(steady_error_rad=math.radians(-0.6))
            for a in (30, 45, 60, 90)}
    assert [v for _, v, _ in _claims(rows, 'Kp = 9')] == [True]
    rows['course_mariner_90_pd_thesisgains_004'] = _row(steady_error_rad=math.radians(-0.12))
    assert [v for _, v, _ in _claims(rows, 'Kp = 9')] == [False]
    del rows['course_mariner_90_pd_thesisgains_004']
    assert [v for _, v, _ in _claims(rows, 'Kp = 9')] == [None]


def test_current_claim_needs_both_finished_and_the_fuzzy_pid_no_worse():
    def rows(pd, fz, fin=1000.0):
        return {'route_following_tanker_pd_current075_004': _row(xte_rms_m=pd,
                                                                 guidance_finished_s=fin),
                'route_following_tanker_fuzzy_current075_004': _row(xte_rms_m=fz,
                                                                    guidance_finished_s=1000.0)}
    assert [v for _, v, _ in _claims(rows(50.0, 40.0), '0.75 m/s')] == [True]
    assert [v for _, v, _ in _claims(rows(40.0, 50.0), '0.75 m/s')] == [False]
    assert [v for _, v, _ in _claims(rows(50.0, 40.0, None), '0.75 m/s')] == [False]
