"""The batched closed loop (ship_autopilot.batch_closed_loop) against the single-vessel loop.

- Every episode of a batch equals scripts/evaluate_controllers.run (the in-process loop of
  Table I, one vessel on the float paths) to 1e-12 relative, per model and per controller
  (PD on LOS and ILOS, fuzzy PID, the learned policy), with and without current: the batch
  only stacks the same arithmetic, so any larger difference is a fork of the logic.
- In wind and waves (ship_mission.conditions wind10, wind20: wind loads in the plant, the
  wave-frequency motion superposed on what is measured) likewise, per model and controller;
  with a seed per episode an episode equals its single-vessel run whatever its batch.
- The batched guidance equals one Guidance per vessel on a waypoint route with corners and an
  acceptance circle (switching, the integrator across corners, completion).
- An episode's result does not depend on the batch around it (order, neighbours), the same
  run twice is identical, and memory does not grow with the number of steps (O(N)).

These run on the numpy backend, the reference (ship_sim.kernels). The compiled backend is held
to it step by step, for every model, controller and route shape, in test_kernels.py; running
this whole file a second time on it would add minutes and no case (wind, waves, the fuzzy PID
and the policy stay on numpy in both).
"""
import math
import tracemalloc

import numpy as np
import pytest

import evaluate_controllers as ec
from ship_autopilot.batch_closed_loop import METRICS, BatchClosedLoop
from ship_guidance.batch_guidance import BatchGuidance
from ship_guidance.guidance import Guidance
from ship_guidance.path import Route
from ship_planner.route_loader import load_route
from ship_sim import kernels

#: Table I controller -> (batch controller, guidance law).
CONTROLLERS = {'los': ('pd', 'los'), 'ilos': ('pd', 'ilos'), 'fuzzy_pid': ('fuzzy_pid', 'los'),
               'policy': ('policy', 'los')}
RTOL = 1e-12


@pytest.fixture(autouse=True)
def numpy_backend():
    """The reference backend, whatever SHIPNAV_KERNELS says."""
    with kernels.using('numpy'):
        yield


def curved_route(model):
    return load_route(ec.ROOT / 'scenarios' / 'routes' / f'curved_path_{model}_000.yaml').route


def episodes(starts, current):
    eps = {k: [s[k] for s in starts] for k in ('route', 'along', 'cross', 'heading',
                                                'current_direction')}
    eps['current_speed'] = current
    return eps


def assert_metrics_equal(batch, refs):
    for key, ref in refs[0].items():
        want = np.array([r[key][0] for r in refs])
        np.testing.assert_allclose(batch[key], want, rtol=RTOL, atol=RTOL, err_msg=key)


# The equality is per step; the runs are long enough for the branches to be taken: the
# rudder at its limit (the container and the tanker under every controller within 60 s, the
# Mariner under the learned policy after about a minute), a switch to the next of the
# route's 10 m legs every second or so, the fuzzy PID's and the policy's commands at the limit.
@pytest.mark.parametrize('model, duration', [('mariner', 90.0), ('container', 60.0),
                                             ('tanker', 60.0)])
@pytest.mark.parametrize('controller', sorted(CONTROLLERS))
def test_each_episode_equals_the_single_vessel_loop(model, duration, controller):
    route = curved_route(model)
    starts = ec.start_states(3)
    for current in (0.0, 0.9):
        refs = [ec.run(model, route, controller, [s], current, duration, activity=True)
                for s in starts]
        loop = BatchClosedLoop(model, [route], *CONTROLLERS[controller])
        res = loop.run(episodes(starts, current), duration)
        assert_metrics_equal(res.metrics, refs)
        assert not res.metrics['failed'].any()


@pytest.mark.parametrize('model', ['mariner', 'container', 'tanker'])
@pytest.mark.parametrize('controller', sorted(CONTROLLERS))
def test_wind_and_waves_each_episode_equals_the_single_vessel_loop(model, controller):
    """Both conditions, two starts in the 0.9 m/s current; the disturbance must show (every
    episode's reward differs from calm water's), so equality is not that of two calm runs."""
    route = curved_route(model)
    starts = ec.start_states(2)
    loop = BatchClosedLoop(model, [route], *CONTROLLERS[controller])
    duration = 20.0
    calm = loop.run(episodes(starts, 0.9), duration).metrics
    for condition in ('wind10', 'wind20'):
        ref = ec.run(model, route, controller, starts, 0.9, duration, condition=condition,
                     activity=True)
        wind, waves, _ = ec.disturbances(condition, [route], loop.model, [0, 0])
        res = loop.run(episodes(starts, 0.9), duration, wind=wind, waves=waves).metrics
        assert_metrics_equal(res, [{k: v[[i]] for k, v in ref.items()} for i in range(2)])
        assert np.all(res['gaussian'] != calm['gaussian'])


def test_an_episode_with_its_own_seed_does_not_depend_on_its_batch():
    """Seeds per episode (sweeps): episode i of a batch of three equals the single-vessel
    loop of that episode alone with its seed (its own gust stream and sea)."""
    route = curved_route('mariner')
    starts, seeds = ec.start_states(3), [101, 7, 55]
    loop = BatchClosedLoop('mariner', [route], 'pd', 'ilos')
    wind, waves, _ = ec.disturbances('wind20', [route], loop.model, [0] * 3, seeds)
    res = loop.run(episodes(starts, 0.9), 30.0, wind=wind, waves=waves).metrics
    refs = [ec.run('mariner', route, 'ilos', [s], 0.9, 30.0, condition='wind20', seeds=[seed],
                   activity=True) for s, seed in zip(starts, seeds)]
    assert_metrics_equal(res, refs)


#: Gauss-Markov currents of three episodes (ship_sim.current): speed and direction varying
#: with their own nominal values, standard deviations, time constants and seeds, and one
#: constant (zero intensities) in the same batch.
GM_CURRENTS = {'speed': [0.9, 0.5, 0.7], 'direction': [0.4, -2.0, 1.5],
               'speed_sd': [0.3, 0.2, 0.0], 'direction_sd': [0.5, 0.3, 0.0],
               'time_constant': [5.0, 20.0, 10.0], 'seed': [11, 4, 9]}


def gm_current(i=None):
    """The Gauss-Markov current of episode i (shape (1,), default_rng(its seed): what the
    single-vessel loop draws), or of all three (shape (3,), a stream per episode)."""
    from ship_sim.current import OceanCurrent
    c = {k: np.asarray(v, dtype=float) for k, v in GM_CURRENTS.items()}
    sel = slice(None) if i is None else slice(i, i + 1)
    return OceanCurrent.from_std(c['speed'][sel], c['direction'][sel], c['speed_sd'][sel],
                                 c['direction_sd'][sel], c['time_constant'][sel],
                                 seed=c['seed'].astype(int) if i is None else int(c['seed'][i]),
                                 shape=c['seed'][sel].shape)


@pytest.mark.parametrize('controller', ['ilos', 'policy'])   # PD, and the policy's features
def test_a_gauss_markov_current_per_episode_equals_the_single_vessel_loop(controller):
    """Each episode's current is what its single-vessel run draws (same seed, same stream):
    the episode equals evaluate_controllers.run with that episode's OceanCurrent alone, and
    the constant one equals the run without a current field. The variation must show: the
    varying episodes differ from their constant-current runs."""
    route = curved_route('mariner')
    starts = [dict(s, current_direction=d)
              for s, d in zip(ec.start_states(3), GM_CURRENTS['direction'])]
    duration = 30.0
    loop = BatchClosedLoop('mariner', [route], *CONTROLLERS[controller])
    eps = episodes(starts, GM_CURRENTS['speed'])
    res = loop.run(eps, duration, current=gm_current()).metrics
    refs = [ec.run('mariner', route, controller, [s], v, duration, activity=True,
                   current_field=gm_current(i) if i < 2 else None)
            for i, (s, v) in enumerate(zip(starts, GM_CURRENTS['speed']))]
    assert_metrics_equal(res, refs)
    const = loop.run(eps, duration).metrics
    assert const['max_abs_e'][2] == res['max_abs_e'][2]
    assert (np.abs(const['max_abs_e'][:2] - res['max_abs_e'][:2]) > 1e-3).all()


def test_turn_rate_lead_and_per_episode_gains_equal_the_single_loop():
    """'los_lead' of Table I: a faster PD per episode (k1, k2 arrays) and the lead."""
    from ship_autopilot.gains import autopilot_gains, nomoto_gains
    from ship_autopilot.pd import pd_gains
    route = curved_route('mariner')
    starts = ec.start_states(2)
    loop = BatchClosedLoop('mariner', [route], 'pd', 'los')
    speed, length = loop.speed, loop.length
    zeta = autopilot_gains('mariner')['zeta']
    tunings = [(2.5, 1.0), (1.5, 2.5)]
    refs, params = [], {'lookahead': [], 'lead': [], 'k1': [], 'k2': []}
    nomoto = nomoto_gains('mariner')
    for s, (k_nd, d_l) in zip(starts, tunings):
        refs.append(ec.run('mariner', route, 'los_lead', [s], 0.9, 150.0, tuning=(k_nd, d_l)))
        omega_n = k_nd * speed / length
        k1, k2 = pd_gains(nomoto['a'], nomoto['b'], omega_n=omega_n, zeta=zeta)
        for key, v in (('lookahead', d_l * length), ('lead', 2 * zeta * speed / omega_n),
                       ('k1', k1), ('k2', k2)):
            params[key].append(v)
    res = loop.run(dict(episodes(starts, 0.9), **params), 150.0)
    assert_metrics_equal(res.metrics, refs)


def zigzag():
    return Route.polyline([(0, 0), (1500, 0), (2500, 900), (3500, 900), (4200, 0)])


def test_batched_guidance_equals_guidance_per_vessel_at_corners():
    """Closed-loop positions on a route with four corners and a 150 m acceptance circle,
    replayed through one Guidance per vessel: the same commands, progress, integral and
    completion at every step, and every vessel switched at every corner and finished."""
    route = zigzag()
    n = 4
    loop = BatchClosedLoop('mariner', [route], 'pd', 'ilos', acceptance_radius=150.0,
                           corner_angle=math.radians(1.0))
    eps = {'route': 0, 'along': [0, 50, 100, 200], 'cross': [-80, 0, 40, 120],
           'heading': [0.2, -0.1, 0.0, 0.3], 'current_speed': [0, 0.5, 0.9, 0.3],
           'current_direction': [0, 1.0, -2.0, 2.5], 'lookahead': [300, 400, 500, 600]}
    # The route is ~5 km: at about 7.7 m/s every vessel finishes by ~720 s (the last at
    # 717.5 s); 780 s leaves every vessel a minute of finished steps.
    duration = 780.0
    res = loop.run(eps, duration, log_every=1)
    assert res.metrics['finished'].all()
    assert np.nanmax(res.metrics['finish_time_s']) <= duration - 30.0
    north, east = res.log['north'], res.log['east']
    sigma = loop.defaults()['integral_gain']
    singles = [Guidance(route, 'ilos', d, 150.0, integral_gain=sigma)
               for d in eps['lookahead']]
    batch = BatchGuidance(route, n, 'ilos', eps['lookahead'], integral_gain=sigma,
                          acceptance_radius=150.0)
    # Every step's outputs gathered, then compared at once (step, vessel, quantity).
    steps = len(res.log['t'])
    got, want = np.empty((2, steps, n, 4))
    legs, finished = np.empty((2, steps, n), dtype=int), np.empty((2, steps, n), dtype=bool)
    heading = np.empty((steps, n))
    for step in range(steps):
        dt = 0.1 if step else 0.0
        out = batch.update(north[step], east[step], dt)
        got[step] = np.column_stack([out.heading_cmd, out.cross_track, out.s, out.integral])
        legs[0, step], finished[0, step], heading[step] = \
            out.leg_index, out.finished, out.heading_cmd
        for i, g in enumerate(singles):
            o = g.update(north[step, i], east[step, i], 0.0, dt)
            want[step, i] = o.heading_cmd, o.cross_track, o.s, o.integral
            legs[1, step, i], finished[1, step, i] = o.leg_index, o.finished
    np.testing.assert_array_equal(legs[0], legs[1])
    np.testing.assert_array_equal(finished[0], finished[1])
    np.testing.assert_allclose(got, want, rtol=RTOL, atol=1e-9)
    np.testing.assert_array_equal(heading, res.log['heading_cmd'])
    assert all(set(legs[1, :, i]) == set(range(len(route.legs))) for i in range(n))


def test_an_episode_does_not_depend_on_its_batch():
    """Reordered, or run alone, an episode gives the same numbers: elementwise arithmetic has
    no coupling between vessels (the policy's float64 matrix products sum each row alone)."""
    route = curved_route('mariner')
    starts = ec.start_states(4)
    for controller in ('ilos', 'policy'):
        loop = BatchClosedLoop('mariner', [route], *CONTROLLERS[controller])
        eps = episodes(starts, 0.5)
        res = loop.run(eps, 60.0).metrics
        order = [2, 0, 3, 1]
        shuffled = loop.run({k: np.asarray(v)[order] if np.ndim(v) else v
                             for k, v in eps.items()}, 60.0).metrics
        alone = loop.run({k: np.asarray(v)[[1]] if np.ndim(v) else v
                          for k, v in eps.items()}, 60.0).metrics
        for key in METRICS:
            np.testing.assert_allclose(shuffled[key], res[key][order], rtol=RTOL, atol=0)
            np.testing.assert_allclose(alone[key], res[key][[1]], rtol=RTOL, atol=0)


def test_several_routes_in_one_batch_equal_their_own_batches():
    routes = [curved_route('mariner'), zigzag()]
    loop = BatchClosedLoop('mariner', routes, 'pd', 'ilos')
    eps = {'route': [0, 1, 0, 1], 'along': [10, 20, 30, 40], 'cross': [50, -50, 0, 20],
           'heading': 0.1, 'current_speed': 0.4, 'current_direction': [0, 1, 2, 3]}
    mixed = loop.run(eps, 100.0).metrics
    for r in (0, 1):
        sel = np.flatnonzero(np.asarray(eps['route']) == r)
        own = loop.run({k: np.asarray(v)[sel] if np.ndim(v) else v for k, v in eps.items()},
                       100.0).metrics
        for key in METRICS:
            np.testing.assert_allclose(own[key], mixed[key][sel], rtol=RTOL, atol=0)


def test_same_run_twice_is_identical():
    route = curved_route('mariner')
    loop = BatchClosedLoop('mariner', [route], 'fuzzy_pid', 'ilos')
    eps = episodes(ec.start_states(3), 0.9)
    a, b = loop.run(eps, 50.0, log_every=10), loop.run(eps, 50.0, log_every=10)
    for key in METRICS:
        np.testing.assert_array_equal(a.metrics[key], b.metrics[key])
    for key in a.log:
        np.testing.assert_array_equal(a.log[key], b.log[key])
    np.testing.assert_allclose(a.log['t'], np.arange(51) * 1.0)   # every 10 steps of 0.1 s


def test_memory_does_not_grow_with_the_number_of_steps():
    """Peak traced memory of a 4x longer run is the same (running metrics, no per-step
    arrays kept): within 10 % (allocator noise) plus 100 kB, where a per-step history of the
    200 vessels' seven metrics would add 200 x 8 B x 7 x 450 steps = 5 MB (one metric's alone
    0.72 MB)."""
    route = zigzag()
    loop = BatchClosedLoop('mariner', [route], 'pd', 'ilos')
    n = 200
    eps = {'route': 0, 'along': np.linspace(0, 500, n), 'cross': np.linspace(-100, 100, n),
           'heading': 0.0, 'current_speed': 0.5, 'current_direction': 1.0}
    peaks = []
    for duration in (15.0, 60.0):
        loop.run(eps, 10.0)   # warm caches
        tracemalloc.start()
        loop.run(eps, duration)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    assert peaks[1] < 1.1 * peaks[0] + 100_000


def test_bad_episodes_are_refused():
    loop = BatchClosedLoop('mariner', [zigzag()], 'pd', 'ilos')
    eps = {'route': 0, 'along': 0, 'cross': 0, 'heading': 0, 'current_speed': 0,
           'current_direction': 0}
    with pytest.raises(ValueError, match='route index 3'):
        loop.run(dict(eps, route=3), 1.0)
    with pytest.raises(ValueError, match='missing'):
        loop.run({'route': 0}, 1.0)
    with pytest.raises(ValueError, match='lookahead'):
        loop.run(dict(eps, lookahead=-1.0), 1.0)
    with pytest.raises(ValueError, match='controller'):
        BatchClosedLoop('mariner', [zigzag()], 'bangbang')


@pytest.mark.parametrize('model', ['mariner', 'container', 'tanker'])
@pytest.mark.parametrize('controller', ['los', 'fuzzy_pid'])
def test_wave_filter_each_episode_equals_the_single_vessel_filtered_loop(model, controller):
    """Behind the wave filter (a batch of filters, one per sea state) each episode equals the
    single-vessel loop with its own filter; the filter must act (the rudder's total
    variation differs from the unfiltered run's; a start whose rudder turns at its rate limit
    throughout has the same either way), so equality is not that of two unfiltered runs."""
    route = curved_route(model)
    starts = ec.start_states(2)
    duration = 30.0   # the tanker's rudder turns at its rate limit for the first 20 s
    eps = [dict(s, current_speed=0.9) for s in starts]
    plain = ec.run_batched(model, [route], controller, eps, duration, condition='wind10')
    res = ec.run_batched(model, [route], controller, eps, duration, condition='wind10',
                         wave_filter=True)
    ref = ec.run(model, route, controller, starts, 0.9, duration, condition='wind10',
                 wave_filter=True, activity=True)
    assert_metrics_equal({k: res[k] for k in ref}, [{k: v[[i]] for k, v in ref.items()}
                                                   for i in range(2)])
    assert np.any(res['rudder_tv_deg'] != plain['rudder_tv_deg'])
