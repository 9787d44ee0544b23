"""ship_autopilot.steering: the interface the autopilot node feeds, both implementations."""
import math

import numpy as np
import pytest

from ship_autopilot.gains import build_autopilot
from ship_autopilot.steering import HeadingSteering, PolicySteering


def pd_steering():
    return HeadingSteering(build_autopilot('pd', {'k1': 2.0, 'k2': 30.0}, math.radians(35.0),
                                           math.radians(5.0)))


def test_heading_decode_converts_enu_yaw_and_refuses_non_finite():
    assert HeadingSteering.decode(math.pi / 2) == pytest.approx(0.0)   # north
    assert HeadingSteering.decode(0.0) == pytest.approx(math.pi / 2)   # east
    assert HeadingSteering.decode(math.nan) is None


def test_heading_steering_is_the_controller_with_dt_from_the_odometry_times():
    steer = pd_steering()
    ref = build_autopilot('pd', {'k1': 2.0, 'k2': 30.0}, math.radians(35.0), math.radians(5.0))
    for t, psi, r, psi_c in ((0.0, 0.1, 0.0, 0.0), (0.1, 0.1, 0.01, 0.0), (0.2, 0.09, 0.01, 0.2)):
        dt = 1e-9 if t == 0.0 else 0.1
        assert steer.update(t, psi, r, psi_c) == pytest.approx(float(ref.update(psi, r, psi_c, dt)))


def test_heading_steering_holds_the_previous_command_or_the_heading():
    steer = pd_steering()
    steer.update(0.0, 0.3, 0.0, None)            # no command yet: hold the heading
    assert steer.psi_c == 0.3
    steer.update(0.1, 0.3, 0.0, -0.2)
    steer.update(0.2, 0.3, 0.0, None)            # refused: hold -0.2
    assert steer.psi_c == -0.2
    assert steer.mode is None and steer.n_rejected == 0


def test_policy_decode_makes_a_wrong_length_state_invalid():
    assert PolicySteering.decode([1.0] * 9).shape == (9,)
    bad = PolicySteering.decode([1.0] * 4)
    assert bad.shape == (9,) and np.isnan(bad).all()


def test_policy_steering_holds_on_an_invalid_state():
    from ship_autopilot.learning.policy import LearnedSteering, load_policy
    steer = PolicySteering(LearnedSteering(load_policy('mariner')))
    assert steer.mode == 'policy'
    first = steer.update(0.0, 0.0, 0.0, np.zeros(9))
    assert math.isfinite(first)
    assert steer.update(0.1, 0.0, 0.0, None) == first    # no state: held, counted
    assert steer.n_rejected == 1 and steer.rejected_text == 'invalid path_state'
