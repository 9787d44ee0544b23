"""Why a PD autopilot keeps a steady heading error (Lee 2004 sec. 5.2, Figs. 5.7-5.18): the
hull's own constant yaw moment must be held by a constant rudder delta_hold, and the PD law
delta = k1 (psi - psi_c) + k2 r can only produce it from a heading error, so at rest (r = 0)
psi - psi_c = delta_hold / k1. Checked on the MSS Mariner and tanker in the closed loop with
our gain table's PD and with Lee 2004's own gains (Kp = 9, Kd = 70; Kp = 0.7, Kd = 25)."""
import math

import numpy as np
import pytest

from ship_autopilot.gains import autopilot_gains, build_autopilot, heading_loop_design
from ship_sim.maneuvers import course_keeping_trim
from ship_sim.models import make_model
from ship_sim.simulator import VesselSimulator

DT = 0.2        # control step of the seed scenarios (s); the model integrates at 0.1 s
STEP = math.radians(30.0)


def test_course_keeping_trim_holds_a_straight_course():
    # the trim's rudder, held open loop, keeps r = 0: no yaw acceleration, no drift of heading
    for name in ('mariner', 'tanker'):
        model = make_model(name)
        trim = course_keeping_trim(model)
        sim = VesselSimulator(model, dt=0.1, state=trim.state)
        for _ in range(2000):          # 200 s
            sim.step(trim.rudder)
        assert abs(sim.state[model.IR]) < 1e-9
        assert abs(sim.pose_ned()[2]) < 1e-7
        # the hull needs a rudder to go straight (Y0/N0, propeller side force): not zero
        assert abs(trim.rudder) > math.radians(0.1)
    # a symmetric hull (container: no constant moment) needs none
    assert course_keeping_trim(make_model('container')).rudder == pytest.approx(0.0, abs=1e-12)


def _steady_heading_error(name, k1, k2, t_end):
    """Closed loop: start from the trim on heading 0, command 30 deg to starboard, return the
    heading error psi - psi_c (NED, rad), yaw rate and rudder at t_end."""
    model = make_model(name)
    sim = VesselSimulator(model, dt=0.1, state=course_keeping_trim(model).state)
    ap = build_autopilot('pd', {'k1': k1, 'k2': k2}, model.rudder_max, model.rudder_rate_max)
    delta = 0.0
    for _ in range(int(round(t_end / DT))):
        psi, r = sim.pose_ned()[2], float(sim.state[model.IR])
        delta = float(ap.update(psi, r, STEP, DT))
        sim.step(delta)
        sim.step(delta)
    return sim.pose_ned()[2] - STEP, float(sim.state[model.IR]), delta


@pytest.mark.parametrize('name, gains', [
    ('mariner', 'table'), ('mariner', (9.0, 70.0)), ('tanker', 'table'), ('tanker', (0.7, 25.0))])
def test_pd_steady_heading_error_is_the_hold_rudder_over_k1(name, gains):
    k1, k2 = ((autopilot_gains(name)['pd']['k1'], autopilot_gains(name)['pd']['k2'])
              if gains == 'table' else gains)
    design = heading_loop_design(name, 'pd', k1, k2)
    # run 60 time constants of the design's envelope exp(-zeta omega_n t) past the step: its
    # leftover is e^-60 of the 30 deg step (~1e-27 rad); 1e-3 relative leaves room for hull
    # modes the Nomoto design does not see (sway) decaying up to ~7x slower than it
    t_end = 60.0 / (design.zeta * design.omega_n)
    e, r, delta = _steady_heading_error(name, k1, k2, t_end)
    hold = course_keeping_trim(make_model(name)).rudder
    assert r == pytest.approx(0.0, abs=1e-3 * abs(hold) / k2)
    assert delta == pytest.approx(hold, rel=1e-3)
    assert e == pytest.approx(hold / k1, rel=1e-3)


def test_lee_scaling_read_in_radians_cannot_hold_the_tanker_off_course():
    # Lee 2004 sec. 5.2.2's tanker scaling (L = 1/9, GE = 0.6, GR = 11.5, GA = 175, GU = 1/13),
    # read in radians as our fuzzy PID does: block 1's output is bounded by GU L, and the
    # integrator runs only within the error universe L / GE. Outside it (any course change
    # beyond ~10.6 deg) the rudder cannot exceed GU L, less than what the tanker needs just to
    # hold a straight course, so the tanker cannot turn towards the command.
    d = heading_loop_design('tanker', 'fuzzy_pid', fuzzy_ge=0.6, fuzzy_gr=11.5, fuzzy_ga=175.0,
                            fuzzy_gu=1 / 13, fuzzy_l=1 / 9)
    g = d.gains
    assert d.source == 'GE, GR, GA, GU' and d.zeta is None
    band = g['L'] / g['GE']
    assert math.radians(10.0) < band < STEP
    assert g['GU'] * g['L'] < abs(course_keeping_trim(make_model('tanker')).rudder)
    ap = build_autopilot('fuzzy_pid', g, math.radians(10.0))
    # 30 deg off (outside the band), turning the wrong way at any rate: never more than GU L
    for r in np.linspace(-0.01, 0.01, 21):
        ap.reset()
        assert abs(float(ap.update(-STEP, r, 0.0, DT))) <= g['GU'] * g['L'] * (1 + 1e-12)


def test_fuzzy_scaling_parameters_all_or_none():
    with pytest.raises(ValueError, match='all > 0'):
        heading_loop_design('mariner', 'fuzzy_pid', fuzzy_ge=2.75, fuzzy_gr=50.0)
    table = heading_loop_design('mariner', 'fuzzy_pid')
    assert table.source == 'gain table'
    lee = heading_loop_design('mariner', 'fuzzy_pid', fuzzy_ge=2.75, fuzzy_gr=50.0,
                              fuzzy_ga=500.0, fuzzy_gu=1 / 11)
    assert lee.gains == {'GE': 2.75, 'GR': 50.0, 'GA': 500.0, 'GU': 1 / 11, 'L': 1.0}
