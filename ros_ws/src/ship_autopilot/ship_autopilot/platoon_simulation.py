"""Time-domain platoon of ship models under the PD autopilot and LOS / follower guidance (pure).

The platoon (Angelopoulos 2011 eqs. 31-41 in the time domain): N identical vessels on a straight
route due north, each a ship_sim model (its batched ``model.step``, RK4 as the simulator; every
vessel of every case in one array), each with the PD autopilot of its gain table entry
(Angelopoulos 2011 eq. 20; ship_autopilot.pd, rudder saturated at the model's limit), sampled
every dt (zero-order hold, as the lockstep graph does). The leader steers LOS with look-ahead
d1, follower i the follower law of ship_guidance.follower (eq. 31, nonlinear atan form) with
the look-ahead = its measured along-path gap to vessel i-1 (no spacing control), started at d_i.

Equilibrium: a ship that needs rudder to run straight (asymmetry terms such as the MSS
mariner's Y0, N0) under a PD autopilot without integral settles with a heading and cross-track
offset y_eq(d); follower i then sits at y_{i-1} + y_eq(d_i) (``equilibrium``; Nomoto's is zero).

Linearisation: ``doc_eigenvalues`` is the thesis's model (eq. 30 via
ship_guidance.string_stability.single_vessel_matrix: Nomoto, PD, linearised LOS);
``sampled_eigenvalues`` the Jacobian of one step dt of the simulated closed loop at the
equilibrium (model, PD with zero-order hold, LOS), lambda = log(mu) / dt, which includes the
sway dynamics of a full model; ``sampled_critical_lookahead`` bisects its stability limit.

Envelope growth (``envelope_peaks``, ``envelope_rate``): half the swing between consecutive
extrema, log A = c + sigma t + m log t fitted by least squares (m = vessel index: a follower is
driven at its own resonance by its predecessor, a Jordan chain of degree m).

It lives in ship_autopilot because it closes the loop through the autopilot's PD law and gain
table (ship_guidance may not import ship_autopilot); scripts/platoon_time_domain.py is its CLI.
"""
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ship_guidance.follower import follower_heading_straight
from ship_guidance.los import critical_lookahead
from ship_guidance.string_stability import single_vessel_matrix, string_matrix
from ship_sim.models import make_model

from .gains import autopilot_gains
from .pd import PDAutopilot
from .rudder import RudderLimiter


@dataclass
class ShipClosedLoop:
    """One vessel's closed loop: model, PD gains (k1, k2), design zeta, omega_n (rad/s), speed U
    (m/s) and the document's critical look-ahead d* = U / (2 zeta omega_n) (m)."""
    name: str
    model: object
    k1: float
    k2: float
    zeta: float
    omega_n: float
    speed: float
    d_crit: float


def make_loop(name):
    """The model ``name`` with its autopilot_gains entry."""
    model = make_model(name)
    g = autopilot_gains(name)
    speed = float(model.surge_speed(model.initial_state()))
    zeta, omega_n = float(g['zeta']), float(g['omega_n'])
    return ShipClosedLoop(name, model, float(g['pd']['k1']), float(g['pd']['k2']), zeta, omega_n,
                          speed, critical_lookahead(zeta, omega_n, speed))


# ---------------------------------------------------------------- one vessel's loop

def rudder_law(loop, x, psi_c):
    """The PD autopilot (ship_autopilot.pd, Angelopoulos 2011 eq. 16) hard-saturated at the
    model's rudder limit; without a rate limit it is memoryless, so a fresh one per call."""
    m = loop.model
    pd = PDAutopilot(loop.k1, loop.k2, RudderLimiter(m.rudder_max))
    return pd.update(x[..., m.IPSI], x[..., m.IR], psi_c, 1.0)


def loop_rhs(loop, x, d, y_pred=0.0):
    """Closed-loop derivative: model + PD + (follower) LOS about a path due north; y_pred is the
    predecessor's cross-track (0 for the leader)."""
    m = loop.model
    psi_c = follower_heading_straight(0.0, x[..., m.IY], y_pred, d)
    return m.rhs(x, m.inputs(rudder_law(loop, x, psi_c)))


def loop_step(loop, x, d, dt, y_pred=0.0):
    """One sampled step: rudder computed at the start and held over dt (as the simulator)."""
    m = loop.model
    psi_c = follower_heading_straight(0.0, x[..., m.IY], y_pred, d)
    return m.step(x, m.inputs(rudder_law(loop, x, psi_c)), dt)


def _free(loop):
    """State indices that evolve: all but north (no dynamics depends on it)."""
    return [i for i in range(loop.model.n_states) if i != loop.model.IX]


def equilibrium(loop, d):
    """Straight-running equilibrium of the LOS loop with look-ahead d (m), full state (north 0).

    Solved by least squares on the closed-loop derivative without the north component; for a
    model whose speed is a constant (Nomoto) that state simply stays at its trim value."""
    m = loop.model
    x0 = np.asarray(m.initial_state(), dtype=float)
    free = _free(loop)

    def resid(z):
        x = x0.copy()
        x[free] = z
        return loop_rhs(loop, x, d)[free]

    sol = least_squares(resid, x0[free], method='lm', xtol=1e-15, ftol=1e-15, gtol=1e-15)
    x = x0.copy()
    x[free] = sol.x
    if np.max(np.abs(resid(sol.x))) > 1e-9:
        raise RuntimeError(f'{loop.name}: no equilibrium found for d = {d} m')
    return x


def sampled_eigenvalues(loop, d, dt, x_eq=None):
    """Continuous-time equivalents log(mu)/dt of the eigenvalues mu of the one-step map's
    Jacobian at the equilibrium (central differences). States whose derivative is identically
    zero (a constant speed) are parameters and left out."""
    x_eq = equilibrium(loop, d) if x_eq is None else x_eq
    free = _free(loop)
    n = len(free)
    jac = np.zeros((n, n))
    for j, k in enumerate(free):
        h = 1e-6 * max(1.0, abs(x_eq[k]))
        xp, xm = x_eq.copy(), x_eq.copy()
        xp[k] += h
        xm[k] -= h
        jac[:, j] = (loop_step(loop, xp, d, dt)[free] - loop_step(loop, xm, d, dt)[free]) / (2 * h)
    # A state whose derivative is zero at every perturbed state is a constant (Nomoto's u, v).
    rng = np.random.default_rng(0)
    probes = x_eq + 1e-3 * rng.standard_normal((4, len(x_eq)))
    moving = np.any(loop_rhs(loop, probes, d)[:, free] != 0.0, axis=0)
    keep = np.flatnonzero(moving)
    mu = np.linalg.eigvals(jac[np.ix_(keep, keep)])
    return np.log(mu.astype(complex)) / dt


def dominant_pair(lams):
    """The oscillatory eigenvalue with the largest real part (positive imaginary part)."""
    lams = np.asarray(lams)
    osc = lams[lams.imag > 1e-12]
    return osc[np.argmax(osc.real)]


def doc_eigenvalues(loop, d):
    """Angelopoulos 2011 eq. 30 (dimensional: y' = U psi) eigenvalues for look-ahead d."""
    return np.linalg.eigvals(single_vessel_matrix(loop.zeta, loop.omega_n, d, loop.speed))


def sampled_critical_lookahead(loop, dt, lo=0.5, hi=2.0, rtol=1e-6):
    """Look-ahead where the sampled loop's dominant pair crosses the imaginary axis, by
    bisection between lo d* (unstable) and hi d* (stable)."""
    def re(d):
        return dominant_pair(sampled_eigenvalues(loop, d, dt)).real
    a, b = lo * loop.d_crit, hi * loop.d_crit
    if not (re(a) > 0.0 > re(b)):
        raise RuntimeError(f'{loop.name}: no stability change between {a:.1f} and {b:.1f} m')
    while b - a > rtol * b:
        mid = 0.5 * (a + b)
        a, b = (a, mid) if re(mid) < 0.0 else (mid, b)
    return b


# ---------------------------------------------------------------- the platoon

def simulate_platoon(loop, lookaheads, t_end, dt, y0, stop_amplitude=np.inf, x_dev=None):
    """Simulate platoons of identical vessels on a path due north, all cases in one batch.

    lookaheads: (C, N) array, one row per case: d1 of the leader, then the initial gaps (the
    followers' look-aheads). The leader starts y0 (m) east of its equilibrium, the others at
    theirs. x_dev (C, N, 3), optional: further deviations (cross-track m, heading rad, yaw rate
    rad/s) of every vessel from its equilibrium at the start (Angelopoulos 2011 Figs. 17-21
    start both vessels off the path). A case whose deviation exceeds stop_amplitude (m; scalar
    or one per case) is stopped: from then on it is
    held at its initial state and recorded as NaN. The follower law's look-ahead is the measured
    gap, floored at half the initial gap (as FollowerGuidance's min_lookahead; it acts only far
    outside the linear regime).
    Returns dict t (T,), dy (T, C, N) cross-track deviation from equilibrium, y_eq (C, N),
    stopped_at (C,) time of the stop or NaN."""
    m = loop.model
    d = np.atleast_2d(np.asarray(lookaheads, dtype=float))
    c, n = d.shape
    x = np.zeros((c, n, m.n_states))
    y_eq = np.zeros((c, n))
    for ci in range(c):
        ahead = offset = 0.0
        for i in range(n):
            xe = equilibrium(loop, d[ci, i])
            offset += xe[m.IY]          # follower i: y_{i-1} + y_eq(d_i)
            x[ci, i] = xe
            x[ci, i, m.IY] = y_eq[ci, i] = offset
            x[ci, i, m.IX] = -ahead
            if i + 1 < n:
                ahead += d[ci, i + 1]
    x[:, 0, m.IY] += y0
    if x_dev is not None:
        dev = np.broadcast_to(np.asarray(x_dev, dtype=float), (c, n, 3))
        x[..., m.IY] += dev[..., 0]
        x[..., m.IPSI] += dev[..., 1]
        x[..., m.IR] += dev[..., 2]
    x0 = x.copy()
    d_min = 0.5 * d[:, 1:]
    stop = np.broadcast_to(np.asarray(stop_amplitude, dtype=float), (c,))
    pd = PDAutopilot(loop.k1, loop.k2, RudderLimiter(m.rudder_max))
    steps = int(round(t_end / dt))
    dys = np.full((steps + 1, c, n), np.nan)
    stopped_at = np.full(c, np.nan)
    live = np.ones(c, dtype=bool)
    psi_c = np.empty((c, n))
    for k in range(steps + 1):
        north, east, psi = x[..., m.IX], x[..., m.IY], x[..., m.IPSI]
        dy = east - y_eq
        dys[k, live] = dy[live]
        over = live & ~(np.max(np.abs(dy), axis=1) <= stop)   # NaN counts as over
        if over.any():
            live &= ~over
            stopped_at[over] = k * dt
            x[over] = x0[over]
            if not live.any():
                dys = dys[:k + 1]
                break
        if k == steps:
            break
        psi_c[:, 0] = follower_heading_straight(0.0, east[:, 0], 0.0, d[:, 0])
        gap = np.maximum(north[:, :-1] - north[:, 1:], d_min)
        psi_c[:, 1:] = follower_heading_straight(0.0, east[:, 1:], east[:, :-1], gap)
        rudder = pd.update(psi, x[..., m.IR], psi_c, dt)
        x = m.step(x, m.inputs(rudder), dt)
        x[~live] = x0[~live]
    return {'t': dt * np.arange(len(dys)), 'dy': dys, 'y_eq': y_eq, 'stopped_at': stopped_at}


def linear_string_response(zeta, omega_n, lookaheads, x0, t_end, dt, speed=1.0):
    """The document's own platoon (Angelopoulos 2011 eq. 36 for N vessels:
    ship_guidance.string_stability.string_matrix) from the initial state x0 (psi_i, r_i, y_i per
    vessel, as the thesis's Simulink runs of Figs. 17-21), exactly: x_{k+1} = expm(A dt) x_k.
    Non-dimensional with speed = 1 (lengths in L, time in L/U). Returns t (T,) and x (T, 3N)."""
    from scipy.linalg import expm
    a = string_matrix(zeta, omega_n, lookaheads, speed)
    step = expm(a * dt)
    steps = int(round(t_end / dt))
    x = np.empty((steps + 1, a.shape[0]))
    x[0] = np.asarray(x0, dtype=float)
    for k in range(steps):
        x[k + 1] = step @ x[k]
    return dt * np.arange(steps + 1), x


def envelope_peaks(t, y):
    """Envelope samples of an oscillation y(t) about a possibly drifting mean: half the
    difference between consecutive extrema (each refined by a parabola through three samples),
    at the mid time. Returns arrays (t_k, A_k)."""
    y = np.asarray(y, dtype=float)
    slope = np.diff(y)
    k = np.nonzero(slope[:-1] * slope[1:] < 0.0)[0] + 1
    y0, y1, y2 = y[k - 1], y[k], y[k + 1]
    den = y0 - 2.0 * y1 + y2
    off = 0.5 * (y0 - y2) / den
    h = t[1] - t[0]
    te, ve = t[k] + off * h, y1 - 0.25 * (y0 - y2) * off
    return 0.5 * (te[1:] + te[:-1]), 0.5 * np.abs(np.diff(ve))


def envelope_rate(t, y, t_skip, floor=0.0, ceiling=np.inf, power=0):
    """Growth rate sigma (1/s) of the envelope of y(t): least squares of
    log A_k - power log t_k = c + sigma t_k over the peaks with t_k >= t_skip and
    floor < A_k < ceiling. Returns (sigma, number of peaks used); NaN if fewer than 4."""
    tk, ak = envelope_peaks(t, y)
    sel = (tk >= t_skip) & (ak > floor) & (ak < ceiling)
    if np.count_nonzero(sel) < 4:
        return math.nan, int(np.count_nonzero(sel))
    tk, ak = tk[sel], ak[sel]
    slope = np.polyfit(tk, np.log(ak) - power * np.log(tk), 1)[0]
    return float(slope), int(tk.size)
