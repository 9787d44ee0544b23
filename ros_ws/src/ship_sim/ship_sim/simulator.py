"""Vessel simulators without ROS: one vessel (VesselSimulator) or N of one model (BatchSimulator).

A simulator owns a plant model (ship_sim.models), its state, a fixed integration step dt (s),
an optional ocean current (ship_sim.current.OceanCurrent), an optional wind
(ship_sim.environment.wind.WindField) and the sim time. One ``step``:

1. checks the commands: non-finite values raise ValueError (the state is never touched by
   them); the rudder command (rad, unified sign: positive turns to PORT, doc/design.md) is
   saturated at the model's ``rudder_max`` (a per-vessel override is given to the model when
   it is built, e.g. ``make_model('mariner', rudder_max=...)``); the shaft command (rpm, models
   with a shaft) at [shaft_min, shaft_max]; it is held until the next shaft command;
2. integrates the model one step of dt with the inputs held (MSS rk4.m: ``model.step`` where
   the model provides its fast path, else ship_sim.integrators.rk4_step on ``model.rhs``);
   with wind, the wind loads (X, Y, K, N) at the start of the step (relative wind from the
   velocity over ground, ship_sim.environment.wind.wind_disturbance) are held over the step
   like the inputs and enter the model's own force equations (``loads``,
   ship_sim.models.mss_ship); without wind the step is the same computation as before wind
   existed, and a calm WindField (speed 0, no gusts) gives loads of exactly 0.0;
3. adds the current's drift to the position: the model's velocity states are relative to the
   water and no model's derivative depends on its position, so this equals integrating the
   kinematics with the current added (Fossen 2011, Sec. 8.3; ship_sim.current), held over the
   step; then the current and the wind are advanced by dt (Gauss-Markov parts);
4. refuses a result outside the model's domain (``model.check_state`` -> ModelStateError; the
   previous state is kept), so bad numbers never enter the state.

Both classes share that one implementation (``_SimulatorCore._advance``); they differ only in
the shape of the state ((n,) or (N, n)) and in what the accessors return (floats or arrays).

Accessors (NED / FRD, SI units, angles in rad, heading wrapped to [-pi, pi)):
``t``, ``pose_ned()``, ``velocity_water()`` (u, v, r through the water; u is the total surge
speed), ``velocity_ground()`` (u, v, r over ground: water-relative velocity plus the current
rotated into the body frame), ``rudder()`` (actual rudder angle, unified sign),
``rudder_command`` (the saturated command in use), ``shaft()`` (rpm or None), and
``nav_state()`` = (t, north, east, psi, u_g, v_g, r), the content of an Odometry message.

Sim time is t0 + k dt with an integer step counter k, so it never accumulates rounding.
"""
import math

import numpy as np

from .environment.wind import wind_disturbance, wind_loads, wind_profile
from .frames import wrap_angle
from .integrators import rk4_step
from .models import VesselModel, make_model, model_names


def _model_from(model, model_params):
    if isinstance(model, VesselModel):
        if model_params:
            raise ValueError('model parameters are given to make_model, not with a built model')
        return model
    return make_model(model, **model_params)


class _SimulatorCore:
    """What both simulators share: commands, one integration step, current, time, checks."""

    def __init__(self, model, state, dt, current, shaft_cmd, t0, wind=None,
                 wind_coefficients='blendermann94'):
        dt = float(dt)
        if not (math.isfinite(dt) and dt > 0.0):
            raise ValueError(f'dt = {dt!r} s is not allowed: a finite step > 0')
        self.model = model
        self.dt = dt
        self.t0 = float(t0)
        self.k = 0
        self.current = current
        state = np.array(state, dtype=float)
        if state.shape[-1:] != (model.n_states,):
            raise ValueError(f'{model.name}: state must end in {model.n_states} components, '
                             f'got shape {state.shape}')
        model.check_state(state)
        self.x = state
        m = model
        self._rudder_max = float(m.rudder_max)
        # Shaft: the command starts at the given default, else at the state's shaft speed.
        if m.has_shaft:
            s = state[..., m.IN] if shaft_cmd is None else shaft_cmd
            self.shaft_command = self._check_shaft(s)
        else:
            if shaft_cmd is not None:
                raise ValueError(f'{m.name} has no shaft (got shaft_cmd={shaft_cmd!r})')
            self.shaft_command = None
        self.rudder_command = self._zeros_like_batch(0.0)
        # The integration kernel: the model's own step (float fast path for one vessel) or RK4.
        step = getattr(m, 'step', None)
        self._integrate = step if step is not None else (lambda x, u, h: rk4_step(m.rhs, x, u, h))
        self.wind = wind
        self.wind_coefficients = wind_coefficients
        if wind is not None:
            if not m.takes_external_loads:
                raise ValueError(f'wind: model {m.name!r} takes no external loads; use one of '
                                 f"{', '.join(model_names('wind'))}")
            self.wind_profile = wind_profile(m.name)
            wind_loads(self.wind_profile, 1.0, 0.0, wind_coefficients)   # checks the name

    # -- commands ------------------------------------------------------------------------------
    def _zeros_like_batch(self, value):
        return float(value) if self.x.ndim == 1 else np.full(self.x.shape[:-1], float(value))

    def _check_finite(self, name, value):
        if self.x.ndim == 1:
            try:
                v = float(value)
            except (TypeError, ValueError):
                raise ValueError(f'{name} = {value!r} is not a number') from None
            if not math.isfinite(v):
                raise ValueError(f'{name} = {v!r} refused: not finite')
            return v
        v = np.broadcast_to(np.asarray(value, dtype=float), self.x.shape[:-1])
        bad = ~np.isfinite(v)
        if bad.any():
            idx = np.flatnonzero(bad)
            raise ValueError(f'{name} refused: not finite for vessel(s) {idx[:10].tolist()}')
        return v

    def _saturate(self, v, lo, hi):
        if self.x.ndim == 1:
            return lo if v < lo else hi if v > hi else v
        return np.clip(v, lo, hi)

    def _check_rudder(self, rudder_cmd):
        v = self._check_finite('rudder_cmd', rudder_cmd)
        return self._saturate(v, -self._rudder_max, self._rudder_max)

    def _check_shaft(self, shaft_cmd):
        m = self.model
        v = self._check_finite('shaft_cmd', shaft_cmd)
        lo = -math.inf if m.shaft_min is None else m.shaft_min
        hi = math.inf if m.shaft_max is None else m.shaft_max
        return self._saturate(v, lo, hi)

    # -- stepping ------------------------------------------------------------------------------
    def _advance(self, rudder_cmd, shaft_cmd):
        """One step of dt; returns nothing. Raises ValueError / ModelStateError, state kept."""
        m = self.model
        rudder = self._check_rudder(rudder_cmd)
        shaft = self.shaft_command
        if shaft_cmd is not None:
            if not m.has_shaft:
                raise ValueError(f'{m.name} has no shaft (got shaft_cmd={shaft_cmd!r})')
            shaft = self._check_shaft(shaft_cmd)
        u = m.inputs(rudder, shaft)
        if self.wind is None:
            x = self._integrate(self.x, u, self.dt)
        else:
            x = m.step(self.x, u, self.dt, loads=self.wind_loads())
        c = self.current
        if c is not None:
            vn, ve = c.velocity_ne()
            # Drift over the step with the current held (see the module docstring).
            x[..., m.IX] += vn * self.dt
            x[..., m.IY] += ve * self.dt
        m.check_state(x)
        # Accepted: commit state, commands, current and time together.
        self.x = x
        self.rudder_command = rudder
        self.shaft_command = shaft
        if c is not None:
            c.advance(self.dt)
        if self.wind is not None:
            self.wind.advance(self.dt)
        self.k += 1

    def step(self, rudder_cmd, shaft_cmd=None):
        """Advance one step dt with the rudder command (rad, + to port) and optional shaft (rpm).

        Returns self (so ``sim.step(d).pose_ned()`` reads naturally).
        """
        self._advance(rudder_cmd, shaft_cmd)
        return self

    def run(self, rudder_cmd, n, shaft_cmd=None):
        """``n`` steps with the same commands; returns self."""
        for _ in range(int(n)):
            self._advance(rudder_cmd, shaft_cmd)
        return self

    # -- accessors shared by both (arrays; VesselSimulator returns floats) ------------------------
    @property
    def t(self):
        """Sim time (s)."""
        return self.t0 + self.k * self.dt

    @property
    def state(self):
        """The model's native state (do not modify it in place)."""
        return self.x

    def wind_loads(self):
        """Wind loads (X, Y, K, N) in N, N m on the present state: the relative wind's minus
        still air's (ship_sim.environment.wind.wind_disturbance); zeros without wind."""
        if self.wind is None:
            return (self._zeros_like_batch(0.0), ) * 4
        u, v, _ = self.velocity_ground()
        psi, speed = self.x[..., self.model.IPSI], self.wind.speed
        if self.x.ndim == 1:   # Python floats: the float path of wind_disturbance
            psi, speed = float(psi), float(speed)
        return wind_disturbance(self.wind_profile, u, v, psi, speed, self.wind.direction_from,
                                self.wind_coefficients)

    def _current_ne(self):
        if self.current is None:
            return 0.0, 0.0
        return self.current.velocity_ne()

    def _pose(self):
        m, x = self.model, self.x
        return x[..., m.IX], x[..., m.IY], wrap_angle(x[..., m.IPSI])

    def _velocity_water(self):
        m, x = self.model, self.x
        return m.surge_speed(x), x[..., m.IV], x[..., m.IR]

    def _velocity_ground(self):
        u, v, r = self._velocity_water()
        vn, ve = self._current_ne()
        if self.current is None:
            return u, v, r
        psi = self.x[..., self.model.IPSI]
        c, s = np.cos(psi), np.sin(psi)
        # Current (NED) rotated into the body frame: R(psi)^T [vn, ve].
        return u + c * vn + s * ve, v - s * vn + c * ve, r


class VesselSimulator(_SimulatorCore):
    """One vessel. Accessors return Python floats.

    ``model``: a VesselModel or a registry name (then ``model_params`` go to make_model).
    ``state``: the model's native state; default ``model.initial_state(speed, north, east,
    psi, shaft)`` (straight running; NED, rad). ``shaft_cmd``: the held shaft command (rpm)
    until ``step`` gets one (default: the state's shaft speed). ``current``: an OceanCurrent
    with shape () or None. ``wind``: a WindField with shape () or None (MSS ships only), with
    ``wind_coefficients`` 'blendermann94' or 'isherwood72'.
    """

    def __init__(self, model, *, dt=0.1, state=None, north=0.0, east=0.0, psi=0.0, speed=None,
                 shaft=None, shaft_cmd=None, current=None, t0=0.0, model_params=None,
                 wind=None, wind_coefficients='blendermann94'):
        model = _model_from(model, model_params or {})
        if state is None:
            state = model.initial_state(speed=speed, north=north, east=east, psi=psi,
                                        shaft=shaft)
        state = np.asarray(state, dtype=float)
        if state.ndim != 1:
            raise ValueError(f'VesselSimulator takes one state vector, got shape {state.shape}; '
                             'use BatchSimulator for many')
        if current is not None and getattr(current, 'shape', ()) != ():
            raise ValueError('VesselSimulator needs a current of shape ()')
        if wind is not None and wind.shape != ():
            raise ValueError('VesselSimulator needs a wind of shape ()')
        super().__init__(model, state, dt, current, shaft_cmd, t0, wind, wind_coefficients)

    def pose_ned(self):
        """(north, east, psi): m, m, rad in [-pi, pi)."""
        # Python floats, not numpy scalars: the nodes read this every step, and floats are cheaper.
        m, x = self.model, self.x
        return float(x[m.IX]), float(x[m.IY]), wrap_angle(float(x[m.IPSI]))

    def velocity_water(self):
        """(u, v, r) body FRD relative to the water: m/s, m/s, rad/s (u = total surge)."""
        u, v, r = self._velocity_water()
        return float(u), float(v), float(r)

    def velocity_ground(self):
        """(u, v, r) body FRD over ground: m/s, m/s, rad/s."""
        u, v, r = self.velocity_water()
        if self.current is None:
            return u, v, r
        # _velocity_ground on floats (see there).
        vn, ve = self.current.velocity_ne()
        psi = float(self.x[self.model.IPSI])
        c, s = math.cos(psi), math.sin(psi)
        return u + c * vn + s * ve, v - s * vn + c * ve, r

    def rudder(self):
        """Actual rudder angle (rad), unified sign (positive turns to port)."""
        return float(self.model.rudder_angle(self.x))

    def shaft(self):
        """Actual shaft speed (rpm), or None for models without a shaft."""
        return float(self.x[self.model.IN]) if self.model.has_shaft else None

    def speed_water(self):
        """Speed through the water sqrt(u^2 + v^2) (m/s)."""
        u, v, _ = self._velocity_water()
        return math.hypot(u, v)

    def nav_state(self):
        """(t, north, east, psi, u_g, v_g, r): what an Odometry message carries (NED / FRD)."""
        n, e, psi = self.pose_ned()
        u, v, r = self.velocity_ground()
        return self.t, n, e, psi, u, v, r


class BatchSimulator(_SimulatorCore):
    """N vessels of one model, stepped together (Monte Carlo, reinforcement learning).

    ``states``: (N, n_states) native states, or None with ``n`` vessels built from
    ``model.initial_state`` with per-vessel ``north``, ``east``, ``psi`` (scalars or length-N
    arrays) and one ``speed`` / ``shaft``. Commands to ``step`` are scalars (same for all) or
    length-N arrays. ``current``: an OceanCurrent of shape (N,) (independent currents) or ()
    (one current shared by all), or None; ``wind``: a WindField likewise, with
    ``wind_coefficients``. Accessors return length-N arrays.
    """

    def __init__(self, model, *, dt=0.1, states=None, n=None, north=0.0, east=0.0, psi=0.0,
                 speed=None, shaft=None, shaft_cmd=None, current=None, t0=0.0,
                 model_params=None, wind=None, wind_coefficients='blendermann94'):
        model = _model_from(model, model_params or {})
        if states is None:
            if n is None:
                raise ValueError('give states (N, n_states) or the number of vessels n')
            n = int(n)
            x0 = model.initial_state(speed=speed, shaft=shaft)
            states = np.repeat(x0[None, :], n, axis=0)
            states[:, model.IX] = north
            states[:, model.IY] = east
            states[:, model.IPSI] = psi
        states = np.asarray(states, dtype=float)
        if states.ndim != 2:
            raise ValueError(f'BatchSimulator takes states of shape (N, n_states), '
                             f'got {states.shape}')
        if current is not None and getattr(current, 'shape', ()) not in ((), states.shape[:1]):
            raise ValueError(f'current shape {current.shape} does not match {states.shape[0]} '
                             'vessels')
        if wind is not None and wind.shape not in ((), states.shape[:1]):
            raise ValueError(f'wind shape {wind.shape} does not match {states.shape[0]} vessels')
        super().__init__(model, states, dt, current, shaft_cmd, t0, wind, wind_coefficients)

    @property
    def n(self):
        """Number of vessels."""
        return self.x.shape[0]

    def pose_ned(self):
        """(north, east, psi) arrays (m, m, rad in [-pi, pi))."""
        return self._pose()

    def velocity_water(self):
        """(u, v, r) arrays, body FRD relative to the water (u = total surge)."""
        u, v, r = self._velocity_water()
        return np.asarray(u), v, r

    def velocity_ground(self):
        """(u, v, r) arrays, body FRD over ground."""
        u, v, r = self._velocity_ground()
        return np.asarray(u), np.asarray(v), r

    def rudder(self):
        """Actual rudder angles (rad), unified sign."""
        return self.model.rudder_angle(self.x)

    def shaft(self):
        """Shaft speeds (rpm), or None."""
        return self.x[:, self.model.IN] if self.model.has_shaft else None

    def speed_water(self):
        u, v, _ = self._velocity_water()
        return np.hypot(u, v)

    def nav_state(self):
        """(t, north, east, psi, u_g, v_g, r), arrays except t."""
        n, e, psi = self.pose_ned()
        u, v, r = self.velocity_ground()
        return self.t, n, e, psi, u, v, r
