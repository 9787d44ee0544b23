#!/usr/bin/env python3
"""Train the learned steering policy of Martinsen and Lekkas 2018 with DDPG; export it as a numpy policy file.

    scripts/train_ddpg.py train --model mariner --schedule transfer [--transitions 120000]
    scripts/train_ddpg.py train --model mariner --schedule continue \
        --init-from runs/rl/mariner_transfer/checkpoint.pt --out runs/rl/mariner_continue
    scripts/train_ddpg.py train --model mariner --schedule scratch --seed 1 \
        --export none --out runs/rl/transfer_study/mariner_scratch_s1    # (and transfer)
    scripts/train_ddpg.py compare --model mariner       # transfer vs scratch time-to-threshold
    scripts/train_ddpg.py plot --model mariner          # training curves (PNG) from the logs

Source: Martinsen and Lekkas 2018, Sec. III and Algorithm 1: DDPG
(Lillicrap et al. 2016), actor and critic with two fully connected ReLU layers of 400 and 300
units, learning rates 1e-4 (actor) and 1e-3 (critic), soft target updates tau = 1e-3, discount
gamma = 0.99, minibatches of 64 from a replay buffer (size 1e6 here), 1000 s episodes with random
starts near the path and unknown current; transfer learning = train on straight lines first,
then continue on curved paths (30 % of the transitions straight: Martinsen and Lekkas's "40-50 % less
training time" claim, measured by ``compare``).

Why our own compact DDPG and not stable-baselines3 (which pip can install next to torch 2.13
without pulling CUDA): (1) training is dominated by the 400-300 network updates (milliseconds each on
one core), so the environment must be batched (N vessels in one numpy RK4 call,
learning.env.PathFollowingBatch) with several updates per batched step; SB3 can be fed a
custom VecEnv, but its per-step bookkeeping and the transfer schedule (one process, keep
networks, optimisers and the replay buffer across the straight -> curved switch, count
transitions per phase) are simpler to state exactly in ~150 lines here; (2) the export to the
numpy policy file (weights + metadata + reference outputs) needs only our own layer layout;
(3) no dependency beyond torch for training. Choices Martinsen and Lekkas 2018 leave open, ours: tanh output
scaled to the rudder limit; critic input = [state, action] at the first layer; final-layer init
uniform +-3e-3 (DDPG paper); Ornstein-Uhlenbeck exploration (theta 0.15, sigma 0.1 per 1 s
control step, as DDPG); no weight decay; 5000 warm-up transitions before updates; truncated
episodes are bootstrapped, terminations (|e| > 1000 m) are not.

CPU only, ``torch.set_num_threads(1)`` (shared 2-core machine). Seeds are fixed (numpy, torch,
environment). Output folder (default runs/rl/<model>_<schedule>): log.csv (one row per
evaluation), checkpoint.pt (networks + optimisers), best_actor.pt, curves.png, and the exported
policy (default: ship_autopilot/data/policies/<model>.npz for the transfer schedule).

Evaluation during training: the deterministic policy on a fixed, seeded set of curved-path
episodes (separate curves from the training pool, currents uniform in [0, 0.9] m/s), score =
mean Gaussian reward summed per 1000 s episode at the 1 s control step (<= 1000). The exported
policy is the best-scoring one of the curved phase.
"""
import argparse
import copy
import csv
import json
import math
import time
from pathlib import Path

import numpy as np

from ship_autopilot.learning.env import EnvConfig, PathFollowingBatch
from ship_autopilot.learning.policy import policy_path, save_policy
from ship_guidance.path_state import CLIP, OBS_DIM
from ship_sim.allocator import tune_allocator
from ship_sim.models import model_names
from ship_sim.safe_load import load_json_file

ROOT = Path(__file__).resolve().parent.parent

HIDDEN = (400, 300)
SETTINGS = {'actor_lr': 1e-4, 'critic_lr': 1e-3, 'tau': 1e-3, 'gamma': 0.99, 'batch': 64,
            'buffer': 1_000_000, 'hidden': list(HIDDEN), 'warmup': 5000, 'ou_theta': 0.15,
            'ou_sigma': 0.1}
RUNS = ROOT / 'runs' / 'rl'
EVAL_EPISODES = 4
#: EnvConfig fields set from the command line (--control-dt), applied to every environment.
ENV_OPTIONS = {}


def env_config(mode, **kw):
    return EnvConfig(mode=mode, **ENV_OPTIONS, **kw)


def build_nets(torch):
    nn = torch.nn

    def mlp(n_in, out_act):
        layers = [nn.Linear(n_in, HIDDEN[0]), nn.ReLU(), nn.Linear(HIDDEN[0], HIDDEN[1]),
                  nn.ReLU(), nn.Linear(HIDDEN[1], 1)]
        nn.init.uniform_(layers[-1].weight, -3e-3, 3e-3)
        nn.init.uniform_(layers[-1].bias, -3e-3, 3e-3)
        if out_act:
            layers.append(nn.Tanh())
        return nn.Sequential(*layers)

    return mlp(OBS_DIM, True), mlp(OBS_DIM + 1, False)


class Replay:
    """Ring buffer of transitions (float32)."""

    def __init__(self, size, rng):
        self.obs = np.zeros((size, OBS_DIM), np.float32)
        self.act = np.zeros((size, 1), np.float32)
        self.rew = np.zeros((size, 1), np.float32)
        self.nxt = np.zeros((size, OBS_DIM), np.float32)
        self.done = np.zeros((size, 1), np.float32)
        self.size, self.n, self.i, self.rng = size, 0, 0, rng

    def add(self, obs, act, rew, nxt, done):
        k = len(obs)
        idx = (self.i + np.arange(k)) % self.size
        self.obs[idx], self.act[idx, 0], self.rew[idx, 0] = obs, act, rew
        self.nxt[idx], self.done[idx, 0] = nxt, done
        self.i = (self.i + k) % self.size
        self.n = min(self.n + k, self.size)

    def sample(self, batch):
        j = self.rng.integers(0, self.n, batch)
        return self.obs[j], self.act[j], self.rew[j], self.nxt[j], self.done[j]


class DDPG:
    def __init__(self, torch, seed):
        torch.manual_seed(seed)
        self.torch = torch
        self.actor, self.critic = build_nets(torch)
        self.actor_t, self.critic_t = copy.deepcopy(self.actor), copy.deepcopy(self.critic)
        self.opt_a = torch.optim.Adam(self.actor.parameters(), SETTINGS['actor_lr'])
        self.opt_c = torch.optim.Adam(self.critic.parameters(), SETTINGS['critic_lr'])
        self.params = list(self.actor.parameters()) + list(self.critic.parameters())
        self.params_t = list(self.actor_t.parameters()) + list(self.critic_t.parameters())
        self.updates = 0

    def act(self, obs):
        with self.torch.no_grad():
            return self.actor(self.torch.from_numpy(obs)).numpy()[:, 0]

    def update(self, batch):
        t = self.torch
        o, a, r, o2, d = (t.from_numpy(x) for x in batch)
        with t.no_grad():
            q_next = self.critic_t(t.cat([o2, self.actor_t(o2)], 1))
            y = r + SETTINGS['gamma'] * (1.0 - d) * q_next                  # eq. 12
        q = self.critic(t.cat([o, a], 1))
        loss_c = ((y - q) ** 2).mean()                                       # eq. 10
        self.opt_c.zero_grad()
        loss_c.backward()
        self.opt_c.step()
        loss_a = -self.critic(t.cat([o, self.actor(o)], 1)).mean()          # eq. 11
        self.opt_a.zero_grad()
        loss_a.backward()
        self.opt_a.step()
        with t.no_grad():                                                    # eqs. 13-14
            t._foreach_lerp_(self.params_t, self.params, SETTINGS['tau'])
        self.updates += 1
        return loss_c.detach(), loss_a.detach()

    def state_dict(self):
        return {k: getattr(self, k).state_dict() for k in
                ('actor', 'critic', 'actor_t', 'critic_t', 'opt_a', 'opt_c')}

    def load_state_dict(self, sd):
        for k, v in sd.items():
            getattr(self, k).load_state_dict(v)


def evaluate(agent, model, seed, episodes=EVAL_EPISODES):
    """Mean Gaussian sum per 1000 s curved episode, mean |e| (m), with the deterministic actor."""
    env = PathFollowingBatch(model, episodes, env_config('curved', n_routes=episodes),
                             seed=10_000 + seed)
    obs = env.reset()
    gauss = np.zeros(episodes)
    abs_e = np.zeros(episodes)
    alive = np.ones(episodes, bool)
    steps = 0
    while alive.any():
        obs, _, term, trunc, info = env.step(agent.act(obs))
        gauss += np.where(alive, info['gaussian'], 0.0)
        abs_e += np.where(alive, np.abs(info['cross_track']), 0.0)
        steps += 1
        alive &= ~(term | trunc)
    return float(gauss.mean()), float(abs_e.mean() / steps)


def train(args):
    import torch
    torch.set_num_threads(1)
    rng = np.random.default_rng(args.seed)
    out = Path(args.out or RUNS / f'{args.model}_{args.schedule}')
    out.mkdir(parents=True, exist_ok=True)
    agent = DDPG(torch, args.seed)
    if args.init_from:
        agent.load_state_dict(torch.load(args.init_from))
        print(f'networks and optimisers from {args.init_from}', flush=True)
    elif args.schedule == 'continue':
        raise SystemExit('--schedule continue needs --init-from <checkpoint.pt>')
    buf = Replay(SETTINGS['buffer'], rng)
    n_straight = int(round(args.straight_fraction * args.transitions)) \
        if args.schedule == 'transfer' else 0
    phases = [('straight', n_straight), ('curved', args.transitions - n_straight)]
    log_rows, best = [], (-math.inf, None)
    total, episodes, t0 = 0, 0, time.perf_counter()
    returns = []
    n = args.n_envs
    log_file = open(out / 'log.csv', 'w', newline='')
    writer = csv.writer(log_file)
    writer.writerow(['phase', 'transitions', 'updates', 'episodes', 'wall_s', 'train_return',
                     'eval_gaussian', 'eval_abs_e'])
    theta, sigma = SETTINGS['ou_theta'], SETTINGS['ou_sigma']
    stop = False
    for phase, count in phases:
        if count <= 0 or stop:
            continue
        env = PathFollowingBatch(args.model, n, env_config(phase),
                                 seed=args.seed * 100 + (phase == 'curved'))
        obs = env.reset()
        noise = np.zeros(n)
        ep_ret = np.zeros(n)
        done_phase = 0
        next_eval = args.eval_every
        while done_phase < count:
            noise += theta * (0.0 - noise) + sigma * rng.standard_normal(n)
            act = np.clip(agent.act(obs) + noise, -1.0, 1.0).astype(np.float32)
            nxt, rew, term, trunc, _ = env.step(act)
            buf.add(obs, act, rew, nxt, term.astype(np.float32))
            ep_ret += rew
            done = term | trunc
            if done.any():
                returns.extend(ep_ret[done].tolist())
                episodes += int(done.sum())
                ep_ret[done] = 0.0
                noise[done] = 0.0
                nxt = env.reset(done)
            obs = nxt
            total += n
            done_phase += n
            if buf.n >= SETTINGS['warmup']:
                for _ in range(args.updates_per_step):
                    agent.update(buf.sample(SETTINGS['batch']))
            out_of_time = time.perf_counter() - t0 > args.max_wall_s
            if out_of_time and phase == 'straight':
                out_of_time = False   # the wall limit only cuts the curved phase short
            if done_phase >= next_eval or done_phase >= count or out_of_time:
                next_eval += args.eval_every
                score, abs_e = evaluate(agent, args.model, args.seed)
                wall = time.perf_counter() - t0
                recent = float(np.mean(returns[-20:])) if returns else float('nan')
                row = [phase, total, agent.updates, episodes, round(wall, 1), round(recent, 2),
                       round(score, 2), round(abs_e, 2)]
                writer.writerow(row)
                log_file.flush()
                log_rows.append(row)
                print(f'[{args.model} {args.schedule}] {phase:8s} transitions {total:7d} '
                      f'updates {agent.updates:7d} episodes {episodes:4d} '
                      f'{total / wall:6.0f} steps/s  train return {recent:7.1f}  '
                      f'eval gaussian {score:6.1f} |e| {abs_e:6.1f} m  ({wall:5.0f} s)',
                      flush=True)
                torch.save(agent.state_dict(), out / 'checkpoint.pt')
                if phase == 'curved' and score > best[0]:
                    best = (score, copy.deepcopy(agent.actor.state_dict()))
                    torch.save(best[1], out / 'best_actor.pt')
                if out_of_time:
                    print(f'wall limit {args.max_wall_s:.0f} s reached: stopping', flush=True)
                    stop = True
                    break
    log_file.close()
    wall = time.perf_counter() - t0
    summary = {'model': args.model, 'schedule': args.schedule, 'transitions': total,
               'straight_transitions': n_straight, 'updates': agent.updates,
               'episodes': episodes, 'wall_s': round(wall, 1), 'best_eval_gaussian': best[0],
               'seed': args.seed, 'n_envs': n, 'updates_per_step': args.updates_per_step,
               'planned_transitions': args.transitions, 'stopped_by_wall_limit': stop,
               'control_dt': env.config.control_dt}
    (out / 'summary.json').write_text(json.dumps(summary, indent=2))
    plot_curves([out], out / 'curves.png')
    if best[1] is not None and args.export != 'none':
        agent.actor.load_state_dict(best[1])
        path = Path(args.export) if args.export else (
            policy_path(args.model) if args.schedule in ('transfer', 'continue')
            else out / 'policy.npz')
        export(agent, args.model, path, summary)
        print(f'exported {path}')
    print(json.dumps(summary))


def export(agent, model_name, path, summary):
    """Write the actor as a numpy policy file with reference outputs computed by torch."""
    import torch
    env = PathFollowingBatch(model_name, 1, env_config('straight'))
    lin = [m for m in agent.actor if isinstance(m, torch.nn.Linear)]
    weights = {}
    for i, layer in enumerate(lin):
        weights[f'W{i}'] = layer.weight.detach().numpy().T.copy()
        weights[f'b{i}'] = layer.bias.detach().numpy().copy()
    rng = np.random.default_rng(0)
    ref_obs = np.concatenate([rng.uniform(-CLIP, CLIP, (24, OBS_DIM)),
                              rng.normal(0.0, 0.5, (24, OBS_DIM)),
                              np.zeros((1, OBS_DIM))]).astype(np.float32)
    ref_action = agent.act(ref_obs)
    meta = {'model': model_name, 'state_offset': env.state_offset.tolist(),
            'state_scale': env.state_scale.tolist(), 'clip': CLIP,
            'action_scale': env.rudder_max, 'control_dt': env.config.control_dt,
            'sim_dt': env.config.sim_dt, 'hidden': list(HIDDEN),
            'training': dict(SETTINGS, **summary, env=env.config.__dict__,
                             algorithm='DDPG (scripts/train_ddpg.py)')}
    save_policy(path, weights, meta, ref_obs, ref_action)


def read_log(path):
    with open(path) as f:
        return [dict(r) for r in csv.DictReader(f)]


def plot_curves(folders, png):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for folder in folders:
        rows = read_log(Path(folder) / 'log.csv')
        if not rows:
            continue
        x = [int(r['transitions']) for r in rows]
        label = Path(folder).name
        axes[0].plot(x, [float(r['eval_gaussian']) for r in rows], 'o-', label=label)
        axes[1].plot(x, [float(r['train_return']) for r in rows], 'o-', label=label)
        straight = [int(r['transitions']) for r in rows if r['phase'] == 'straight']
        if straight:
            axes[0].axvline(max(straight), ls=':', color='gray')
    axes[0].set(xlabel='transitions (1 s each)', ylabel='eval: Gaussian sum per 1000 s',
                title='curved-path evaluation (deterministic)')
    axes[1].set(xlabel='transitions (1 s each)', ylabel='mean return, last 20 episodes',
                title='training episodes (with exploration)')
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def time_to(rows, threshold, key, scale=1.0):
    """First value of column ``key`` at which the curved evaluation, times ``scale``, reaches
    ``threshold``."""
    for r in rows:
        if r['phase'] == 'curved' and scale * float(r['eval_gaussian']) >= threshold:
            return float(r[key])
    return None


def score_scale(folder):
    """Factor that puts a run's evaluation on the 1 s step's scale: the evaluation sums the
    Gaussian once per policy step, so a 1000 s episode scores at most 1000 / control_dt."""
    summary = folder / 'summary.json'
    control_dt = load_json_file(summary).get('control_dt', 1.0) if summary.exists() else 1.0
    return float(control_dt)


def compare(args):
    """Transfer vs scratch: for every seed with both runs (<runs>/<model>_<schedule>_s<seed>),
    the transitions (all phases; updates are proportional, so this is training time on an
    idle core) until the curved evaluation first reaches each threshold, and the saving
    1 - transfer / scratch (also counting only the transfer run's curved transitions), and
    the means over seeds. A run that never reaches a threshold counts as censored at its last
    transition count (the saving is then a bound, marked as such)."""
    runs = Path(args.runs)
    seeds = sorted({int(f.name.rsplit('_s', 1)[1]) for f in runs.glob(f'{args.model}_*_s*')
                    if f.is_dir()})
    result = {'model': args.model, 'thresholds': args.thresholds, 'seeds': {}}
    folders = []
    for seed in seeds:
        pair = {s: runs / f'{args.model}_{s}_s{seed}' for s in ('scratch', 'transfer')}
        if not all((f / 'log.csv').exists() for f in pair.values()):
            continue
        folders += list(pair.values())
        logs = {s: read_log(f / 'log.csv') for s, f in pair.items()}
        scale = {s: score_scale(f) for s, f in pair.items()}
        entry = {s: {'transitions_total': int(logs[s][-1]['transitions']),
                     'score_scale': scale[s],
                     'straight_transitions': max([int(r['transitions']) for r in logs[s]
                                                  if r['phase'] == 'straight'], default=0),
                     'best_eval': scale[s] * max(float(r['eval_gaussian']) for r in logs[s]
                                                 if r['phase'] == 'curved')} for s in logs}
        for thr in args.thresholds:
            t = {s: time_to(logs[s], thr, 'transitions', scale[s]) for s in logs}
            censored = {s: t[s] is None for s in t}
            t_or_end = {s: t[s] if t[s] is not None else entry[s]['transitions_total']
                        for s in t}
            saving = saving_curved = None
            if not all(censored.values()):
                saving = 1.0 - t_or_end['transfer'] / t_or_end['scratch']
                # Counting only the curved-path transitions (the straight ones as free).
                saving_curved = 1.0 - ((t_or_end['transfer']
                                        - entry['transfer']['straight_transitions'])
                                       / t_or_end['scratch'])
            entry[f'{thr:g}'] = {'transitions': t, 'saving': saving,
                                 'saving_curved_only': saving_curved,
                                 'bound': ('lower' if censored['scratch'] else 'upper')
                                 if any(censored.values()) else None}
        result['seeds'][seed] = entry
    for thr in args.thresholds:
        for key in ('saving', 'saving_curved_only'):
            vals = [e[f'{thr:g}'][key] for e in result['seeds'].values()
                    if e[f'{thr:g}'][key] is not None]
            result.setdefault('mean', {}).setdefault(f'{thr:g}', {})[key] = (
                float(np.mean(vals)) if vals else None)
    print(json.dumps(result, indent=2))
    for thr in args.thresholds:
        row = ' '.join(f"s{seed}: {e[f'{thr:g}']['transitions']['scratch']} vs "
                       f"{e[f'{thr:g}']['transitions']['transfer']}"
                       for seed, e in result['seeds'].items())
        m = result['mean'][f'{thr:g}']
        print(f'threshold {thr:g}: transitions scratch vs transfer {row}; mean saving '
              f"{m['saving']}, curved-only {m['saving_curved_only']}")
    out = runs / f'{args.model}_compare'
    plot_curves(folders, out.with_suffix('.png'))
    out.with_suffix('.json').write_text(json.dumps(result, indent=2))
    print(f'wrote {out}.json and {out}.png')


def main(argv=None):
    tune_allocator()
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    sub = p.add_subparsers(dest='cmd', required=True)
    t = sub.add_parser('train')
    t.add_argument('--model', required=True, choices=model_names('mss'))
    t.add_argument('--schedule', default='transfer', choices=('transfer', 'scratch', 'continue'),
                   help='transfer: straight then curved; scratch: curved only; continue: '
                        'curved only from --init-from (more training of a finished run)')
    t.add_argument('--init-from', default=None, metavar='CHECKPOINT',
                   help='start from a checkpoint.pt (networks and optimisers; the replay '
                        'buffer is not saved and fills again)')
    t.add_argument('--transitions', type=int, default=120_000)
    t.add_argument('--straight-fraction', type=float, default=0.3)
    t.add_argument('--n-envs', type=int, default=8)
    t.add_argument('--updates-per-step', type=int, default=4,
                   help='gradient updates per batched step of n-envs transitions')
    t.add_argument('--eval-every', type=int, default=12_000)
    t.add_argument('--seed', type=int, default=0)
    t.add_argument('--max-wall-s', type=float, default=math.inf,
                   help='stop the curved phase after this wall time (s), export the best')
    t.add_argument('--warmup', type=int, default=SETTINGS['warmup'])
    t.add_argument('--start-cross-max', type=float, default=EnvConfig.start_cross_max,
                   help='episode starts within this distance of the path (m, default 100): '
                        'a policy knows only the region its episodes visit')
    t.add_argument('--start-heading-max-deg', type=float,
                   default=math.degrees(EnvConfig.start_heading_max),
                   help='start heading within this angle of the path (deg, default 20)')
    t.add_argument('--control-dt', type=float, default=EnvConfig.control_dt,
                   help='policy step (s, a multiple of the 0.1 s plant step; default 1). The '
                        "discount 0.99 is per step, so the return's horizon is ~100 steps: a "
                        'ship with a slow heading response (tanker, Nomoto T ~160 s) needs a '
                        'longer step for a rudder action to be credited with its effect')
    t.add_argument('--out', default=None)
    t.add_argument('--export', default=None,
                   help="policy file to write ('none' to skip; default: package data for "
                        "the transfer schedule, <out>/policy.npz otherwise)")
    c = sub.add_parser('compare')
    c.add_argument('--model', required=True)
    c.add_argument('--runs', default=str(RUNS / 'transfer_study'),
                   help='folder with <model>_scratch_s<seed> and <model>_transfer_s<seed> runs')
    c.add_argument('--thresholds', type=float, nargs='+', default=[500.0, 700.0, 850.0],
                   help='curved evaluation scores on the 1 s step\'s scale (Gaussian sum per '
                        '1000 s, max 1000; a run at a longer control_dt is scaled by it)')
    g = sub.add_parser('plot')
    g.add_argument('folders', nargs='+')
    g.add_argument('--png', required=True)
    args = p.parse_args(argv)
    if args.cmd == 'train':
        SETTINGS['warmup'] = args.warmup
        for key, value in (('control_dt', args.control_dt),
                           ('start_cross_max', args.start_cross_max),
                           ('start_heading_max', math.radians(args.start_heading_max_deg))):
            if not math.isclose(value, getattr(EnvConfig, key)):
                ENV_OPTIONS[key] = value
        train(args)
    elif args.cmd == 'compare':
        compare(args)
    else:
        plot_curves(args.folders, args.png)


if __name__ == '__main__':
    main()
