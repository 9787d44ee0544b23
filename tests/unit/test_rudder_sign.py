"""Unified rudder sign, for every registered model: positive rudder turns the vessel to port.

From straight running (the model's own initial state, heading 0.7 rad), a rudder command of
+0.1 rad held for 5 ship lengths of travel must make the NED heading decrease (ENU yaw
increase) and move the vessel to the port side of its initial heading line; -0.1 rad the
opposite. The actual rudder (``rudder_angle``) must carry the command's sign. 0.1 rad is
inside every model's rudder limit and well above the mariner's straight-running offset
(about -1.1 deg, see reference/README.md).
"""

import numpy as np
import pytest

from ship_sim.frames import psi_to_yaw, wrap_angle
from ship_sim.integrators import rk4_step
from ship_sim.models import MODEL_NAMES, make_model

PSI0 = 0.7
CMD = 0.1


def build(name):
    # A card holds its model class, so every registered name can be built.
    return make_model(name)


@pytest.mark.parametrize('name', MODEL_NAMES)
def test_positive_rudder_turns_to_port(name):
    model = build(name)
    x0 = model.initial_state(north=10.0, east=-20.0, psi=PSI0)
    X = np.stack([x0, x0])                      # batch: +CMD and -CMD
    cmd = np.array([CMD, -CMD])
    shaft = None if not model.has_shaft else np.full(2, x0[model.IN])
    u = model.inputs(cmd, shaft)
    speed = model.surge_speed(x0)
    h = 0.1
    n = int(np.ceil(5.0 * model.length / speed / h))
    yaw = [psi_to_yaw(X[:, model.IPSI])]
    for _ in range(n):
        X = rk4_step(model.rhs, X, u, h)
        yaw.append(psi_to_yaw(X[:, model.IPSI]))
    model.check_state(X)
    yaw_change = np.sum(wrap_angle(np.diff(np.array(yaw), axis=0)), axis=0)   # unwrapped
    d_north, d_east = X[:, model.IX] - 10.0, X[:, model.IY] + 20.0
    starboard = -np.sin(PSI0) * d_north + np.cos(PSI0) * d_east  # along the initial starboard
    pos, neg = 0, 1
    assert yaw_change[pos] > 0.05 and yaw_change[neg] < -0.05, yaw_change
    assert starboard[pos] < 0 and starboard[neg] > 0, starboard
    rud = model.rudder_angle(X)
    assert rud[pos] > 0 and rud[neg] < 0, rud
