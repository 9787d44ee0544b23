"""Wind field, relative wind and the wind loads on the MSS ships.

Wind field (``WindField``): mean speed V (m/s, at the height the coefficients assume) and the
direction it blows FROM (meteorological convention, rad clockwise from north: 0 = a north wind,
which blows towards the south), optionally with slowly varying gusts: the speed follows the
first-order Gauss-Markov process of ship_sim.current (Fossen 2021, Ch. 10.1, "wind speed
variations"), stationary standard deviation ``gust_sd`` and time constant ``time_constant``,
clipped at 0, from numpy.random.default_rng(seed) (same seed, same wind, bit for bit).

Relative wind (Fossen 2021, Ch. 10.1): the wind velocity in the body frame is
u_w = V cos(beta - psi), v_w = V sin(beta - psi) with beta = direction_from + pi the direction
it blows towards; with the ship's velocity over ground (u, v), u_rw = u - u_w, v_rw = v - v_w,
V_rw = sqrt(u_rw^2 + v_rw^2) and gamma_rw = -atan2(v_rw, u_rw) (0 = wind from ahead, + = from
port: the sway force is then positive, to starboard).

Loads (``wind_loads``): (X, Y, K, N) in the body frame from the ship's ``WindProfile``
(projected areas and lengths, doc/results/wind_waves.md) and the coefficients of
ship_sim.environment.wind_coefficients:
- 'blendermann94' (default; the ship's Blendermann type; gives the roll moment K): evaluated at
  |gamma_rw| and mirrored (Y, K, N odd in gamma_rw, X even). This knowingly departs from MSS,
  whose CN term -0.18 (gamma_r - pi/2) is not mirror-symmetric and would give a wind from
  starboard a yaw moment unlike the mirror image of the same wind from port.
- 'isherwood72': gamma_rw wrapped into [-pi, pi] before the call (so the MSS sign quirk at
  angles above 180 deg never applies); K = 0 (the method has none).

What the plants get (``wind_disturbance``) is the load of the relative wind MINUS the load of
still air at the same ship velocity: the air drag of the ship's own motion is taken to be part
of each model's resistance as identified (the MSS trims are those of calm air), so a calm day
leaves every model exactly as it was (the difference is 0.0), and the loads grow continuously
from zero wind speed.
"""
import math

import numpy as np

from ..current import _param, gauss_markov_step, random_source
from ..models.math_backends import ARRAY_OPS, FLOAT_OPS
from .wind_profile import WindProfile  # noqa: F401 (re-exported)
from .wind_coefficients import (blendermann94_roll, blendermann94_terms, blendermann_row,
                                isherwood72)

COEFFICIENTS = ('blendermann94', 'isherwood72')


def _wind_cards():
    from ..models import cards
    return {c.name: c.wind for c in cards() if c.has_wind}


def __getattr__(name):
    # WIND_PROFILES: model name -> WindProfile of the registered cards (read at each access, so
    # a card registered later is included); the profiles themselves live on the cards.
    if name == 'WIND_PROFILES':
        return _wind_cards()
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')


def wind_profile(model_name):
    """The WindProfile of a plant model by name; ValueError naming the models that have one."""
    profiles = _wind_cards()
    try:
        return profiles[model_name]
    except KeyError:
        raise ValueError(f'wind: model {model_name!r} has no wind profile; allowed: '
                         f"{', '.join(profiles)}") from None


class WindField:
    """Wind of mean ``speed`` (m/s) from ``direction_from`` (rad, clockwise from north).

    ``gust_sd`` (m/s) > 0 with ``time_constant`` (s) makes the speed a Gauss-Markov process
    (module docstring); ``seed`` its random stream; ``shape`` independent fields (batches);
    ``seed`` may also be one int per element of ``shape`` (a stream each: ElementStreams).
    """

    MAX_SPEED = 60.0

    def __init__(self, speed=0.0, direction_from=0.0, *, gust_sd=0.0, time_constant=60.0,
                 seed=None, shape=()):
        self.shape = tuple(shape)
        self.speed_nominal = _param('wind speed', speed, 0.0, self.MAX_SPEED)
        self.direction_from = _param('wind direction', direction_from, -1e3, 1e3)
        self.gust_sd = _param('wind gust_sd', gust_sd, 0.0, 30.0)
        self.time_constant = _param('wind time_constant', time_constant, 0.0, 1e7,
                                    lo_open=True)
        self._rng = random_source(seed, self.shape)
        self.speed = np.full(self.shape, self.speed_nominal)

    @property
    def varying(self):
        """True if advance() changes the wind."""
        return self.gust_sd > 0.0

    def advance(self, dt):
        """Advance the gusts by dt seconds (no-op without gusts)."""
        dt = _param('dt', dt, 0.0, 1e6)
        if dt == 0.0 or not self.varying:
            return
        q = 2.0 * self.gust_sd ** 2 / self.time_constant   # stationary sd = gust_sd
        s = gauss_markov_step(self.speed, self.speed_nominal, self.time_constant, q, dt,
                              self._rng, self.shape)
        self.speed = np.maximum(s, 0.0)

    def describe(self):
        """One line for logs: speed, direction and gusts."""
        text = f'{self.speed_nominal:g} m/s from {math.degrees(self.direction_from):g} deg'
        if self.varying:
            text += f' (gust sd {self.gust_sd:g} m/s, T {self.time_constant:g} s)'
        return text


def _relative_wind(ops, u, v, psi, speed, direction_from):
    rel = direction_from - psi
    u_rw = u + speed * ops.cos(rel)    # u - u_w with u_w = V cos(direction_from + pi - psi)
    v_rw = v + speed * ops.sin(rel)
    return ops.hypot(u_rw, v_rw), -ops.atan2(v_rw, u_rw)


def relative_wind(u, v, psi, speed, direction_from):
    """(V_rw, gamma_rw): relative wind speed (m/s) and angle (rad, 0 = from ahead, + from port).

    u, v: body velocity over ground (m/s); psi heading (rad); speed, direction_from the wind
    (m/s, rad clockwise from north, where it comes from). Arrays broadcast.
    """
    return _relative_wind(ARRAY_OPS, u, v, psi, speed, direction_from)


def _loads(ops, p, V_rw, gamma, coefficients):
    # gamma in [-pi, pi] (relative_wind gives that; wind_loads wraps other angles).
    if coefficients == 'blendermann94':
        sign = ops.sign(gamma)
        X, Y, N, _, _, CK, _ = blendermann94_terms(ops, abs(gamma), V_rw, p.AFw, p.ALw, p.sH,
                                                   p.sL, p.Loa, blendermann_row(p.blendermann_type))
        return X, sign * Y, sign * blendermann94_roll(CK, V_rw, p.ALw, p.Loa), sign * N
    if coefficients == 'isherwood72':
        tau = isherwood72(gamma, V_rw, p.Loa, p.B, p.ALw, p.AFw, p.A_SS, p.S, p.C, p.M)[0]
        return tau[..., 0], tau[..., 1], 0.0 * tau[..., 0], tau[..., 2]
    raise ValueError(f'wind coefficients = {coefficients!r}; allowed: {", ".join(COEFFICIENTS)}')


def wind_loads(profile, V_rw, gamma_rw, coefficients='blendermann94'):
    """Body-frame wind loads (X, Y, K, N) in N and N m of a WindProfile (module docstring)."""
    g = np.asarray(gamma_rw, dtype=float)
    # Angles outside [-pi, pi] wrapped into it; the others untouched (bit for bit).
    g = np.where(np.abs(g) > math.pi, np.arctan2(np.sin(g), np.cos(g)), g)
    return _loads(ARRAY_OPS, profile, np.asarray(V_rw, dtype=float), g, coefficients)


def wind_disturbance(profile, u, v, psi, speed, direction_from, coefficients='blendermann94'):
    """Loads (X, Y, K, N) the wind adds to a ship moving at (u, v) over ground (module docstring).

    Arguments as ``relative_wind``; arrays broadcast. Zero wind speed gives exact zeros. All
    Python floats (one vessel, Blendermann): evaluated on floats, as the models' fast path
    (the same arithmetic, so the same numbers as the array path).
    """
    if coefficients == 'blendermann94' and all(
            type(a) is float for a in (u, v, psi, speed, direction_from)):
        ops = FLOAT_OPS
        V_rw, g_rw = _relative_wind(ops, u, v, psi, speed, direction_from)
        V_0, g_0 = _relative_wind(ops, u, v, psi, 0.0, 0.0)
        wind = _loads(ops, profile, V_rw, g_rw, coefficients)
        still = _loads(ops, profile, V_0, g_0, coefficients)
        return tuple(a - b for a, b in zip(wind, still))
    V_rw, g_rw = relative_wind(u, v, psi, speed, direction_from)
    V_0, g_0 = relative_wind(u, v, psi, 0.0, 0.0)
    both = wind_loads(profile, np.stack(np.broadcast_arrays(V_rw, V_0)),
                      np.stack(np.broadcast_arrays(g_rw, g_0)), coefficients)
    return tuple(c[0] - c[1] for c in both)
