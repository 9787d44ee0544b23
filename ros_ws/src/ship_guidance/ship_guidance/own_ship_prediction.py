"""Simple identified prediction model of the own ship for collision avoidance (pure, vectorised).

Scenario-based MPC (Johansen, Perez and Cristofaro 2016) predicts every candidate command with a
cheap model of the ship under its own autopilot rather than the full plant:

- course: the ship's first-order Nomoto yaw response under its heading autopilot (Nomoto et al.
  1957, Fossen 2011 Ch. 7). The autopilot's PD law, placed at the natural frequency omega_n and
  damping zeta of its design, demands the rudder whose steady turn rate is

      r_d = clip(omega_n^2 T (chi_c - chi) - (2 zeta omega_n T - 1) r, -r_max, r_max)

  (r_max = K delta_max, the full-rudder steady turn), and the turn rate follows it with the
  Nomoto time constant T: r_dot = (r_d - r) / T, chi_dot = r. Unsaturated this is the
  closed loop chi'' + 2 zeta omega_n chi' + omega_n^2 chi = omega_n^2 chi_c the autopilot was
  designed for (ship_guidance.heading_loop); saturated, the turn rate builds up from the
  current one towards r_max with T (the MSS tanker at 12 kn, T 212 s, needs minutes to reach
  its steady turn, which a model turning at r_max from the first second put 25 deg ahead of
  the plant after 4 min). r_d is held over each prediction step and the linear lag integrated
  exactly over it (a zero-order hold), the steps all scenarios at once. A rudder in the
  propeller race loses authority when the shaft slows: r_d is scaled by
  a = a_0 + (1 - a_0) P for the speed multiplier P of the scenario, a_0 the authority with the
  shaft stopped (the MSS tanker's rudder inflow is c^2 = cun u n + cnn n^2: stopped, it kept
  0.31 of its full-rudder turn over the first 2 min, the container 0.66);
- speed: a first-order response towards the commanded speed, less the speed a turn costs,

      u_dot = (u_c - u) / T_u - k u r^2,

  the surge equation's coupling (m + X_vr) v r with the sway velocity of a turn proportional to
  u r (drift angle ~ r, linear sway-yaw theory), lumped into one constant k (s) identified on
  the plant in a full-rudder turn (its accuracy against the MSS plants: doc/colav.md). r is
  the course model's mean turn rate over each prediction step, held over the step, and the
  linear ODE integrated exactly over it;
- position: the NED velocity (u cos chi, u sin chi) integrated by the trapezoidal rule on the
  prediction grid, so a prediction restarted on the grid reproduces the samples of a longer one.

Targets move in straight lines at their current velocity. Every constant is a field of
``OwnShipModel`` (``from_nomoto`` derives the course constants of an identified Nomoto model, e.g.
ship_autopilot/data/nomoto_gains.yaml; the launcher passes them, this package cannot import
ship_autopilot). Shapes: S scenarios, M targets, N + 1 samples at t = 0, dt, ..., N dt.
"""
from dataclasses import dataclass, fields

import numpy as np

from ship_sim import kernels
from ship_sim.frames import wrap_angle

from . import own_ship_prediction_compiled as _compiled


@dataclass(frozen=True)
class OwnShipModel:
    """Constants of the prediction model (SI units, rad).

    Defaults: the mariner at its identification speed. ``course_time_constant_s`` is its
    identified Nomoto T (the turn rate's lag) and ``max_turn_rate`` its K times the 40 deg
    rudder limit (ship_autopilot/data/nomoto_gains.yaml, rounded); ``heading_loop_omega_n`` and
    ``heading_loop_zeta`` the design of its PD autopilot (ship_autopilot/data/
    autopilot_gains.yaml: omega_n = U / L, zeta 0.8); ``speed_time_constant_s`` is the linear
    surge time constant of the MSS mariner, (m' - X_udot') / |X_u'| L / U (coefficients in
    ship_sim/models/mariner.py)."""
    course_time_constant_s: float = 28.0
    max_turn_rate: float = 0.0587 * np.deg2rad(40.0)
    heading_loop_omega_n: float = 0.048
    heading_loop_zeta: float = 0.8
    speed_time_constant_s: float = 95.0
    #: Turn authority with the shaft stopped, relative to the shaft at the nominal command
    #: (1: the rudder does not depend on the shaft, e.g. a ship without a shaft command).
    stop_turn_authority: float = 1.0
    #: Speed through the water at speed factor 1 (m/s); None: the current speed is taken as the
    #: speed of the nominal command.
    speed_at_factor_one_mps: float | None = None
    #: False for ships without a shaft (speed) command: only speed factor 1 is considered.
    has_shaft: bool = True
    #: Speed lost in a turn: k (s) in u_dot = (u_c - u) / T_u - k u r^2 (0: none modelled).
    turn_speed_loss_s: float = 0.0

    def __post_init__(self):
        for name in ('course_time_constant_s', 'max_turn_rate', 'heading_loop_omega_n',
                     'heading_loop_zeta', 'speed_time_constant_s'):
            if not getattr(self, name) > 0.0:
                raise ValueError(f'{name} = {getattr(self, name)!r} must be > 0')
        if not 0.0 <= self.stop_turn_authority <= 1.0:
            raise ValueError(f'stop_turn_authority = {self.stop_turn_authority!r} must lie in [0, 1]')
        if not self.turn_speed_loss_s >= 0.0:
            raise ValueError(f'turn_speed_loss_s = {self.turn_speed_loss_s!r} must be >= 0')

    @classmethod
    def from_dict(cls, values):
        """From a flat mapping holding some of the fields (e.g. the node's parameters; other keys
        are ignored); ``speed_at_factor_one_mps`` <= 0 means None."""
        out = {f.name: values[f.name] for f in fields(cls) if f.name in values}
        if out.get('speed_at_factor_one_mps') is not None and out['speed_at_factor_one_mps'] <= 0.0:
            out['speed_at_factor_one_mps'] = None
        return cls(**out)

    @classmethod
    def from_nomoto(cls, K, T, rudder_max, **kwargs):
        """The model of a ship with first-order Nomoto gains K (1/s), T (s) and rudder limit (rad)."""
        return cls(course_time_constant_s=float(T), max_turn_rate=float(abs(K) * rudder_max), **kwargs)

    def turn_authority(self, multipliers):
        """(S,) scale of the demanded turn rate at speed multipliers P (module doc)."""
        a0 = self.stop_turn_authority
        return a0 + (1.0 - a0) * np.asarray(multipliers, dtype=float)

    @property
    def heading_gain(self):
        """Demanded turn rate per rad of course error (1/s): omega_n^2 T."""
        return self.heading_loop_omega_n ** 2 * self.course_time_constant_s

    @property
    def rate_gain(self):
        """Demanded turn rate taken off per unit of turn rate: 2 zeta omega_n T - 1."""
        return 2.0 * self.heading_loop_zeta * self.heading_loop_omega_n * \
            self.course_time_constant_s - 1.0


def time_grid(horizon_s, dt_s):
    """Sample times 0, dt, ..., N dt with N = round(horizon / dt)."""
    n = int(round(horizon_s / dt_s))
    if n < 1:
        raise ValueError(f'horizon_s = {horizon_s} must hold at least one step of dt_s = {dt_s}')
    return np.arange(n + 1) * float(dt_s)


def course_response(chi0, chi_c, t, model, r0=0.0, with_rate=False, authority=1.0):
    """(S, N+1) predicted courses (rad, not wrapped) for commanded courses ``chi_c`` (S,), from
    course ``chi0`` turning at ``r0`` (rad/s), on the grid ``t``, with the turn authority
    (scalar or (S,), ``OwnShipModel.turn_authority``) (module doc); with ``with_rate`` also the
    (S,) turn rates at the last sample (to restart a prediction there)."""
    chi_c = np.asarray(chi_c, dtype=float)
    e0 = wrap_angle(chi_c - chi0)            # the shorter way round, as the autopilot turns
    T, r_max = model.course_time_constant_s, model.max_turn_rate
    g_e, g_r = model.heading_gain, model.rate_gain
    dt = np.diff(t)
    lag = np.exp(-dt / T)                    # r's decay over each step
    gain = T * (1.0 - lag)                   # its course increment per unit rate
    err = np.empty((chi_c.size, t.size))     # chi_c - chi, from e0 (the wrap kept out)
    if kernels.compiled():                   # the loop below, per scenario, compiled
        a = np.broadcast_to(np.asarray(authority, dtype=float), chi_c.shape)
        r = _compiled.course_errors(np.ascontiguousarray(e0, dtype=float), float(r0),
                                    np.ascontiguousarray(a), dt, lag, gain, float(g_e),
                                    float(g_r), float(r_max), err)
        chi = chi0 + e0[:, None] - err
        return (chi, r) if with_rate else chi
    err[:, 0] = e0
    e = err[:, 0].copy()
    r = np.full(chi_c.shape, float(r0))
    for n in range(dt.size):
        r_d = authority * np.clip(g_e * e - g_r * r, -r_max, r_max)
        e -= r_d * dt[n] + (r - r_d) * gain[n]
        r = r_d + (r - r_d) * lag[n]
        err[:, n + 1] = e
    chi = chi0 + e0[:, None] - err
    return (chi, r) if with_rate else chi


def speed_response(u0, u_c, t, model, chi=None):
    """(S, N+1) predicted speeds (m/s) for commanded speeds ``u_c`` (S,), on the courses ``chi``
    (S, N+1) of ``course_response`` (their turn rates cost speed, module doc; None: straight)."""
    u_c = np.asarray(u_c, dtype=float)[:, None]
    inv_tu = 1.0 / model.speed_time_constant_s
    if chi is None or model.turn_speed_loss_s == 0.0 or t.size < 2:
        return u_c + (u0 - u_c) * np.exp(-t * inv_tu)
    # per step n: u_dot = -a_n u + u_c / T_u, a_n = 1 / T_u + k r_n^2 held, so
    # u_{n+1} = e_n u_n + (1 - e_n) u_c / (T_u a_n), e_n = exp(-a_n dt_n); unrolled with
    # E_n = e_0 ... e_{n-1}: u_n = E_n (u_0 + sum_{j<n} (1 - e_j) u_c / (T_u a_j) / E_{j+1})
    dt = np.diff(t)
    a_dt = (inv_tu + model.turn_speed_loss_s * (np.diff(chi, axis=1) / dt) ** 2) * dt   # (S, N)
    big_e = np.exp(-np.cumsum(a_dt, axis=1))
    gain = -np.expm1(-a_dt) * (u_c * inv_tu * dt / a_dt) / big_e
    u = np.empty(chi.shape)
    u[:, 0] = u0
    u[:, 1:] = big_e * (u0 + np.cumsum(gain, axis=1))
    return u


def predict_own(north, east, chi0, u0, chi_c, u_c, t, model, r0=0.0, authority=1.0,
                with_speed=False):
    """(S, N+1, 2) NED positions and (S, N+1) courses of the own ship under each command, from
    course ``chi0`` turning at ``r0`` (rad/s) and speed ``u0``, with the turn ``authority``;
    with ``with_speed`` also the (S, N+1) speeds (``speed_response`` on those courses)."""
    chi = course_response(chi0, chi_c, t, model, r0, authority=authority)
    u = speed_response(u0, u_c, t, model, chi)
    v = np.stack((u * np.cos(chi), u * np.sin(chi)), axis=-1)
    dt = np.diff(t)[None, :, None]
    steps = 0.5 * dt * (v[:, 1:] + v[:, :-1])
    p = np.concatenate((np.zeros_like(v[:, :1]), np.cumsum(steps, axis=1)), axis=1)
    p += np.array([north, east], dtype=float)
    return (p, chi, u) if with_speed else (p, chi)


def predict_targets(p_targets, v_targets, t):
    """(M, N+1, 2) straight-line positions of targets at (M, 2) positions with (M, 2) velocities."""
    return np.asarray(p_targets, float)[:, None, :] + np.asarray(v_targets, float)[:, None, :] * t[None, :, None]


def segment_min_distance(p_own, p_targets):
    """Closest approach on each prediction step, both ships moving linearly within the step.

    ``p_own`` (S, N+1, 2), ``p_targets`` (M, N+1, 2) -> (distance (S, M, N) m, fraction (S, M, N)
    of the step at which it occurs, in [0, 1], relative displacement over the step (S, M, N) m).
    Sampling alone would miss the closest point of a fast pass between two samples."""
    ox, oy = np.ascontiguousarray(p_own[..., 0]), np.ascontiguousarray(p_own[..., 1])
    tx, ty = np.ascontiguousarray(p_targets[..., 0]), np.ascontiguousarray(p_targets[..., 1])
    if kernels.compiled():
        out = np.empty((3, ox.shape[0], tx.shape[0], ox.shape[1] - 1))
        _compiled.segment_min_distance(ox, oy, tx, ty, out[0], out[1], out[2])
        return out[0], out[1], out[2]
    x0 = tx[None, :, :-1] - ox[:, None, :-1]                  # (S, M, N) target from own
    y0 = ty[None, :, :-1] - oy[:, None, :-1]
    dx = np.diff(tx, axis=-1)[None] - np.diff(ox, axis=-1)[:, None]
    dy = np.diff(ty, axis=-1)[None] - np.diff(oy, axis=-1)[:, None]
    dd = dx * dx
    dd += dy * dy
    s = x0 * dx
    s += y0 * dy
    np.negative(s, out=s)
    np.divide(s, dd, out=s, where=dd > 0.0)
    np.clip(s, 0.0, 1.0, out=s)                               # 0 where the ships keep station
    dx *= s
    dx += x0
    dy *= s
    dy += y0
    dx *= dx
    dy *= dy
    dx += dy
    return np.sqrt(dx, out=dx), s, np.sqrt(dd, out=dd)
