"""A toy vessel model with its card, kept outside ship_sim: test_vessel_card.py copies this file
into a temporary folder, registers the card there (register_card in the test process,
SHIPNAV_EXTRA_CARDS=toy_vessel for the node processes) and writes the toy's gain tables next
to it (the card's gain_tables is this module's folder).

T r_dot + r = -K delta in the unified rudder sign (positive turns to port), constant speed U:
a first-order Nomoto model, so the identification must give back its own K and T.
"""
from pathlib import Path

import numpy as np

from ship_sim.models.card import VesselCard
from ship_sim.models.constant_speed import ConstantSpeedModel, check_param


class Toy(ConstantSpeedModel):
    name = 'toy'
    source = 'test toy, made-up constants'
    state_names = ('u', 'v', 'r', 'north', 'east', 'psi', 'delta')
    state_units = ('m/s', 'm/s', 'rad/s', 'm', 'm', 'rad', 'rad')
    input_names = ('delta_c',)

    def __init__(self, *, K=0.1, T=30.0, U=6.0, length=100.0, rudder_max=np.deg2rad(35.0),
                 rudder_rate_max=np.deg2rad(5.0), rudder_time_constant=1.0):
        self.K = check_param('K', K, 0.0, 10.0, lo_open=True)
        self.T = check_param('T', T, 0.0, 1e4, lo_open=True)
        self.U = check_param('U', U, 0.0, 30.0)
        self.length = check_param('length', length, 0.0, 500.0, lo_open=True)
        self.rudder_max = check_param('rudder_max', rudder_max, 0.0, np.pi / 2, lo_open=True)
        self.rudder_rate_max = check_param('rudder_rate_max', rudder_rate_max, 0.0, 2 * np.pi,
                                           lo_open=True)
        self.rudder_time_constant = check_param('rudder_time_constant', rudder_time_constant,
                                                0.0, 60.0, lo_open=True)

    def rhs(self, x, u):
        x, u = np.asarray(x, dtype=float), np.asarray(u, dtype=float)
        xdot = np.zeros(np.broadcast_shapes(x.shape, u.shape[:-1] + x.shape[-1:]))
        speed, r, psi, delta = x[..., 0], x[..., 2], x[..., 5], x[..., 6]
        xdot[..., 2] = (-r - self.K * delta) / self.T
        xdot[..., 3] = speed * np.cos(psi)
        xdot[..., 4] = speed * np.sin(psi)
        xdot[..., 5] = r
        xdot[..., 6] = self._rudder_rate(delta, u[..., 0])
        return xdot


CARD = VesselCard(name='toy', model=Toy, node_kwargs={'nominal_speed_mps': 'U'}, kinds={'ship'},
                  gain_tables=str(Path(__file__).resolve().parent))
