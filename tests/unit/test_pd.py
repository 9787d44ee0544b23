"""PD heading autopilot, rudder shaping and the common controller interface.

Expected values are hand computed from Angelopoulos 2011 eqs. (15)-(20) / Simakis 1992 eqs. (2.13)-(2.16)
and the standard second-order step response (overshoot exp(-pi zeta / sqrt(1 - zeta^2)),
peak time pi / (omega_n sqrt(1 - zeta^2))). The plant is a linear first-order Nomoto model
written here: psi_dot = r, r_dot = a r + b delta (unified rudder, b < 0), rudder held over
each controller step.
"""
import math

import numpy as np
import pytest

from ship_autopilot.pd import PDAutopilot, nomoto_ab, pd_gains
from ship_autopilot.rudder import RudderLimiter, rate_limit, saturate

DEG = math.pi / 180.0


def nomoto_step(psi, r, delta, a, b, h):
    """Exact step of psi_dot = r, r_dot = a r + b delta with delta held (a != 0)."""
    e = math.exp(a * h)
    r_inf = -b * delta / a                      # steady yaw rate for this rudder
    r1 = r_inf + (r - r_inf) * e
    psi1 = psi + r_inf * h + (r - r_inf) * (e - 1.0) / a
    return psi1, r1


def closed_loop(ctrl, a, b, psi_c, t_end, dt, psi0=0.0, disturbance=0.0):
    psi, r = psi0, 0.0
    ctrl.reset()
    psis, deltas = [], []
    for _ in range(int(round(t_end / dt))):
        delta = ctrl.update(psi, r, psi_c, dt)
        psi, r = nomoto_step(psi, r, delta + disturbance, a, b, dt)
        psis.append(psi)
        deltas.append(delta)
    return np.array(psis), np.array(deltas)


# -- gains ------------------------------------------------------------------------------------
def test_pd_gains_hand_values():
    # a = -0.1, b = -0.02, wn = 0.2, zeta = 0.5: k1 = 0.04/0.02, k2 = -(-0.1 + 0.2)/(-0.02)
    k1, k2 = pd_gains(-0.1, -0.02, omega_n=0.2, zeta=0.5)
    assert k1 == pytest.approx(2.0, rel=1e-12)
    assert k2 == pytest.approx(5.0, rel=1e-12)
    # Nomoto K = 0.185 1/s, T = 107.3 s (Lee 2004 Table 4.1, first order): a = -1/T, b = -K/T.
    a, b = nomoto_ab(0.185, 107.3)
    assert (a, b) == pytest.approx((-1 / 107.3, -0.185 / 107.3))
    k1, k2 = pd_gains(a, b, omega_n=0.05, zeta=0.8)
    assert k1 == pytest.approx(0.05 ** 2 * 107.3 / 0.185, rel=1e-12)
    assert k2 == pytest.approx((2 * 0.8 * 0.05 * 107.3 - 1.0) / 0.185, rel=1e-12)


def test_pd_gains_reproduce_simakis_choice():
    # Simakis 1992 Ch. III: NPS AUV II, a' = -1.468, b' = -2.859 (eq. 2.11, time in L/U),
    # wn = 3.0, zeta = 0.8 give gains "about 3.2 and 1.2".
    k1, k2 = pd_gains(-1.468, -2.859, omega_n=3.0, zeta=0.8)
    assert k1 == pytest.approx(3.2, abs=0.1)
    assert k2 == pytest.approx(1.2, abs=0.1)


@pytest.mark.parametrize('args', [(-0.1, 0.0, 0.2, 0.5), (-0.1, -0.02, 0.0, 0.5),
                                  (-0.1, -0.02, 0.2, -0.1), (float('nan'), -0.02, 0.2, 0.5),
                                  (-0.1, -0.02, float('inf'), 0.5)])
def test_pd_gains_refuse_bad_arguments(args):
    with pytest.raises(ValueError):
        a, b, omega_n, zeta = args
        pd_gains(a, b, omega_n=omega_n, zeta=zeta)


# -- closed loop has the designed poles -------------------------------------------------------
@pytest.mark.parametrize('zeta', [0.3, 0.5, 0.7])
def test_closed_loop_step_has_designed_omega_n_and_zeta(zeta):
    a, b, wn = -0.1, -0.02, 0.2
    ctrl = PDAutopilot.from_nomoto(a, b, wn, zeta, RudderLimiter(np.pi / 2))
    step = 5 * DEG  # k1 * step = 2 * 5 deg: far from the 90 deg limit, the loop stays linear
    dt = 0.01
    t_end = 12.0 / (zeta * wn)  # envelope exp(-zeta wn t) down to 6e-6: settled
    psi, delta = closed_loop(ctrl, a, b, step, t_end, dt)
    assert np.max(np.abs(delta)) < 0.5 * np.pi / 2
    k_peak = int(np.argmax(psi))
    overshoot = psi[k_peak] / step - 1.0
    t_peak = (k_peak + 1) * dt
    expected = math.exp(-math.pi * zeta / math.sqrt(1 - zeta ** 2))
    assert overshoot == pytest.approx(expected, rel=0.02)
    # Fit zeta and omega_n back from the measured overshoot and peak time.
    ln_os = math.log(overshoot)
    zeta_fit = -ln_os / math.sqrt(math.pi ** 2 + ln_os ** 2)
    wn_fit = math.pi / (t_peak * math.sqrt(1 - zeta_fit ** 2))
    assert zeta_fit == pytest.approx(zeta, abs=0.01)
    assert wn_fit == pytest.approx(wn, rel=0.01)
    assert psi[-1] == pytest.approx(step, abs=1e-4 * step)


# -- rudder shaping -----------------------------------------------------------------------------
def test_saturation_forms():
    d = np.array([-1.0, -0.4, -0.1, 0.0, 0.1, 0.4, 1.0])
    assert saturate(d, 0.4, 'hard') == pytest.approx([-0.4, -0.4, -0.1, 0.0, 0.1, 0.4, 0.4])
    # Angelopoulos 2011 eq. (15): 0.4 tanh(d / 0.4); tanh(1) = 0.7615942, tanh(2.5) = 0.9866143.
    assert saturate(d, 0.4, 'tanh') == pytest.approx(
        [-0.4 * 0.9866143, -0.4 * 0.7615942, -0.4 * math.tanh(0.25), 0.0,
         0.4 * math.tanh(0.25), 0.4 * 0.7615942, 0.4 * 0.9866143], rel=1e-6)
    assert abs(saturate(1e-4, 0.4, 'tanh') - 1e-4) < 1e-11  # slope 1 at zero
    with pytest.raises(ValueError):
        saturate(0.1, 0.4, 'cubic')


def test_pd_output_uses_selected_saturation():
    k1, k2 = 2.0, 5.0
    e, r = 10 * DEG, 0.01  # raw command 2 * 0.1745 + 0.05 = 0.399 rad
    raw = k1 * e + k2 * r
    hard = PDAutopilot(k1, k2, RudderLimiter(0.3, shape='hard'))
    smooth = PDAutopilot(k1, k2, RudderLimiter(0.3, shape='tanh'))
    assert hard.update(e, r, 0.0, 0.1) == pytest.approx(0.3)
    assert smooth.update(e, r, 0.0, 0.1) == pytest.approx(0.3 * math.tanh(raw / 0.3))
    small = PDAutopilot(k1, k2, RudderLimiter(0.3))
    assert small.update(1 * DEG, 0.0, 0.0, 0.1) == pytest.approx(2 * DEG)  # linear inside


def test_rate_limit_function():
    assert rate_limit(0.5, 0.0, 0.1, 0.5) == pytest.approx(0.05)
    assert rate_limit(-0.5, 0.0, 0.1, 0.5) == pytest.approx(-0.05)
    assert rate_limit(0.02, 0.0, 0.1, 0.5) == pytest.approx(0.02)


def test_rate_and_angle_limits_hold_at_every_step():
    a, b = nomoto_ab(0.185, 107.3)
    max_angle, max_rate, dt = 20 * DEG, 2.33 * DEG, 0.1
    ctrl = PDAutopilot.from_nomoto(a, b, 0.05, 0.8, RudderLimiter(max_angle, max_rate))
    psi, delta = closed_loop(ctrl, a, b, 90 * DEG, 400.0, dt)
    steps = np.abs(np.diff(np.concatenate(([0.0], delta))))
    assert np.all(steps <= max_rate * dt * (1 + 1e-12))
    assert np.all(np.abs(delta) <= max_angle)
    # Both limits were actually reached, so the checks above had something to check.
    assert steps.max() == pytest.approx(max_rate * dt)
    assert np.abs(delta).max() == pytest.approx(max_angle)
    assert psi[-1] == pytest.approx(90 * DEG, abs=0.5 * DEG)


@pytest.mark.parametrize('bad', [dict(max_angle=0.0), dict(max_angle=2.0), dict(max_rate=-1.0),
                                 dict(max_angle=float('nan')), dict(shape='soft')])
def test_limiter_refuses_bad_parameters(bad):
    kw = dict(max_angle=0.4, max_rate=0.1, shape='hard')
    kw.update(bad)
    with pytest.raises(ValueError, match=next(iter(bad))):
        RudderLimiter(**kw)


# -- wrap-around --------------------------------------------------------------------------------
def test_command_across_pi_turns_the_short_way():
    a, b = nomoto_ab(0.185, 107.3)
    ctrl = PDAutopilot.from_nomoto(a, b, 0.05, 0.8, RudderLimiter(35 * DEG, 5 * DEG))
    # Heading 170 deg, command -170 deg (= 190 deg): 20 deg to starboard, not 340 to port.
    first = ctrl.update(170 * DEG, 0.0, -170 * DEG, 0.1)
    assert first < 0.0  # negative rudder turns to starboard (psi increasing)
    psi, _ = closed_loop(ctrl, a, b, -170 * DEG, 400.0, 0.1, psi0=170 * DEG)
    track = np.unwrap(np.concatenate(([170 * DEG], psi)))
    assert track.min() > 169 * DEG            # never turned to port
    assert track[-1] == pytest.approx(190 * DEG, abs=0.2 * DEG)


# -- interface: hold on bad input, batches ------------------------------------------------------
def test_non_finite_input_holds_previous_command():
    ctrl = PDAutopilot(2.0, 5.0, RudderLimiter(0.5, 0.1))
    d1 = ctrl.update(0.1, 0.0, 0.0, 0.5)
    for args in [(float('nan'), 0.0, 0.0, 0.5), (0.1, float('inf'), 0.0, 0.5),
                 (0.1, 0.0, float('nan'), 0.5), (0.1, 0.0, 0.0, 0.0), (0.1, 0.0, 0.0, -1.0),
                 (0.1, 0.0, 0.0, float('nan'))]:
        assert ctrl.update(*args) == d1
        assert not ctrl.last_ok
    assert ctrl.n_rejected == 6
    assert ctrl.update(0.1, 0.0, 0.0, 0.5) == pytest.approx(d1 + 0.05)  # rate limit resumes
    assert ctrl.last_ok


def test_batch_equals_scalar_runs_and_holds_per_element():
    lim = RudderLimiter(0.3, 0.05)
    batch = PDAutopilot(2.0, 5.0, lim)
    singles = [PDAutopilot(2.0, 5.0, lim) for _ in range(3)]
    psi = np.array([0.1, -0.2, 3.0])
    r = np.array([0.0, 0.01, -0.02])
    psi_c = np.array([0.0, 0.0, -3.0])
    for k in range(5):
        psi_k = psi.copy()
        if k == 2:
            psi_k[1] = np.nan
        out = batch.update(psi_k, r, psi_c, 1.0)
        ref = [s.update(p, ri, c, 1.0) for s, p, ri, c in zip(singles, psi_k, r, psi_c)]
        assert out == pytest.approx(ref)
    assert [s.n_rejected for s in singles] == [0, 1, 0]


def test_reset_sets_rate_limit_origin():
    ctrl = PDAutopilot(2.0, 0.0, RudderLimiter(0.5, 0.1))
    ctrl.reset(rudder=0.3)
    assert ctrl.update(0.0, 0.0, 0.0, 1.0) == pytest.approx(0.2)  # from 0.3 towards 0
