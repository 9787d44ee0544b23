"""mission.metrics against hand-computed values (synthetic signals, no ROS)."""
import json
import math

import numpy as np
import pytest

from mission import metrics as m


def test_rms_of_a_sine_over_whole_periods_is_amplitude_over_sqrt2():
    t = np.arange(0.0, 100.0, 0.01)  # 10 whole periods of 10 s, uniformly sampled
    e = 4.0 * np.sin(2 * np.pi * t / 10.0)
    stats = m.cross_track_stats(t, e, t_from=0.0)
    assert stats['xte_rms_m'] == pytest.approx(4.0 / math.sqrt(2.0), rel=1e-9)
    assert stats['xte_max_abs_m'] == pytest.approx(4.0, rel=1e-6)
    assert stats['xte_mean_m'] == pytest.approx(0.0, abs=1e-9)
    assert stats['xte_samples'] == t.size


def test_settling_cut_off_excludes_the_transient():
    t = np.arange(0.0, 100.0, 0.1)
    e = np.where(t < 20.0, 100.0, 1.0)
    assert m.cross_track_stats(t, e, m.settle_cutoff(t, settle_s=20.0))['xte_rms_m'] == pytest.approx(1.0)
    assert m.cross_track_stats(t, e, m.settle_cutoff(t, settle_s=20.0))['xte_max_abs_m'] == 1.0
    # default: 10 % of the run (99.9 s) -> cut at 9.99 s: the 100 m samples from 10.0 to 19.9 s count
    cut = m.settle_cutoff(t)
    assert cut == pytest.approx(9.99)
    stats = m.cross_track_stats(t, e, cut)
    n_big, n_small = 100, 800  # samples at 10.0 .. 19.9 s and at 20.0 .. 99.9 s
    assert stats['xte_samples'] == n_big + n_small
    assert stats['xte_rms_m'] == pytest.approx(math.sqrt((n_big * 100.0**2 + n_small) / (n_big + n_small)))
    with pytest.raises(ValueError):
        m.settle_cutoff(t, settle_s=-1.0)


def test_reward_is_one_per_step_on_the_path_and_exp_minus_half_at_sigma():
    t = np.arange(1000) * 0.1  # 1000 samples, one per 0.1 s step
    on_path = m.gaussian_reward(t, np.zeros_like(t), step_s=0.1)
    assert on_path['reward_steps'] == 1000
    assert on_path['reward_gaussian_sum'] == pytest.approx(1000.0, rel=1e-12)
    assert on_path['reward_gaussian_integral_s'] == pytest.approx(100.0, rel=1e-12)
    at_sigma = m.gaussian_reward(t, np.full_like(t, 10.0), sigma_m=10.0, step_s=0.1)
    assert at_sigma['reward_gaussian_sum'] == pytest.approx(1000.0 * math.exp(-0.5), rel=1e-12)
    # the sign of e does not matter
    port = m.gaussian_reward(t, np.full_like(t, -10.0), sigma_m=10.0, step_s=0.1)
    assert port['reward_gaussian_sum'] == pytest.approx(at_sigma['reward_gaussian_sum'], rel=1e-12)


def test_reward_sampling_is_explicit_and_resampled():
    t = np.arange(2000) * 0.05  # recorded at 20 Hz, 99.95 s
    e = np.zeros_like(t)
    r01 = m.gaussian_reward(t, e, step_s=0.1)
    r1 = m.gaussian_reward(t, e, step_s=1.0)
    assert r01['reward_steps'] == 1000  # 0, 0.1, ..., 99.9
    assert r1['reward_steps'] == 100    # 0, 1, ..., 99
    assert r01['reward_gaussian_integral_s'] == pytest.approx(r1['reward_gaussian_integral_s'])
    # an episode limit (Martinsen and Lekkas 2018: 1000 s episodes) truncates the sum
    assert m.gaussian_reward(t, e, step_s=0.1, episode_s=50.0)['reward_steps'] == 501  # 0 .. 50.0


def test_reward_is_zero_when_heading_the_wrong_way():
    t = np.arange(100) * 0.1
    yaw_err = np.where(t < 5.0, 3.0, 0.2)  # first half: sailing backwards along the path (eq. 8 gate)
    r = m.gaussian_reward(t, np.zeros_like(t), yaw_error=yaw_err, step_s=0.1)
    assert r['reward_gaussian_sum'] == pytest.approx(50.0)
    # +-pi on both sides of the wrap stays gated (no averaging to 0 across the wrap)
    r = m.gaussian_reward(t, np.zeros_like(t), yaw_error=np.where(np.arange(100) % 2, 3.1, -3.1), step_s=0.05)
    assert r['reward_gaussian_sum'] == 0.0


def test_projection_on_an_l_shaped_route():
    rx, ry = np.array([0.0, 100.0, 100.0]), np.array([0.0, 0.0, 100.0])  # east, then north
    x = np.array([50.0, 50.0, 110.0, 90.0, -10.0, 100.0])
    y = np.array([-5.0, 3.0, 50.0, 50.0, 0.0, 130.0])
    s, e, gamma, length = m.project_on_route(x, y, rx, ry)
    assert length == 200.0
    np.testing.assert_allclose(s, [50.0, 50.0, 150.0, 150.0, -10.0, 230.0])
    # + = starboard: south of an eastbound leg, east of a northbound leg
    np.testing.assert_allclose(e, [5.0, -3.0, 10.0, -10.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(gamma, [0.0, 0.0, np.pi / 2, np.pi / 2, 0.0, np.pi / 2])
    assert m.completion_time(np.arange(6.0), s, length) == 5.0
    assert m.completion_time(np.arange(6.0), s, length, finish_tolerance_m=60.0) == 2.0
    assert m.completion_time(np.arange(2.0), s[:2], length) is None


def test_rudder_usage_hand_computed():
    t = np.array([0.0, 1.0, 2.0, 3.0])
    d = np.array([0.0, 0.1, -0.1, 0.1])
    r = m.rudder_stats(t, d, t_from=0.0, limit_rad=0.1)
    assert r['rudder_mean_abs_rad'] == pytest.approx(0.075)
    assert r['rudder_rms_rad'] == pytest.approx(math.sqrt(0.03 / 4))
    assert r['rudder_total_variation_rad_per_s'] == pytest.approx(0.5 / 3.0)
    assert r['rudder_saturated_samples'] == 3
    assert r['rudder_saturated_fraction'] == pytest.approx(0.75)
    assert m.rudder_stats(t, d, t_from=0.0)['rudder_saturated_samples'] is None
    assert m.rudder_stats(t, d, t_from=1.5, limit_rad=0.2)['rudder_saturated_samples'] == 0


def test_heading_error_wraps_across_pi():
    t = np.array([0.0, 10.0])
    yaw = np.array([np.pi - 0.1, np.pi - 0.1])
    h = m.heading_error_stats(np.array([5.0]), np.array([-np.pi + 0.1]), t, yaw, t_from=0.0)
    assert h['heading_error_mean_rad'] == pytest.approx(-0.2)
    assert h['heading_error_max_abs_rad'] == pytest.approx(0.2)


def test_vessel_metrics_on_a_straight_run_is_plain_json():
    # straight eastbound run 5 m north of (= to port of) an eastbound route, 4 m/s for 100 s
    t = np.arange(0.0, 100.0, 0.1)
    x, y, yaw = 4.0 * t, np.full_like(t, 5.0), np.zeros_like(t)
    route = (np.array([0.0, 300.0]), np.array([0.0, 0.0]))
    out = m.vessel_metrics(t, x, y, yaw, route=route, rudder=(t, np.zeros_like(t)), rudder_limit_rad=0.6)
    text = json.dumps(out, allow_nan=False)
    assert '"xte_rms_m"' in text
    assert out['xte_source'] == 'route'
    assert out['xte_rms_m'] == pytest.approx(5.0) and out['xte_mean_m'] == pytest.approx(-5.0)
    assert out['settle_s'] == pytest.approx(9.99)
    assert out['route_length_m'] == 300.0 and out['finished'] is True
    assert out['time_to_complete_s'] == pytest.approx(75.0)  # 300 m at 4 m/s
    assert out['reward_gaussian_sum'] == pytest.approx(1000 * math.exp(-25.0 / 200.0))
    assert out['rudder_saturated_samples'] == 0
    assert out['distance_travelled_m'] == pytest.approx(4.0 * 99.9)


def test_guidance_finish_flag_takes_precedence_over_the_route_geometry():
    t = np.arange(0.0, 100.0, 0.1)
    x, y, yaw = 4.0 * t, np.zeros_like(t), np.zeros_like(t)
    route = (np.array([0.0, 300.0]), np.array([0.0, 0.0]))
    flag = (t >= 60.0).astype(float)  # the guidance declares the end at 60 s (circle of acceptance)
    out = m.vessel_metrics(t, x, y, yaw, route=route, finished=(t, flag), remaining=(t, 300.0 - x))
    assert out['completion_source'] == 'guidance'
    assert out['time_to_complete_s'] == pytest.approx(60.0)
    assert out['remaining_at_end_m'] == pytest.approx(300.0 - 4.0 * 99.9)
    never = m.vessel_metrics(t, x, y, yaw, route=route, finished=(t, np.zeros_like(t)))
    assert never['finished'] is False and never['time_to_complete_s'] is None
