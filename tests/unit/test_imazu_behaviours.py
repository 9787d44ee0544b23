"""Target behaviours in the in-process Imazu runner (scripts/imazu/runner.py) and the study's
choice of runs (scripts/imazu_behaviours.py)."""
import tempfile

import numpy as np
import pytest

from imazu.cases import load_cases
from imazu.runner import case_scenario, run_scenario, write_scenario
from imazu_behaviours import case_behaviours

CASES = load_cases()
#: Long enough for the own ship's first decisions (the reactions themselves come minutes
#: later: tests/unit/test_reacting_traffic.py steps them without the plant).
SHORT_S = 120.0


def _run(case, behaviours):
    sc, route = case_scenario(case, CASES[case], 'mariner', 'sbmpc', SHORT_S)
    with tempfile.TemporaryDirectory() as tmp:
        return run_scenario(write_scenario(sc, route, tmp), behaviours=behaviours)


def _same(a, b):
    return (np.array_equal(a.t, b.t) and np.array_equal(a.own, b.own)
            and np.array_equal(a.heading, b.heading) and a.decisions == b.decisions
            and all(np.array_equal(a.targets[n], b.targets[n]) for n in a.targets))


def test_straight_and_no_alteration_targets_leave_a_run_bit_for_bit_as_without_behaviours():
    plain = _run(1, None)
    assert _same(plain, _run(1, {'ts1': 'straight'}))
    assert _same(plain, _run(1, {'ts1': 'no_alteration'}))


@pytest.mark.parametrize('case, behaviour, expected', [
    (1, 'no_alteration', {'ts1'}), (1, 'turns_to_port', None),
    (2, 'turns_to_port', {'ts1'}), (2, 'no_alteration', None),
    (3, 'reciprocal', {'ts1'}), (3, 'turns_to_port', None), (4, 'no_alteration', {'ts1'}),
])
def test_the_study_runs_a_behaviour_only_on_the_targets_it_applies_to(case, behaviour, expected):
    chosen = case_behaviours(CASES[case], behaviour)
    assert (None if chosen is None else set(chosen)) == expected


def _row(case, behaviour, method, near_misses, min_distance_m):
    return {'case': case, 'targets': 'head-on', 'ship': 'mariner', 'method': method,
            'behaviour': behaviour, 'reacting_targets': ['ts1'], 'collisions': 0,
            'near_misses': near_misses, 'below_safe': 0, 'min_distance_m': min_distance_m,
            'rule_score': 1.0, 'path_deviation_m': 100.0, 'run_end': 'clear', 'run_end_s': 1.0,
            'last_resort_decisions': 0, 'target_alteration_deg': {'ts1': 0.0}}


def test_the_page_lists_the_breaking_runs_and_sums_each_behaviour():
    from results_pages.studies import render
    data = {'runs': [_row(1, 'reciprocal', 'sbmpc', 0, 900.0), _row(4, 'reciprocal', 'sbmpc', 1, 400.0),
                     _row(1, 'straight', 'sbmpc', 0, 1200.0)]}
    breaks = render('reacting_traffic', 'breaks', data).splitlines()
    assert len(breaks) == 3 and breaks[2].startswith('| 4 | reciprocal |')
    summary = render('reacting_traffic', 'summary', data).splitlines()
    reciprocal = [line for line in summary if line.startswith('| reciprocal |')]
    # two runs, cases 1 and 4, one near miss, the smaller of the two distances
    assert reciprocal == ['| reciprocal | mariner | sbmpc | 2 | 1, 4 | 0 | 1 | 400 | 1.000 | 100 |']
    clean = {'runs': [_row(1, 'straight', 'sbmpc', 0, 1200.0)]}
    assert 'No run' in render('reacting_traffic', 'breaks', clean)
