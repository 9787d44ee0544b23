"""VesselSimulator / BatchSimulator (ship_sim.simulator), no ROS.

Reference: MSS turning circles integrated under GNU Octave with the unchanged MSS models and
rk4.m (tests/data/mss_golden/traj, 1 s samples of h = 0.1 s runs). Commands there are
MSS-native; the simulator takes the unified sign (positive turns to port), so e.g. the
mariner's ui = +35 deg (starboard) is our -35 deg, the container's delta_c = +10 deg
(starboard) our -10 deg, the tanker's +10 deg (port) our +10 deg.
"""
import math
from pathlib import Path

import numpy as np
import pytest

from ship_sim.current import OceanCurrent
from ship_sim.models import MODEL_NAMES, ModelStateError, VesselModel, make_model
from ship_sim.simulator import BatchSimulator, VesselSimulator

# provenance: tests/data/README.md
TRAJ = Path(__file__).resolve().parents[1] / 'data' / 'mss_golden' / 'traj'

MSS_CASES = [
    # file, model, model params, unified rudder (deg), shaft (rpm)
    ('mariner_turn_ui+35_rk4_h0.1_1s.csv', 'mariner', {}, -35.0, None),
    ('mariner_turn_ui-35_rk4_h0.1_1s.csv', 'mariner', {}, 35.0, None),
    ('tanker_turn_dc+10_h1000_rk4_h0.1_1s.csv', 'tanker', {'h': 1000.0}, 10.0, 80.0),
    ('tanker_turn_dc-10_h30_rk4_h0.1_1s.csv', 'tanker', {'h': 30.0}, -10.0, 80.0),
    ('container_turn_dc+10_n70_rk4_h0.1_1s.csv', 'container', {}, -10.0, 70.0),
]


@pytest.mark.parametrize('fname, model, params, rudder_deg, shaft', MSS_CASES)
def test_turning_circle_reproduces_mss(fname, model, params, rudder_deg, shaft):
    ref = np.genfromtxt(TRAJ / fname, delimiter=',', names=True)
    sim = VesselSimulator(model, dt=0.1, model_params=params, shaft=shaft)
    got = []
    for k in range(len(ref) * 10 - 9):
        if k % 10 == 0:
            t, n, e, psi, *_ = sim.nav_state()
            got.append((t, n, e, sim.speed_water(), sim.state[sim.model.IPSI]))
        sim.step(math.radians(rudder_deg))
    got = np.array(got)
    np.testing.assert_allclose(got[:, 0], ref['t'], rtol=0, atol=1e-9)
    # Same RK4 arithmetic as MSS: agreement to rounding over 700 s of turning.
    np.testing.assert_allclose(got[:, 1], ref['x'], rtol=0, atol=1e-8)
    np.testing.assert_allclose(got[:, 2], ref['y'], rtol=0, atol=1e-8)
    np.testing.assert_allclose(got[:, 3], ref['U'], rtol=0, atol=1e-10)
    np.testing.assert_allclose(got[:, 4], ref['psi'], rtol=0, atol=1e-10)


@pytest.mark.parametrize('name', MODEL_NAMES)
def test_positive_rudder_turns_to_port_for_every_model(name):
    for rudder, sign in ((0.15, -1.0), (-0.15, 1.0)):
        sim = VesselSimulator(name, dt=0.1)
        sim.run(rudder, 300)   # 30 s
        _, _, r = sim.velocity_water()
        assert np.sign(r) == sign, f'{name}: rudder {rudder} gave r = {r}'
        assert np.sign(sim.rudder()) == np.sign(rudder)   # actual rudder in the unified sign


def test_rudder_command_saturates_at_the_model_limit():
    a = VesselSimulator('mariner', dt=0.1)
    b = VesselSimulator('mariner', dt=0.1)
    limit = a.model.rudder_max
    assert limit == pytest.approx(math.radians(40.0))
    a.run(1.0, 50)
    b.run(limit, 50)
    assert a.rudder_command == limit
    np.testing.assert_array_equal(a.state, b.state)
    a.step(-5.0)
    assert a.rudder_command == -limit


def test_rudder_limit_override_goes_through_the_model():
    sim = VesselSimulator('mariner', dt=0.1, model_params={'rudder_max': math.radians(20.0)})
    sim.run(0.6, 400)   # 40 s: the rudder has long reached the (overridden) limit
    assert sim.rudder_command == pytest.approx(math.radians(20.0))
    assert sim.rudder() == pytest.approx(math.radians(20.0), abs=1e-9)


@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf, 'x', None])
def test_non_finite_commands_are_refused_and_leave_the_state_alone(bad):
    sim = VesselSimulator('tanker', dt=0.1)
    sim.run(0.1, 10)
    x, k, cmd = sim.state.copy(), sim.k, sim.rudder_command
    with pytest.raises(ValueError):
        sim.step(bad)
    if bad is not None:   # shaft_cmd None means "hold the shaft command"
        with pytest.raises(ValueError):
            sim.step(0.1, shaft_cmd=bad)
    np.testing.assert_array_equal(sim.state, x)
    assert (sim.k, sim.rudder_command) == (k, cmd)
    assert sim.t == pytest.approx(1.0)


def test_shaft_command_is_saturated_and_held():
    sim = VesselSimulator('tanker', dt=0.1)
    assert sim.shaft_command == 80.0          # the state's shaft speed by default
    sim.step(0.0, shaft_cmd=500.0)
    assert sim.shaft_command == sim.model.shaft_max == 80.0
    sim.step(0.0, shaft_cmd=40.0)
    sim.run(0.0, 10)                           # no shaft_cmd: held
    assert sim.shaft_command == 40.0
    assert sim.shaft() < 80.0                  # the shaft follows (time constant 50 s)
    with pytest.raises(ValueError):
        VesselSimulator('mariner', dt=0.1).step(0.0, shaft_cmd=10.0)


class _Sinking(VesselModel):
    """Test model: surge decelerates at 1 m/s^2; states with u <= 0 are outside its domain."""

    name = 'sinking'
    state_names = ('u', 'v', 'r', 'x', 'y', 'psi', 'delta')
    input_names = ('delta_c',)

    def rhs(self, x, u):
        xdot = np.zeros_like(x)
        xdot[..., 0] = -1.0
        xdot[..., 3] = x[..., 0] * np.cos(x[..., 5])
        xdot[..., 4] = x[..., 0] * np.sin(x[..., 5])
        return xdot

    def inputs(self, rudder_cmd, shaft_cmd=None):
        return np.asarray(rudder_cmd, dtype=float)[..., None]

    def initial_state(self, speed=None, north=0.0, east=0.0, psi=0.0, shaft=None):
        return np.array([1.0 if speed is None else speed, 0, 0, north, east, psi, 0.0])

    def check_state(self, x, u=None):
        super().check_state(x, u)
        if np.any(np.asarray(x)[..., 0] <= 0.0):
            raise ModelStateError('sinking: u <= 0')


def test_a_state_outside_the_model_domain_is_refused_and_not_stored():
    sim = VesselSimulator(_Sinking(), dt=0.3)
    sim.run(0.0, 3)                             # u = 1 - 0.9 = 0.1
    x, k = sim.state.copy(), sim.k
    with pytest.raises(ModelStateError):
        sim.step(0.0)                           # would give u = -0.2
    np.testing.assert_array_equal(sim.state, x)
    assert sim.k == k
    assert sim.velocity_water()[0] == pytest.approx(0.1)


def test_constant_current_drifts_the_position_and_not_the_water_relative_motion():
    speed, direction = 1.2, math.radians(60.0)   # flowing towards 060 deg
    vn, ve = speed * math.cos(direction), speed * math.sin(direction)
    still = VesselSimulator('mariner', dt=0.1)
    drift = VesselSimulator('mariner', dt=0.1, current=OceanCurrent(speed, direction))
    for k in range(600):
        cmd = 0.3 * math.sin(0.01 * k)
        still.step(cmd)
        drift.step(cmd)
    np.testing.assert_allclose(drift.velocity_water(), still.velocity_water(), rtol=0,
                               atol=1e-12)
    n0, e0, psi0 = still.pose_ned()
    n1, e1, psi1 = drift.pose_ned()
    assert psi1 == pytest.approx(psi0, abs=1e-12)
    assert n1 - n0 == pytest.approx(vn * 60.0, abs=1e-9)
    assert e1 - e0 == pytest.approx(ve * 60.0, abs=1e-9)
    # Over ground = through the water + the current in body axes R(psi)^T [vn, ve].
    u, v, r = drift.velocity_water()
    ug, vg, rg = drift.velocity_ground()
    assert ug == pytest.approx(u + math.cos(psi1) * vn + math.sin(psi1) * ve, abs=1e-12)
    assert vg == pytest.approx(v - math.sin(psi1) * vn + math.cos(psi1) * ve, abs=1e-12)
    assert rg == r


def test_velocity_over_ground_heading_north_with_an_eastward_current():
    # Hand check: heading north (psi = 0), current 1 m/s towards east -> sway +1 (starboard).
    sim = VesselSimulator('nomoto1', dt=0.1, current=OceanCurrent(1.0, math.pi / 2))
    u, v, r = sim.velocity_water()
    assert sim.velocity_ground() == pytest.approx((u, v + 1.0, r), abs=1e-12)


def test_gauss_markov_current_is_repeatable_with_its_seed():
    def run(seed):
        c = OceanCurrent(0.5, 0.0, speed_time_constant=50.0, speed_noise=0.01,
                         direction_time_constant=50.0, direction_noise=0.01, seed=seed)
        sim = VesselSimulator('mariner', dt=0.1, current=c)
        sim.run(0.1, 500)
        return sim.pose_ned()

    assert run(3) == run(3)
    assert run(3) != run(4)


def test_time_is_step_count_times_dt_and_pose_is_wrapped():
    sim = VesselSimulator('nomoto1', dt=0.05, t0=10.0, psi=3.0)
    sim.run(-0.3, 1234)
    assert sim.k == 1234
    assert sim.t == 10.0 + 1234 * 0.05
    _, _, psi = sim.pose_ned()
    assert -math.pi <= psi < math.pi
    assert psi == pytest.approx(math.remainder(sim.state[sim.model.IPSI], 2 * math.pi))


def test_initial_pose_and_nav_state():
    sim = VesselSimulator('container', dt=0.1, north=100.0, east=-50.0, psi=-1.0)
    t, n, e, psi, u, v, r = sim.nav_state()
    assert (t, n, e, psi) == (0.0, 100.0, -50.0, -1.0)
    assert (v, r) == (0.0, 0.0) and u > 0.0


def test_batch_equals_single_vessels():
    cmds = np.array([0.2, -0.1, 0.35])
    psis = np.array([0.0, 1.0, -2.0])
    batch = BatchSimulator('tanker', dt=0.1, n=3, psi=psis, model_params={'h': 50.0})
    singles = [VesselSimulator('tanker', dt=0.1, psi=p, model_params={'h': 50.0}) for p in psis]
    for k in range(300):
        batch.step(cmds * math.cos(0.01 * k), shaft_cmd=70.0)
        for s, c in zip(singles, cmds):
            s.step(c * math.cos(0.01 * k), shaft_cmd=70.0)
    np.testing.assert_allclose(batch.state, np.array([s.state for s in singles]),
                               rtol=1e-12, atol=1e-9)
    for i, s in enumerate(singles):
        got = [a[i] for a in batch.nav_state()[1:]]
        np.testing.assert_allclose(got, s.nav_state()[1:], rtol=1e-12, atol=1e-9)
    assert batch.rudder() == pytest.approx([s.rudder() for s in singles], abs=1e-12)
    assert batch.t == singles[0].t


def test_batch_refuses_a_nan_for_any_vessel_and_keeps_all_states():
    batch = BatchSimulator('mariner', dt=0.1, n=4)
    batch.run(0.1, 5)
    x = batch.state.copy()
    with pytest.raises(ValueError, match='2'):
        batch.step(np.array([0.1, 0.1, np.nan, 0.1]))
    np.testing.assert_array_equal(batch.state, x)
    batch.step(np.array([1.0, -1.0, 0.0, 0.1]))
    lim = batch.model.rudder_max
    np.testing.assert_array_equal(batch.rudder_command, [lim, -lim, 0.0, 0.1])


def test_batch_with_independent_currents():
    c = OceanCurrent(1.0, 0.0, speed_time_constant=20.0, speed_noise=0.05, seed=1, shape=(3,))
    batch = BatchSimulator('nomoto1', dt=0.1, n=3, current=c)
    batch.run(0.0, 200)
    north = batch.pose_ned()[0]
    assert len(set(north.tolist())) == 3   # each vessel drifted with its own current
    with pytest.raises(ValueError):
        BatchSimulator('nomoto1', dt=0.1, n=2, current=c)


def test_constructor_checks():
    with pytest.raises(ValueError):
        VesselSimulator('mariner', dt=0.0)
    with pytest.raises(ValueError):
        VesselSimulator('mariner', dt=math.nan)
    with pytest.raises(ValueError):
        VesselSimulator('warship')
    with pytest.raises(ValueError):
        VesselSimulator(make_model('mariner'), model_params={'U0': 5.0})
    with pytest.raises(ValueError):
        VesselSimulator('mariner', state=np.zeros((2, 7)))
    with pytest.raises(ModelStateError):
        VesselSimulator('tanker', state=np.full(8, np.nan))
