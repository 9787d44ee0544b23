"""The one interface every plant model implements.

A model is a stateless description (parameters + equations); the state lives in arrays owned
by the caller, so one model object serves one vessel or ten thousand (leading batch axes).

Conventions (see ship_sim.frames):
- State and equations are the model's own, in NED/FRD as in its source (e.g. MSS). The indices
  IU, IV, IR, IX, IY, IPSI, IDELTA locate the quantities every model has; IN locates the shaft
  speed (rpm) for models with a shaft, else None.
- ``rhs(x, u)`` is the source's derivative function, unchanged in meaning and sign (it is
  tested against the original MSS functions), batched over leading axes of x and u.
- The rudder sign is unified at this boundary: ``inputs(rudder_cmd, shaft_cmd)`` takes the
  project's rudder command (rad, positive turns the vessel to port) and returns the model's
  native input vector; ``rudder_angle(x)`` returns the actual rudder in the same unified sign.
- Ocean current enters as relative velocity (Fossen): the velocity states are velocities
  relative to the water, and the simulator adds the current to the position kinematics.
"""
from abc import ABC, abstractmethod

import numpy as np


class ModelStateError(ValueError):
    """Raised when a state or input is outside the domain where a model's equations hold."""


class VesselModel(ABC):
    """Base class of all plant models. Subclasses set the class attributes and implement rhs."""

    #: Registry name (``model`` parameter of the vessel node).
    name: str = ''
    #: Names of the state components, in order, with units in ``state_units``.
    state_names: tuple = ()
    state_units: tuple = ()
    #: Names of the native inputs, in order.
    input_names: tuple = ()
    #: Indices of the common quantities in the state vector.
    IU = 0
    IV = 1
    IR = 2
    IX = 3
    IY = 4
    IPSI = 5
    IDELTA = 6
    IN = None
    #: Native rudder input = RUDDER_SIGN * unified rudder command (unified: + turns to port).
    RUDDER_SIGN = 1.0
    #: Actual unified rudder angle = STATE_RUDDER_SIGN * x[IDELTA].
    STATE_RUDDER_SIGN = 1.0

    # Limits, SI (rad, rad/s, rpm); subclasses override, instances may override per vessel.
    rudder_max = np.deg2rad(35.0)
    rudder_rate_max = np.deg2rad(5.0)
    shaft_min = None
    shaft_max = None
    #: Length between perpendiculars (m), used e.g. for look-ahead in ship lengths.
    length = 1.0
    #: Source of the equations and parameters, for the docs and the node's start-up log.
    source = ''
    #: True if rhs/step take external loads ``loads`` = (X, Y, K, N) (ship_sim.models.mss_ship).
    takes_external_loads = False

    @property
    def n_states(self):
        return len(self.state_names)

    @property
    def n_inputs(self):
        return len(self.input_names)

    @property
    def has_shaft(self):
        return self.IN is not None

    @abstractmethod
    def rhs(self, x, u):
        """Native state derivative: x (..., n_states), u (..., n_inputs) -> xdot like x."""

    @abstractmethod
    def inputs(self, rudder_cmd, shaft_cmd=None):
        """Unified commands (rudder rad, port positive; shaft rpm) -> native input array."""

    def rudder_angle(self, x):
        """Actual rudder angle (rad), unified sign (positive turns to port)."""
        return self.STATE_RUDDER_SIGN * np.asarray(x)[..., self.IDELTA]

    def surge_speed(self, x):
        """Total surge speed through the water (m/s)."""
        return np.asarray(x)[..., self.IU]

    def speed(self, x):
        """Speed through the water U = sqrt(surge^2 + v^2) (m/s), as MSS returns it; every
        model has both in its state (the sweeps and the learning environment ask for it)."""
        return np.hypot(self.surge_speed(x), np.asarray(x)[..., self.IV])

    @abstractmethod
    def initial_state(self, speed=None, north=0.0, east=0.0, psi=0.0, shaft=None):
        """State for straight running at ``speed`` (m/s, model default if None) at a pose (NED)."""

    def check_state(self, x, u=None):
        """Raise ModelStateError if x or u is outside the model's valid domain. Default: finite."""
        if not np.all(np.isfinite(x)):
            raise ModelStateError(f'{self.name}: state is not finite: {x}')
