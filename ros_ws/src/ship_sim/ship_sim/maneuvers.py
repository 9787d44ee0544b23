"""Standard manoeuvres (turning circle, zig-zag) run on a plant model and measured.

Method (as the MSS reference runs under Octave document it, tests/data/mss_golden/maneuvers.json,
so our numbers are comparable with MSS; cf. the IMO manoeuvring standards and Fossen, Handbook
of Marine Craft Hydrodynamics and Motion Control, 2nd ed., Sec. 16.1):

- Start from the model's straight-running trim (``model.initial_state``), rudder 0, and
  integrate with MSS RK4 (``ship_sim.integrators``) at step h with the command held over each
  step; the model's own rudder servo (rate limit, angle limit) produces the actual rudder.
- Turning circle: rudder step at t = 0. Positions are taken relative to the execute point in
  the frame of the initial heading: advance = distance along it, transfer = |distance across
  it|. Advance and transfer at 90 deg heading change, tactical diameter = transfer at 180 deg;
  the heading crossings are found by linear interpolation between samples (every step).
  Steady turning radius = U/|r| at the final time (as MSS turncircle.m prints it).
- Steady turn (``steady_turn``): the same rudder step, integrated on until U/|r| changes by
  less than a relative tolerance over a stretch of time, so slow ships (the tanker's speed
  still falls after 700 s) reach their true steady circle. Lee 2004 (Ch. 4, Fig. 4.5) sizes
  the turning circle between route legs by it.
- Zig-zag (MSS zigzag.m logic): the rudder goes to starboard-turning first; at the start of
  every step, if the heading change is >= +switch and r > 0 the rudder is reversed to port, if
  it is <= -switch and r < 0 back to starboard. Overshoot = peak heading change beyond the
  switch heading after a reversal (sample maximum, no interpolation), for each reversal that
  is followed by another one.

Commands use the project's unified rudder sign (rad, positive turns to port); headings NED
(rad); distances m; speeds m/s; times s.
"""
from dataclasses import dataclass

import numpy as np

from .integrators import rk4_step, rk4_step_floats


@dataclass(frozen=True)
class TurningCircle:
    """Turning-circle measures (m, s, m/s, rad/s). NaN where a heading change is not reached."""

    direction: int                 # +1 starboard (psi increasing), -1 port
    time_to_90deg_s: float
    advance_m: float               # along the initial heading at 90 deg heading change
    transfer_m: float              # across the initial heading at 90 deg
    time_to_180deg_s: float
    tactical_diameter_m: float     # across the initial heading at 180 deg
    max_advance_m: float
    max_transfer_m: float
    steady_radius_m: float         # U/|r| at the final time
    final_speed_mps: float
    final_yaw_rate_radps: float


@dataclass(frozen=True)
class ZigZag:
    """Zig-zag measures: reversal times (s) and overshoot angles (rad), in order."""

    switch_times_s: tuple
    overshoots_rad: tuple


def integrate(model, x0, u, h, t_end):
    """Integrate ``model`` from x0 with the native input u held constant, MSS RK4 step h (s).

    x0 (n,) uses the single-vessel float path (models with ``rhs_scalar``; others are run as a
    batch of one and squeezed back); x0 (N, n) the batched numpy path. Returns
    t (K+1,) and the states (K+1, n) or (K+1, N, n), K = round(t_end / h). Raises
    ModelStateError if any sample leaves the model's domain.
    """
    n_steps = int(round(t_end / h))
    x0 = np.asarray(x0, dtype=float)
    u = np.asarray(u, dtype=float)
    if x0.ndim == 1 and not hasattr(model, 'rhs_scalar'):
        t, states = integrate(model, x0[None], u[None] if u.ndim == 1 else u, h, t_end)
        return t, states[:, 0]
    if x0.ndim == 1:
        x, ul, f = x0.tolist(), u.tolist(), model.rhs_scalar
        traj = [x]
        for _ in range(n_steps):
            x = rk4_step_floats(f, x, ul, h)
            traj.append(x)
        states = np.array(traj)
    else:
        states = np.empty((n_steps + 1,) + x0.shape)
        states[0] = x0
        for k in range(n_steps):
            states[k + 1] = rk4_step(model.rhs, states[k], u, h)
    model.check_state(states)
    return np.arange(n_steps + 1) * h, states


def _crossing(level, dpsi, *series):
    """Linear interpolation of each series where dpsi first reaches level (NaN if never)."""
    above = np.flatnonzero(dpsi >= level)
    if above.size == 0 or above[0] == 0:
        return (np.nan,) * len(series)
    k = above[0]
    w = (level - dpsi[k - 1]) / (dpsi[k] - dpsi[k - 1])
    return tuple(s[k - 1] + w * (s[k] - s[k - 1]) for s in series)


def turning_metrics(t, north, east, psi, speed, r):
    """Turning-circle measures from sampled tracks (1-D arrays; first sample = execute)."""
    psi = np.unwrap(psi)
    direction = 1 if psi[-1] >= psi[0] else -1
    dpsi = direction * (psi - psi[0])
    c, s = np.cos(psi[0]), np.sin(psi[0])
    dn, de = north - north[0], east - east[0]
    along = c * dn + s * de
    across = np.abs(-s * dn + c * de)
    t90, adv, tr = _crossing(np.pi / 2, dpsi, t, along, across)
    t180, td = _crossing(np.pi, dpsi, t, across)
    return TurningCircle(
        direction=direction, time_to_90deg_s=float(t90), advance_m=float(adv),
        transfer_m=float(tr), time_to_180deg_s=float(t180), tactical_diameter_m=float(td),
        max_advance_m=float(along.max()), max_transfer_m=float(across.max()),
        steady_radius_m=float(speed[-1] / abs(r[-1])), final_speed_mps=float(speed[-1]),
        final_yaw_rate_radps=float(r[-1]))


def turning_circle(model, rudder, shaft=None, h=0.1, t_end=700.0):
    """Run a turning circle from straight-running trim: unified rudder step (rad) at t = 0.

    ``shaft`` (rpm) for models with a shaft: trim and command (default: model nominal).
    Returns (TurningCircle, t, states).
    """
    x0 = model.initial_state(shaft=shaft)
    u = model.inputs(rudder, shaft)
    t, states = integrate(model, x0, u, h, t_end)
    return (turning_metrics(t, states[:, model.IX], states[:, model.IY],
                            states[:, model.IPSI], model.speed(states), states[:, model.IR]),
            t, states)


@dataclass(frozen=True)
class SteadyTurn:
    """A converged steady turn: radius U/|r| (m), speed (m/s), yaw rate (rad/s), sim time (s)."""

    radius_m: float
    speed_mps: float
    yaw_rate_radps: float
    time_s: float


def steady_turn(model, rudder, shaft=None, h=0.1, chunk_s=200.0, rel_tol=1e-6, t_max=20000.0):
    """The steady turning circle at a constant unified rudder angle (rad, != 0).

    From straight-running trim, the rudder step at t = 0 is integrated in chunks of chunk_s
    until U/|r| changes by less than rel_tol (relative) over one chunk. ValueError if that does
    not happen by t_max (e.g. a rudder too small to turn the ship steadily).
    """
    if not np.isfinite(rudder) or rudder == 0.0:
        raise ValueError(f'rudder must be a finite non-zero angle (rad), got {rudder}')
    x = model.initial_state(shaft=shaft)
    u = model.inputs(rudder, shaft)
    t, prev = 0.0, None
    while t < t_max:
        _, states = integrate(model, x, u, h, chunk_s)
        x, t = states[-1], t + chunk_s
        speed = float(_speed(model, x))
        r = float(x[model.IR])
        radius = speed / abs(r) if r != 0.0 else np.inf
        if prev is not None and np.isfinite(radius) and abs(radius - prev) <= rel_tol * radius:
            return SteadyTurn(float(radius), speed, r, t)
        prev = radius
    raise ValueError(f'no steady turn at rudder {np.degrees(rudder):.3g} deg within {t_max:g} s')


def _speed(model, x):
    """Speed through the water (m/s) of one state."""
    return float(model.speed(np.asarray(x)))


def zigzag(model, rudder, switch_heading, shaft=None, h=0.1, t_end=700.0):
    """Run a rudder/heading zig-zag (both rad, > 0), first turn to starboard as MSS zigzag.m.

    Returns (ZigZag, t, states, rudder commands (unified, rad) applied over each step).
    """
    n_steps = int(round(t_end / h))
    x = model.initial_state(shaft=shaft).tolist()
    psi0 = x[model.IPSI]
    to_port = model.inputs(rudder, shaft).tolist()
    to_stbd = model.inputs(-rudder, shaft).tolist()
    f, ipsi, ir = model.rhs_scalar, model.IPSI, model.IR
    cmd = -rudder
    traj, cmds, switches = [x], [], []
    for k in range(n_steps):
        dpsi, r = x[ipsi] - psi0, x[ir]
        if dpsi >= switch_heading and r > 0 and cmd < 0:
            cmd = rudder
            switches.append(k)
        elif dpsi <= -switch_heading and r < 0 and cmd > 0:
            cmd = -rudder
            switches.append(k)
        x = rk4_step_floats(f, x, to_port if cmd > 0 else to_stbd, h)
        traj.append(x)
        cmds.append(cmd)
    states = np.array(traj)
    model.check_state(states)
    t = np.arange(n_steps + 1) * h
    dpsi = states[:, ipsi] - psi0
    overshoots = []
    for k0, k1 in zip(switches, switches[1:]):
        side = 1.0 if dpsi[k0] > 0 else -1.0
        overshoots.append(float(np.max(side * dpsi[k0:k1]) - switch_heading))
    return (ZigZag(tuple(float(t[k]) for k in switches), tuple(overshoots)), t, states,
            np.array(cmds))


@dataclass(frozen=True)
class CourseKeepingTrim:
    """Straight running on a constant heading with the rudder that holds it (r = 0)."""

    rudder: float        # unified rudder angle (rad, + turns to port) that holds the heading
    state: np.ndarray    # native state at the trim (heading and position as given)


def course_keeping_trim(model, shaft=None, psi=0.0):
    """The rudder a model needs to run straight (r = 0) and the state it does so in.

    A hull with a constant yaw moment of its own (the Mariner's Y0, N0; the tanker's propeller
    side force and moment, Lee 2004 Tables 5.4 and 5.6) needs a constant rudder to hold a
    heading; this is the disturbance an autopilot must cancel, so a PD delta = k1 (psi - psi_c)
    + k2 r keeps the steady heading error delta_hold / k1. Solved for surge, sway and rudder
    with u_dot = v_dot = r_dot = 0 (the rudder servo at rest: command = rudder; shaft models at
    ``shaft`` rpm, default nominal), from the model's zero-rudder trim.
    """
    from scipy.optimize import fsolve
    x0 = np.array(model.initial_state(psi=psi, shaft=shaft), dtype=float)
    shaft_cmd = None if model.IN is None else float(x0[model.IN])
    unknown = [model.IU, model.IV, model.IDELTA]
    sign = model.STATE_RUDDER_SIGN

    def residual(z):
        x = x0.copy()
        x[unknown] = z
        u = np.asarray(model.inputs(sign * x[model.IDELTA], shaft_cmd), dtype=float)
        xdot = np.asarray(model.rhs(x, u), dtype=float)
        return xdot[[model.IU, model.IV, model.IR]]

    z, _, ok, msg = fsolve(residual, x0[unknown], xtol=1e-13, full_output=True)
    if ok != 1 or np.max(np.abs(residual(z))) > 1e-9:
        raise ValueError(f'{model.name}: no course-keeping trim found ({msg})')
    x = x0.copy()
    x[unknown] = z
    return CourseKeepingTrim(rudder=float(sign * x[model.IDELTA]), state=x)
