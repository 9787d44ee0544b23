"""The Imazu runner with colav on sensed targets (run_scenario(..., sensing=...)), on the first
minutes of case 2 (one target crossing from starboard, the own ship gives way), and the study's
summary of where a level breaks (scripts/imazu_degraded.py)."""
import math
import tempfile

import numpy as np
import pytest

from imazu.cases import load_cases
from imazu.runner import case_scenario, run_scenario, sensed_targets, write_scenario
from imazu_degraded import summarise

from ship_guidance.colav_params import ColavParams
from ship_guidance.sensor_levels import LEVELS

CASE = 2
#: Sim time of the short runs: past the first give-way decision of the perfect run (the target
#: 4 NM from the meeting point at 12 kn: 20 min to it; colav acts once the encounter enters its
#: horizon, ColavParams.horizon_s before the closest point, plus the settling of the turn).
DURATION_S = 1200.0 - ColavParams().horizon_s + 120.0


def _run(sensing):
    case = load_cases()[CASE]
    with tempfile.TemporaryDirectory() as tmp:
        sc, route = case_scenario(CASE, case, 'mariner', 'sbmpc', DURATION_S)
        return run_scenario(write_scenario(sc, route, tmp), sensing=sensing)


@pytest.fixture(scope='module')
def today():
    return _run(None)


def _same(a, b):
    return (np.array_equal(a.t, b.t) and np.array_equal(a.own, b.own)
            and np.array_equal(a.heading, b.heading) and a.decisions == b.decisions
            and all(np.array_equal(a.targets[n], b.targets[n]) for n in a.targets))


def test_perfect_is_todays_run_bit_for_bit(today):
    assert sensed_targets('perfect', ['ts1']) is None
    assert sensed_targets(('perfect', 9), ['ts1']) is None
    assert any(d[1] == 'avoid' for d in today.decisions)      # a run in which colav acts
    for sensing in ('perfect', ('perfect', 4)):
        assert _same(_run(sensing), today)


def test_poor_ais_repeats_for_a_seed_and_colav_still_gives_way_in_time(today):
    a = _run(('poor_ais', 3))
    b = _run(('poor_ais', 3))
    assert _same(a, b) and a.sensing == b.sensing
    assert a.sensing['ais_lost'] > 0 and a.sensing['ais_received'] > 0
    # colav acts on the tracked target: a give-way decision to starboard (Rule 15/16, a
    # crossing from starboard), taken while the true target is still outside the safe distance
    # widened by the largest sigma colav was given
    avoid = [d for d in a.decisions if d[1] == 'avoid']
    assert avoid and avoid[0][2] > 0.0
    k = int(np.searchsorted(a.t, avoid[0][0]))
    rng = math.hypot(*(a.own[k, :2] - a.targets['ts1'][k, :2]))
    assert rng > ColavParams().safe_distance(a.sensing['position_sigma_m_max'])
    # and not later than the perfect run's give-way, delayed by the longest the level can keep
    # a report from the tracker (latency + jitter) plus one report interval lost in a burst of
    # the level's mean length on top of the interval itself (10 s at 12 kn, class A)
    first_today = next(d[0] for d in today.decisions if d[1] == 'avoid')
    ais = LEVELS['poor_ais'].ais
    slack = ais.latency_s + ais.latency_jitter_s + 10.0 * (1.0 + ais.mean_burst_length)
    assert avoid[0][0] <= first_today + slack
    # another seed hears other reports
    assert _run(('poor_ais', 4)).sensing != a.sensing


def _row(case, level, seed, d, coll=0, nm=0):
    return {'ship': 'mariner', 'method': 'sbmpc', 'case': case, 'level': level, 'seed': seed,
            'min_distance_m': d, 'collisions': coll, 'near_misses': nm, 'below_safe': d < 926,
            'last_resort_decisions': 0, 'run_end': 'clear', 'sensing': {}}


def test_summary_names_the_cases_where_a_level_breaks():
    runs = [_row(1, 'perfect', 0, 1300.0), _row(2, 'perfect', 0, 1000.0),
            _row(1, 'poor_ais', 1, 1250.0), _row(1, 'poor_ais', 2, 1200.0),
            _row(2, 'poor_ais', 1, 900.0), _row(2, 'poor_ais', 2, 300.0, nm=1)]
    groups, breaks = summarise(runs, ['perfect', 'poor_ais'], 926.0)
    g = groups['mariner/sbmpc']['poor_ais']
    assert g['runs'] == 4 and g['near_misses'] == 1 and g['runs_with_near_miss'] == 1
    assert (g['min_distance_m'], g['min_distance_case']) == (300.0, 2)
    assert g['cases']['1'] == {'seeds': 2, 'min_distance_m': 1200.0, 'max_min_distance_m': 1250.0,
                               'collisions': 0, 'near_misses': 0,
                               'position_error_m_rms_max': None}
    b = breaks['mariner/sbmpc']['poor_ais']
    assert b['cases_with_collision_or_near_miss'] == [2]
    assert b['cases_newly_below_r_min'] == [2]
    assert (b['largest_loss_m'], b['largest_loss_case']) == (700.0, 2)
    assert 'perfect' not in breaks['mariner/sbmpc']
