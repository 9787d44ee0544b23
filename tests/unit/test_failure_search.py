"""The failure search (scripts/colav_search): the encounter geometry, the cross-entropy method
against uniform sampling on a toy problem whose failure probability is known, determinism by
seed, what counts as a distinct failure, and a written failure's header."""
import math

import numpy as np
import pytest
from scipy.stats import binom

from colav_search import distinct, encounter, episode, replay
from colav_search.sampling import CrossEntropy, Uniform
from montecarlo.encounters import target_cpa


def _feasible_vectors(n_targets, count, seed):
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        x = rng.random(encounter.DIM)
        if encounter.feasible(n_targets, x):
            out.append(x)
    return out


def test_each_target_passes_at_its_cpa_offset_at_the_meeting_time():
    # against the unmanoeuvred own ship, with the CPA of ship_guidance.cpa (not the geometry's)
    for x in _feasible_vectors(3, 20, seed=4):
        e = encounter.decode(3, x)
        case = encounter.case_of(3, x)
        for target, placed in zip(e.targets, case['targets']):
            tcpa, dcpa = target_cpa(case['own'], placed)
            assert tcpa == pytest.approx(e.meeting_s, abs=1e-6)
            assert dcpa == pytest.approx(abs(target.cpa_m), abs=1e-6)
            assert placed['speed_mps'] == pytest.approx(
                target.speed_ratio * encounter.OWN['speed_mps'])
            assert math.hypot(placed['north_m'], placed['east_m']) >= encounter.MIN_START_RANGE_M


def test_a_target_on_a_collision_course_keeps_its_approach_bearing():
    x = _feasible_vectors(1, 1, seed=9)[0]
    x[encounter.slot_dims(0)[2]] = 0.5           # CPA offset 0
    e = encounter.decode(1, x)
    north, east, course, speed, bearing = encounter.target_state(e, e.targets[0])
    own_v = np.array([encounter.OWN['speed_mps'], 0.0])
    c = math.radians(course)
    for t in (0.0, 0.5 * e.meeting_s, 0.9 * e.meeting_s):
        rel = np.array([north, east]) + speed * t * np.array([math.cos(c), math.sin(c)]) \
            - own_v * t
        assert math.degrees(math.atan2(rel[1], rel[0])) % 360.0 == pytest.approx(bearing)


def test_a_positive_offset_passes_a_head_on_target_to_starboard():
    x = np.full(encounter.DIM, 0.5)
    x[encounter.slot_dims(0)] = [1.0, 0.5, 0.75]    # reciprocal course, CPA offset +500 m
    case = encounter.case_of(1, x)
    t = case['targets'][0]
    assert t['colregs'] == 'head-on'
    assert t['east_m'] == pytest.approx(500.0)


# A toy problem: the box [0, 1]^2 fails in the corner [0.9, 1]^2 (probability P = 0.01 under
# uniform draws), the score the distance to the corner (0 inside it).
P_CORNER = 0.01
GENERATIONS, GENERATION = 10, 20


def _corner_score(sample):
    _, x = sample
    return math.hypot(max(0.9 - x[0], 0.0), max(0.9 - x[1], 0.0))


def _failures(sampler):
    found = 0
    for _ in range(GENERATIONS):
        samples = sampler.propose(GENERATION)
        scores = [_corner_score(s) for s in samples]
        sampler.update(samples, scores)
        found += sum(s == 0.0 for s in scores)
    return found


@pytest.mark.parametrize('seed', [1, 2, 3])
def test_cross_entropy_finds_a_rare_corner_far_more_often_than_uniform_draws(seed):
    budget = GENERATIONS * GENERATION
    # the smallest count that uniform draws reach with probability below 1e-4 (binomial)
    bound = next(k for k in range(budget) if binom.sf(k - 1, budget, P_CORNER) < 1e-4)
    ce = CrossEntropy(2, (1,), seed, level=1e-12)
    assert _failures(ce) >= bound
    # and the density has moved into the corner
    assert np.all(ce.mean > 0.8)


def test_same_seed_same_draws_and_another_seed_other_draws():
    def draws(cls, seed, **kw):
        s = cls(encounter.DIM, encounter.TARGET_COUNTS, seed, feasible=encounter.feasible, **kw)
        out = []
        for _ in range(3):
            samples = s.propose(8)
            s.update(samples, [float(np.sum(x)) for _, x in samples])
            out += [(n, tuple(x)) for n, x in samples]
        return out
    ce = {'circular': encounter.circular_dims(), 'level': 1.0}
    for cls, kw in ((Uniform, {}), (CrossEntropy, ce)):
        assert draws(cls, 5, **kw) == draws(cls, 5, **kw)
        assert draws(cls, 5, **kw) != draws(cls, 6, **kw)


def test_a_cross_entropy_draw_is_feasible_and_uses_every_target_count():
    ce = CrossEntropy(encounter.DIM, encounter.TARGET_COUNTS, 0, feasible=encounter.feasible,
                      circular=encounter.circular_dims())
    samples = ce.propose(60)
    assert all(encounter.feasible(n, x) for n, x in samples)
    assert {n for n, _ in samples} == set(encounter.TARGET_COUNTS)


def test_failures_with_targets_swapped_or_within_the_tolerance_are_one_failure():
    x = _feasible_vectors(2, 1, seed=2)[0]
    swapped = x.copy()
    swapped[encounter.slot_dims(0)], swapped[encounter.slot_dims(1)] = \
        x[encounter.slot_dims(1)], x[encounter.slot_dims(0)]
    near = x.copy()
    near[0] = x[0] + 0.5 * distinct.TOLERANCE if x[0] < 0.5 else x[0] - 0.5 * distinct.TOLERANCE
    far = x.copy()
    far[0] = x[0] + 3 * distinct.TOLERANCE if x[0] < 0.5 else x[0] - 3 * distinct.TOLERANCE
    assert distinct.distinct([(2, x), (2, swapped), (2, near)]) == [0]
    assert distinct.distinct([(2, x), (2, far)]) == [0, 1]
    assert distinct.distinct([(2, x), (1, x)]) == [0, 1]      # another target count


def test_relative_courses_either_side_of_reciprocal_are_close():
    a = np.full(encounter.DIM, 0.5)
    b = a.copy()
    a[encounter.slot_dims(0)[0]] = 0.01     # course -176 deg
    b[encounter.slot_dims(0)[0]] = 0.99     # course +176 deg
    assert distinct.same((1, a), (1, b))


def test_a_written_failure_states_its_in_process_distance_and_runs_to_its_end(tmp_path):
    import yaml
    x = np.full(encounter.DIM, 0.5)
    row = {'min_distance_m': 123.4567, 't_min_s': 400.0, 'score': 0.5, 'collision': False,
           'end_s': 512.3}
    path = episode.write_failure(1, x, 'mariner', 'vo', row, tmp_path, 'uniform_0007')
    assert replay.in_process_min_distance(path) == pytest.approx(123.457)
    scenario = yaml.safe_load(path.read_text())
    assert scenario['duration_s'] == 512.3 and scenario['stepping'] == 'lockstep'
    assert scenario['vessels']['vessel_0']['colav']['method'] == 'vo'
    assert (tmp_path / 'route.yaml').exists()
    assert replay.scenarios(tmp_path) == [path]


def _row(n, x, failure, score, distance, generation=0):
    return {'generation': generation, 'n_targets': n, 'x': list(x), 'score': score,
            'failure': failure, 'collision': False, 'near_miss': failure,
            'min_distance_m': distance, 't_min_s': 300.0, 'end_s': 400.0, 'end': 'clear',
            'wall_s': 1.0}


def test_the_summary_scales_counts_to_1000_sims_and_marks_the_distinct_failures():
    from colav_search import study
    x = _feasible_vectors(1, 1, seed=11)[0]
    rows = [_row(1, x, False, 2.0, 900.0)] * 3 + [_row(1, x, True, 0.5, 200.0),
                                                  _row(1, x, True, 0.6, 210.0)]
    s = study.summary(rows, 'mariner', 'vo')
    assert (s['sims'], s['failures'], s['distinct_failures']) == (5, 2, 1)
    assert s['failures_per_1000'] == pytest.approx(2 * 1000 / 5)
    assert s['distinct_failures_per_1000'] == pytest.approx(1000 / 5)
    assert s['first_failure_sim'] == 4
    assert [f['distinct'] for f in s['failure_list']] == [True, False]


def test_the_failures_table_lists_only_the_distinct_failures():
    from results_pages.failure_search import failures
    x = _feasible_vectors(1, 1, seed=11)[0]
    listed = {'index': 3, 'generation': 1, 'collision': False, 'min_distance_m': 200.0,
              'domain_index': 0.5, 't_min_s': 300.0, 'x': list(x), 'scenario': 'a.yaml',
              **encounter.describe(1, x)}
    data = {'samplers': {'uniform': {'failure_list': [
        dict(listed, distinct=True), dict(listed, distinct=False, scenario='b.yaml')]}}}
    table = failures(data)
    assert '`a.yaml`' in table and '`b.yaml`' not in table
    assert failures({'samplers': {'uniform': {'failure_list': []}}}) == 'No failure was found.\n'
