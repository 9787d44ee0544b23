"""Ocean current in NED: constant, or slowly varying (first-order Gauss-Markov), and its effect.

Sources
- Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control* (2011), Sec. 8.3: the
  current enters the equations of motion as relative velocity nu_r = nu - nu_c; for an
  irrotational current constant in NED the rigid-body and hydrodynamic terms are written in
  nu_r only (Property 8.1), so the model's velocity states are velocities through the water and
  only the position kinematics see the current: eta_dot = R(psi) nu_r + [v_N, v_E, 0].
  The slowly varying speed is the first-order Gauss-Markov process V_dot + V/T = w of the same
  section, limited to [speed_min, speed_max].
- Lee 2004 eq. (4.30) (Fig. 4.8): current of mean speed V_c and direction beta in NED,
  v_N = V_c cos beta, v_E = V_c sin beta. Martinsen and Lekkas 2018 (Table I) uses a constant 0.9 m/s current.

Conventions: speed in m/s; ``direction`` (rad) is the direction the water flows TOWARDS,
clockwise from north (0 = flowing north, pi/2 = flowing east), as NED headings are. Note that
this is the opposite of the meteorological "coming from" convention.

Gauss-Markov part (when a time constant and a noise intensity are given), for speed V and
direction beta alike, with nominal value X0, time constant T (s) and white-noise intensity q
(spectral density, (m/s)^2/s for speed, rad^2/s for direction):
    X_dot = -(X - X0) / T + w,        E[w(t) w(t')] = q delta(t - t')
It is advanced with its exact discretisation (valid for any dt), so its stationary standard
deviation is sqrt(q T / 2) and its mean is X0. The speed is then clipped to
[speed_min, speed_max] (the bound makes the mean differ from X0 only if the bounds are not
symmetric about X0 and are reached). Random numbers come from numpy.random.default_rng(seed):
the same seed gives the same current, bit for bit.

Vectorised: with ``shape=(n,)`` the object holds n independent currents (one per vessel or
Monte Carlo run); ``velocity_ne()`` returns arrays of that shape.
"""
import math

import numpy as np


def _param(name, value, lo, hi, lo_open=False, array=False):
    """Float parameter check: ValueError naming the parameter, its value and the allowed range.
    ``array``: the value (and the bounds) may be arrays, checked element by element; a float
    comes back for a scalar, an array otherwise."""
    try:
        v = np.asarray(value, dtype=float) if array else float(value)
    except (TypeError, ValueError):
        raise ValueError(f'{name} = {value!r} is not a number') from None
    ok = np.atleast_1d(np.isfinite(v) & ((v > lo) if lo_open else (v >= lo)) & (v <= hi))
    if not ok.all():
        i = int(np.argmin(ok))       # the first element out of range

        def at(x):
            return np.broadcast_to(x, ok.shape).ravel()[i].item()
        shown = f'{at(v)!r} (element {i})' if np.ndim(v) else repr(value)
        raise ValueError(f"{name} = {shown} is outside the allowed range "
                         f"{'(' if lo_open else '['}{at(lo)}, {at(hi)}]")
    return float(v) if np.ndim(v) == 0 else v


class OceanCurrent:
    """Current velocity in NED, constant or Gauss-Markov in speed and direction.

    Parameters (SI): ``speed`` (m/s, [0, 10]); ``direction`` (rad, flowing towards, clockwise
    from north); ``speed_time_constant``, ``direction_time_constant`` (s, > 0, or None for a
    constant); ``speed_noise`` ((m/s)^2/s), ``direction_noise`` (rad^2/s) intensities (>= 0);
    ``speed_min``/``speed_max`` (m/s; default 0 and 2 * speed + 0.5 m/s); ``seed``; ``shape``.

    Batches (``shape=(n,)``): every parameter may be an array of that shape, one value per
    element, and ``seed`` one int per element (a stream each, ElementStreams), so that element
    i is, number for number, the current of shape (1,) with element i's parameters and seed:
    a batch of episodes each with the current its single-vessel run draws. An element draws
    from its stream for the speed (direction) whenever any element's speed (direction) varies,
    so that equality holds for elements whose speed and direction vary as the batch's do (or
    that vary in neither: a zero intensity keeps the value at its nominal exactly).
    """

    MAX_SPEED = 10.0

    def __init__(self, speed=0.0, direction=0.0, *, speed_time_constant=None, speed_noise=0.0,
                 direction_time_constant=None, direction_noise=0.0, speed_min=0.0,
                 speed_max=None, seed=None, shape=()):
        self.shape = tuple(shape)
        batch = self.shape != ()
        self.speed_nominal = _param('speed', speed, 0.0, self.MAX_SPEED, array=batch)
        self.direction_nominal = _param('direction', direction, -1e3, 1e3, array=batch)
        self.speed_min = _param('speed_min', speed_min, 0.0, self.speed_nominal, array=batch)
        if speed_max is None:
            speed_max = np.minimum(2.0 * self.speed_nominal + 0.5, self.MAX_SPEED)
        self.speed_max = _param('speed_max', speed_max, self.speed_nominal, self.MAX_SPEED,
                                array=batch)
        self.speed_noise = _param('speed_noise', speed_noise, 0.0, 100.0, array=batch)
        self.direction_noise = _param('direction_noise', direction_noise, 0.0, 100.0,
                                      array=batch)
        self.speed_time_constant = (None if speed_time_constant is None else
                                    _param('speed_time_constant', speed_time_constant,
                                           0.0, 1e7, lo_open=True, array=batch))
        self.direction_time_constant = (None if direction_time_constant is None else
                                        _param('direction_time_constant',
                                               direction_time_constant, 0.0, 1e7,
                                               lo_open=True, array=batch))
        self._rng = random_source(seed, self.shape)
        self.speed = np.full(self.shape, self.speed_nominal)
        self.direction = np.full(self.shape, self.direction_nominal)

    @classmethod
    def from_std(cls, speed, direction, speed_sd, direction_sd, time_constant, *, seed=None,
                 shape=()):
        """A Gauss-Markov current given the stationary standard deviations of its speed (m/s)
        and direction (rad) and one time constant (s) for both: intensities q = 2 sd^2 / T
        (the stationary sd is sqrt(q T / 2)). Arrays of ``shape`` or scalars, as __init__."""
        return cls(speed, direction, speed_time_constant=time_constant,
                   speed_noise=2.0 * np.square(speed_sd) / time_constant,
                   direction_time_constant=time_constant,
                   direction_noise=2.0 * np.square(direction_sd) / time_constant,
                   seed=seed, shape=shape)

    @property
    def _speed_varies(self):
        return self.speed_time_constant is not None and bool(np.any(self.speed_noise > 0.0))

    @property
    def _direction_varies(self):
        return (self.direction_time_constant is not None
                and bool(np.any(self.direction_noise > 0.0)))

    @property
    def varying(self):
        """True if advance() changes the current."""
        return self._speed_varies or self._direction_varies

    def velocity_ne(self):
        """Current velocity (v_north, v_east) in m/s, floats or arrays of ``shape``."""
        vn = self.speed * np.cos(self.direction)
        ve = self.speed * np.sin(self.direction)
        if self.shape == ():
            return float(vn), float(ve)
        return vn, ve

    def _gm_step(self, x, x0, tc, q, dt):
        return gauss_markov_step(x, x0, tc, q, dt, self._rng, self.shape)

    def advance(self, dt):
        """Advance the Gauss-Markov parts by dt seconds (no-op for a constant current)."""
        dt = _param('dt', dt, 0.0, 1e6)
        if dt == 0.0:
            return
        if self._speed_varies:
            s = self._gm_step(self.speed, self.speed_nominal, self.speed_time_constant,
                              self.speed_noise, dt)
            self.speed = np.clip(s, self.speed_min, self.speed_max)
        if self._direction_varies:
            self.direction = self._gm_step(self.direction, self.direction_nominal,
                                           self.direction_time_constant,
                                           self.direction_noise, dt)


class ElementStreams:
    """One random stream per element of a batch: ``seeds`` (one int per element) ->
    numpy.random.default_rng(seed) each; ``standard_normal(shape)`` draws one number from every
    stream. An element's numbers are then those of its own default_rng(seed) of shape (1,),
    whatever batch it sits in (a sweep's rows do not depend on the chunking).

    The streams are read ahead in blocks (one generator call per element every ``block``
    draws, not one per draw, which would be a Python call per vessel and step): numpy fills
    an array of normals one number after another, so a stream gives the same numbers in the
    same order either way. The generators are private: drawing from them otherwise would
    skip the numbers read ahead."""

    #: Numbers read ahead over the whole batch per refill (8 bytes each: 8 MB), at most 256 per
    #: stream: a refill is a Python call per element (~1 us), so it must be rare.
    READ_AHEAD = 1 << 20

    def __init__(self, seeds):
        self._generators = [np.random.default_rng(int(s)) for s in seeds]
        self.block = int(np.clip(self.READ_AHEAD // max(1, len(self._generators)), 1, 256))
        self._buffer = np.empty((0, len(self._generators)))
        self._next = 0

    def standard_normal(self, shape):
        if self._next == len(self._buffer):
            self._buffer = np.stack([g.standard_normal(self.block) for g in self._generators],
                                    axis=1)
            self._next = 0
        out = self._buffer[self._next]
        self._next += 1
        return out.reshape(shape)


def random_source(seed, shape):
    """numpy Generator of ``seed`` (None or an int), or ElementStreams for a sequence of
    seeds, one per element of ``shape``."""
    if seed is None or np.ndim(seed) == 0:
        return np.random.default_rng(seed)
    seeds = np.asarray(seed).ravel()
    if seeds.size != math.prod(shape):
        raise ValueError(f'{seeds.size} seeds given for shape {tuple(shape)}')
    return ElementStreams(seeds)


def gauss_markov_step(x, x0, tc, q, dt, rng, shape=()):
    """Exact discretisation over dt of X_dot = -(X - X0)/T + w, E[w w'] = q delta (see above).

    Shared by the current and the wind gusts (ship_sim.environment.wind); ``rng`` a numpy
    Generator (or ElementStreams), ``shape`` the shape of the independent processes.
    """
    phi = np.exp(-dt / tc)
    sd = np.sqrt(0.5 * q * tc * (1.0 - phi * phi))
    return x0 + phi * (x - x0) + sd * rng.standard_normal(shape)


def add_current_to_kinematics(model, xdot, v_north, v_east):
    """Model derivative through the water -> derivative over ground: add the current.

    ``xdot`` is ``model.rhs(x, u)`` (velocity states relative to the water, Fossen Sec. 8.3);
    the current (m/s, NED, floats or arrays broadcast over xdot's leading axes) is added to the
    north and east position rates. Returns a new array; xdot is not modified.
    """
    out = np.array(xdot, dtype=float, copy=True)
    out[..., model.IX] += v_north
    out[..., model.IY] += v_east
    return out


def apply_current_drift(model, x, v_north, v_east, h):
    """Shortcut for one integration step of length h (s) with the current held over the step.

    No model's derivative depends on its position, so integrating ``add_current_to_kinematics``
    with any Runge-Kutta scheme equals integrating the model alone and then adding
    (v_north, v_east) * h to the position; this returns that x (a new array).
    """
    out = np.array(x, dtype=float, copy=True)
    out[..., model.IX] += v_north * h
    out[..., model.IY] += v_east * h
    return out
