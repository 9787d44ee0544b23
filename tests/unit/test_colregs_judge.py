"""The agreement table of our COLREGs evaluator and the CommonOcean monitor, on a hand-made
head-on pair: one own track that turns 40 deg to starboard early, one that holds on into the
target. The end-to-end test runs the monitor in .venv-judge and skips without it."""
import math

import numpy as np
import pytest

from colregs_judge import JUDGE_PYTHON, judge, monitor_run, run_monitor
from imazu.judge_agreement import CLASSES, agreement_table, pair_class
from ship_guidance.colav_evaluation import ShipDimensions, Track, evaluate_run

DT = 10.0
U = 6.1733            # 12 kn
RANGE0 = 9260.0       # 5 NM: closest approach at RANGE0 / (2 U), about 750 s
T = np.arange(0.0, 1500.0 + DT, DT)
DIMS = ShipDimensions(160.0)


def _rows(chi):
    """(N, 4) north, east, course, speed of a ship at U on the courses ``chi`` (rad)."""
    n = np.concatenate(([0.0], np.cumsum(U * np.cos(chi[:-1]) * DT)))
    e = np.concatenate(([0.0], np.cumsum(U * np.sin(chi[:-1]) * DT)))
    return np.stack((n, e, chi, np.full_like(chi, U)), axis=1)


def _track(rows):
    return Track.of(T, rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3])


def _runs():
    straight = _rows(np.zeros_like(T))
    # starboard 40 deg at 200 s: 550 s before the closest approach (our 300 s 'early'), beyond
    # 30 deg (apparent), at 6.8 km, outside the monitor's 7-minute collision horizon
    turned = _rows(np.where(T < 200.0, 0.0, math.radians(40.0)))
    target = np.stack((RANGE0 - U * T, np.zeros_like(T), np.full_like(T, math.pi),
                       np.full_like(T, U)), axis=1)
    return straight, {'turned': turned, 'held': straight}, target


def test_pair_classes_and_table_counts():
    assert pair_class(True, True, False) == 'both_compliant'
    assert pair_class(False, False, True) == 'both_violating'
    assert pair_class(False, True, False) == 'ours_only_not_triggered'
    assert pair_class(False, True, True) == 'ours_only_triggered'
    assert pair_class(True, False, True) == 'theirs_only'
    ps = [{'row': 'head_on', 'class': c} for c in CLASSES] + [{'row': 'head_on',
                                                               'class': 'both_compliant'}]
    row = agreement_table(ps)['head_on']
    assert row['n'] == 6 and row['agree'] == 3 and row['both_compliant'] == 2
    assert row['agreement'] == 0.5
    assert agreement_table([])['overtaking']['agreement'] is None


@pytest.mark.skipif(not JUDGE_PYTHON.is_file(), reason='.venv-judge absent (make venv-judge)')
@pytest.mark.timeout(1800)
def test_head_on_pair_both_judges_agree():
    reference, owns, target = _runs()
    ours, inputs = {}, []
    for case, (name, own) in enumerate(owns.items(), 1):
        ours[('mariner', name, case)] = evaluate_run(
            _track(own), {'ts1': _track(target)}, _track(reference), DIMS,
            situations={'ts1': 'head-on'})
        inputs.append(monitor_run(f'mariner|{name}|{case}', T, own, {'ts1': target}, DIMS))
    theirs = run_monitor(inputs, jobs=2)
    res = judge(ours, theirs)['seconds']
    turned, held = res['sets']['mariner/turned'], res['sets']['mariner/held']
    # the early starboard turn: compliant for both (theirs: head-on never triggered)
    assert turned['head_on']['both_compliant'] == 1 and turned['safe_passing']['both_compliant'] == 1
    # holding on into the target: a collision, flagged by both
    assert held['head_on']['both_violating'] == 1 and held['safe_passing']['both_violating'] == 1
    assert res['all']['head_on']['agreement'] == 1.0
    (p,) = [p for p in res['pairs'] if p['set'] == 'mariner/held' and p['row'] == 'head_on']
    assert {'late', 'not_apparent', 'not_starboard'} <= set(p['penalties'])
    assert p['their_situation_samples'] > 0


def test_rendered_tables_count_what_the_pairs_say():
    from results_pages.colregs_judge import agreement_rows, disagreement_rows
    rules = [{'id': 'head_on', 'title': 'Rule 14 head-on', 'their_rule': 'R_G4'},
             {'id': 'safe_passing', 'title': 'safe passing', 'their_rule': 'R_G1'}]
    pair = {'set': 'mariner/sbmpc', 'case': 1, 'target': 'ts1', 'row': 'head_on', 'ours': False,
            'theirs': True, 'class': 'ours_only_not_triggered', 'situation': 'head-on',
            'penalties': ['not_apparent'], 'near_miss': False, 'their_situation_samples': 0,
            'their_other_violations': []}
    table = agreement_table([pair])
    data = {'rules': rules, 'readings_result': {'seconds': {
        'sets': {'mariner/sbmpc': table}, 'all': table, 'pairs': [pair]}}}
    (row,) = agreement_rows(data, 'seconds')   # safe passing has no pair: left out
    assert row['rule'] == 'Rule 14 head-on / R_G4' and row['n'] == 1 and row['agree'] == 0
    (d,) = disagreement_rows(data, 'seconds')
    assert d['our_verdict'] == 'not_apparent' and d['their_verdict'] == 'compliant'


def test_setup_names_the_imazu_cases_not_judged_yet():
    # the set's cases, not the run folder's: a folder of four cases judged whole is not the
    # whole set
    from results_pages.colregs_judge import setup
    data = {'runs': 2, 'cases': [1, 3], 'cases_in_run_dir': [1, 2, 3, 4], 'package': 'x',
            'dt_s': 10.0, 'monitor_wall_s': 5.0,
            'readings_result': {'seconds': {'sets': {'mariner/sbmpc': {}}}}}
    text = setup(data)
    assert '| cases judged | 1, 3 |' in text
    left = ', '.join(str(c) for c in [2] + list(range(4, 23)))
    assert f'| Imazu cases not judged yet | {left} |' in text
    data['cases'] = [1, 2, 3, 4]
    assert f'| Imazu cases not judged yet | {", ".join(map(str, range(5, 23)))} |' in setup(data)
    data['cases'] = list(range(1, 23))
    assert '| Imazu cases not judged yet | none |' in setup(data)
