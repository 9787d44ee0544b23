"""Interface of the MSS ship ports: rudder sign, saturation, limits, trim, domain checks."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from ship_sim.models import ModelStateError, make_model
from ship_sim.models.container import Container
from ship_sim.models.mariner import Mariner
from ship_sim.models.tanker import Tanker
from ship_sim.integrators import rk4_step

# provenance: tests/data/README.md
MANEUVERS = Path(__file__).resolve().parents[1] / 'data' / 'mss_golden' / 'maneuvers.json'
MODELS = ('mariner', 'tanker', 'container')
deg = math.radians


def test_registry_builds_the_ports():
    assert type(make_model('mariner')) is Mariner
    assert type(make_model('tanker', h=30.0)) is Tanker
    assert type(make_model('container')) is Container
    # Lpp from the MSS headers.
    assert (Mariner.length, Tanker.length, Container.length) == (160.93, 304.8, 175.0)


@pytest.mark.parametrize('name', MODELS)
def test_positive_unified_rudder_turns_to_port(name):
    model = make_model(name)
    x0 = model.initial_state()
    for cmd in (0.15, -0.15):
        x, u = x0, model.inputs(cmd)
        for _ in range(600):              # 60 s
            x = model.step(x, u, 0.1)
        # NED: a port turn decreases psi and has r < 0.
        assert np.sign(x[model.IPSI]) == -np.sign(cmd)
        assert np.sign(x[model.IR]) == -np.sign(cmd)
        settled = np.sign(cmd) * min(abs(cmd), model.rudder_max)
        assert model.rudder_angle(x) == pytest.approx(settled, abs=1e-9)


def test_native_rudder_signs_follow_mss():
    # mariner.m: delta_c = -ui; tanker.m: positive delta -> port; container.m: -> starboard.
    assert make_model('mariner').inputs(0.1)[0] == -0.1
    assert make_model('tanker').inputs(0.1)[0] == 0.1
    assert make_model('container').inputs(0.1)[0] == -0.1


def test_inputs_fill_shaft_and_depth_and_batch():
    tanker = Tanker(h=25.0)
    np.testing.assert_array_equal(tanker.inputs(0.1), [0.1, 80.0, 25.0])
    np.testing.assert_array_equal(tanker.inputs(0.1, 60.0), [0.1, 60.0, 25.0])
    batch = make_model('container').inputs(np.array([0.1, -0.2, 0.0]), 75.0)
    np.testing.assert_array_equal(batch, [[-0.1, 75.0], [0.2, 75.0], [-0.0, 75.0]])
    assert make_model('mariner').inputs(np.zeros((4, 2))).shape == (4, 2, 1)
    with pytest.raises(ValueError, match='no shaft'):
        make_model('mariner').inputs(0.1, 80.0)


@pytest.mark.parametrize('name', MODELS)
def test_rudder_command_saturates_at_mss_limit(name):
    model = make_model(name)
    x = model.initial_state()
    x[model.IDELTA] = model.STATE_RUDDER_SIGN * (model.rudder_max - deg(0.5))
    at_limit = model.rhs(x, model.inputs(model.rudder_max))
    beyond = model.rhs(x, model.inputs(3 * model.rudder_max))
    np.testing.assert_array_equal(at_limit, beyond)
    # 0.5 deg short of the limit: the 1 s servo moves at 0.5 deg/s, below every rate limit.
    assert model.rudder_angle(at_limit) == pytest.approx(deg(0.5), rel=1e-12)
    # From 0 to a full command the rate limit binds.
    x[model.IDELTA] = 0.0
    xdot = model.rhs(x, model.inputs(-5.0))
    assert model.rudder_angle(xdot) == pytest.approx(-model.rudder_rate_max, rel=1e-15)


def test_mss_limit_values():
    assert Mariner.rudder_max == pytest.approx(deg(40)) and Mariner.rudder_rate_max == deg(5)
    assert Tanker.rudder_max == pytest.approx(deg(10))
    assert Tanker.rudder_rate_max == pytest.approx(deg(2.33))
    # MSS saturates the shaft command at +-80 / +-160 rpm, but both models describe forward
    # motion only (astern drives u <= 0, outside their domain): ours stop at 0 and 1 rpm.
    assert (Tanker.shaft_min, Tanker.shaft_max) == (0.0, 80.0)
    assert Container.rudder_max == pytest.approx(deg(10))
    assert Container.rudder_rate_max == pytest.approx(deg(5))
    assert (Container.shaft_min, Container.shaft_max) == (1.0, 160.0)


@pytest.mark.parametrize('name, shaft_cmd, limit', [('tanker', 120.0, 80.0),
                                                    ('container', 300.0, 160.0)])
def test_shaft_command_saturates(name, shaft_cmd, limit):
    model = make_model(name)
    x = model.initial_state()
    np.testing.assert_array_equal(model.rhs(x, model.inputs(0.0, shaft_cmd)),
                                  model.rhs(x, model.inputs(0.0, limit)))


def test_tanker_shaft_time_constant_is_50_s():
    tanker = Tanker()
    x = tanker.initial_state()             # n = 80 rpm
    n_dot = tanker.rhs(x, tanker.inputs(0.0, 30.0))[tanker.IN]
    assert n_dot == pytest.approx((30.0 - 80.0) / 50.0, rel=1e-12)


def test_per_instance_rudder_limits():
    model = Mariner(rudder_max=deg(20), rudder_rate_max=deg(2))
    x = model.initial_state()
    x[model.IDELTA] = deg(19.5)
    xdot = model.rhs(x, model.inputs(deg(35)))
    assert xdot[model.IDELTA] == pytest.approx(deg(0.5), rel=1e-12)
    x[model.IDELTA] = 0.0
    assert model.rhs(x, model.inputs(deg(35)))[model.IDELTA] == pytest.approx(deg(2))
    assert Mariner.rudder_max == pytest.approx(deg(40))     # class default untouched
    for bad in ({'rudder_max': -0.1}, {'rudder_max': math.nan}, {'rudder_max': 2.0},
                {'rudder_rate_max': 0.0}, {'rudder_rate_max': math.inf}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            Tanker(**bad)


def test_constructor_parameters_are_validated():
    with pytest.raises(ValueError, match='h = 18.0'):
        Tanker(h=18.0)
    Tanker(h=18.5)
    with pytest.raises(ValueError, match='U0'):
        Mariner(U0=0.0)
    assert Mariner(U0=9.0).surge_speed(np.zeros(7)) == 9.0


def test_trim_speeds_match_the_reference_harness():
    # maneuvers.json 'initial_state': u0 solved from xdot(1) = 0 at zero rudder, n = n_c.
    runs = json.loads(MANEUVERS.read_text())['turning_circle']
    for key, model, shaft in [('tanker_turn_dc+10_h1000', Tanker(h=1000.0), 80.0),
                              ('tanker_turn_dc-10_h30', Tanker(h=30.0), 80.0),
                              ('container_turn_dc+10_n70', Container(), 70.0),
                              ('container_turn_dc+10_n80', Container(), 80.0)]:
        x = model.initial_state(shaft=shaft, north=10.0, east=-5.0, psi=0.3)
        expected = runs[key]['rk4_h0.1']['initial_speed_U_mps']
        assert x[model.IU] == pytest.approx(expected, rel=1e-12)
        assert (x[model.IX], x[model.IY], x[model.IPSI], x[model.IN]) == (10.0, -5.0, 0.3, shaft)
    assert not Mariner().initial_state().any()


@pytest.mark.parametrize('name, speed', [('tanker', 6.0), ('container', 9.5)])
def test_trim_for_a_requested_speed_solves_the_shaft(name, speed):
    model = make_model(name)
    x = model.initial_state(speed=speed)
    assert x[model.IU] == speed and 0.0 < x[model.IN] < model.shaft_max
    xdot = model.rhs(x, model.inputs(0.0, x[model.IN]))
    assert abs(xdot[model.IU]) < 1e-10
    with pytest.raises(ValueError, match='speed'):
        model.initial_state(speed=30.0)


def test_mariner_refuses_a_speed_it_cannot_hold():
    with pytest.raises(ValueError, match='U0'):
        Mariner().initial_state(speed=5.0)
    assert not Mariner(U0=5.0).initial_state(speed=5.0).any()


@pytest.mark.parametrize('name, index, value, quantity', [
    ('mariner', 0, -7.7175, 'speed U'),
    ('tanker', 0, 0.0, 'surge'),
    ('tanker', 0, -1.0, 'surge'),
    ('tanker', 7, -2.0, 'shaft'),       # cun u n + cnn n^2 < 0: MSS returns complex numbers
    ('container', 0, 0.0, 'surge'),
    ('container', 9, 0.0, 'shaft'),
    ('container', 9, -10.0, 'shaft'),
    ('container', 2, math.nan, 'not finite'),
])
def test_invalid_states_are_refused(name, index, value, quantity):
    model = make_model(name)
    x = model.initial_state()
    x[index] = value
    with pytest.raises(ModelStateError, match=quantity):
        model.check_state(x)
    batch = np.tile(model.initial_state(), (3, 1))
    batch[2] = x
    with pytest.raises(ModelStateError, match=quantity):
        model.check_state(batch)


def test_batch_error_names_the_vessel_and_value():
    model = Tanker()
    batch = np.tile(model.initial_state(), (4, 1))
    batch[3, 0] = -0.5
    with pytest.raises(ModelStateError, match=r'-0\.5.*vessel index 3'):
        model.check_state(batch)


def test_tanker_large_negative_shaft_is_valid_and_real():
    # Below -cun u/cnn (rps) the square root is real again: MSS computes it, so do we.
    model = Tanker()
    x = model.initial_state()
    x[model.IN] = -60.0
    model.check_state(x)
    assert np.all(np.isfinite(model.rhs(x, model.inputs(0.0, -60.0))))


def test_tanker_refuses_shallow_depth_in_the_input():
    model = Tanker()
    with pytest.raises(ModelStateError, match='depth'):
        model.check_state(model.initial_state(), [0.0, 80.0, 15.0])


@pytest.mark.parametrize('name, index, value', [('mariner', 0, -7.7175),
                                                ('tanker', 7, -2.0)])
def test_float_path_turns_math_errors_into_model_state_errors(name, index, value):
    model = make_model(name)
    x = model.initial_state()
    x[index] = value
    with pytest.raises(ModelStateError):
        model.rhs_scalar(x.tolist(), model.inputs(0.0).tolist())


@pytest.mark.parametrize('name', MODELS)
def test_step_float_path_equals_array_path(name):
    model = make_model(name)
    x = model.initial_state()
    x[model.IV], x[model.IR], x[model.IDELTA] = 0.2, -0.003, 0.05
    u = model.inputs(0.1)
    fast = model.step(x, u, 0.1)
    assert isinstance(fast, np.ndarray) and fast.shape == x.shape
    np.testing.assert_allclose(fast, rk4_step(model.rhs, x, u, 0.1), rtol=1e-14, atol=1e-15)
    batch = model.step(np.stack([x, x]), np.stack([u, u]), 0.1)
    np.testing.assert_allclose(batch[1], fast, rtol=1e-14, atol=1e-15)
