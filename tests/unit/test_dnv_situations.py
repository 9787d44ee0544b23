"""DNV ship-traffic-generator's 55 baseline situations as an encounter set of the benchmark.

The files (scripts/imazu/trafficgen_baseline, MIT, source in its README) read as cases: 55 of
them, the own ship at the origin at 10 kn on course 000 in every one (the benchmark's single
no-traffic reference per ship relies on it), one to three targets whose count and situations
match each file's title, every target with its length and beam; the benchmark takes
``--set dnv`` and refuses a case outside the set in one line; and a target's own length, not
the own ship's, sizes its hull and domain in the evaluation.
"""
import math

import numpy as np
import pytest

from imazu.cases import DNV_DIR, load_set, single_target
from imazu.evaluate import evaluate
from imazu.runner import RunResult
from imazu.trafficgen_situations import SITUATIONS, read_situation
from imazu_benchmark import parse_args

KNOT_MPS = 1852.0 / 3600.0


def test_the_55_situations_read_with_their_titles_lengths_and_one_own_start():
    cases = load_set('dnv')
    assert sorted(cases) == list(range(1, 56))
    assert (DNV_DIR / 'LICENSE').read_text().startswith('MIT License')
    counts = {1: 0, 2: 0, 3: 0}
    for n, case in cases.items():
        title, _ = read_situation(DNV_DIR / f'traffic_situation_{n:02d}.json')
        codes = [c.strip() for c in title.split(',')]
        assert [t['colregs'] for t in case['targets']] == [SITUATIONS[c] for c in codes]
        own = case['own']
        assert (own['north_m'], own['east_m']) == (0.0, 0.0)
        assert math.isclose(own['speed_mps'], 10.0 * KNOT_MPS)
        assert math.isclose(math.sin(math.radians(own['course_deg'])), 0.0, abs_tol=1e-9)
        for t in case['targets']:
            assert t['length_m'] > 0.0 and t['beam_m'] > 0.0
            assert 0.0 < t['speed_mps'] < 30.0 * KNOT_MPS
        counts[len(case['targets'])] += 1
    assert counts == {1: 5, 2: 15, 3: 35}
    assert single_target(cases) == (1, 2, 3, 4, 5)


def test_the_benchmark_takes_the_dnv_set_and_refuses_a_case_outside_it(capsys):
    args, cases = parse_args(['--set', 'dnv', '--quick'])
    assert args.cases == [1, 2, 3, 4, 5] and len(cases) == 55
    with pytest.raises(SystemExit) as err:
        parse_args(['--set', 'dnv', '--cases', '56'])
    assert err.value.code == 2
    assert 'no dnv case [56]; cases are 1-55' in capsys.readouterr().err


def test_a_targets_own_length_sizes_its_domain():
    # Own ship (the mariner, 160.9 m) north at 5 m/s; a target passes southbound 400 m abeam.
    # The Fujii domain reaches 1.6 L abeam: 257 m for the mariner, 480 m for a 300 m target, so
    # the pass is a near miss only when the target is scored with its own length.
    t = np.arange(0.0, 2001.0, 1.0)
    own = np.column_stack((5.0 * t - 5000.0, 0.0 * t, 0.0 * t, 5.0 + 0.0 * t))
    tgt = np.column_stack((5000.0 - 5.0 * t, 400.0 + 0.0 * t, np.pi + 0.0 * t, 5.0 + 0.0 * t))
    run = RunResult(t, own, {'ts1': tgt}, heading=0.0 * t)
    reference = RunResult(t, own.copy(), heading=0.0 * t)
    case = {'own': {'north_m': -5000.0, 'east_m': 0.0, 'course_deg': 0.0, 'speed_mps': 5.0},
            'targets': [{'name': 'ts1', 'colregs': 'head-on'}]}
    assert evaluate(run, reference, case, 'mariner')['near_misses'] == 0
    case['targets'][0].update(length_m=300.0, beam_m=50.0)
    assert evaluate(run, reference, case, 'mariner')['near_misses'] == 1
