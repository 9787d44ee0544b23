"""Rudder command shaping shared by every heading autopilot: saturation and rate limit.

Sources
- Hard limit: Angelopoulos 2011 (platoon thesis), text before eq. (15): delta = delta_0 while
  |delta_0| <= delta_sat, else delta_sat (with the sign of delta_0).
- Smooth limit: Angelopoulos 2011 eq. (15) (used in its closed loop eq. (25)):
  delta = delta_sat * tanh(delta_0 / delta_sat).
- Rate limit: |delta_k - delta_(k-1)| <= rate_max * dt, the discrete form of the rudder-rate
  limit of every steering machine (MSS ship models: 2.33 .. 5 deg/s).

Units: rad, rad/s, s. Sign: the project's unified rudder (positive turns the vessel to port);
both limits are odd functions, so the sign convention does not matter here.

All functions work on floats and on numpy arrays (one element per vessel).
"""
import numpy as np

#: Saturation shapes accepted by ``saturate`` and ``RudderLimiter``.
SATURATION_SHAPES = ('hard', 'tanh')


def saturate(delta0, delta_sat, shape='hard'):
    """Limit a raw rudder command (rad) to +-delta_sat (rad).

    ``shape='hard'`` clips (Angelopoulos 2011, text before eq. 15); ``shape='tanh'`` is
    delta_sat * tanh(delta0 / delta_sat) (Angelopoulos 2011 eq. 15): slope 1 at zero, smooth, never
    reaching the limit.
    """
    if shape == 'hard':
        return np.clip(delta0, -delta_sat, delta_sat)
    if shape == 'tanh':
        return delta_sat * np.tanh(np.asarray(delta0) / delta_sat)
    raise ValueError(f"saturation shape = {shape!r} is not allowed; allowed: "
                     f"{', '.join(SATURATION_SHAPES)}")


def rate_limit(delta, delta_prev, rate_max, dt):
    """Move from delta_prev towards delta by at most rate_max * dt (rad, rad/s, s)."""
    step = rate_max * dt
    return delta_prev + np.clip(np.asarray(delta) - delta_prev, -step, step)


class RudderLimiter:
    """Saturation then rate limit: the one place where every controller's command is shaped.

    Parameters (validated; a bad value raises ValueError naming it, its value and the range):
    ``max_angle`` (rad, (0, pi/2]), ``max_rate`` (rad/s, > 0, or None for no rate limit),
    ``shape`` ('hard' or 'tanh').

    Stateless: the caller keeps the previous command (the controllers do, see
    ``controller.HeadingController``), so one limiter serves a batch of vessels.
    """

    def __init__(self, max_angle, max_rate=None, shape='hard'):
        self.max_angle = _positive('max_angle', max_angle, np.pi / 2)
        self.max_rate = None if max_rate is None else _positive('max_rate', max_rate, np.inf)
        if shape not in SATURATION_SHAPES:
            raise ValueError(f"shape = {shape!r} is not allowed; allowed: "
                             f"{', '.join(SATURATION_SHAPES)}")
        self.shape = shape

    def __call__(self, delta0, delta_prev, dt):
        """Raw command delta0 (rad) -> saturated, rate-limited command (rad); dt (s) > 0."""
        if type(delta0) is float and type(delta_prev) is float and type(dt) is float:
            return self._limit_float(delta0, delta_prev, dt)
        delta = saturate(delta0, self.max_angle, self.shape)
        if self.max_rate is not None:
            delta = rate_limit(delta, delta_prev, self.max_rate, dt)
        return delta

    def _limit_float(self, delta0, delta_prev, dt):
        # saturate + rate_limit for one vessel on floats (clip = min of max for finite values).
        m = self.max_angle
        if self.shape == 'hard':
            delta = min(max(delta0, -m), m)
        else:
            delta = float(m * np.tanh(delta0 / m))
        if self.max_rate is not None:
            step = self.max_rate * dt
            delta = delta_prev + min(max(delta - delta_prev, -step), step)
        return delta

    def saturated(self, delta0):
        """True where the raw command is at or beyond the angle limit (for anti-windup)."""
        return np.abs(delta0) >= self.max_angle

    def __repr__(self):
        return (f'RudderLimiter(max_angle={self.max_angle!r}, max_rate={self.max_rate!r}, '
                f'shape={self.shape!r})')


def _positive(name, value, upper):
    v = float(value)
    if not 0.0 < v <= upper:  # also refuses NaN
        raise ValueError(f'{name} = {value!r} is outside the allowed range (0, {upper:.6g}]')
    return v
