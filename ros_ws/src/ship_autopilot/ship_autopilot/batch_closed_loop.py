"""Many closed-loop episodes in one process, stepped together as arrays (Monte Carlo; pure).

N episodes of one plant model, each with its own route, start, current, guidance and gains:

    plant (learning.env.PathFollowingBatch: MSS RK4, current added to the kinematics, optional
           wind loads in the model's force equations; optional wave-frequency motion
           superposed on what everything downstream measures, ship_sim.environment.sea_state)
    -> guidance (ship_guidance.batch_guidance.BatchGuidance: LOS / ILOS [+ turn-rate lead])
    -> autopilot (PD or fuzzy PID, ship_autopilot.controller on arrays; optionally behind
       the wave filter, ship_autopilot.wave_filter on arrays), or the learned policy
       (learning.policy, numpy MLP on the eq. 9 path state, at its own control step)
    -> rudder command back into the plant, every ``sim_dt``.

It is the loop of scripts/evaluate_controllers.py (Table I of Martinsen and Lekkas 2018) for
many episodes at once: the same modules, the same order of operations, so each episode equals
that single-vessel loop to rounding (tests/unit/test_batch_closed_loop.py), and through it the
node graph in lockstep (tests/integration/test_closed_loop.py). No Python loop runs over
the vessels per step (the plant, guidance, PD autopilot and metrics run compiled per vessel
when ship_sim.kernels selects numba: doc/guide/kernels.md), and memory is O(N): metrics are
running sums, the optional log is preallocated and decimated.

    loop = BatchClosedLoop('mariner', [route], controller='pd', law='ilos')
    result = loop.run(episodes, duration=1000.0)      # result.metrics: arrays of length N

``episodes``: a dict of equally long arrays (or scalars, broadcast): start ``route`` (index
into ``routes``), ``along`` (m of arc length), ``cross`` (m, + starboard), ``heading`` (rad,
relative to the path), ``current_speed`` (m/s), ``current_direction`` (rad, flowing towards,
NED); optional per-episode ``lookahead`` (m; default 2.5 ship lengths), ``integral_gain``
(m/s, ILOS; default U / 4), ``lead`` (s, turn-rate lead 2 zeta U / omega_n; default 0), ``k1``,
``k2`` (PD gains; default the gain table's). Metrics per episode (``METRICS``): cumulative
Gaussian reward (Martinsen and Lekkas 2018 eq. 8, every sample after the start), cross-track
mean / RMS / max |e| (m) and mean and max |e| over the second half, rudder activity (mean
|rudder rate| deg/s, total variation deg, fraction of samples at the limit, mean |rudder|
deg), completion (route end reached, and when), and whether the
state left the model's domain (that episode's plant then stays at its last valid state).
"""
import math
import resource
import time
from dataclasses import dataclass, field

import numpy as np

from ship_guidance.batch_guidance import BatchGuidance
from ship_guidance.path_state import PathFeatures
from ship_sim import kernels

from .compiled import metrics_step
from .gains import autopilot_gains, build_autopilot
from .learning.env import EnvConfig, PathFollowingBatch, start_states
from .learning.policy import load_policy
from .learning.reward import gaussian_reward

CONTROLLERS = ('pd', 'fuzzy_pid', 'policy')
#: Default look-ahead (ship lengths) and ILOS gain (fraction of the speed), as Table I's.
LOOKAHEAD_SHIP_LENGTHS = 2.5
INTEGRAL_SPEED_FRACTION = 0.25
START_KEYS = ('route', 'along', 'cross', 'heading', 'current_speed', 'current_direction')
PARAM_KEYS = ('lookahead', 'integral_gain', 'lead', 'k1', 'k2')
METRICS = ('gaussian', 'mean_abs_e', 'rms_e', 'max_abs_e', 'mean_abs_e_settled',
           'max_abs_e_settled', 'rudder_rate_deg_s', 'rudder_tv_deg',
           'rudder_saturated_fraction', 'mean_abs_rudder_deg', 'finished', 'finish_time_s',
           'failed')
LOG_FIELDS = ('north', 'east', 'psi', 'rudder', 'rudder_cmd', 'cross_track', 'heading_cmd')


@dataclass
class BatchResult:
    """``metrics``: name -> array (N,) (METRICS); ``log``: name -> array (n_log, N) of
    LOG_FIELDS every ``log_every`` steps, with ``log['t']`` (n_log,) (empty without a log)."""
    metrics: dict
    log: dict = field(default_factory=dict)
    steps: int = 0
    #: Wall time (s) of the set-up (starts, first projections) and of the stepping, and the
    #: stepping's CPU time (process_time): for throughput figures and progress estimates.
    setup_s: float = 0.0
    loop_s: float = 0.0
    loop_cpu_s: float = 0.0
    #: Minor page faults of the process during the stepping (getrusage): memory the steps
    #: map afresh rather than reuse (ship_sim.allocator).
    loop_minor_faults: int = 0


def _episode_arrays(episodes, keys):
    """Dict of arrays -> (N, {key: array (N,)}); a list of dicts is accepted too."""
    if isinstance(episodes, (list, tuple)):
        episodes = {k: [e[k] for e in episodes] for k in episodes[0]} if episodes else {}
    unknown = set(episodes) - set(keys)
    if unknown:
        raise ValueError(f'unknown episode keys {sorted(unknown)}; allowed: {", ".join(keys)}')
    n = max((np.size(v) for v in episodes.values()), default=0)
    if n == 0:
        raise ValueError('no episodes given')
    out = {}
    for k, v in episodes.items():
        a = np.asarray(v, dtype=int if k == 'route' else float)
        if a.ndim > 1 or (a.ndim == 1 and len(a) != n):
            raise ValueError(f'episode key {k!r} has {np.size(a)} values, expected 1 or {n}')
        out[k] = np.broadcast_to(a, (n,)).copy()
    missing = [k for k in START_KEYS if k not in out]
    if missing:
        raise ValueError(f'episodes need {", ".join(START_KEYS)}; missing {missing}')
    return n, out


class BatchClosedLoop:
    """Closed-loop episodes of ``model`` on ``routes`` (list of ship_guidance.path.Route).

    ``controller``: 'pd' (with ``law`` 'los' or 'ilos'), 'fuzzy_pid' (LOS or ILOS), or
    'policy' (the shipped policy of the model, or ``policy`` = a loaded learning.policy.Policy
    or a path). ``gains``: an autopilot_gains.yaml entry (default the model's).
    ``acceptance_radius`` (m), ``corner_angle`` (rad): the guidance's, per batch.
    """

    def __init__(self, model, routes, controller='pd', law='ilos', *, sim_dt=0.1, gains=None,
                 policy=None, acceptance_radius=0.0, corner_angle=math.radians(1.0)):
        if controller not in CONTROLLERS:
            raise ValueError(f'controller = {controller!r}; allowed: {", ".join(CONTROLLERS)}')
        self.routes = list(routes)
        if not self.routes:
            raise ValueError('give at least one route')
        self.controller, self.law = controller, law
        self.sim_dt = float(sim_dt)
        self.config = EnvConfig(mode='straight', sim_dt=self.sim_dt, control_dt=self.sim_dt)
        self._model = model
        probe = PathFollowingBatch(model, 1, self.config, routes=self.routes[:1])
        self.model = probe.model
        self.speed, self.length = probe.speed0, probe.length
        self.gains = autopilot_gains(self.model.name) if gains is None else gains
        self.policy = None
        if controller == 'policy':
            self.policy = (load_policy(self.model.name, policy) if not hasattr(policy, 'action')
                           else policy)
        self.guidance_options = {'acceptance_radius': acceptance_radius,
                                 'corner_angle': corner_angle}

    def defaults(self):
        """Per-episode parameters used when ``episodes`` leaves them out."""
        g = self.gains.get('pd', self.gains)
        return {'lookahead': LOOKAHEAD_SHIP_LENGTHS * self.length,
                'integral_gain': INTEGRAL_SPEED_FRACTION * self.speed, 'lead': 0.0,
                'k1': g.get('k1', math.nan), 'k2': g.get('k2', math.nan)}

    # -- set-up --------------------------------------------------------------------------------
    def _plant(self, n, ep, wind=None):
        env = PathFollowingBatch(self._model, n, self.config, routes=self.routes, wind=wind)
        env.x, env.current = start_states(env.model, env.x0, self.routes,
                                          **{k: ep[k] for k in START_KEYS})
        return env

    def _guidance(self, ep, n):
        """[(vessel index or slice, BatchGuidance)], one per route in use."""
        law = 'ilos' if (self.law == 'ilos' and self.controller != 'policy') else 'los'
        groups = []
        used = np.unique(ep['route'])
        for r in used.tolist():
            idx = slice(None) if len(used) == 1 else np.flatnonzero(ep['route'] == r)
            groups.append((idx, BatchGuidance(
                self.routes[r], n if len(used) == 1 else len(idx), law,
                ep['lookahead'][idx], integral_gain=ep['integral_gain'][idx],
                lead=ep['lead'][idx], **self.guidance_options)))
        return groups

    def _autopilot(self, ep):
        m = self.model
        if self.controller == 'pd':
            gains = {'k1': ep['k1'], 'k2': ep['k2']}
            return build_autopilot('pd', gains, m.rudder_max, m.rudder_rate_max)
        return build_autopilot('fuzzy_pid', self.gains, m.rudder_max, m.rudder_rate_max)

    # -- the loop ------------------------------------------------------------------------------
    def run(self, episodes, duration, log_every=0, wind=None, waves=None, current=None,
            wave_filter=None):
        """Run every episode for ``duration`` s; -> BatchResult. ``log_every``: log every that
        many steps (0: no log). ``wind``: a ship_sim.environment.wind.WindField of shape (N,)
        (its loads enter the plant); ``waves``: a batch ship_sim.environment.sea_state.ShipWaves
        of N sea states, whose wave-frequency motion is superposed on what the guidance, the
        autopilot or policy and the metrics measure (PathFollowingBatch.measured);
        ``wave_filter``: a ship_autopilot.wave_filter.WaveFilter of N filters (with waves,
        PD or fuzzy PID) between the measured heading and yaw rate and the autopilot (the
        guidance and the metrics keep the measured ones), as scripts/evaluate_controllers.run
        and the autopilot node place it. ``current``: a ship_sim.current.OceanCurrent of shape
        (N,) (a Gauss-Markov current per episode, e.g. one seed each) that sets the plant's
        current before every step and is then advanced by it, as in the single-vessel loop (it
        replaces the episodes' constant current from the first step on; give the same nominal
        values there)."""
        t_setup = time.perf_counter()
        n, ep = _episode_arrays(episodes, START_KEYS + PARAM_KEYS)
        for k, v in self.defaults().items():
            ep.setdefault(k, np.full(n, v))
        bad = (ep['route'] < 0) | (ep['route'] >= len(self.routes))
        if bad.any():
            raise ValueError(f'route index {ep["route"][bad][0]} outside 0..'
                             f'{len(self.routes) - 1}')
        n_steps = int(round(float(duration) / self.sim_dt))
        dt = self.sim_dt
        env = self._plant(n, ep, wind)
        m = self.model
        groups = self._guidance(ep, n)
        single = len(groups) == 1
        policy = self.policy
        autopilot = None if policy else self._autopilot(ep)
        if wave_filter is not None and (policy is not None or waves is None):
            raise ValueError('the wave filter needs waves and a PD or fuzzy PID autopilot')
        features = PathFeatures((n,)) if policy else None
        control_dt = policy.control_dt if policy else dt
        # Running metrics (O(N)).
        zeros = np.zeros
        gauss, sum_e, sum_e2, max_e, settled = zeros(n), zeros(n), zeros(n), zeros(n), zeros(n)
        rate_sum, abs_rud, max_settled, saturated = zeros(n), zeros(n), zeros(n), zeros(n)
        rudder_limit = m.rudder_max * (1 - 1e-9)
        finish_t = np.full(n, np.nan)
        failed = np.zeros(n, dtype=bool)
        rud_prev = np.array(m.rudder_angle(env.x), dtype=float)
        compiled = kernels.compiled()
        reward_defaults = gaussian_reward.__defaults__   # amplitude, sigma, yaw_error_max
        abs_rud += np.abs(rud_prev)
        settle_from = n_steps // 2
        log = self._new_log(n, n_steps, log_every)
        cmd = zeros(n)
        psi_c = np.full(n, np.nan)
        t_feat = -math.inf
        if single:
            e = gamma = kappa = None
        else:
            e, gamma, kappa, fin = zeros(n), zeros(n), zeros(n), zeros(n, dtype=bool)
            psi_c_all = zeros(n)
        for step in range(n_steps + 1):
            t = step * dt
            x = env.x
            north, east, psi, r = x[:, m.IX], x[:, m.IY], x[:, m.IPSI], x[:, m.IR]
            if waves is not None:
                north, east, psi, u_m, v_m, r = env.measured(waves, t)
            h = dt if step else 0.0
            if single:
                out = groups[0][1].update(north, east, h)
                e, gamma, kappa, fin, psi_c = (out.cross_track, out.path_angle, out.curvature,
                                               out.finished, out.heading_cmd)
            else:
                for idx, g in groups:
                    out = g.update(north[idx], east[idx], h)
                    e[idx], gamma[idx], kappa[idx] = out.cross_track, out.path_angle, \
                        out.curvature
                    fin[idx], psi_c_all[idx] = out.finished, out.heading_cmd
                psi_c = psi_c_all
            if not step:  # the first update searched the whole route: set-up, not stepping
                t_loop, c_loop = time.perf_counter(), time.process_time()
                f_loop = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
            new = fin & np.isnan(finish_t)
            if new.any():
                finish_t[new] = t
            if step and compiled:   # the same lines per vessel, compiled, in place
                metrics_step(e, psi - gamma, env.x, m.IDELTA, m.STATE_RUDDER_SIGN,
                             step - 1 >= settle_from, *reward_defaults, rudder_limit, gauss,
                             sum_e, sum_e2, max_e, settled, max_settled, rate_sum, saturated,
                             abs_rud, rud_prev)
            elif step:
                gauss += gaussian_reward(e, psi - gamma)
                a = np.abs(e)
                sum_e += a
                sum_e2 += e * e
                np.maximum(max_e, a, out=max_e)
                if step - 1 >= settle_from:
                    settled += a
                    np.maximum(max_settled, a, out=max_settled)
                rud = m.rudder_angle(env.x)
                rate_sum += np.abs(rud - rud_prev)
                saturated += np.abs(rud) >= rudder_limit
                abs_rud += np.abs(rud)
                rud_prev = rud
            if step == n_steps:
                if log:
                    self._log_row(log, step, log_every, t, x, m, rud_prev, cmd, e, psi_c)
                break
            if policy is not None:
                if t - t_feat >= control_dt - 1e-9:   # features at the policy's own step
                    u, v, r = env.ground_velocity() if waves is None else (u_m, v_m, r)
                    raw = features(e, gamma, kappa, psi, u, v, r,
                                   0.0 if t_feat == -math.inf else t - t_feat)
                    z, ok = policy.normalise(raw)
                    act = policy.action(z).astype(np.float64) * policy.action_scale
                    cmd = np.where(ok, act, cmd)
                    t_feat = t
            elif wave_filter is not None:
                psi_f, r_f = wave_filter.update(t, psi, r, np.hypot(u_m, v_m))
                cmd = np.asarray(autopilot.update(psi_f, r_f, psi_c, dt))
            else:
                cmd = np.asarray(autopilot.update(psi, r, psi_c, dt))
            if log:
                self._log_row(log, step, log_every, t, x, m, rud_prev, cmd, e, psi_c)
            if current is not None:
                env.current[:, 0], env.current[:, 1] = current.velocity_ne()
                current.advance(dt)
            ok = env.integrate(cmd, 1)
            if not ok.all():
                failed |= ~ok
        loop_s, loop_cpu_s = time.perf_counter() - t_loop, time.process_time() - c_loop
        loop_faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f_loop
        n_s = max(n_steps, 1)
        metrics = {
            'gaussian': gauss, 'mean_abs_e': sum_e / n_s, 'rms_e': np.sqrt(sum_e2 / n_s),
            'max_abs_e': max_e, 'mean_abs_e_settled': settled / max(n_steps - settle_from, 1),
            'max_abs_e_settled': max_settled,
            'rudder_rate_deg_s': np.degrees(rate_sum / n_s / dt),
            'rudder_tv_deg': np.degrees(rate_sum), 'rudder_saturated_fraction': saturated / n_s,
            'mean_abs_rudder_deg': np.degrees(abs_rud / (n_steps + 1)),
            'finished': ~np.isnan(finish_t), 'finish_time_s': finish_t, 'failed': failed}
        return BatchResult(metrics, log, n_steps, t_loop - t_setup, loop_s, loop_cpu_s,
                           loop_faults)

    # -- log -----------------------------------------------------------------------------------
    @staticmethod
    def _new_log(n, n_steps, every):
        if not every:
            return {}
        rows = n_steps // int(every) + 1
        log = {k: np.full((rows, n), np.nan) for k in LOG_FIELDS}
        log['t'] = np.full(rows, np.nan)
        return log

    @staticmethod
    def _log_row(log, step, every, t, x, m, rudder, cmd, e, psi_c):
        if step % every:
            return
        i = step // every
        log['t'][i] = t
        log['north'][i], log['east'][i], log['psi'][i] = x[:, m.IX], x[:, m.IY], x[:, m.IPSI]
        log['rudder'][i], log['rudder_cmd'][i] = rudder, cmd
        log['cross_track'][i], log['heading_cmd'][i] = e, psi_c
