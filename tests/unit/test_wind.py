"""Wind in the plants: the physics behind each claim of ship_sim.environment.wind.

- calm changes nothing (bit for bit), on the single-vessel and the batched path;
- the loads act as forces through each model's own inertia (the mass its source states);
- conventions: a north wind pushes the ship south, a wind from port pushes it to starboard;
- a head wind slows a shaft-driven ship to the speed where its resistance curve plus the
  Blendermann surge coefficient balance the thrust;
- in beam wind, a ship free in sway only (a captive drift test: yaw held) drifts downwind to the
  sway speed where the Van Berlekom and Goddard sway damping balances the Blendermann force.
"""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from ship_sim.current import OceanCurrent
from ship_sim.environment.wind import (WIND_PROFILES, WindField, relative_wind,
                                       wind_disturbance, wind_profile)
from ship_sim.environment.wind_coefficients import RHO_AIR, blendermann94
from ship_sim.models import container, make_model, mariner, tanker
from ship_sim.simulator import BatchSimulator, VesselSimulator

MSS_SHIPS = ('mariner', 'tanker', 'container')


def _rudder(k):
    return 0.08 * math.sin(k / 25.0)


@pytest.mark.parametrize('name', MSS_SHIPS)
def test_calm_wind_run_equals_no_wind_run_bit_for_bit(name):
    cur = dict(speed=0.4, direction=1.0)
    a = VesselSimulator(name, psi=0.3, current=OceanCurrent(**cur))
    b = VesselSimulator(name, psi=0.3, current=OceanCurrent(**cur),
                        wind=WindField(0.0, math.radians(250.0)))
    for k in range(400):
        a.step(_rudder(k))
        b.step(_rudder(k))
    assert np.array_equal(a.state, b.state)
    assert b.wind_loads() == (0.0, 0.0, 0.0, 0.0)


@pytest.mark.parametrize('name', MSS_SHIPS)
def test_calm_wind_batch_equals_no_wind_batch_bit_for_bit(name):
    psi = np.linspace(-3.0, 3.0, 7)
    a = BatchSimulator(name, n=7, psi=psi)
    b = BatchSimulator(name, n=7, psi=psi, wind=WindField(0.0, 2.0, shape=(7,)))
    for k in range(100):
        a.step(_rudder(k))
        b.step(_rudder(k))
    assert np.array_equal(a.state, b.state)


def test_wind_needs_a_ship_with_a_profile():
    with pytest.raises(ValueError, match='takes no external loads'):
        VesselSimulator('nomoto1', wind=WindField(10.0, 0.0))
    with pytest.raises(ValueError, match='coefficients'):
        VesselSimulator('tanker', wind=WindField(10.0, 0.0), wind_coefficients='nope')


# --- the loads act through the model's inertia --------------------------------------------------
LOADS = (2.0e5, -3.0e5, 4.0e6, 5.0e6)   # X, Y (N), K, N (N m)


def test_tanker_loads_are_forces_on_its_stated_mass():
    m = make_model('tanker')
    x = m.initial_state()
    u = m.inputs(0.0)
    d = m.rhs(x, u, loads=LOADS) - m.rhs(x, u)
    z = tanker.T / (m.h - tanker.T)
    mass = 225.5e6   # SIMtanker.m
    assert d[m.IU] == pytest.approx(LOADS[0] / (mass * (tanker.m11 - tanker.Xudotz * z)), rel=1e-9)
    assert d[m.IV] == pytest.approx(LOADS[1] / (mass * (tanker.m22 - tanker.Yvdotz * z)), rel=1e-9)
    assert d[m.IR] == pytest.approx(
        LOADS[3] / (mass * tanker.L ** 2 * (tanker.m33 - tanker.Nrdotz * z)), rel=1e-9)


@pytest.mark.parametrize('module, mass_t', [(mariner, 17045.0), (container, 21750.0)])
def test_prime_system_density_gives_the_mass_mss_states(module, mass_t):
    # m' 1/2 rho L^3 with rho = 1025 kg/m^3 must be the SIM*.m mass (stated to 4-5 digits).
    assert module.m * 0.5 * 1025.0 * module.L ** 3 / 1e3 == pytest.approx(mass_t, rel=5e-4)


def test_mariner_loads_act_through_its_mass_matrix():
    m = make_model('mariner')
    x = m.initial_state()
    u = m.inputs(0.0)
    d = m.rhs(x, u, loads=LOADS) - m.rhs(x, u)
    s = 0.5 * 1025.0 * mariner.L ** 3          # prime mass -> kg
    M = np.array([[mariner.m22 * s, mariner.m23 * s * mariner.L],
                  [mariner.m32 * s * mariner.L, mariner.m33 * s * mariner.L ** 2]])
    np.testing.assert_allclose(d[[m.IV, m.IR]], np.linalg.solve(M, [LOADS[1], LOADS[3]]),
                               rtol=1e-9)
    assert d[m.IU] == pytest.approx(LOADS[0] / (mariner.m11 * s), rel=1e-9)


def test_container_roll_moment_heels_it_and_uses_the_coupled_inertia():
    m = make_model('container')
    x = m.initial_state()
    u = m.inputs(0.0)
    c = container
    s = 0.5 * c.rho * c.L ** 3
    # The sway-roll-yaw mass matrix container.m inverts, [[m22 m32 m42], [m32 m33 0],
    # [m42 0 m44]] (prime), in SI.
    M = np.array([[c.m22 * s, c.m32 * s * c.L, c.m42 * s * c.L],
                  [c.m32 * s * c.L, c.m33 * s * c.L ** 2, 0.0],
                  [c.m42 * s * c.L, 0.0, c.m44 * s * c.L ** 2]])
    d = m.rhs(x, u, loads=LOADS) - m.rhs(x, u)
    np.testing.assert_allclose(d[[m.IV, m.IP, m.IR]], np.linalg.solve(M, LOADS[1:]), rtol=1e-9)
    only_k = m.rhs(x, u, loads=(0.0, 0.0, 1e6, 0.0)) - m.rhs(x, u)
    assert only_k[m.IP] > 0   # K > 0 rolls to starboard (FRD)


# --- conventions --------------------------------------------------------------------------------
@pytest.mark.parametrize('name', MSS_SHIPS)
def test_north_wind_pushes_the_ship_south(name):
    east = math.pi / 2
    calm = VesselSimulator(name, psi=east)
    windy = VesselSimulator(name, psi=east, wind=WindField(20.0, 0.0))
    X, Y, K, N = windy.wind_loads()
    assert Y > 0           # heading east, starboard is south
    calm.run(0.0, 600)
    windy.run(0.0, 600)
    south = calm.pose_ned()[0] - windy.pose_ned()[0]
    # Positive, and below the undamped drift 1/2 a t^2 with a = Y / (sway mass incl. added
    # mass >= the ship's mass) over the 60 s.
    mass = {'mariner': 17.045e6, 'tanker': 225.5e6, 'container': 21.75e6}[name]
    assert 0.1 < south < 0.5 * Y / mass * 60.0 ** 2


def test_relative_wind_angle_convention():
    # Ship at rest heading north; wind from the west (port) and from ahead.
    V, g = relative_wind(0.0, 0.0, 0.0, 10.0, math.radians(270.0))
    assert V == pytest.approx(10.0) and g == pytest.approx(math.pi / 2)
    V, g = relative_wind(5.0, 0.0, 0.0, 10.0, 0.0)
    assert V == pytest.approx(15.0) and g == pytest.approx(0.0, abs=1e-15)


def test_mirror_winds_give_mirror_loads():
    p = WIND_PROFILES['container']
    port = wind_disturbance(p, 7.0, 0.0, 0.0, 15.0, math.radians(-70.0))
    stbd = wind_disturbance(p, 7.0, 0.0, 0.0, 15.0, math.radians(70.0))
    np.testing.assert_allclose(stbd, np.array(port) * [1, -1, -1, -1], rtol=1e-12)


def test_gusts_have_the_stated_sd_and_repeat_with_the_seed():
    a = WindField(15.0, 0.0, gust_sd=2.0, time_constant=20.0, seed=3, shape=(4000,))
    b = WindField(15.0, 0.0, gust_sd=2.0, time_constant=20.0, seed=3, shape=(4000,))
    for _ in range(50):
        a.advance(2.0)
        b.advance(2.0)
    assert np.array_equal(a.speed, b.speed)
    # 4000 independent stationary samples: sd within 5 standard errors of the sd (~1.1 %).
    assert a.speed.std() == pytest.approx(2.0, rel=5 * 2 ** -0.5 / 4000 ** 0.5)
    assert a.speed.mean() == pytest.approx(15.0, abs=5 * 2.0 / 4000 ** 0.5)


# --- head wind: surge balance --------------------------------------------------------------------
def _tanker_surge_accel_per_mass(u, n_rps, h=1000.0):
    """tanker.m's gX at v = r = delta = 0 (Van Berlekom and Goddard 1972 terms), m/s^2 * m11."""
    t = tanker
    z = t.T / (h - t.T)
    gT = 1 / t.L * t.Tuu * u ** 2 + t.Tun * u * n_rps + t.L * t.Tnn * abs(n_rps) * n_rps
    return 1 / t.L * (t.Xuu * u ** 2 + t.L * gT * (1 - t.t) + t.Xuuz * u ** 2 * z)


def _head_wind_x(profile, u, V):
    # Blendermann CX(0) = -CDl_AF(bow); still air subtracted (ship_sim.environment.wind).
    cx = blendermann94(0.0, 1.0, profile.AFw, profile.ALw, profile.sH, profile.sL, profile.Loa,
                       profile.blendermann_type)[1]
    return 0.5 * RHO_AIR * cx * profile.AFw * ((u + V) ** 2 - u ** 2)


def test_head_wind_slows_the_tanker_by_the_predicted_amount():
    V = 20.0
    p = wind_profile('tanker')
    n = 80.0 / 60.0
    u_calm = brentq(lambda u: _tanker_surge_accel_per_mass(u, n), 1.0, 20.0, xtol=1e-12)
    u_wind = brentq(lambda u: _tanker_surge_accel_per_mass(u, n)
                    + _head_wind_x(p, u, V) / tanker.MASS, 1.0, 20.0, xtol=1e-12)
    # Captive surge run (sway and yaw held at 0: the tanker's thrust asymmetry YT, NT would
    # turn it out of the head wind with the rudder fixed): the model's surge equation with the
    # wind loads of ship_sim.environment.wind, integrated to steady state.
    m = make_model('tanker')
    x = m.initial_state()                                     # heading north, n = 80 rpm
    assert x[m.IU] == pytest.approx(u_calm, rel=1e-9)
    uin = m.inputs(0.0)
    for _ in range(12000):                                    # 6000 s >> surge time constant
        loads = wind_disturbance(p, x[m.IU], 0.0, 0.0, V, 0.0)
        x[m.IU] = m.step(x, uin, 0.5, loads=loads)[m.IU]
    assert x[m.IU] == pytest.approx(u_wind, abs=1e-6)
    assert u_calm - u_wind > 0.05        # a real slow-down, not rounding


def test_head_wind_slows_the_container_by_its_resistance_curve():
    # Net surge force without wind from the model's own surge equation, F(u) = m11 u_dot(u),
    # and the Blendermann head-wind force: the steady speed solves F(u) + X_wind(u) = 0.
    V = 20.0
    m = make_model('container')
    p = wind_profile('container')
    x0 = m.initial_state()
    mass11 = container.m11 * 0.5 * container.rho * container.L ** 3

    def net(u):
        x = x0.copy()
        x[m.IU] = u
        return mass11 * m.rhs(x, m.inputs(0.0, x0[m.IN]))[m.IU] + _head_wind_x(p, u, V)

    u_wind = brentq(net, 1.0, 15.0, xtol=1e-12)
    sim = VesselSimulator('container', dt=0.2, wind=WindField(V, 0.0))
    sim.run(0.0, 10000)
    assert sim.velocity_water()[0] == pytest.approx(u_wind, abs=1e-5)
    assert x0[m.IU] - u_wind > 0.05


# --- beam wind: sway drift balance ---------------------------------------------------------------
def test_tanker_drifts_downwind_to_the_sway_force_balance():
    """Captive drift (surge, yaw and rudder held, sway free, as in a towing tank): v settles
    where the tanker's sway damping terms balance the Blendermann sway force of the relative
    wind (still air subtracted). Free running, the tanker also yaws (the wind's yaw moment and
    its thrust asymmetry YT, NT), so there is no steady drift without a steering loop."""
    t, V = tanker, 15.0
    p = wind_profile('tanker')
    m = make_model('tanker')
    x0 = m.initial_state()                  # heading north at trim
    u0, n = x0[m.IU], x0[m.IN] / 60
    uin = m.inputs(0.0)
    z = t.T / (m.h - t.T)

    def wind_y(v):   # wind from the west (port beam): gamma = -atan2(v - V, u)
        def y(vr):
            g = -math.atan2(vr, u0)
            return blendermann94(g, math.hypot(u0, vr), p.AFw, p.ALw, p.sH, p.sL, p.Loa,
                                 p.blendermann_type)[0][1]
        return y(v - V) - y(v)

    def sway(v):     # tanker.m gY at r = delta = 0, times the mass, plus the wind
        gT = 1 / t.L * t.Tuu * u0 ** 2 + t.Tun * u0 * n + t.L * t.Tnn * abs(n) * n
        gY = 1 / t.L * (t.Yuv * u0 * v + t.Yvv * abs(v) * v + t.YT * gT * t.L
                        + t.Yvvz * abs(v) * v * z)
        return t.MASS * gY + wind_y(v)

    v_pred = brentq(sway, -2.0, 2.0, xtol=1e-13)
    v_calm = brentq(lambda v: sway(v) - wind_y(v), -2.0, 2.0, xtol=1e-13)

    def v_dot(v):                           # the model's sway equation, everything else held
        x = x0.copy()
        x[m.IV] = v
        loads = wind_disturbance(p, u0, v, 0.0, V, -math.pi / 2)
        return m.rhs(x, uin, loads=loads)[m.IV]

    v, h = 0.0, 0.5
    for _ in range(4000):                   # RK4 in v over 2000 s (sway time constant ~60 s)
        k1 = v_dot(v)
        k2 = v_dot(v + 0.5 * h * k1)
        k3 = v_dot(v + 0.5 * h * k2)
        k4 = v_dot(v + h * k3)
        v += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    assert v == pytest.approx(v_pred, abs=1e-9)
    assert v_pred - v_calm > 0.02           # drifts downwind (to starboard) by a real amount


@pytest.mark.parametrize('name', MSS_SHIPS)
def test_batched_wind_agrees_with_single_vessels(name):
    # Same equations on arrays and on floats; math.atan2 and numpy.arctan2 may differ in the
    # last bit, so the paths agree to rounding (not bit for bit, unlike calm air).
    psi = [0.3, 2.0, -2.5]
    singles = [VesselSimulator(name, psi=q, wind=WindField(17.0, 4.0)) for q in psi]
    batch = BatchSimulator(name, n=3, psi=np.array(psi), wind=WindField(17.0, 4.0))
    for k in range(200):
        batch.step(_rudder(k))
        for s in singles:
            s.step(_rudder(k))
    np.testing.assert_allclose(batch.state, [s.state for s in singles], rtol=1e-9, atol=1e-9)
    loads = batch.wind_loads()
    for i, s in enumerate(singles):
        np.testing.assert_allclose([c[i] for c in loads], s.wind_loads(), rtol=1e-9)


@pytest.mark.parametrize('coefficients', ['blendermann94', 'isherwood72'])
def test_float_path_of_the_wind_equals_the_array_path(coefficients):
    p = WIND_PROFILES['mariner']
    args = (7.0, 0.4, 0.5, 17.0, 4.0)
    f = wind_disturbance(p, *args, coefficients)
    a = wind_disturbance(p, *(np.array([x]) for x in args), coefficients)
    np.testing.assert_allclose(f, [c[0] for c in a], rtol=1e-12)
