"""Path-following metrics of one recorded run (pure numpy; no ROS).

Inputs are the topic quantities (doc/design.md): time t (s), ENU position x, y (m) and yaw (rad),
rudder angles (rad, positive to port), heading command (ENU yaw, rad), cross-track error e (m,
positive = vessel to starboard of the path) and the route as ENU waypoints. Every function
returns plain floats, ints or None, so ``json.dump`` writes the result; key names carry units.

Conventions of this module (so that runs compare with each other):

- Settling: cross-track, heading and rudder statistics ignore the first ``settle_s`` seconds
  after the first odometry sample (the approach to the path is a transient, not tracking
  error). Default: ``DEFAULT_SETTLE_FRACTION`` (10 %) of the run's duration. The cut-off used
  is reported as ``settle_s``.
- Cumulative Gaussian reward of Martinsen and Lekkas 2018 (ship_autopilot.learning.reward)
  eq. (8) and Table I: per step ``a exp(-e^2 / (2 sigma^2))`` with a = 1, sigma = 10 m, and 0
  when the yaw error to the path, |psi - gamma_p|, exceeds pi/2 (the eq. 8 gate; applied when
  the route is known). Table I sums the Gaussian term only (its title: "cumulative Gaussian
  reward"), over the whole episode (no settling), episodes being 1000 s. The document does not
  state its time step, so the sum depends on an assumed sampling: we resample e on a uniform
  grid of ``reward_step_s`` (default 0.1 s, the step of the MSS simulations of the paper) and
  also report the sampling-free integral ``reward_gaussian_integral_s`` = sum * step, from
  which the sum at any other step h follows as integral / h. An episode of ``T`` s with e = 0
  scores T / step (10 000 for 1000 s at 0.1 s).
- Completion: when the guidance's own finish flag is given (ship_guidance's progress topic,
  column 'finished'), the first time it is set; otherwise the first time the vessel's
  projection on the route polyline (last segment extended past the end) is within
  ``finish_tolerance_m`` of the route's end, i.e. the remaining along-track distance reaches 0
  (default tolerance 0 m). ``completion_source`` says which. Times are from the first odometry
  sample. The route is taken as the polyline of its poses (arcs arrive split into short
  chords, see ship_guidance.ros.path_msgs).
"""
import numpy as np

from ship_autopilot.learning.reward import gaussian_reward as _gaussian_term
from ship_sim.frames import wrap_angle

DEFAULT_SETTLE_FRACTION = 0.10
REWARD_SIGMA_M = 10.0   # Martinsen and Lekkas 2018 eq. (8): Gaussian standard deviation
REWARD_STEP_S = 0.1     # assumed step of the paper's episodes (not stated there)
SATURATION_RTOL = 1e-3  # |delta| >= limit * (1 - rtol) counts as saturated


def wrap(a):
    """Angle(s) to [-pi, pi) (ship_sim.frames.wrap_angle on a float array)."""
    return wrap_angle(np.asarray(a, dtype=float))


def json_float(x):
    """numpy scalar -> JSON-able float (NaN/inf -> None)."""
    x = float(x)
    return x if np.isfinite(x) else None


def rms(x):
    x = np.asarray(x, dtype=float)
    return float(np.sqrt(np.mean(x * x))) if x.size else float('nan')


def settle_cutoff(t, settle_s=None, settle_fraction=DEFAULT_SETTLE_FRACTION):
    """Absolute time (s) from which statistics count: t[0] + settle_s (default: a fraction of the run)."""
    t = np.asarray(t, dtype=float)
    if t.size == 0:
        return 0.0
    if settle_s is None:
        settle_s = settle_fraction * (t[-1] - t[0])
    if settle_s < 0:
        raise ValueError(f'settle_s must be >= 0, got {settle_s}')
    return float(t[0] + settle_s)


# -- cross-track error -------------------------------------------------------------------------

def cross_track_stats(t, e, t_from):
    """RMS, max |e| and mean e (m) of the samples at t >= t_from."""
    t, e = np.asarray(t, dtype=float), np.asarray(e, dtype=float)
    sel = e[t >= t_from]
    if sel.size == 0:
        return {'xte_rms_m': None, 'xte_max_abs_m': None, 'xte_mean_m': None, 'xte_samples': 0}
    return {'xte_rms_m': json_float(rms(sel)), 'xte_max_abs_m': json_float(np.max(np.abs(sel))),
            'xte_mean_m': json_float(np.mean(sel)), 'xte_samples': int(sel.size)}


# -- route geometry -----------------------------------------------------------------------------

def project_on_route(x, y, route_x, route_y, chunk=4096):
    """Project positions on the route polyline (ENU).

    Returns (s, e, gamma, length): along-track distance of the projection (m; on the first and
    last segments the line is extended, so s < 0 before the start and s > length past the end),
    signed cross-track error (m, positive to starboard of the path direction), path tangent yaw
    (rad, ENU) at the projection, and the route length (m).
    """
    px, py = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    rx, ry = np.asarray(route_x, dtype=float), np.asarray(route_y, dtype=float)
    keep = np.concatenate(([True], np.hypot(np.diff(rx), np.diff(ry)) > 0))  # drop repeated points
    rx, ry = rx[keep], ry[keep]
    if rx.size < 2:
        raise ValueError('a route needs at least two distinct points')
    dx, dy = np.diff(rx), np.diff(ry)
    seg_len = np.hypot(dx, dy)
    s0 = np.concatenate(([0.0], np.cumsum(seg_len)[:-1]))
    length = float(seg_len.sum())
    ux, uy = dx / seg_len, dy / seg_len
    lo = np.zeros_like(seg_len)
    hi = seg_len.copy()
    lo[0], hi[-1] = -np.inf, np.inf  # extend the ends
    s, e, gamma = (np.empty(px.size) for _ in range(3))
    for a in range(0, px.size, chunk):  # bound memory: chunk x segments
        qx = px[a:a + chunk, None] - rx[None, :-1]
        qy = py[a:a + chunk, None] - ry[None, :-1]
        along = np.clip(qx * ux + qy * uy, lo, hi)
        dist2 = (qx - along * ux) ** 2 + (qy - along * uy) ** 2
        k = np.argmin(dist2, axis=1)
        rows = np.arange(k.size)
        s[a:a + chunk] = s0[k] + along[rows, k]
        # right of the direction (starboard) is positive: e = u x q . (-z)
        e[a:a + chunk] = uy[k] * qx[rows, k] - ux[k] * qy[rows, k]
        gamma[a:a + chunk] = np.arctan2(uy[k], ux[k])
    return s, e, gamma, length


def completion_time(t, s, length, finish_tolerance_m=0.0):
    """First time (s, absolute) the remaining along-track distance length - s is <= the tolerance; None if never."""
    t, s = np.asarray(t, dtype=float), np.asarray(s, dtype=float)
    done = np.nonzero(length - s <= finish_tolerance_m)[0]
    return float(t[done[0]]) if done.size else None


# -- reward (Martinsen and Lekkas 2018) ------------------------------------------------------------

def gaussian_reward(t, e, yaw_error=None, sigma_m=REWARD_SIGMA_M, step_s=REWARD_STEP_S, episode_s=None):
    """Cumulative Gaussian reward of Martinsen and Lekkas 2018, eq. (8) / Table I, on a uniform grid of ``step_s``.

    e (m) is linearly interpolated at t0, t0 + step, ... (t0 = t[0]; the last grid point is <=
    t[-1], or t0 + episode_s when given). ``yaw_error`` (rad, same times as e) zeroes the reward
    where |yaw error| > pi/2. Returns the sum, the integral sum * step (s) and the grid used.
    """
    t, e = np.asarray(t, dtype=float), np.asarray(e, dtype=float)
    if sigma_m <= 0 or step_s <= 0:
        raise ValueError(f'sigma_m and step_s must be > 0, got {sigma_m}, {step_s}')
    if t.size == 0:
        return {'reward_gaussian_sum': None, 'reward_gaussian_integral_s': None, 'reward_steps': 0,
                'reward_step_s': step_s, 'reward_sigma_m': sigma_m, 'reward_episode_s': 0.0}
    end = t[-1] if episode_s is None else min(t[-1], t[0] + episode_s)
    n = int(np.floor((end - t[0]) / step_s + 1e-9)) + 1
    grid = t[0] + step_s * np.arange(n)
    # the yaw error is interpolated unwrapped, so +-pi never averages to 0
    yaw_grid = (0.0 if yaw_error is None else
                np.interp(grid, t, np.unwrap(np.asarray(yaw_error, dtype=float))))
    r = _gaussian_term(np.interp(grid, t, e), yaw_grid, sigma=sigma_m)
    total = float(r.sum())
    return {'reward_gaussian_sum': total, 'reward_gaussian_integral_s': total * step_s, 'reward_steps': int(n),
            'reward_step_s': float(step_s), 'reward_sigma_m': float(sigma_m),
            'reward_episode_s': float(grid[-1] - grid[0] + step_s)}


# -- rudder and heading -----------------------------------------------------------------------------

def rudder_stats(t, delta, t_from, limit_rad=None, prefix='rudder'):
    """Rudder usage after t_from: mean |delta|, RMS (rad), total variation per second (rad/s), saturation.

    Total variation = sum |delta[k+1] - delta[k]| over the window, divided by its duration.
    Saturated samples: |delta| >= limit (1 - 1e-3); None when no limit is given.
    """
    t, d = np.asarray(t, dtype=float), np.asarray(delta, dtype=float)
    sel = t >= t_from
    t, d = t[sel], d[sel]
    out = {f'{prefix}_mean_abs_rad': None, f'{prefix}_rms_rad': None, f'{prefix}_max_abs_rad': None,
           f'{prefix}_total_variation_rad_per_s': None, f'{prefix}_saturated_samples': None,
           f'{prefix}_saturated_fraction': None, f'{prefix}_samples': int(d.size)}
    if d.size == 0:
        return out
    out[f'{prefix}_mean_abs_rad'] = json_float(np.mean(np.abs(d)))
    out[f'{prefix}_rms_rad'] = json_float(rms(d))
    out[f'{prefix}_max_abs_rad'] = json_float(np.max(np.abs(d)))
    span = t[-1] - t[0]
    out[f'{prefix}_total_variation_rad_per_s'] = json_float(np.sum(np.abs(np.diff(d))) / span) if span > 0 else None
    if limit_rad is not None:
        sat = int(np.count_nonzero(np.abs(d) >= limit_rad * (1.0 - SATURATION_RTOL)))
        out[f'{prefix}_saturated_samples'] = sat
        out[f'{prefix}_saturated_fraction'] = sat / d.size
    return out


def rudder_time_at_limit(t, delta, t_from, limit_rad):
    """Time (s) the rudder spends at its limit after t_from (|delta| >= limit (1 - 1e-3), as
    ``rudder_stats`` counts saturation): each sample holds until the next one, the last adds
    nothing. None without samples."""
    t, d = np.asarray(t, dtype=float), np.asarray(delta, dtype=float)
    sel = t >= t_from
    t, d = t[sel], d[sel]
    if d.size == 0:
        return None
    at_limit = np.abs(d) >= limit_rad * (1.0 - SATURATION_RTOL)
    return json_float(np.sum(np.diff(t)[at_limit[:-1]]))


def step_response_stats(t_cmd, yaw_cmd, t, yaw, t_steady, band_fraction=0.02):
    """Heading step response of a course change: the command's last step and what followed.

    The step starts at the last change of the command (or its first sample); its size is the
    final command minus the yaw there (wrapped). After it, with s the sign of the step:
    overshoot = max(0, max s (yaw - command)) (rad, and as a fraction of |step|); steady error =
    mean of yaw - command at t >= t_steady (rad); settling time = time from the step until the
    yaw stays within band_fraction |step| of its own steady value (the mean yaw over
    t >= t_steady): settling to where it ends, whatever its steady error (None if it never
    does before t_steady). Yaw is unwrapped and interpolated at the command times.
    """
    t_cmd, yaw_cmd = np.asarray(t_cmd, dtype=float), np.asarray(yaw_cmd, dtype=float)
    t, yaw = np.asarray(t, dtype=float), np.unwrap(np.asarray(yaw, dtype=float))
    keys = ('step_rad', 'step_time_s', 'overshoot_rad', 'overshoot_fraction',
            'steady_error_rad', 'settling_time_s', 'settling_band_rad')
    out = dict.fromkeys(keys)
    sel = (t_cmd >= t[0]) & (t_cmd <= t[-1])
    t_cmd, yaw_cmd = t_cmd[sel], yaw_cmd[sel]
    if t_cmd.size < 2:
        return out
    changes = np.nonzero(np.abs(wrap(np.diff(yaw_cmd))) > 1e-9)[0]
    k0 = int(changes[-1]) + 1 if changes.size else 0
    t_cmd, yaw_cmd = t_cmd[k0:], yaw_cmd[k0:]
    psi = np.interp(t_cmd, t, yaw)
    step = float(wrap(yaw_cmd[-1] - psi[0]))
    err = wrap(psi - yaw_cmd)                   # yaw - command
    steady = t_cmd >= t_steady
    out.update(step_rad=json_float(step), step_time_s=json_float(t_cmd[0]))
    if step == 0.0 or not np.any(steady):
        return out
    over = max(0.0, float(np.max(np.sign(step) * err)))
    band = band_fraction * abs(step)
    final_err = float(np.mean(err[steady]))
    outside = np.nonzero(np.abs(err - final_err) > band)[0]
    settled_at = t_cmd[0] if outside.size == 0 else (
        t_cmd[outside[-1] + 1] if outside[-1] + 1 < t_cmd.size else None)
    settling = None if settled_at is None or settled_at > t_steady else settled_at - t_cmd[0]
    out.update(overshoot_rad=json_float(over), overshoot_fraction=json_float(over / abs(step)),
               steady_error_rad=json_float(final_err), settling_band_rad=json_float(band),
               settling_time_s=None if settling is None else json_float(settling))
    return out


def heading_error_stats(t_cmd, yaw_cmd, t, yaw, t_from):
    """Heading error yaw - command (rad, wrapped) at the command times after t_from.

    The vessel yaw is unwrapped and interpolated at each command time.
    """
    t_cmd, yaw_cmd = np.asarray(t_cmd, dtype=float), np.asarray(yaw_cmd, dtype=float)
    sel = (t_cmd >= t_from) & (t_cmd >= t[0]) & (t_cmd <= t[-1])
    if not np.any(sel):
        return {'heading_error_rms_rad': None, 'heading_error_max_abs_rad': None,
                'heading_error_mean_rad': None, 'heading_error_samples': 0}
    err = wrap(np.interp(t_cmd[sel], t, np.unwrap(yaw)) - yaw_cmd[sel])
    return {'heading_error_rms_rad': json_float(rms(err)), 'heading_error_max_abs_rad': json_float(np.max(np.abs(err))),
            'heading_error_mean_rad': json_float(np.mean(err)), 'heading_error_samples': int(err.size)}


# -- motion over ground ------------------------------------------------------------------------------

def over_ground(t, x, y, yaw, min_speed_mps=0.05):
    """Speed over ground (m/s), course over ground (ENU yaw, rad) and drift angle (rad) at each
    odometry sample, from the track itself (central differences of the ENU position, so a
    current is in them). Drift = course over ground - heading, compass sense: + = the ground
    track runs to starboard of the heading. Course and drift are NaN where the speed is below
    ``min_speed_mps`` (no course to speak of)."""
    t, x, y, yaw = (np.asarray(a, dtype=float) for a in (t, x, y, yaw))
    if t.size < 2:
        nan = np.full(t.size, np.nan)
        return nan, nan, nan
    vx, vy = np.gradient(x, t), np.gradient(y, t)
    sog = np.hypot(vx, vy)
    moving = sog >= min_speed_mps
    cog = np.where(moving, np.arctan2(vy, vx), np.nan)
    # ENU angles count counter-clockwise; a compass difference clockwise: hence heading - course
    drift = np.where(moving, wrap(yaw - cog), np.nan)
    return sog, cog, drift


# -- everything for one vessel ------------------------------------------------------------------------

def vessel_metrics(t, x, y, yaw, *, xte=None, rudder=None, rudder_cmd=None, heading_cmd=None, route=None,
                   settle_s=None, settle_fraction=DEFAULT_SETTLE_FRACTION, rudder_limit_rad=None,
                   reward_sigma_m=REWARD_SIGMA_M, reward_step_s=REWARD_STEP_S, episode_s=None,
                   finish_tolerance_m=0.0, finished=None, remaining=None):
    """All metrics of one vessel as a JSON-able dict.

    t, x, y, yaw: odometry (s, m, m, rad ENU). xte, rudder, rudder_cmd, heading_cmd: (t, values)
    pairs or None. route: (route_x, route_y) ENU waypoints or None. finished, remaining: the
    guidance's finish flag (0/1) and remaining distance (m) as (t, values), or None. The cross-track error and
    reward use the recorded ``xte`` (the guidance's own); without it, the error is computed
    from the route geometry (``xte_source`` says which).
    """
    t, x, y, yaw = (np.asarray(a, dtype=float) for a in (t, x, y, yaw))
    if t.size < 2:
        raise ValueError('need at least two odometry samples')
    t_from = settle_cutoff(t, settle_s, settle_fraction)
    out = {'duration_s': json_float(t[-1] - t[0]), 'start_time_s': json_float(t[0]),
           'settle_s': json_float(t_from - t[0]),
           'odom_samples': int(t.size),
           'distance_travelled_m': json_float(np.sum(np.hypot(np.diff(x), np.diff(y))))}
    geo = None
    if route is not None and len(route[0]) >= 2:
        s, e_geo, gamma, length = project_on_route(x, y, route[0], route[1])
        geo = (s, e_geo, wrap(yaw - gamma))
        t_done = completion_time(t, s, length, finish_tolerance_m)
        out.update({'route_length_m': json_float(length), 'finished': t_done is not None,
                    'completion_source': 'route',
                    'time_to_complete_s': json_float(t_done - t[0]) if t_done is not None else None,
                    'remaining_at_end_m': json_float(max(0.0, length - s[-1])),
                    'path_yaw_error_max_abs_rad': json_float(np.max(np.abs(geo[2][t >= t_from]), initial=0.0))})
    if finished is not None and len(finished[0]):
        flag_t, flag = np.asarray(finished[0], dtype=float), np.asarray(finished[1], dtype=float)
        done = np.nonzero(flag >= 0.5)[0]
        out.update({'finished': bool(done.size), 'completion_source': 'guidance',
                    'time_to_complete_s': json_float(flag_t[done[0]] - t[0]) if done.size else None})
    if remaining is not None and len(remaining[0]):
        out['remaining_at_end_m'] = json_float(np.asarray(remaining[1], dtype=float)[-1])
    if xte is not None and len(xte[0]):
        t_e, e, source = np.asarray(xte[0], dtype=float), np.asarray(xte[1], dtype=float), 'topic'
    elif geo is not None:
        t_e, e, source = t, geo[1], 'route'
    else:
        t_e, e, source = None, None, None
    out['xte_source'] = source
    if e is not None:
        out.update(cross_track_stats(t_e, e, t_from))
        # gate of eq. (8): yaw error to the path at the error's sample times
        yaw_err = wrap(np.interp(t_e, t, np.unwrap(geo[2]))) if geo is not None else None
        out.update(gaussian_reward(t_e, e, yaw_err, reward_sigma_m, reward_step_s, episode_s))
    if geo is not None:
        out['xte_route_rms_m'] = json_float(rms(geo[1][t >= t_from]))
    if rudder is not None:
        out.update(rudder_stats(rudder[0], rudder[1], t_from, rudder_limit_rad, 'rudder'))
    if rudder_cmd is not None:
        out.update(rudder_stats(rudder_cmd[0], rudder_cmd[1], t_from, rudder_limit_rad, 'rudder_cmd'))
    if heading_cmd is not None:
        out.update(heading_error_stats(heading_cmd[0], heading_cmd[1], t, yaw, t_from))
    out['rudder_limit_rad'] = json_float(rudder_limit_rad) if rudder_limit_rad is not None else None
    return out


def track_metrics(t, x, y):
    """Metrics of a target's track (odometry only: a light or AIS target), JSON-able: duration,
    samples, distance travelled and mean speed over ground."""
    t, x, y = (np.asarray(a, dtype=float) for a in (t, x, y))
    if t.size < 2:
        return {'duration_s': None, 'start_time_s': json_float(t[0]) if t.size else None,
                'odom_samples': int(t.size), 'distance_travelled_m': 0.0,
                'speed_mean_mps': None}
    dist = float(np.sum(np.hypot(np.diff(x), np.diff(y))))
    duration = float(t[-1] - t[0])
    return {'duration_s': json_float(duration), 'start_time_s': json_float(t[0]), 'odom_samples': int(t.size),
            'distance_travelled_m': json_float(dist),
            'speed_mean_mps': json_float(dist / duration) if duration > 0 else None}


# -- platoons ----------------------------------------------------------------------------------

def gap_error_stats(t, gap_error, t_from):
    """RMS, mean and max |.| (m) of a follower's gap error (gap - spacing, > 0 = too far behind)
    at t >= t_from; NaN samples (the follower in route_fallback) are left out and counted."""
    t, g = np.asarray(t, dtype=float), np.asarray(gap_error, dtype=float)
    sel = g[t >= t_from]
    ok = sel[np.isfinite(sel)]
    if ok.size == 0:
        return {'gap_error_rms_m': None, 'gap_error_mean_m': None, 'gap_error_max_abs_m': None,
                'gap_error_samples': 0, 'gap_error_undefined_samples': int(sel.size)}
    return {'gap_error_rms_m': json_float(rms(ok)), 'gap_error_mean_m': json_float(np.mean(ok)),
            'gap_error_max_abs_m': json_float(np.max(np.abs(ok))), 'gap_error_samples': int(ok.size),
            'gap_error_undefined_samples': int(sel.size - ok.size)}


def string_ratios(values, predecessors):
    """String-stability measure of a platoon: each follower's value (e.g. its peak |cross-track
    error|) divided by its predecessor's. values: {vessel: float or None}; predecessors:
    {vessel: predecessor or None}. Returns {follower: ratio or None}; a ratio above 1 means the
    deviation grew from the predecessor to the follower (Angelopoulos 2011's string stability asks
    that it does not: the error of vessel i bounded by that of vessel i-1)."""
    out = {}
    for ns, pred in predecessors.items():
        if pred is None:
            continue
        a, b = values.get(ns), values.get(pred)
        out[ns] = json_float(a / b) if a is not None and b is not None and b > 0.0 else None
    return out
