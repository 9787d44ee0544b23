"""Path-following environment for learning a steering policy, batched and gymnasium.

Source: Martinsen and Lekkas 2018, "Curved path following with deep reinforcement learning:
results from three vessel models", Sec. III: episodes of 1000 s, the
vessel started at random within a bound of the path, unknown ocean current, state eq. 9
(ship_guidance.path_state), action = commanded rudder, reward eq. 8.

Reward (eq. 8; the functions are learning.reward's, which the run metrics use too). The OCR
reads "R(y_e, psi~, delta) = -c ... + {a exp(-y_e^2 / (2 sigma^2)) if |psi~| < ...; 0 otherwise}",
with a = 1, sigma = 10 m, psi~ "the angle between the yaw angle of the vessel and the path
heading", and the first term "a penalty to solutions that involve
fast rudder changes" (its symbols are unreadable). We implement, per control step k,

    r_k = a exp(-e_k^2 / (2 sigma^2)) [|wrap(psi_k - gamma_p,k)| <= psi_max]
          - c_delta ((delta_c,k - delta_c,k-1) / delta_max)^2

a = 1, sigma = 10 m (as printed); psi_max = 90 deg (our choice: "travels along the path in the
forward direction"); the penalty is on the change of the commanded rudder per control step as
a fraction of the model's rudder limit delta_max (the action's own scale, so one c_delta means
the same for every ship), c_delta = 0.1: reversing a full rudder (change 2) costs 0.4 per step,
a 10 % correction 0.001. (A first version normalised by the servo's rate limit instead; for
the Mariner, 40 deg at 5 deg/s, exploration noise alone then cost ~ -100 per episode, a term
the critic cannot predict because eq. 9 does not contain the previous command.)
``gaussian`` (the first term alone) is what Table I accumulates; ``info['gaussian']`` carries it.

Time steps (our choice, justified): the plant is integrated with MSS's RK4 at sim_dt = 0.1 s
(MSS's sample time h = 0.1 s); the policy acts every control_dt = 1 s (rudder held), so the
discount gamma = 0.99 of Martinsen and Lekkas 2018 spans ~100 s, the time scale of a ship's heading response,
and a 1000 s episode is 1000 transitions. The paper does not print its step; its Table I
(up to 3264 for a 1000 s episode with a per-sample reward <= 1) implies at least 3.3 samples
per second, consistent with the MSS step of 0.1 s: evaluation (scripts/evaluate_controllers.py)
therefore accumulates the Gaussian at every 0.1 s sample for every controller.

Episodes: ``episode_s`` = 1000 s (truncation, bootstrapped). Start: a random point on the path
within the first ``start_along_max`` = 1000 m, offset sideways uniformly within
+-``start_cross_max`` = 100 m, heading = path angle + uniform +-``start_heading_max`` = 20 deg,
straight-running trim at the model's nominal speed (and shaft). Ocean current: speed uniform
in [0, max_current] (0.9 m/s), direction uniform (flowing towards, NED), constant over the
episode and unknown to the agent (Fossen Sec. 8.3: drift added to the position; ship_sim.current).
An episode terminates (no bootstrap) when |e| > ``terminate_cross_track`` = 1000 m or the state
leaves the model's valid domain.

Paths: 'straight' = a line; 'curved' = sine curves about a straight base line (ship_planner
curves, as in scenarios/routes/curved_path_<model>_000.yaml), a pool of ``n_routes`` drawn once
per environment with amplitude, wavelength and phase randomised around the ship's nominal curve
(smallest radius of curvature kept >= 0.8 x the nominal one).

Wind (optional, evaluation under disturbances; training never used it): ``wind`` a
ship_sim.environment.wind.WindField of shape () or (N,); its loads (relative wind from the
velocity over ground minus still air's, ship_sim.environment.wind.wind_disturbance) are
computed at the start of every sim step, held over it and enter the model's own force
equations, then the gusts advance: the same step as ship_sim.simulator's. Without it the
integration is the computation it always was.

Classes: ``PathFollowingBatch`` steps N vessels of one model together (numpy batched RK4; the
vectorised variant used for training); ``PathFollowingEnv`` is the gymnasium.Env of one vessel on
the same core. Observations are float32 (9,) normalised states (path_state.normalise); actions
float32 in [-1, 1], scaled to the model's rudder limit, unified sign (positive turns to port).
"""
import math
from dataclasses import dataclass

import gymnasium
import numpy as np

from ship_guidance.path import Line, Route
from ship_guidance.path_state import CLIP, OBS_DIM, PathFeatures, default_scales, normalise
from ship_sim.environment.wind import wind_disturbance, wind_profile
from ship_sim import kernels
from ship_sim.models import card, make_model
from ship_sim.models.compiled import batch_rk4

from .reward import gaussian_reward, rudder_change_penalty

MODES = ('straight', 'curved')


@dataclass(frozen=True)
class EnvConfig:
    """Environment settings (SI units, rad). See the module docstring."""
    mode: str = 'curved'
    episode_s: float = 1000.0
    control_dt: float = 1.0
    sim_dt: float = 0.1
    reward_amplitude: float = 1.0
    reward_sigma: float = 10.0
    yaw_error_max: float = math.pi / 2
    rudder_change_penalty: float = 0.1
    max_current: float = 0.9
    start_along_max: float = 1000.0
    start_cross_max: float = 100.0
    start_heading_max: float = math.radians(20.0)
    terminate_cross_track: float = 1000.0
    n_routes: int = 16
    route_margin: float = 3000.0

    def __post_init__(self):
        if self.mode not in MODES:
            raise ValueError(f'mode = {self.mode!r}; allowed: {", ".join(MODES)}')
        n_sub = self.control_dt / self.sim_dt
        if not (self.sim_dt > 0 and self.control_dt > 0 and abs(n_sub - round(n_sub)) < 1e-9):
            raise ValueError(f'control_dt = {self.control_dt} s must be a positive multiple of '
                             f'sim_dt = {self.sim_dt} s')

    @property
    def substeps(self):
        return int(round(self.control_dt / self.sim_dt))


def make_curve_pool(model_name, speed, config, rng):
    """``config.n_routes`` sine Routes (NED) for ``model_name`` (see the module docstring)."""
    from ship_guidance.curves import sine_route  # only curved mode samples a curve
    # The card's nominal curve (amplitude m, wavelength m); the Mariner's if it states none.
    amp0, wave0 = card(model_name).nominal_curve or card('mariner').nominal_curve
    r_min0 = wave0 ** 2 / (4 * math.pi ** 2 * amp0)
    length = speed * config.episode_s + config.route_margin + config.start_along_max
    routes = []
    for _ in range(config.n_routes):
        wave = wave0 * rng.uniform(0.75, 1.5)
        amp = amp0 * rng.uniform(0.25, 1.25)
        amp = min(amp, wave ** 2 / (4 * math.pi ** 2 * 0.8 * r_min0))
        routes.append(sine_route(length, amp, wave, 10.0, phase=rng.uniform(0, 2 * math.pi)))
    return routes


def start_states(model, x0, routes, route, along, cross, heading, current_speed,
                 current_direction):
    """Start states of episodes (arrays, one entry each): the point ``along`` (m) of route
    ``routes[route]`` moved ``cross`` (m, + starboard) along the normal, heading = path angle
    + ``heading`` (rad), the rest of the state ``x0`` (the model's straight-running trim); and
    the constant current (v_north, v_east) (m/s) from its speed and direction (rad, flowing
    towards). -> (x (N, n_states), current (N, 2))."""
    route = np.asarray(route, dtype=int)
    x = np.repeat(np.asarray(x0, dtype=float)[None, :], len(route), axis=0)
    pn, pe, gamma = np.empty(len(route)), np.empty(len(route)), np.empty(len(route))
    for r in np.unique(route).tolist():
        sel = route == r
        pn[sel], pe[sel], gamma[sel] = routes[r].point_at(np.asarray(along, dtype=float)[sel])
    normal = gamma + 0.5 * math.pi          # starboard of the path direction
    m = model
    x[:, m.IX] = pn + cross * np.cos(normal)
    x[:, m.IY] = pe + cross * np.sin(normal)
    x[:, m.IPSI] = gamma + heading
    current = np.stack([current_speed * np.cos(current_direction),
                        current_speed * np.sin(current_direction)], axis=1)
    return x, current


class PathFollowingBatch:
    """N vessels of ``model`` following paths, stepped together (the vectorised core).

    ``reset(mask=None)`` starts new episodes (all, or where mask is True) and returns the
    observations (N, 9) float32; ``step(action (N,))`` advances every vessel one control step
    and returns (obs, reward, terminated, truncated, info) with arrays of length N; it does not
    reset finished vessels (call ``reset(done)``). ``routes`` may be given (list of Route) to
    replace the generated pool; ``starts`` in ``reset`` fixes start states (evaluation).
    ``wind``: an optional WindField (module docstring) with ``wind_coefficients``.
    """

    def __init__(self, model, n_envs=1, config=None, seed=0, routes=None, wind=None,
                 wind_coefficients='blendermann94'):
        self.config = config or EnvConfig()
        self.model = make_model(model) if isinstance(model, str) else model
        self.n = int(n_envs)
        m, c = self.model, self.config
        self.x0 = m.initial_state()
        self.speed0 = float(m.speed(self.x0))
        self.length = float(m.length)
        self.rudder_max = float(m.rudder_max)
        self.rudder_rate_max = float(m.rudder_rate_max)
        self.state_offset, self.state_scale = default_scales(self.speed0, self.length)
        self.rng = np.random.default_rng(seed)
        if routes is not None:
            self.routes = list(routes)
        elif c.mode == 'curved':
            self.routes = make_curve_pool(m.name, self.speed0, c, self.rng)
        else:
            length = self.speed0 * c.episode_s + c.route_margin + c.start_along_max
            self.routes = [Route([Line((0.0, 0.0), (length, 0.0))])]
        n = self.n
        self.x = np.repeat(self.x0[None, :], n, axis=0)
        self._buffers = []   # the compiled integration's state buffers (integrate)
        self.current = np.zeros((n, 2))           # (v_north, v_east), m/s
        self.route_index = np.zeros(n, dtype=int)
        self.s = np.zeros(n)                      # arc length of the closest point (m)
        self.t = np.zeros(n)
        self.prev_cmd = np.zeros(n)               # previous rudder command (rad, unified)
        self.features = PathFeatures((n,))
        self.proj = np.zeros((n, 3))              # cross_track, path_angle, curvature
        self.raw = np.zeros((n, OBS_DIM))
        self.wind, self.wind_coefficients = wind, wind_coefficients
        if wind is not None:
            if wind.shape not in ((), (n,)):
                raise ValueError(f'wind shape {wind.shape} does not match {n} vessels')
            self.wind_profile = wind_profile(m.name)

    # -- episodes ------------------------------------------------------------------------------
    def sample_starts(self, k):
        """k random start specifications (dicts) drawn from this env's rng (module docstring)."""
        c, rng = self.config, self.rng
        out = []
        for _ in range(k):
            speed = rng.uniform(0.0, c.max_current)
            out.append({'route': int(rng.integers(len(self.routes))),
                        'along': rng.uniform(0.0, c.start_along_max),
                        'cross': rng.uniform(-c.start_cross_max, c.start_cross_max),
                        'heading': rng.uniform(-c.start_heading_max, c.start_heading_max),
                        'current_speed': speed,
                        'current_direction': rng.uniform(-math.pi, math.pi)})
        return out

    def reset(self, mask=None, starts=None):
        """New episodes where ``mask`` (default all); ``starts``: one dict per reset vessel
        (keys route, along (m), cross (m, + starboard), heading (rad, relative to the path),
        current_speed (m/s), current_direction (rad, flowing towards)). Returns all obs."""
        idx = np.arange(self.n) if mask is None else np.flatnonzero(mask)
        if starts is None:
            starts = self.sample_starts(len(idx))
        if len(starts) != len(idx):
            raise ValueError(f'{len(starts)} starts given for {len(idx)} vessels')
        m = self.model
        keys = ('route', 'along', 'cross', 'heading', 'current_speed', 'current_direction')
        self.x[idx], self.current[idx] = start_states(
            m, self.x0, self.routes, **{k: np.array([st[k] for st in starts]) for k in keys})
        for i, st in zip(idx, starts):
            self.route_index[i] = st['route']
            self.s[i] = self.routes[st['route']].project(self.x[i, m.IX], self.x[i, m.IY]).s
            self.t[i] = 0.0
            self.prev_cmd[i] = 0.0
        reset_mask = np.zeros(self.n, dtype=bool)
        reset_mask[idx] = True
        self.features.reset(reset_mask)
        self._observe(idx, dt=np.zeros(self.n))
        return self.obs()

    # -- physics -------------------------------------------------------------------------------
    def ground_velocity(self, x=None):
        """(u, v, r) over ground, body FRD (m/s, m/s, rad/s): through-water velocity + current."""
        m = self.model
        x = self.x if x is None else x
        psi = x[:, m.IPSI]
        c, s = np.cos(psi), np.sin(psi)
        vn, ve = self.current[:, 0], self.current[:, 1]
        u = m.surge_speed(x) + c * vn + s * ve
        v = x[:, m.IV] - s * vn + c * ve
        return u, v, x[:, m.IR]

    def integrate(self, rudder_cmd, steps):
        """Advance all vessels ``steps`` x sim_dt with the rudder command held (rad, unified);
        returns a boolean array: the state stayed finite and in the model's domain."""
        m, h = self.model, self.config.sim_dt
        u_in = m.inputs(rudder_cmd)
        drift = self.current * h
        if self.wind is not None:
            x = self.x
            for _ in range(steps):
                x = m.step(x, u_in, h, loads=self.wind_loads(x))
                x[:, m.IX] += drift[:, 0]
                x[:, m.IY] += drift[:, 1]
                self.wind.advance(h)
        elif self.n == 1:  # the model's float fast path for one vessel
            x1, u1, d = self.x[0], u_in[0], drift[0]
            for _ in range(steps):
                x1 = m.step(x1, u1, h)
                x1[m.IX] += d[0]
                x1[m.IY] += d[1]
            x = x1[None, :]
        elif kernels.compiled() and hasattr(m, '_derivatives'):
            # The same RK4 and drift per vessel, compiled (ship_sim.models.compiled).
            # Three reused buffers (no fresh pages per step), none of them self.x: a vessel
            # that leaves the domain falls back to it below.
            step = batch_rk4(m)
            u_in = np.ascontiguousarray(np.broadcast_to(u_in, (self.n, m.n_inputs)))
            if len(self._buffers) != 3 or self._buffers[0].shape != self.x.shape:
                self._buffers = [np.empty_like(self.x) for _ in range(3)]
            a, b = [buf for buf in self._buffers if buf is not self.x][:2]
            x = self.x
            for _ in range(steps):
                x = step(x, u_in, h, drift, m.IX, m.IY, a)
                a, b = b, a
        else:
            x = self.x
            for _ in range(steps):
                x = m.step(x, u_in, h)
                x[:, m.IX] += drift[:, 0]
                x[:, m.IY] += drift[:, 1]
        ok = np.all(np.isfinite(x), axis=1)
        all_ok = bool(ok.all())
        try:
            m.check_state(x if all_ok else x[ok])
            if all_ok:   # the common case: no copies
                self.x = x
                return ok
        except ValueError:
            for i in np.flatnonzero(ok):
                try:
                    m.check_state(x[i])
                except ValueError:
                    ok[i] = False
        # A vessel that left the domain keeps its last valid state (its episode ends).
        self.x = np.where(ok[:, None], x, self.x)
        return ok

    def measured(self, waves, t):
        """(north, east, psi, u, v, r) arrays (N) that a sensor measures at time t (s): the
        state over ground plus each vessel's wave-frequency motion (``waves``: a batch
        ship_sim.environment.sea_state.ShipWaves of N sea states; ``superpose``), the RAOs
        taken at the speed through the water, as vessel_node superposes them on odom."""
        from ship_sim.environment.sea_state import superpose
        from ship_sim.environment.wave_rao import SURGE_SWAY_YAW
        m, x = self.model, self.x
        u, v, r = self.ground_velocity()
        psi = x[:, m.IPSI]
        eta, nu = waves.motion(t, np.hypot(m.surge_speed(x), x[:, m.IV]), psi,
                               dofs=SURGE_SWAY_YAW)
        return superpose(eta, nu, x[:, m.IX], x[:, m.IY], psi, u, v, r)

    def wind_loads(self, x=None):
        """Wind loads (X, Y, K, N) (N, N m) on states x (default the present ones)."""
        u, v, _ = self.ground_velocity(x)
        x = self.x if x is None else x
        return wind_disturbance(self.wind_profile, u, v, x[:, self.model.IPSI], self.wind.speed,
                                self.wind.direction_from, self.wind_coefficients)

    def project(self, idx):
        """Update the closest-point projection of vessels idx (progress window around s)."""
        m = self.model
        for i in idx:
            route = self.routes[self.route_index[i]]
            p = route.project(self.x[i, m.IX], self.x[i, m.IY], s_hint=self.s[i],
                              window=(100.0, 300.0))
            self.s[i] = p.s
            self.proj[i] = (p.cross_track, p.path_angle, p.curvature)

    def _observe(self, idx, dt):
        self.project(idx)
        u, v, r = self.ground_velocity()
        raw = self.features(self.proj[:, 0], self.proj[:, 1], self.proj[:, 2],
                            self.x[:, self.model.IPSI], u, v, r, dt)
        self.raw[idx] = raw[idx]

    def obs(self):
        """Normalised observations (N, 9) float32."""
        return normalise(self.raw, self.state_offset, self.state_scale, CLIP)[0]

    def step(self, action):
        c = self.config
        a = np.clip(np.nan_to_num(np.asarray(action, dtype=float).reshape(self.n)), -1.0, 1.0)
        cmd = a * self.rudder_max
        ok = self.integrate(cmd, c.substeps)
        self.t += c.control_dt
        self._observe(np.arange(self.n), dt=np.full(self.n, c.control_dt))
        e, heading_rel = self.raw[:, 0], self.raw[:, 4]
        gauss = gaussian_reward(e, heading_rel, c.reward_amplitude, c.reward_sigma,
                                c.yaw_error_max)
        penalty = rudder_change_penalty(cmd, self.prev_cmd, self.rudder_max,
                                        c.rudder_change_penalty)
        self.prev_cmd = cmd
        terminated = (~ok) | (np.abs(e) > c.terminate_cross_track)
        truncated = (self.t >= c.episode_s - 1e-9) & ~terminated
        info = {'gaussian': gauss, 'penalty': penalty, 'cross_track': e.copy(),
                'rudder_cmd': cmd, 'valid': ok}
        return self.obs(), gauss - penalty, terminated, truncated, info


class PathFollowingEnv(gymnasium.Env):
    """One vessel following a path (gymnasium API) on the PathFollowingBatch core.

    ``PathFollowingEnv('mariner', mode='straight')``; other EnvConfig fields as keywords.
    reset(seed=..., options={'start': {...}}) fixes the start (see PathFollowingBatch.reset).
    """

    metadata = {'render_modes': []}

    def __init__(self, model='mariner', seed=0, routes=None, **config):
        super().__init__()
        self.core = PathFollowingBatch(model, 1, EnvConfig(**config), seed=seed, routes=routes)
        self.observation_space = gymnasium.spaces.Box(-CLIP, CLIP, (OBS_DIM,), np.float32)
        self.action_space = gymnasium.spaces.Box(-1.0, 1.0, (1,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        if seed is not None:
            self.core.rng = np.random.default_rng(seed)
        start = (options or {}).get('start')
        obs = self.core.reset(starts=None if start is None else [start])
        return obs[0], {'raw_state': self.core.raw[0].copy()}

    def step(self, action):
        obs, reward, term, trunc, info = self.core.step(np.asarray(action, dtype=float)[:1])
        info = {k: (v[0] if isinstance(v, np.ndarray) else v) for k, v in info.items()}
        info['raw_state'] = self.core.raw[0].copy()
        return obs[0], float(reward[0]), bool(term[0]), bool(trunc[0]), info
