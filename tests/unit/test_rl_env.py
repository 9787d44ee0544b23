"""Learning environment (Martinsen and Lekkas 2018): eq. 9 state, eq. 8 reward, episodes, batched stepping.

Expected values are hand-derived from the definitions (ship_guidance.path_state /
ship_autopilot.learning.env docstrings): Gaussian a = 1, sigma = 10 m -> 1 at e = 0 and
exp(-1/2) at e = sigma; the closest-point cross-track rate U sin(chi - gamma_p); on a circle of
radius R a vessel on the path with r = U / R keeps a constant heading relative to the path.
"""
import math

import numpy as np
import pytest

gymnasium = pytest.importorskip('gymnasium')

from ship_autopilot.learning.env import (EnvConfig, PathFollowingBatch,  # noqa: E402
                                         PathFollowingEnv, gaussian_reward,
                                         rudder_change_penalty)
from ship_guidance.path import Arc, Line, Route  # noqa: E402
from ship_guidance.path_state import (OBS_DIM, STATE_NAMES, PathFeatures,  # noqa: E402
                                      default_scales, normalise)


def start(cross=0.0, heading=0.0, current=0.0, direction=0.0, along=100.0):
    return {'route': 0, 'along': along, 'cross': cross, 'heading': heading,
            'current_speed': current, 'current_direction': direction}


# -- reward (eq. 8) ------------------------------------------------------------------------------

def test_gaussian_reward_values():
    assert gaussian_reward(0.0, 0.0) == pytest.approx(1.0)
    assert gaussian_reward(10.0, 0.0) == pytest.approx(math.exp(-0.5))
    assert gaussian_reward(-10.0, 0.3) == pytest.approx(math.exp(-0.5))
    assert gaussian_reward(20.0, 0.0) == pytest.approx(math.exp(-2.0))
    # Yaw-error bound: travelling against the path earns nothing even on the path.
    assert gaussian_reward(0.0, math.radians(91.0)) == 0.0
    assert gaussian_reward(0.0, math.radians(-179.0)) == 0.0
    assert gaussian_reward(0.0, math.radians(89.0)) == pytest.approx(1.0)


def test_rudder_change_penalty_values():
    dmax = math.radians(10.0)
    assert rudder_change_penalty(0.5 * dmax, 0.0, dmax, 0.1) == pytest.approx(0.1 * 0.25)
    assert rudder_change_penalty(-dmax, dmax, dmax, 0.1) == pytest.approx(0.4)
    assert rudder_change_penalty(0.3, 0.3, dmax, 0.1) == 0.0


def test_step_reward_is_gaussian_minus_penalty_on_the_path():
    env = PathFollowingEnv('tanker', mode='straight', seed=1)
    env.reset(options={'start': start()})
    # e = 0 at the start: one step with a held 50 % rudder -> reward = G(e_1) - 0.1 * 0.5^2.
    obs, reward, term, trunc, info = env.step(np.array([0.5], np.float32))
    e1 = info['raw_state'][0]
    assert abs(e1) < 1.0  # 1 s of a 8 m/s tanker barely leaves the line
    assert info['penalty'] == pytest.approx(0.025)
    assert reward == pytest.approx(math.exp(-0.5 * (e1 / 10.0) ** 2) - 0.025)
    # Holding the command costs nothing more.
    _, reward2, _, _, info2 = env.step(np.array([0.5], np.float32))
    assert info2['penalty'] == 0.0
    assert reward2 == pytest.approx(info2['gaussian'])


def test_start_at_sigma_gives_exp_minus_half():
    env = PathFollowingEnv('mariner', mode='straight')
    _, info = env.reset(options={'start': start(cross=10.0)})
    e, heading_rel = info['raw_state'][0], info['raw_state'][4]
    assert e == pytest.approx(10.0, abs=1e-9)
    assert gaussian_reward(e, heading_rel) == pytest.approx(math.exp(-0.5))


# -- spaces, shapes, episodes --------------------------------------------------------------------

@pytest.mark.parametrize('model', ['mariner', 'container', 'tanker'])
def test_gym_env_shapes_and_dtypes(model):
    env = PathFollowingEnv(model, mode='curved', n_routes=2, seed=3)
    obs, info = env.reset(seed=3)
    assert env.observation_space.shape == (OBS_DIM,) and env.action_space.shape == (1,)
    assert obs.shape == (OBS_DIM,) and obs.dtype == np.float32
    assert env.observation_space.contains(obs)
    obs, reward, term, trunc, info = env.step(env.action_space.sample())
    assert obs.shape == (OBS_DIM,) and obs.dtype == np.float32
    assert isinstance(reward, float) and isinstance(term, bool) and isinstance(trunc, bool)
    assert info['raw_state'].shape == (OBS_DIM,)
    assert abs(info['rudder_cmd']) <= env.core.rudder_max + 1e-12


def test_batch_shapes_reset_mask_and_determinism():
    a = PathFollowingBatch('mariner', 4, EnvConfig(mode='straight'), seed=7)
    b = PathFollowingBatch('mariner', 4, EnvConfig(mode='straight'), seed=7)
    oa, ob = a.reset(), b.reset()
    np.testing.assert_array_equal(oa, ob)
    assert oa.shape == (4, OBS_DIM) and oa.dtype == np.float32
    act = np.array([0.1, -0.2, 0.3, 0.0])
    ra, rb = a.step(act), b.step(act)
    np.testing.assert_array_equal(ra[0], rb[0])
    np.testing.assert_array_equal(ra[1], rb[1])
    assert ra[1].shape == ra[2].shape == ra[3].shape == (4,)
    # Resetting vessel 2 only leaves the others' states alone.
    x_before = a.x.copy()
    a.reset(np.array([False, False, True, False]))
    np.testing.assert_array_equal(a.x[[0, 1, 3]], x_before[[0, 1, 3]])
    assert a.t[2] == 0.0 and a.t[0] == 1.0


def test_batch_and_single_vessel_integrate_alike():
    """The gym env takes the float fast path, the batch the array path: same physics."""
    st = start(cross=40.0, heading=0.2, current=0.9, direction=1.0)
    single = PathFollowingEnv('container', mode='straight')
    single.reset(options={'start': st})
    batch = PathFollowingBatch('container', 2, EnvConfig(mode='straight'))
    batch.reset(starts=[st, st])
    for k in range(5):
        single.step(np.array([0.3]))
        batch.step(np.array([0.3, 0.3]))
    np.testing.assert_allclose(batch.x[0], single.core.x[0], rtol=1e-9, atol=1e-9)


def test_truncation_at_episode_end_and_termination_far_off():
    env = PathFollowingEnv('tanker', mode='straight', episode_s=5.0)
    env.reset(options={'start': start()})
    flags = [env.step(np.zeros(1))[3] for _ in range(5)]
    assert flags == [False] * 4 + [True]
    env = PathFollowingEnv('tanker', mode='straight', terminate_cross_track=50.0)
    env.reset(options={'start': start(cross=60.0)})
    _, _, term, trunc, _ = env.step(np.zeros(1))
    assert term and not trunc


def test_random_starts_and_currents_within_bounds():
    cfg = EnvConfig(mode='straight')
    env = PathFollowingBatch('mariner', 64, cfg, seed=11)
    env.reset()
    speed = np.hypot(env.current[:, 0], env.current[:, 1])
    assert np.all(speed <= cfg.max_current + 1e-12) and speed.max() > 0.5
    direction = np.arctan2(env.current[:, 1], env.current[:, 0])
    assert direction.min() < -1.5 and direction.max() > 1.5        # all around
    e, heading_rel = env.raw[:, 0], env.raw[:, 4]
    assert np.all(np.abs(e) <= cfg.start_cross_max + 1e-6)
    assert np.all(np.abs(heading_rel) <= cfg.start_heading_max + 1e-9)


def test_curved_pool_respects_the_radius_bound_and_straight_is_a_line():
    cfg = EnvConfig(mode='curved', n_routes=4)
    env = PathFollowingBatch('mariner', 1, cfg, seed=5)
    amp, wave = 500.0, 4000.0
    r_min = wave ** 2 / (4 * math.pi ** 2 * amp)
    for route in env.routes:
        assert route.length > env.speed0 * cfg.episode_s
        assert np.max(np.abs(route.curvatures)) <= 1.0 / (0.8 * r_min) * 1.01
    straight = PathFollowingBatch('mariner', 1, EnvConfig(mode='straight'))
    assert len(straight.routes) == 1 and straight.routes[0].legs[0].kind == 'line'


# -- features (eq. 9) ----------------------------------------------------------------------------

def test_feature_order_and_straight_line_values():
    f = PathFeatures()
    U, chi = 7.0, math.radians(30.0)
    # Heading 30 deg off a northbound line, no sway: course = heading.
    x = f(cross_track=12.0, path_angle=0.0, curvature=0.0, psi=chi, u=U, v=0.0, r=0.01, dt=1.0)
    assert x.shape == (OBS_DIM,) and len(STATE_NAMES) == OBS_DIM
    assert x[0] == 12.0
    assert x[1] == pytest.approx(U * math.sin(chi))
    assert x[2] == pytest.approx(chi) and x[4] == pytest.approx(chi)
    assert x[5] == pytest.approx(0.01)            # kappa = 0: heading rate = r
    assert x[3] == pytest.approx(0.01)            # first call: no drift-angle rate yet
    assert tuple(x[6:]) == pytest.approx((U, 0.0, 0.01))


def test_course_includes_drift_and_its_rate():
    f = PathFeatures()
    f(0.0, 0.0, 0.0, 0.0, 7.0, 0.0, 0.0, 0.0)
    beta = math.atan2(0.7, 7.0)
    x = f(0.0, 0.0, 0.0, 0.0, 7.0, 0.7, 0.0, 2.0)
    assert x[2] == pytest.approx(beta) and x[4] == 0.0
    assert x[3] == pytest.approx(beta / 2.0)      # beta went 0 -> beta in 2 s
    assert x[1] == pytest.approx(math.hypot(7.0, 0.7) * math.sin(beta))


def test_circle_steady_turn_has_zero_relative_rates():
    """On a clockwise circle of radius R with r = U / R along the tangent: (psi - gamma)' = 0."""
    R, U = 1000.0, 7.0
    f = PathFeatures()
    x = f(0.0, 0.3, 1.0 / R, 0.3, U, 0.0, U / R, 1.0)
    assert x[5] == pytest.approx(0.0, abs=1e-12)
    # 10 m to starboard (inside a starboard turn) the closest point moves faster: U / (1 - e/R).
    x = f(10.0, 0.3, 1.0 / R, 0.3, U, 0.0, U / R, 1.0)
    assert x[5] == pytest.approx(U / R - (U / R) / (1.0 - 10.0 / R))


def test_cross_track_rate_matches_the_projection_along_a_trajectory():
    """e' from the features agrees with differences of the projected cross-track error."""
    route = Route([Line((0.0, 0.0), (500.0, 0.0)),
                   Arc((500.0, 0.0), (1500.0, 1000.0), (500.0, 1000.0), clockwise=True)])
    env = PathFollowingBatch('mariner', 1, EnvConfig(mode='straight', control_dt=0.1),
                             routes=[route])
    env.reset(starts=[start(cross=30.0, heading=0.3, current=0.6, direction=2.0, along=300.0)])
    es, rates = [], []
    for _ in range(600):
        env.step(np.array([-0.2]))
        es.append(env.raw[0, 0])
        rates.append(env.raw[0, 1])
    es, rates = np.array(es), np.array(rates)
    fd = np.diff(es) / 0.1
    mid = 0.5 * (rates[1:] + rates[:-1])
    assert np.max(np.abs(fd - mid)) < 0.02        # m/s, vessel speed ~7.7 m/s


def test_normalise_clips_and_never_passes_nan():
    off, scale = default_scales(7.7, 161.0)
    raw = np.array([[1e6, -1e6, 0.1, 0.0, 0.0, 0.0, 7.7, 0.0, 0.0],
                    [np.nan, 0.0, np.inf, 0.0, 0.0, 0.0, 7.7, 0.0, 0.0]])
    z, ok = normalise(raw, off, scale)
    assert z.dtype == np.float32 and np.all(np.isfinite(z))
    assert z[0, 0] == 5.0 and z[0, 1] == -5.0 and z[0, 2] == pytest.approx(0.2)
    assert ok.tolist() == [True, False]
    assert z[1, 0] == 0.0 and z[1, 2] == 0.0
    with pytest.raises(ValueError, match='9 components'):
        normalise(np.zeros(8), off, scale)
