"""The steering interface the autopilot node feeds (pure): odometry + a command -> rudder.

    rudder = steering.update(t, psi, r, command)

``t``: sim time of the odometry (s); ``psi``, ``r``: NED heading (rad) and yaw rate (rad/s);
``command``: what the law steers by, decoded from its topic (``command_topic``) by
``decode(data)``, or None when there is none (hold: see each law). The returned rudder command
(rad, + turns to port) is always finite. ``n_rejected`` counts updates whose input was refused
(the rudder held; ``rejected_text`` names it for the log); ``mode`` names the law in charge
where it can change (``mode_text(command)`` says why, for the log).

Implementations:
- ``HeadingSteering``: a classical heading controller (ship_autopilot.controller: PD, fuzzy PID)
  on the guidance's heading command (NED, rad). A refused (non-finite) command or none at all
  holds the previous command, before the first one the vessel's heading.
- ``PolicySteering``: the learned policy on the guidance's 9-element path state
  (ship_autopilot.learning.policy.LearnedSteering, with its optional ILOS + PD recovery).
"""
import math

import numpy as np

from ship_sim.frames import yaw_to_psi


class HeadingSteering:
    """A HeadingController steering the NED heading command of ``heading_cmd``."""

    command_topic = 'heading_cmd'
    rejected_text = 'non-finite input'
    mode = None

    def __init__(self, controller):
        self.controller = controller
        self.psi_c = None       # the command steered last (NED, rad)
        self.t_prev = None

    @property
    def n_rejected(self):
        return self.controller.n_rejected

    @staticmethod
    def decode(data):
        """An ENU yaw command (rad) -> NED heading command; None if not finite (refused)."""
        return float(yaw_to_psi(data)) if math.isfinite(data) else None

    def update(self, t, psi, r, command):
        psi_c = command
        if psi_c is None:
            psi_c = self.psi_c if self.psi_c is not None else psi
        dt = 0.0 if self.t_prev is None else t - self.t_prev
        self.t_prev = t
        self.psi_c = psi_c
        # A first step (dt = 0) only initialises the rate limiter's memory.
        rudder = self.controller.update(psi, r, psi_c, dt if dt > 0.0 else 1e-9)
        return float(rudder) if math.isfinite(rudder) else 0.0


class PolicySteering:
    """A learned policy (LearnedSteering) steering by the path state of ``path_state``."""

    command_topic = 'path_state'
    rejected_text = 'invalid path_state'

    def __init__(self, learned):
        self.learned = learned

    @property
    def n_rejected(self):
        return self.learned.n_rejected

    @property
    def mode(self):
        return 'recovery' if self.learned.recovering else 'policy'

    @staticmethod
    def decode(data):
        """The state array; one of the wrong length counts as non-finite (the policy holds)."""
        state = np.asarray(data, dtype=float)
        return state if state.shape == (9,) else np.full(9, np.nan)

    def update(self, t, psi, r, command):
        state = command if command is not None else np.full(9, np.nan)
        return self.learned.update(state, t)

    def mode_text(self, command):
        return (f'cross-track {command[0]:.0f} m: '
                + ("outside the policy's training region, ILOS + PD steers"
                   if self.learned.recovering else 'the policy steers again'))
