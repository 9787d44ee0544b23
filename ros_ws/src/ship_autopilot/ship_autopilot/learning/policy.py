"""Learned steering policy at runtime: numpy-only MLP inference, policy files, a node-side wrapper.

Source: the actor of Martinsen and Lekkas 2018 (Sec. III): two fully connected hidden layers
of 400 and 300 ReLU units; our output layer is tanh, scaled to the model's rudder limit
(unified sign: positive turns to port). Trained by scripts/train_ddpg.py (torch, optional);
running a policy needs only numpy.

Policy file (``ship_autopilot/data/policies/<model>.npz``, ``np.load(allow_pickle=False)``):
  W0 (9, 400), b0 (400,), W1 (400, 300), b1 (300,), W2 (300, 1), b2 (1,)   float32, y = x W + b
  ref_obs (k, 9), ref_action (k,)   float32: normalised inputs and the TRAINING framework's
                                    actions in [-1, 1], stored at export (tests compare)
  meta          0-d unicode array holding JSON: format (FORMAT), model, obs_dim, state_names,
                state_offset, state_scale, clip, action_scale (rad, = rudder limit),
                control_dt (s), sim_dt (s), hidden, training (settings and results), sha256
                (of the weight arrays' bytes in the order above)
A file that is missing, unreadable, of another format, for another model, with the wrong
shapes or a changed weight hash raises PolicyError, a one-line message naming the file and
what was expected.

Use:  policy = load_policy('mariner')          # or load_policy(model=..., path=...)
      rudder = policy.rudder(raw_state)        # raw eq. 9 state(s), SI (ship_guidance.path_state)
Raw states are normalised with the file's offsets/scales and clipped to the training range;
non-finite entries never reach the network (see path_state.normalise; ``LearnedSteering`` holds
its previous command instead).
"""
import hashlib
import json
from pathlib import Path

import numpy as np

from ship_guidance.los import ilos_heading, ilos_integral_rate
from ship_guidance.path_state import OBS_DIM, STATE_NAMES, normalise
from ship_sim.frames import wrap_angle

from ..pd import PDAutopilot
from ..rudder import RudderLimiter

FORMAT = 'ship_autopilot.policy.v1'
WEIGHT_NAMES = ('W0', 'b0', 'W1', 'b1', 'W2', 'b2')
#: Shipped policies: package data next to this package.
POLICY_DIR = Path(__file__).resolve().parent.parent / 'data' / 'policies'


class PolicyError(ValueError):
    """A policy file is missing or does not fit; the message is one line naming the file."""


def policy_path(model):
    """Path of the shipped policy of ``model``: its card's ``policy`` file, else where a new
    one is saved (``<model>.npz``; name it on the card to ship it)."""
    from ship_sim.models import card
    return POLICY_DIR / (card(model).policy or f'{model}.npz')


def weights_hash(weights):
    """sha256 hex digest of the weight arrays (float32, C order) in WEIGHT_NAMES order."""
    h = hashlib.sha256()
    for name in WEIGHT_NAMES:
        h.update(np.ascontiguousarray(weights[name], dtype=np.float32).tobytes())
    return h.hexdigest()


#: Rows per matrix product of Policy.action (its docstring).
ROW_BLOCK = 64


def mlp_forward(weights, z):
    """tanh(relu(relu(z W0 + b0) W1 + b1) W2 + b2) for z (..., 9) -> (...,) in [-1, 1]
    (in the dtype of z and the weights)."""
    h = np.maximum(z @ weights['W0'] + weights['b0'], 0.0)
    h = np.maximum(h @ weights['W1'] + weights['b1'], 0.0)
    return np.tanh(h @ weights['W2'] + weights['b2'])[..., 0]


class Policy:
    """A loaded, validated policy. Attributes from the file's metadata (see module docstring)."""

    def __init__(self, weights, meta, path='<memory>'):
        self.weights = weights
        self._weights64 = {k: np.asarray(v, dtype=np.float64) for k, v in weights.items()}
        self.meta = meta
        self.path = str(path)
        self.model = meta['model']
        self.offset = np.asarray(meta['state_offset'], dtype=np.float64)
        self.scale = np.asarray(meta['state_scale'], dtype=np.float64)
        self.clip = float(meta['clip'])
        self.action_scale = float(meta['action_scale'])
        self.control_dt = float(meta['control_dt'])

    def normalise(self, raw_state):
        """Raw eq. 9 state(s) (..., 9) SI -> (clipped float32 (..., 9), finite mask)."""
        return normalise(raw_state, self.offset, self.scale, self.clip)

    def action(self, z):
        """Normalised observation(s) (..., 9) -> action(s) in [-1, 1] (float64).

        Evaluated in float64 on float64 copies of the float32 weights, in blocks of ROW_BLOCK
        rows (the last one padded with zeros): BLAS sums a row's products in an order that
        depends on the matrix's shape and the row's place in it (float32: ~1e-6 between one row
        and a batch; float64: the last row of 31 or 257 differed by 1 ulp), and a block of fixed
        shape gives every row the same sums wherever it sits. So one vessel, a batch
        (ship_autopilot.batch_closed_loop) and any chunking of a sweep get the same bits."""
        z = np.asarray(z, dtype=np.float32).astype(np.float64)
        rows = z.reshape(-1, z.shape[-1])
        n = len(rows)
        padded = np.zeros((-(-n // ROW_BLOCK) * ROW_BLOCK, rows.shape[1]))
        padded[:n] = rows
        out = np.concatenate([mlp_forward(self._weights64, padded[i:i + ROW_BLOCK])
                              for i in range(0, len(padded), ROW_BLOCK)])
        return out[:n].reshape(z.shape[:-1])

    def rudder(self, raw_state):
        """Raw eq. 9 state(s) -> rudder command(s) (rad, unified sign), always finite."""
        z, _ = self.normalise(raw_state)
        a = self.action(z).astype(np.float64) * self.action_scale
        return float(a) if a.ndim == 0 else a

    def __repr__(self):
        return f'Policy({self.model}, {self.path})'


def _fail(path, what):
    raise PolicyError(f'{path}: {what}')


def load_policy(model=None, path=None):
    """Load and validate a policy file: the shipped one of ``model``, or ``path``.

    With both, the file must be for ``model``. Raises PolicyError (one line, names the file).
    """
    if path is None:
        if model is None:
            raise PolicyError('load_policy needs a model name or a path')
        path = policy_path(model)
    path = Path(path)
    if not path.is_file():
        _fail(path, f'policy file not found (expected a trained policy for model '
                    f'{model!r}; train one with scripts/train_ddpg.py)')
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
    except Exception as exc:  # noqa: BLE001 (zip/npy errors of many kinds: all mean "not a policy file")
        _fail(path, f'not a readable .npz policy file ({type(exc).__name__}: '
                    f'{str(exc).splitlines()[0] if str(exc) else ""})')
    missing = [k for k in WEIGHT_NAMES + ('meta',) if k not in arrays]
    if missing:
        _fail(path, f'missing arrays {missing}; expected {list(WEIGHT_NAMES) + ["meta"]}')
    try:
        from ship_sim.safe_load import load_json
        meta = load_json(str(arrays['meta'][()]))
    except (ValueError, TypeError) as exc:
        _fail(path, f'metadata is not JSON ({exc})')
    if not isinstance(meta, dict) or meta.get('format') != FORMAT:
        _fail(path, f'format {meta.get("format") if isinstance(meta, dict) else None!r}, '
                    f'expected {FORMAT!r}')
    if model is not None and meta.get('model') != model:
        _fail(path, f'policy is for model {meta.get("model")!r}, expected {model!r}')
    if meta.get('obs_dim') != OBS_DIM or list(meta.get('state_names', [])) != list(STATE_NAMES):
        _fail(path, f'state {meta.get("obs_dim")} {meta.get("state_names")}, expected '
                    f'{OBS_DIM} {list(STATE_NAMES)}')
    hidden = meta.get('hidden')
    if not (isinstance(hidden, list) and len(hidden) == 2
            and all(isinstance(h, int) and h > 0 for h in hidden)):
        _fail(path, f'hidden = {hidden!r}, expected two positive layer sizes')
    h0, h1 = hidden
    shapes = {'W0': (OBS_DIM, h0), 'b0': (h0,), 'W1': (h0, h1), 'b1': (h1,), 'W2': (h1, 1),
              'b2': (1,)}
    for name, shape in shapes.items():
        a = arrays[name]
        if a.shape != shape or a.dtype != np.float32:
            _fail(path, f'{name} has shape {a.shape} {a.dtype}, expected {shape} float32')
        if not np.all(np.isfinite(a)):
            _fail(path, f'{name} has non-finite weights')
    for key in ('state_offset', 'state_scale'):
        v = np.asarray(meta.get(key, []), dtype=float)
        if v.shape != (OBS_DIM,) or not np.all(np.isfinite(v)):
            _fail(path, f'{key} has shape {v.shape}, expected ({OBS_DIM},) finite')
    if not np.all(np.asarray(meta['state_scale']) > 0):
        _fail(path, 'state_scale must be > 0')
    for key in ('clip', 'action_scale', 'control_dt'):
        v = meta.get(key)
        if not (isinstance(v, (int, float)) and np.isfinite(v) and v > 0):
            _fail(path, f'{key} = {v!r}, expected a positive number')
    weights = {k: arrays[k] for k in WEIGHT_NAMES}
    digest = weights_hash(weights)
    if meta.get('sha256') != digest:
        _fail(path, f'weight hash {digest[:12]}... does not match the stored '
                    f'{str(meta.get("sha256"))[:12]}... (file changed after export)')
    policy = Policy(weights, meta, path)
    for key in ('ref_obs', 'ref_action'):
        if key in arrays:
            setattr(policy, key, arrays[key])
    return policy


def check_model_limits(policy, rudder_max):
    """PolicyError unless the policy's action scale equals the vessel's rudder limit (rad)."""
    if not np.isclose(policy.action_scale, rudder_max, rtol=1e-9, atol=1e-12):
        _fail(policy.path, f'action_scale {policy.action_scale:.6g} rad, expected the '
                           f'vessel\'s rudder limit {rudder_max:.6g} rad')


def save_policy(path, weights, meta, ref_obs=None, ref_action=None):
    """Write a policy file (float32 weights, metadata with format and hash). Returns the meta."""
    weights = {k: np.ascontiguousarray(weights[k], dtype=np.float32) for k in WEIGHT_NAMES}
    meta = dict(meta, format=FORMAT, obs_dim=OBS_DIM, state_names=list(STATE_NAMES),
                sha256=weights_hash(weights))
    arrays = dict(weights, meta=np.array(json.dumps(meta, sort_keys=True)))
    if ref_obs is not None:
        arrays['ref_obs'] = np.asarray(ref_obs, dtype=np.float32)
        arrays['ref_action'] = np.asarray(ref_action, dtype=np.float32)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with open(path, 'wb') as f:
        np.savez_compressed(f, **arrays)
    return meta


#: Look-ahead of the policy's recovery law, in ship lengths: a gentle approach (the heading
#: relative to the path at hand-back, -atan(e / d), stays well inside the +-20 deg the policies
#: were started with) and above ILOS's stability limit with the gain-table PD,
#: (U + 4 zeta^2 sigma) / (2 zeta omega_n) = 1.03 L for omega_n = U / L, sigma = U / 4.
RECOVERY_LOOKAHEAD_SHIP_LENGTHS = 2.5
#: Integral gain of the recovery's ILOS, in units of the speed (sigma = U / 4, as the ILOS of
#: scripts/evaluate_controllers.py): it removes the offset plain LOS keeps in a cross current
#: (d tan(asin(Vc / U)) = 47 m for the Mariner in 0.9 m/s at 2.5 L, at the hand-back edge).
RECOVERY_INTEGRAL_SPEED_FRACTION = 0.25


class Recovery:
    """Integral LOS + PD from the path-relative state, for where a policy was never trained.

    A policy only knows the states its training episodes visited (starts within
    ``start_cross_max`` of the path, heading within +-``start_heading_max``; beyond them it may
    steer the wrong way, as the first shipped ones did from ~150 m off). ``LearnedSteering``
    hands the rudder to this law
    while |e| > ``engage_m`` or |psi - gamma_p| > ``heading_gate`` (eq. 8's yaw bound: the
    reward is zero there, so nothing was learned), and back once |e| < ``release_m`` and the
    heading is inside the gate (hysteresis, so it does not chatter at the edge).

    The law uses only the eq. 9 state: ILOS heading relative to the path
    psi_r = -atan((e + sigma e_int) / d) with e_int' = d e / ((e + sigma e_int)^2 + d^2)
    (ship_guidance.los, Borhaug et al. 2008; reset when the law takes over), steered by a
    pd.PDAutopilot on the heading relative to the path, saturated at ``rudder_max`` (the
    vessel's servo limits the rate). SI units, rad.
    """

    def __init__(self, k1, k2, lookahead, engage_m, release_m, rudder_max, sigma=0.0,
                 heading_gate=np.pi / 2):
        if not (k1 > 0 and k2 >= 0 and lookahead > 0 and 0 < release_m < engage_m
                and 0 < rudder_max <= np.pi / 2 and sigma >= 0 and 0 < heading_gate <= np.pi):
            raise ValueError(f'Recovery needs k1 > 0, k2 >= 0, lookahead > 0, 0 < release_m < '
                             f'engage_m, rudder_max in (0, pi/2], sigma >= 0, heading_gate in '
                             f'(0, pi]; '
                             f'got k1={k1}, k2={k2}, lookahead={lookahead}, '
                             f'release_m={release_m}, engage_m={engage_m}, '
                             f'rudder_max={rudder_max}, sigma={sigma}, '
                             f'heading_gate={heading_gate}')
        self.lookahead = float(lookahead)
        self.engage_m, self.release_m = float(engage_m), float(release_m)
        self.rudder_max, self.heading_gate = float(rudder_max), float(heading_gate)
        self.sigma = float(sigma)
        self.pd = PDAutopilot(k1, k2, RudderLimiter(self.rudder_max))
        self.start()

    @classmethod
    def for_policy(cls, policy, k1, k2, ship_length, speed, release_fraction=0.5):
        """The recovery of ``policy`` for a ship of ``ship_length`` (m) at ``speed`` (m/s):
        engage at the edge of the policy's training starts (its metadata), release at
        ``release_fraction`` of it, look-ahead and integral gain as the module constants."""
        edge = float(policy.meta.get('training', {}).get('env', {}).get('start_cross_max', 100.0))
        return cls(k1, k2, RECOVERY_LOOKAHEAD_SHIP_LENGTHS * ship_length, edge,
                   release_fraction * edge, policy.action_scale,
                   sigma=RECOVERY_INTEGRAL_SPEED_FRACTION * speed)

    def start(self):
        """Forget the integral state (the law is taking over)."""
        self.integral = 0.0
        self.t_prev = None
        self.pd.reset()

    def outside(self, e, heading_rel, active):
        """Whether the state is (still) outside the policy's region, given the current mode."""
        off_heading = abs(wrap_angle(heading_rel)) > self.heading_gate
        return off_heading or abs(e) > (self.release_m if active else self.engage_m)

    def rudder(self, raw_state, t=None):
        """Rudder (rad) for the raw eq. 9 state at time ``t`` (s; None: no integration)."""
        e, heading_rel, r = (float(raw_state[i]) for i in (0, 4, 8))
        dt = 0.0 if t is None or self.t_prev is None else t - self.t_prev
        if dt > 0.0 and self.sigma > 0:
            self.integral += dt * ilos_integral_rate(e, self.integral, self.lookahead, self.sigma)
        if t is not None:
            self.t_prev = t
        psi_r = ilos_heading(0.0, e, self.integral, self.lookahead, self.sigma)
        # No rate limit here, so dt only has to be valid for the PD (> 0).
        return float(self.pd.update(heading_rel, r, psi_r, dt if dt > 0.0 else 1e-9))


class LearnedSteering:
    """Node-side wrapper: hold semantics, the policy's control step, optional recovery.

    ``update(raw_state, t)`` -> rudder command (rad). A new action is computed when at least
    ``control_dt`` (s, from the file; the step the policy was trained with) has passed since the
    last one (first call, or time went backwards: always), else the previous command is held.
    A state with non-finite entries is rejected: the previous command is held, ``n_rejected``
    counts it and ``last_ok`` is False. The output is always finite.
    ``recovery`` (a Recovery, optional): outside the policy's region it steers instead, at every
    call; ``recovering`` says which law is in charge, ``n_switches`` counts hand-overs.
    """

    def __init__(self, policy, control_dt=None, recovery=None):
        self.policy = policy
        self.control_dt = policy.control_dt if control_dt is None else float(control_dt)
        self.recovery = recovery
        self.reset()

    def reset(self, rudder=0.0):
        self.rudder = float(rudder)
        self.t_last = None
        self.n_rejected = 0
        self.last_ok = True
        self.recovering = False
        self.n_switches = 0

    def update(self, raw_state, t):
        z, ok = self.policy.normalise(raw_state)
        self.last_ok = bool(np.all(ok)) and np.isfinite(t)
        if not self.last_ok:
            self.n_rejected += 1
            return self.rudder
        if self.recovery is not None:
            raw = np.asarray(raw_state, dtype=float)
            outside = self.recovery.outside(raw[0], raw[4], self.recovering)
            if outside != self.recovering:
                self.recovering = outside
                self.n_switches += 1
                self.t_last = None          # the policy acts at once when it takes over
                self.recovery.start()
            if outside:
                self.rudder = self.recovery.rudder(raw, t)
                return self.rudder
        # New action every control_dt; a clock that went back (sim restart) starts afresh.
        if (self.t_last is None or t < self.t_last
                or t - self.t_last >= self.control_dt - 1e-9):
            self.rudder = float(self.policy.action(z)) * self.policy.action_scale
            self.t_last = t
        return self.rudder
