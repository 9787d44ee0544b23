"""ship_mission.metrics against hand-computed values (synthetic signals, no ROS)."""
import json
import math

import numpy as np
import pytest

from ship_mission import metrics as m


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


def test_time_at_the_rudder_limit_counts_each_sample_until_the_next():
    # 1 s samples; at the 0.2 rad limit from t = 3 to t = 6 inclusive: samples 3, 4, 5 hold it
    # until the next sample (3 s), sample 6 holds it for 1 s more -> 4 s; the last sample adds 0
    t = np.arange(0.0, 11.0)
    d = np.where((t >= 3) & (t <= 6), -0.2, 0.05)
    d[-1] = 0.2
    assert m.rudder_time_at_limit(t, d, t_from=0.0, limit_rad=0.2) == pytest.approx(4.0)
    assert m.rudder_stats(t, d, t_from=0.0, limit_rad=0.2)['rudder_saturated_samples'] == 5
    assert m.rudder_time_at_limit(t, d, t_from=4.5, limit_rad=0.2) == pytest.approx(2.0)
    assert m.rudder_time_at_limit(t, d, t_from=99.0, limit_rad=0.2) is None


def _first_order_plus_overshoot(t, step, final_err, over, t_peak, tau):
    """Hand-made heading: rises to step + over at t_peak (linear), then decays to step + final_err
    exponentially with time constant tau."""
    yaw = np.where(t <= t_peak, (step + over) * t / t_peak,
                   step + final_err + (over - final_err) * np.exp(-(t - t_peak) / tau))
    return yaw


def test_step_response_overshoot_settling_and_steady_error_hand_computed():
    t = np.arange(0.0, 600.0, 0.5)
    step, over, final_err, t_peak, tau = math.radians(30), math.radians(3), math.radians(-1), 60.0, 20.0
    yaw = _first_order_plus_overshoot(t, step, final_err, over, t_peak, tau)
    cmd = np.full_like(t, step)                 # command stepped at t = 0 from heading 0
    st = m.step_response_stats(t, cmd, t, yaw, t_steady=500.0, band_fraction=0.02)
    assert st['step_rad'] == pytest.approx(step)
    assert st['step_time_s'] == 0.0
    assert st['overshoot_rad'] == pytest.approx(over)
    assert st['overshoot_fraction'] == pytest.approx(0.1)
    assert st['steady_error_rad'] == pytest.approx(final_err, abs=1e-9)
    # leaves the 2 % band around its own final value (0.6 deg) for good when
    # (over - final_err) exp(-(t - t_peak)/tau) = 0.02 step: t = t_peak + tau ln(4 deg / 0.6 deg)
    t_settle = t_peak + tau * math.log(4.0 / 0.6)
    assert st['settling_time_s'] == pytest.approx(t_settle, abs=0.5)   # one sample
    assert st['settling_band_rad'] == pytest.approx(0.02 * step)


def test_step_response_of_a_port_step_after_a_command_change_and_across_pi():
    # heading 170 deg, first command 170 (held), then at t = 10 s a 30 deg step across +-180
    # towards 200 deg = -160 deg (wrapped): the step is +30 deg, no overshoot, no steady error
    t = np.arange(0.0, 300.0, 1.0)
    psi0, step = math.radians(170), math.radians(30)
    yaw = m.wrap(psi0 + np.where(t < 10, 0.0, step * (1 - np.exp(-(t - 10) / 15.0))))
    cmd = m.wrap(np.where(t < 10, psi0, psi0 + step))
    st = m.step_response_stats(t, cmd, t, yaw, t_steady=250.0)
    assert st['step_time_s'] == 10.0
    assert st['step_rad'] == pytest.approx(step)
    assert st['overshoot_rad'] == 0.0
    assert st['steady_error_rad'] == pytest.approx(0.0, abs=1e-6)
    # within 2 % of the step when exp(-(t - 10)/15) <= 0.02 -> 15 ln 50 = 58.7 s, next sample 59
    assert st['settling_time_s'] == pytest.approx(59.0)
    # a starboard step (negative) mirrors it: overshoot measured in the step's direction
    st2 = m.step_response_stats(t, -cmd, t, -yaw, t_steady=250.0)
    assert st2['step_rad'] == pytest.approx(-step)
    assert st2['overshoot_rad'] == 0.0


def test_step_response_that_never_settles_and_without_a_step():
    t = np.arange(0.0, 100.0, 1.0)
    yaw = 0.5 + 0.2 * np.sin(t)            # oscillates +-0.2 rad around the command: never settles
    st = m.step_response_stats(t, np.full_like(t, 0.5), np.concatenate(([-1.0], t[1:])),
                               np.concatenate(([0.0], yaw[1:])), t_steady=80.0)
    assert st['settling_time_s'] is None
    assert st['overshoot_rad'] == pytest.approx(0.2, abs=0.01)
    none = m.step_response_stats(t, np.zeros_like(t), t, np.zeros_like(t), t_steady=50.0)
    assert none['step_rad'] == 0.0 and none['overshoot_rad'] is None
