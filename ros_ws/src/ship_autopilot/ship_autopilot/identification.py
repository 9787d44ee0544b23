"""First-order Nomoto identification (K, T and a, b) from a simulated zig-zag manoeuvre.

Method: equation-error least squares (Fossen, Handbook of Marine Craft Hydrodynamics and Motion
Control, 2011, Sec. 7.1 Nomoto models; the usual linear regression for ship steering models).
The first-order Nomoto model in the project's sign (NED r, unified rudder: positive turns to
port; Lee 2004 eq. 4.29b, Angelopoulos 2011 eq. 12),

    r_dot = a r + b delta + c,        a = -1/T,  b = -K/T,

is linear in (a, b, c), so (a, b, c) minimise sum (r_dot_k - a r_k - b delta_k - c)^2 over the
samples of a manoeuvre, with r_dot from second-order central differences (numpy.gradient) of
the sampled yaw rate and delta the ACTUAL rudder angle (after the model's servo), not the
command. The constant c absorbs a rudder offset: a ship that is not straight at zero rudder
(the MSS mariner needs about -1.1 deg) turns with r_dot = b (delta - delta_0), so
delta_0 = -c / b is reported as ``rudder_trim``. Then T = -1/a and K = b/a.

Manoeuvre: a rudder/heading zig-zag (default 10 deg / 10 deg) from straight-running trim, first
turn to starboard, rudder reversed when the heading change passes +-switch with the yaw rate
moving away from the start heading (the logic of MSS zigzag.m and ship_sim.maneuvers). A
zig-zag excites both the transient (T) and the gain (K) around the operating point the
autopilot works at; a nonlinear ship gives the best-fitting linear model for that amplitude.

What to expect: K and T of a real ship depend on the manoeuvre. A first-order fit sees the
frequencies the zig-zag excites (periods of 1-3 minutes for the ships), not the low-frequency
limit T = T1 + T2 - T3 of a second-order Nomoto model (Lee 2004 Table 2.2), and a nonlinear
hull gives a different fit for each zig-zag amplitude (the MSS mariner's yaw damping grows with
the yaw rate). The fitted values are in the doc/results/nomoto.md.

Simulation: the model's own MSS RK4 step (``model.step`` when the model has it, else
ship_sim.integrators.rk4_step on ``model.rhs``), input held over each step.

Units: s, rad, rad/s, rad/s^2; K (1/s), T (s), a (1/s), b (1/s^2), c (rad/s^2).
"""
from dataclasses import dataclass

import numpy as np

from ship_sim.integrators import rk4_step


@dataclass(frozen=True)
class NomotoFit:
    """Identified first-order Nomoto model (unified rudder sign) and fit quality."""

    K: float            # 1/s, > 0 for a normal ship
    T: float            # s, < 0 for a course-unstable linear fit
    a: float            # 1/s, = -1/T
    b: float            # 1/s^2, = -K/T
    c: float            # rad/s^2, constant yaw acceleration at r = delta = 0
    rudder_trim: float  # rad, rudder for r_dot = 0 at r = 0: -c/b
    rms_residual: float  # rad/s^2, RMS of the equation error
    r_squared: float    # fraction of the r_dot variance explained
    n_samples: int


def fit_nomoto(t, r, delta, bias=True):
    """Least-squares first-order Nomoto fit of sampled yaw rate r and actual rudder delta.

    t (s, increasing), r (rad/s), delta (rad, unified sign); 1-D arrays of equal length >= 5.
    ``bias=False`` fixes c = 0. Raises ValueError for too few or degenerate samples.
    """
    t, r, delta = (np.asarray(v, dtype=float).ravel() for v in (t, r, delta))
    if not (t.size == r.size == delta.size) or t.size < 5:
        raise ValueError(f'need equal-length series of >= 5 samples, got {t.size}, {r.size}, '
                         f'{delta.size}')
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(r)) and np.all(np.isfinite(delta))):
        raise ValueError('samples must be finite')
    if np.any(np.diff(t) <= 0.0):
        raise ValueError('t must be strictly increasing')
    r_dot = np.gradient(r, t, edge_order=2)
    # The end samples use one-sided differences; drop them.
    sl = slice(1, -1)
    cols = [r[sl], delta[sl]] + ([np.ones(t.size - 2)] if bias else [])
    A = np.column_stack(cols)
    y = r_dot[sl]
    theta, *_ = np.linalg.lstsq(A, y, rcond=None)
    a, b = theta[0], theta[1]
    c = theta[2] if bias else 0.0
    if a == 0.0 or b == 0.0:
        raise ValueError('degenerate fit (a or b is zero): the manoeuvre does not excite r')
    resid = y - A @ theta
    var = np.var(y)
    return NomotoFit(K=float(b / a), T=float(-1.0 / a), a=float(a), b=float(b), c=float(c),
                     rudder_trim=float(-c / b), rms_residual=float(np.sqrt(np.mean(resid ** 2))),
                     r_squared=float(1.0 - np.mean(resid ** 2) / var) if var > 0 else float('nan'),
                     n_samples=int(y.size))


@dataclass(frozen=True)
class Manoeuvre:
    """Sampled manoeuvre: t (s), psi (rad, NED), r (rad/s), delta (rad, actual, unified),
    command (rad, unified, held over [t_k, t_k+1)), speed (m/s, surge through water)."""

    t: np.ndarray
    psi: np.ndarray
    r: np.ndarray
    delta: np.ndarray
    command: np.ndarray
    speed: np.ndarray
    description: str


def _stepper(model):
    """One integration step x -> x+ with the native input held (model's MSS RK4 if offered)."""
    if hasattr(model, 'step'):
        return model.step
    return lambda x, u, h: rk4_step(model.rhs, x, u, h)


def zigzag_manoeuvre(model, rudder=np.deg2rad(10.0), switch_heading=np.deg2rad(10.0),
                     n_reversals=6, h=0.1, t_max=4000.0, shaft=None, speed=None):
    """Run a zig-zag on ``model`` (a ship_sim VesselModel) and sample it every step.

    rudder, switch_heading (rad, > 0): the first command turns to starboard (unified rudder
    -rudder); the run ends one switch interval after ``n_reversals`` reversals, or at t_max (s,
    ValueError if fewer than 2 reversals happened: the rudder cannot turn the ship).
    ``shaft`` (rpm) / ``speed`` (m/s) select the trim (model defaults if None).
    """
    if not (rudder > 0.0 and switch_heading > 0.0):
        raise ValueError(f'rudder = {rudder!r} and switch_heading = {switch_heading!r} must be > 0')
    step = _stepper(model)
    x = np.asarray(model.initial_state(speed=speed, shaft=shaft), dtype=float)
    psi0 = x[model.IPSI]
    u_port, u_stbd = model.inputs(rudder, shaft), model.inputs(-rudder, shaft)
    cmd = -rudder
    n_max = int(round(t_max / h))
    xs, cmds, reversals = [x], [], []
    stop = n_max
    for k in range(n_max):
        dpsi, r = x[model.IPSI] - psi0, x[model.IR]
        if (dpsi >= switch_heading and r > 0 and cmd < 0) or \
                (dpsi <= -switch_heading and r < 0 and cmd > 0):
            cmd = -cmd
            reversals.append(k)
            if len(reversals) == n_reversals:
                # Keep the last half period so the final reversal's response is in the data.
                stop = min(n_max, k + (k - reversals[-2]))
        if k >= stop:
            break
        x = step(x, u_port if cmd > 0 else u_stbd, h)
        xs.append(x)
        cmds.append(cmd)
    if len(reversals) < 2:
        raise ValueError(f'{model.name}: only {len(reversals)} rudder reversals in {t_max} s; '
                         f'the zig-zag did not develop (increase t_max or the rudder)')
    states = np.array(xs)
    model.check_state(states)
    cmds.append(cmd)
    deg = np.rad2deg
    return Manoeuvre(
        t=np.arange(len(xs)) * h, psi=states[:, model.IPSI], r=states[:, model.IR],
        delta=np.asarray(model.rudder_angle(states), dtype=float), command=np.array(cmds),
        speed=np.asarray(model.surge_speed(states), dtype=float),
        description=(f'zig-zag {deg(rudder):g} deg / {deg(switch_heading):g} deg, first to '
                     f'starboard, {len(reversals)} reversals, RK4 h = {h:g} s, '
                     f'{len(xs) * h:.0f} s'))


def simulate_nomoto(fit, t, delta, r0=0.0, psi0=0.0):
    """Heading and yaw rate of the fitted model driven by the sampled actual rudder.

    Exact discretisation of r_dot = a r + b delta + c with delta taken as the mean of the two
    end samples over each step (the rudder is piecewise linear between samples). Returns
    (r, psi) arrays like t; psi integrated with the trapezoidal rule.
    """
    t, delta = np.asarray(t, dtype=float), np.asarray(delta, dtype=float)
    h = np.diff(t)
    phi = np.exp(fit.a * h)
    gam = np.expm1(fit.a * h) / fit.a
    forcing = gam * (fit.b * 0.5 * (delta[1:] + delta[:-1]) + fit.c)
    r = np.empty_like(t)
    r[0] = r0
    for k in range(h.size):  # a first-order recursion; h.size is a few thousand
        r[k + 1] = phi[k] * r[k] + forcing[k]
    psi = psi0 + np.concatenate(([0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * h)))
    return r, psi


def heading_prediction_rms(fit, manoeuvre):
    """RMS (rad) of the heading the fitted model predicts from the manoeuvre's rudder."""
    _, psi = simulate_nomoto(fit, manoeuvre.t, manoeuvre.delta, manoeuvre.r[0],
                             manoeuvre.psi[0])
    return float(np.sqrt(np.mean((psi - manoeuvre.psi) ** 2)))


def identify_nomoto(model, **manoeuvre_kw):
    """Zig-zag ``model`` and fit first-order Nomoto: returns (NomotoFit, Manoeuvre)."""
    m = zigzag_manoeuvre(model, **manoeuvre_kw)
    return fit_nomoto(m.t, m.r, m.delta), m
