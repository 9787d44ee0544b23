"""The path-following reward of Martinsen and Lekkas 2018, eq. 8 (pure numpy).

    r_k = a exp(-e_k^2 / (2 sigma^2)) [|wrap(psi_k - gamma_p,k)| <= psi_max]
          - c_delta ((delta_c,k - delta_c,k-1) / delta_max)^2

The Gaussian term alone is what their Table I accumulates: the training environment (learning.env)
and the run metrics (ros_ws/src/ship_mission/ship_mission/metrics.py) both score with ``gaussian_reward``. The choices
behind the rudder term and psi_max are in learning.env's docstring.
"""
import math

import numpy as np

from ship_sim.frames import wrap_angle


def gaussian_reward(cross_track, heading_rel, amplitude=1.0, sigma=10.0,
                    yaw_error_max=math.pi / 2):
    """Eq. 8's Gaussian term: a exp(-e^2 / (2 sigma^2)) where |wrap(psi - gamma_p)| <= psi_max,
    else 0. cross_track e and sigma in m, heading_rel psi - gamma_p in rad; broadcasting."""
    e = np.asarray(cross_track, dtype=float)
    g = amplitude * np.exp(-e ** 2 / (2.0 * sigma ** 2))
    return np.where(np.abs(wrap_angle(np.asarray(heading_rel, dtype=float))) <= yaw_error_max,
                    g, 0.0)[()]


def rudder_change_penalty(rudder_cmd, previous_cmd, rudder_max, weight):
    """Eq. 8's rudder-change term (as we read it): weight ((d_k - d_k-1) / rudder_max)^2."""
    change = (np.asarray(rudder_cmd, float) - np.asarray(previous_cmd, float)) / rudder_max
    return (weight * change * change)[()]
