"""Closest point of approach between ships holding course and speed (pure, vectorised).

With the target's position and velocity relative to the own ship, p = p_t - p_o and
v = v_t - v_o (NED, m and m/s), the range |p + v t| is smallest at

    TCPA = -(p . v) / |v|^2,        DCPA = |p + v TCPA|

(the standard straight-line prediction, e.g. Lenart 1983). TCPA < 0 means
the ships are opening: the closest point lies in the past and the range only grows. When the
relative velocity vanishes the range never changes: TCPA = 0 and DCPA = |p|.

Every function broadcasts over leading axes, so one call evaluates many targets (or many
predicted scenarios x targets); vectors are (..., 2) arrays of (north, east).
"""
import numpy as np

#: Relative speeds below this (m/s) count as none: TCPA = 0, DCPA = the current range.
STILL_MPS = 1e-9


def velocity(course, speed):
    """(..., 2) NED velocity (m/s) of ships with course (rad, clockwise from north) and speed."""
    course, speed = np.asarray(course, dtype=float), np.asarray(speed, dtype=float)
    return np.stack(np.broadcast_arrays(speed * np.cos(course), speed * np.sin(course)), axis=-1)


def cpa(p_own, v_own, p_target, v_target):
    """(TCPA s, DCPA m) of targets relative to the own ship; arrays of the broadcast shape.

    ``p_*``: (..., 2) NED positions (m); ``v_*``: (..., 2) NED velocities (m/s)."""
    p = np.asarray(p_target, dtype=float) - np.asarray(p_own, dtype=float)
    v = np.asarray(v_target, dtype=float) - np.asarray(v_own, dtype=float)
    vv = np.einsum('...i,...i->...', v, v)
    moving = vv > STILL_MPS ** 2
    tcpa = np.where(moving, -np.einsum('...i,...i->...', p, v) / np.where(moving, vv, 1.0), 0.0)
    closest = p + v * tcpa[..., None]
    return tcpa, np.hypot(closest[..., 0], closest[..., 1])


def disc_window(p_own, v_own, p_target, v_target, radius):
    """(t_in s, t_out s): the times between which the straight-line range is below ``radius``
    (m), TCPA -+ sqrt(radius^2 - DCPA^2) / |v|; (inf, -inf) where it never is, (-inf, inf)
    where the relative velocity vanishes inside the radius."""
    tcpa, dcpa = cpa(p_own, v_own, p_target, v_target)
    v = np.asarray(v_target, dtype=float) - np.asarray(v_own, dtype=float)
    speed = np.hypot(v[..., 0], v[..., 1])
    inside = dcpa < radius
    still = speed <= STILL_MPS
    half = np.sqrt(np.maximum(radius ** 2 - dcpa ** 2, 0.0)) / np.where(still, 1.0, speed)
    half = np.where(still, np.inf, half)
    return (np.where(inside, tcpa - half, np.inf), np.where(inside, tcpa + half, -np.inf))


def range_and_bearing(p_own, p_target):
    """(range m, true bearing rad in [0, 2 pi), clockwise from north) of targets."""
    d = np.asarray(p_target, dtype=float) - np.asarray(p_own, dtype=float)
    return np.hypot(d[..., 0], d[..., 1]), np.mod(np.arctan2(d[..., 1], d[..., 0]), 2.0 * np.pi)


def cpa_sigma(p_own, v_own, p_target, v_target, cov):
    """(sigma of TCPA s, sigma of DCPA m): first-order propagation of the relative state's
    covariance ``cov`` ((..., 4, 4) over (north, east, v_north, v_east) of target minus own
    ship; for independent estimates the sum of the two covariances) through ``cpa``.

    DCPA's sigma is that of the signed miss distance s = (p x v) / |v| (p x v = p_n v_e -
    p_e v_n), whose magnitude DCPA is: s is smooth where DCPA = 0 is not, so the sigma stays
    meaningful for a target passing close either side. Gradients, with T = TCPA:
        ds/dp = (v_e, -v_n) / |v|            ds/dv = ((-p_e, p_n) - s v / |v|) / |v|
        dT/dp = -v / |v|^2                   dT/dv = -(p + 2 T v) / |v|^2
    A linearisation: good while the velocity's uncertainty is small beside the relative speed;
    NaN where the relative velocity vanishes (TCPA is then a convention, not a function)."""
    p = np.asarray(p_target, dtype=float) - np.asarray(p_own, dtype=float)
    v = np.asarray(v_target, dtype=float) - np.asarray(v_own, dtype=float)
    cov = np.asarray(cov, dtype=float)
    vv = np.einsum('...i,...i->...', v, v)
    moving = vv > STILL_MPS ** 2
    vv = np.where(moving, vv, 1.0)
    speed = np.sqrt(vv)
    tcpa = -np.einsum('...i,...i->...', p, v) / vv
    s = (p[..., 0] * v[..., 1] - p[..., 1] * v[..., 0]) / speed
    perp = np.stack([-p[..., 1], p[..., 0]], axis=-1)
    g_s = np.concatenate([np.stack([v[..., 1], -v[..., 0]], axis=-1) / speed[..., None],
                          (perp - s[..., None] * v / speed[..., None]) / speed[..., None]],
                         axis=-1)
    g_t = np.concatenate([-v / vv[..., None], -(p + 2.0 * tcpa[..., None] * v) / vv[..., None]],
                         axis=-1)
    var_s = np.einsum('...i,...ij,...j->...', g_s, cov, g_s)
    var_t = np.einsum('...i,...ij,...j->...', g_t, cov, g_t)
    nan = np.nan
    return (np.where(moving, np.sqrt(np.maximum(var_t, 0.0)), nan),
            np.where(moving, np.sqrt(np.maximum(var_s, 0.0)), nan))
