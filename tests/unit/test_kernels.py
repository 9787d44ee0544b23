"""The kernel backends (ship_sim.kernels): selection, and the compiled paths against numpy.

- Selection: SHIPNAV_KERNELS auto / numpy / numba, ``use`` and ``using``; a bad name or numba
  requested where it is missing is refused with the allowed values; auto falls back to numpy.
- The numpy backend never imports numba (the demo's runtime does not install it).
- Every logged step of every episode (positions, heading, rudder, command, cross-track,
  heading command) and every metric of the batched closed loop on numba equals numpy's to
  1e-12, for each MSS model and each controller the batch supports, on a route of lines and
  arcs with corners and on a dense curved path: the compiled steps repeat the same arithmetic
  per vessel, so anything larger is a fork of the logic (the single-vessel equality of both
  backends is tests/unit/test_batch_closed_loop.py's).
- The compiled RK4 of each model equals rk4_step(model.rhs) plus the drift bit for bit or to
  rounding, and a vessel whose step leaves the model's domain keeps its last valid state on both.
- The generated RK4 is compiled once: a new process loads it from the disk cache, a changed
  parameter is another kernel, an unwritable cache folder only costs the compile.
"""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import evaluate_controllers as ec
from ship_autopilot.batch_closed_loop import LOG_FIELDS, BatchClosedLoop
from ship_planner.route_loader import load_route
from ship_sim import kernels

needs_numba = pytest.mark.skipif(not kernels.numba_available(),
                                 reason='numba not installed (requirements/kernels.txt)')
RTOL = 1e-12
MODELS = ('mariner', 'tanker', 'container')
#: The batch's controllers (BatchClosedLoop.CONTROLLERS) with their guidance laws.
CONTROLLERS = (('pd', 'los'), ('pd', 'ilos'), ('fuzzy_pid', 'ilos'), ('policy', 'los'))


def test_selection(monkeypatch):
    before = kernels.backend()
    try:
        assert kernels.use('numpy') == before
        assert kernels.backend() == 'numpy' and not kernels.compiled()
        with kernels.using('auto') as name:
            assert name == ('numba' if kernels.numba_available() else 'numpy')
        assert kernels.backend() == 'numpy'
        with pytest.raises(ValueError, match='allowed: auto, numpy, numba'):
            kernels.use('cuda')
        monkeypatch.setattr(kernels, 'numba_available', lambda: False)
        assert kernels.use('auto') == 'numpy' and kernels.backend() == 'numpy'
        with pytest.raises(ValueError, match='numba is not installed'):
            kernels.use('numba')
    finally:
        monkeypatch.undo()
        kernels.use(before)


def test_environment_variable_and_numpy_never_imports_numba():
    code = ('import sys; from ship_sim import kernels; '
            'from ship_autopilot.batch_closed_loop import BatchClosedLoop; '
            'print(kernels.backend(), "numba" in sys.modules)')
    env = dict(os.environ, SHIPNAV_KERNELS='numpy')
    out = subprocess.run([sys.executable, '-c', code], env=env, capture_output=True, text=True,
                         timeout=300, check=True).stdout.split()
    assert out == ['numpy', 'False']
    env['SHIPNAV_KERNELS'] = 'fortran'
    bad = subprocess.run([sys.executable, '-c', code], env=env, capture_output=True, text=True,
                         timeout=300)
    assert bad.returncode != 0 and 'SHIPNAV_KERNELS' in bad.stderr


def routes(model):
    """A route of lines and arcs with corners (the flagship's) and the model's dense curve."""
    folder = ec.ROOT / 'scenarios' / 'routes'
    return {'corners': load_route(folder / 'flagship_mariner.yaml').route,
            'curved': load_route(folder / f'curved_path_{model}_000.yaml').route}


def episodes(n, seed=3):
    rng = np.random.default_rng(seed)
    return {'route': 0, 'along': rng.uniform(0, 400, n), 'cross': rng.uniform(-80, 80, n),
            'heading': rng.uniform(-0.3, 0.3, n), 'current_speed': rng.uniform(0, 0.9, n),
            'current_direction': rng.uniform(-np.pi, np.pi, n)}


def run_both(model, route, controller, law, eps, duration):
    out = {}
    for name in ('numpy', 'numba'):
        with kernels.using(name):
            loop = BatchClosedLoop(model, [route], controller, law)
            out[name] = loop.run(eps, duration, log_every=1)
    return out['numpy'], out['numba']


def assert_close(ref, got, what):
    np.testing.assert_allclose(np.asarray(got, dtype=float), np.asarray(ref, dtype=float),
                               rtol=RTOL, atol=RTOL, err_msg=what)


# 60 s of 0.1 s steps: on the corner route the starts lie before the first arc, so the
# guidance switches stretches; the rudder reaches its limit for the tanker and container.
@needs_numba
@pytest.mark.parametrize('model', MODELS)
@pytest.mark.parametrize('controller, law', CONTROLLERS)
@pytest.mark.parametrize('route_name', ['corners', 'curved'])
def test_every_step_of_the_compiled_loop_equals_numpy(model, controller, law, route_name):
    route = routes(model)[route_name]
    eps = episodes(3)
    if route_name == 'corners':
        eps['along'] = np.array([1300.0, 1450.0, 1500.0])   # the first corner within 60 s
    ref, got = run_both(model, route, controller, law, eps, 60.0)
    for key in LOG_FIELDS:
        assert_close(ref.log[key], got.log[key], key)
    for key, value in ref.metrics.items():
        assert_close(value, got.metrics[key], key)
    assert ref.steps == got.steps == 600


@needs_numba
@pytest.mark.parametrize('model', MODELS)
def test_compiled_rk4_equals_numpy_and_keeps_the_last_valid_state(model):
    from ship_autopilot.learning.env import EnvConfig, PathFollowingBatch
    route = routes(model)['corners']
    config = EnvConfig(mode='straight', sim_dt=0.1, control_dt=0.1)
    yaw_rate = np.random.default_rng(5).normal(0.0, 0.01, 4)
    envs = {}
    for name in ('numpy', 'numba'):
        env = PathFollowingBatch(model, 4, config, routes=[route])
        env.current = np.tile([0.3, -0.2], (4, 1))
        env.x[:, env.model.IR] = yaw_rate
        envs[name] = env
    cmd = np.array([0.1, -0.2, 0.3, 0.0])
    for name, env in envs.items():
        with kernels.using(name):
            assert env.integrate(cmd, 3).all()
    assert_close(envs['numpy'].x, envs['numba'].x, 'state')
    # A vessel pushed out of the domain (speed 0: NaN in the equations) keeps its state.
    for name, env in envs.items():
        env.x[1, env.model.IU] = -env.model.surge_speed(env.x[1]) + env.x[1, env.model.IU]
        env.x[1, env.model.IV] = 0.0
        before = env.x.copy()
        with kernels.using(name), np.errstate(all='ignore'):
            ok = env.integrate(cmd, 1)
        assert ok.tolist() == [True, False, True, True]
        np.testing.assert_array_equal(env.x[1], before[1])
    assert_close(envs['numpy'].x, envs['numba'].x, 'state after a failed vessel')


_CACHED_RK4 = '''
import json
import os
import sys

import numpy as np
from ship_sim.models import make_model
from ship_sim.models.compiled import CACHE_ENV, batch_rk4
runs = []
for folder, speed in json.loads(sys.argv[1]):   # one kernel per (cache folder, U0)
    os.environ[CACHE_ENV] = folder
    model = make_model('mariner')
    model.U0 = speed
    step = batch_rk4(model)
    x = np.zeros((3, model.n_states))           # straight ahead at U0
    u = np.full((3, model.n_inputs), 0.05)      # rudder (rad)
    out = step(x, u, 0.1, np.zeros((3, 2)), 3, 4, np.empty_like(x))
    runs.append({'hits': sum(step.stats.cache_hits.values()),
                 'misses': sum(step.stats.cache_misses.values()), 'out': out.tolist()})
print(json.dumps(runs))
'''


@needs_numba
def test_the_generated_rk4_is_compiled_once_and_loaded_from_disk_after(tmp_path):
    """A new process (a sweep worker) loads the generated kernel from the disk cache instead
    of compiling it again, with the same result; a changed frozen parameter is another kernel
    (compiled, not a stale one loaded); an unwritable cache folder only costs the compile."""
    def run(*kernels_wanted):
        done = subprocess.run([sys.executable, '-c', _CACHED_RK4, json.dumps(kernels_wanted)],
                              timeout=300, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr[-2000:]
        return json.loads(done.stdout.splitlines()[-1])

    folder = str(tmp_path / 'kernels')
    blocked = tmp_path / 'a_file'
    blocked.write_text('')
    first, other = run((folder, 7.7175), (folder, 5.0))
    again, uncached = run((folder, 7.7175), (str(blocked / 'kernels'), 5.0))
    assert (first['hits'], first['misses']) == (0, 1)
    assert (other['hits'], other['misses']) == (0, 1)
    assert other['out'] != first['out']
    assert len(list((tmp_path / 'kernels').glob('mariner_rk4_*.py'))) == 2
    assert (again['hits'], again['misses']) == (1, 0)
    assert again['out'] == first['out']
    assert uncached['out'] == other['out']
