"""The path-relative state of a vessel (Martinsen and Lekkas 2018, eq. 9), computed from a path
projection and odometry: what the learned steering policy sees.

Source: Martinsen and Lekkas 2018, "Curved path following with deep reinforcement learning:
results from three vessel models", eq. 9:

    x = [y_e, y_e', chi - gamma_p, (chi - gamma_p)', psi - gamma_p, (psi - gamma_p)', u, v, r]

with y_e the cross-track error of the closest path point (eqs. 1-3, ship_guidance.path), chi
the course, psi the heading, gamma_p the path angle there. This module is the ONE
implementation used by the training environment (ship_autopilot.learning.env) and by the nodes
at runtime (guidance_node's ``path_state`` topic, ship_autopilot.learning.policy), so a policy
sees exactly the numbers it was trained on. It lives with the path (ship_guidance) because it
is a function of the path projection, which both the guidance and the autopilot use.

Inputs (NED / FRD, SI units, rad), one vessel (floats) or a batch (arrays):
- from the projection (``Route.project`` or ``GuidanceOutput``): cross_track e (m, positive to
  starboard of the path), path_angle gamma_p (rad), curvature kappa (1/m, + clockwise);
- from odometry: heading psi (rad), body velocities OVER GROUND u, v (m/s; what Odometry
  carries, GNSS-like: with a current the vessel does not know its speed through the water) and
  yaw rate r (rad/s); dt (s) since the previous call.

How each component is computed (no numerical derivative of the projection, which would jump
at leg joins):
- course over ground chi = psi + beta, beta = atan2(v, u) (crab + drift angle);
- y_e' = U sin(chi - gamma_p), U = sqrt(u^2 + v^2): exact for the closest point, because the
  closest point moves along the tangent and the offset is normal to it;
- (psi - gamma_p)' = r - kappa s', with s' = U cos(chi - gamma_p) / (1 - kappa y_e) the speed
  of the closest point along the path (a vessel to starboard of a starboard turn, kappa y_e >
  0, is nearer the centre); the denominator is kept >= 0.1 (a vessel near the centre of
  curvature has no unique closest point);
- (chi - gamma_p)' = (psi - gamma_p)' + beta', beta' by a backward difference of beta over dt
  (the only memory of this class); 0 on the first call after ``reset`` or when dt <= 0.

Normalisation (``normalise``): z_i = clip((x_i - offset_i) / scale_i, -clip, clip), float32.
Scales depend on the vessel's nominal speed U0 (m/s) and length L (m), see ``default_scales``;
they are stored with each trained policy so runtime and training always agree. Non-finite raw
values are never passed on: ``normalise`` maps them to 0 (the nominal value) and reports them.
"""
import numpy as np

from ship_sim.frames import wrap_angle

#: Field order of the state (Martinsen and Lekkas 2018, eq. 9). Units: m, m/s, rad, rad/s, rad, rad/s, m/s, m/s,
#: rad/s.
STATE_NAMES = ('cross_track', 'cross_track_rate', 'course_rel', 'course_rel_rate',
               'heading_rel', 'heading_rel_rate', 'u', 'v', 'r')
STATE_UNITS = ('m', 'm/s', 'rad', 'rad/s', 'rad', 'rad/s', 'm/s', 'm/s', 'rad/s')
OBS_DIM = len(STATE_NAMES)

#: Normalised states are clipped to [-CLIP, CLIP] (the range seen in training).
CLIP = 5.0
#: Smallest value of 1 - kappa y_e used for the speed of the closest point.
_MIN_CURVE_FACTOR = 0.1

# Scales (documented choices, see default_scales):
CROSS_TRACK_SCALE = 50.0     # m: resolves the 10 m Gaussian; the clip keeps +-250 m apart
ANGLE_SCALE = 0.5            # rad (29 deg)
SPEED_SCALE = 1.0            # m/s, for u - U0 and v (sway and the current's 0.9 m/s)
RATE_FRACTION = 0.2          # yaw-rate scale = 0.2 U0 / L (about a steady full-rudder turn)


def default_scales(speed, length):
    """(offset, scale) arrays of the normalisation for nominal speed U0 (m/s), length L (m).

    cross track / 50 m; its rate / (U0 / 2) (1 at a 30 deg intercept); angles / 0.5 rad;
    angular rates / (0.2 U0 / L) (about a ship's steady turn rate at full rudder); u - U0 and
    v / 1 m/s.
    """
    speed, length = float(speed), float(length)
    if not (np.isfinite(speed) and speed > 0 and np.isfinite(length) and length > 0):
        raise ValueError(f'speed = {speed!r} m/s and length = {length!r} m must be positive')
    r_scale = RATE_FRACTION * speed / length
    offset = np.array([0, 0, 0, 0, 0, 0, speed, 0, 0], dtype=np.float64)
    scale = np.array([CROSS_TRACK_SCALE, 0.5 * speed, ANGLE_SCALE, r_scale, ANGLE_SCALE,
                      r_scale, SPEED_SCALE, SPEED_SCALE, r_scale], dtype=np.float64)
    return offset, scale


def normalise(state, offset, scale, clip=CLIP):
    """Raw state (..., 9) SI -> (normalised float32 (..., 9), finite mask (...,)).

    Values beyond the training range are clipped to +-clip; non-finite values become 0 (the
    offset, i.e. the nominal value) and their row is flagged False in the mask.
    """
    x = np.asarray(state, dtype=np.float64)
    if x.shape[-1:] != (OBS_DIM,):
        raise ValueError(f'path state must end in {OBS_DIM} components {STATE_NAMES}, '
                         f'got shape {x.shape}')
    finite = np.isfinite(x)
    z = np.where(finite, (x - offset) / scale, 0.0)
    return np.clip(z, -clip, clip).astype(np.float32), finite.all(axis=-1)


class PathFeatures:
    """Stateful eq. 9 extractor for one vessel (``shape=()``) or a batch (``shape=(n,)``).

    ``__call__(cross_track, path_angle, curvature, psi, u, v, r, dt)`` -> raw state
    (shape + (9,)) in STATE_NAMES order, SI units. See the module docstring for the formulas.
    """

    def __init__(self, shape=()):
        self.shape = tuple(shape)
        self.reset()

    def reset(self, mask=None):
        """Forget the previous drift angle (all vessels, or where the boolean mask is True)."""
        if mask is None or self.shape == ():
            self._beta = np.full(self.shape, np.nan)
        else:
            self._beta = np.where(mask, np.nan, self._beta)

    def __call__(self, cross_track, path_angle, curvature, psi, u, v, r, dt):
        e, gamma, kappa, psi, u, v, r, dt = (np.asarray(a, dtype=np.float64) for a in
                                             (cross_track, path_angle, curvature, psi, u, v,
                                              r, dt))
        beta = np.arctan2(v, u)
        speed = np.hypot(u, v)
        heading_rel = wrap_angle(psi - gamma)
        course_rel = wrap_angle(heading_rel + beta)
        factor = np.maximum(1.0 - kappa * e, _MIN_CURVE_FACTOR)
        s_dot = speed * np.cos(course_rel) / factor
        heading_rel_rate = r - kappa * s_dot
        prev = self._beta
        ok = np.isfinite(prev) & (dt > 0.0)
        beta_rate = np.where(ok, wrap_angle(beta - np.where(ok, prev, 0.0))
                             / np.where(ok, dt, 1.0), 0.0)
        # Remember beta only where it is finite, so one bad sample does not poison the next.
        self._beta = np.where(np.isfinite(beta), beta, prev)
        out = np.stack(np.broadcast_arrays(
            e, speed * np.sin(course_rel), course_rel, heading_rel_rate + beta_rate,
            heading_rel, heading_rel_rate, u, v, r), axis=-1)
        return out
