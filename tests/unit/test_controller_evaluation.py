"""Tools of the learned-steering study: Table I evaluation and the transfer-learning comparison.

- scripts/evaluate_controllers.py: the tuned classical loop (fast PD + turn-rate lead) follows the
  Mariner's curved path closer than the gain table's LOS + PD from the same start, and every
  controller's reward stays within [0, samples].
- scripts/train_ddpg.py compare: time-to-threshold and the saving are read from the training logs
  per seed, with runs that never reach a threshold reported as bounds (no torch needed).
"""
import csv
import json
import math

import pytest

import evaluate_controllers as ec
import train_ddpg
from ship_planner.route_loader import load_route


@pytest.fixture(scope='module')
def mariner_runs():
    route = load_route(ec.ROOT / 'scenarios' / 'routes' / 'curved_path_mariner_000.yaml').route
    starts = ec.start_states(1)
    return {c: ec.run('mariner', route, c, starts, 0.0, 400.0) for c in ('los', 'los_lead')}


def test_fast_pd_with_lead_tracks_the_curve_closer(mariner_runs):
    slow, fast = mariner_runs['los'], mariner_runs['los_lead']
    # Settled half of the episode: the lead removes the autopilot's lag on the sine's curvature.
    assert fast['mean_abs_e_settled'][0] < 0.5 * slow['mean_abs_e_settled'][0]
    assert fast['gaussian'][0] > slow['gaussian'][0]


def test_rewards_are_bounded_by_the_sample_count(mariner_runs):
    for r in mariner_runs.values():
        assert 0.0 <= r['gaussian'][0] <= 400.0 / ec.SIM_DT
        assert math.isfinite(r['max_abs_e'][0])


def test_tuned_classical_refuses_an_unstable_lookahead():
    route = load_route(ec.ROOT / 'scenarios' / 'routes' / 'curved_path_mariner_000.yaml').route
    with pytest.raises(ValueError, match='stability limit'):
        ec.run('mariner', route, 'los_lead', ec.start_states(1), 0.0, 10.0, tuning=(2.5, 0.01))


def write_log(folder, rows):
    folder.mkdir(parents=True)
    with open(folder / 'log.csv', 'w', newline='') as f:
        w = csv.writer(f)
        w.writerow(['phase', 'transitions', 'updates', 'episodes', 'wall_s', 'train_return',
                    'eval_gaussian', 'eval_abs_e'])
        for phase, n, score in rows:
            w.writerow([phase, n, n // 2, 1, 1.0, 0.0, score, 10.0])


def test_compare_reads_time_to_threshold_per_seed(tmp_path, capsys):
    # Seed 1: scratch reaches 700 at 100k, transfer (30k straight first) at 60k: saving 0.4.
    write_log(tmp_path / 'mariner_scratch_s1',
              [('curved', 50_000, 100), ('curved', 100_000, 750), ('curved', 150_000, 900)])
    write_log(tmp_path / 'mariner_transfer_s1',
              [('straight', 30_000, 50), ('curved', 60_000, 720), ('curved', 150_000, 880)])
    # Seed 2: scratch never reaches 850 within 150k; transfer does at 120k: saving >= 0.2.
    write_log(tmp_path / 'mariner_scratch_s2',
              [('curved', 60_000, 300), ('curved', 150_000, 800)])
    write_log(tmp_path / 'mariner_transfer_s2',
              [('straight', 45_000, 900), ('curved', 90_000, 600), ('curved', 120_000, 860)])
    train_ddpg.main(['compare', '--model', 'mariner', '--runs', str(tmp_path),
                     '--thresholds', '700', '850'])
    res = json.loads((tmp_path / 'mariner_compare.json').read_text())
    s1, s2 = res['seeds']['1'], res['seeds']['2']
    assert s1['700']['transitions'] == {'scratch': 100_000.0, 'transfer': 60_000.0}
    assert s1['700']['saving'] == pytest.approx(0.4) and s1['700']['bound'] is None
    assert s1['transfer']['straight_transitions'] == 30_000
    assert s1['700']['saving_curved_only'] == pytest.approx(0.7)   # 30k curved against 100k
    # Seed 2 reaches 700 at 150k (scratch) and 120k (transfer): saving 0.2; mean of 0.4, 0.2.
    assert res['mean']['700']['saving'] == pytest.approx(0.3)
    # A straight-phase score does not count: seed 2 transfer reaches 850 on curves at 120k.
    assert s2['850']['transitions'] == {'scratch': None, 'transfer': 120_000.0}
    assert s2['850']['saving'] == pytest.approx(0.2) and s2['850']['bound'] == 'lower'
    assert (tmp_path / 'mariner_compare.png').stat().st_size > 0


def test_batched_tuning_scores_each_start_as_the_single_loop_and_refuses_unstable_points():
    # (1.0 U/L, 0.75 L) is beyond the ILOS loop's stability limit d > (U + 4 zeta^2 sigma) /
    # (2 zeta omega_n) with sigma = U / 4 (ship_guidance.los): scored -inf, not run.
    stable, unstable = (2.5, 1.0), (1.0, 0.75)
    scores = ec._tune_task(('mariner', [stable, unstable], 'ilos_lead', 30.0))
    assert scores[unstable] == [-math.inf] * ec.TUNE_STARTS
    for (route, start), score in zip(ec.tune_starts('mariner'), scores[stable]):
        ref = ec.run('mariner', route, 'ilos_lead', [dict(start, route=0)],
                     start['current_speed'], 30.0, tuning=stable)
        assert score == pytest.approx(ref['gaussian'][0], rel=1e-12)
