"""The search loop of one sampler and the results file of a study.

Each sampler gets the same budget of simulations, spent in generations of ``generation``
encounters (the cross-entropy method updates its density after each; uniform sampling ignores
the scores). The episodes of a generation run in a process pool of ``jobs`` workers (each
process runs the reference once: montecarlo.encounters.reference) or as Ray tasks
(montecarlo.backends.RayPool, on a cluster); the results come back in draw order, so the search
is deterministic for a seed whatever the pool. A Ray pool counts the simulations that ran again
after a lost worker or node: each row's ``reran`` (None where the count was not available).
"""
import time

from colav_search import distinct, encounter, episode
from colav_search.sampling import CrossEntropy, Uniform

SAMPLERS = ('uniform', 'cross_entropy')


def make_sampler(name, seed):
    common = dict(dim=encounter.DIM, categories=encounter.TARGET_COUNTS, seed=seed,
                  feasible=encounter.feasible)
    if name == 'uniform':
        return Uniform(**common)
    if name == 'cross_entropy':
        return CrossEntropy(**common, circular=encounter.circular_dims(), active=active,
                            level=episode.FAILURE_LEVEL)
    raise ValueError(f'unknown sampler {name!r} (known: {", ".join(SAMPLERS)})')


def active(n_targets):
    """Mask of the dimensions an encounter with ``n_targets`` uses."""
    import numpy as np
    mask = np.zeros(encounter.DIM, bool)
    mask[0] = True
    for j in range(n_targets):
        mask[encounter.slot_dims(j)] = True
    return mask


def _run(task):
    n, x, ship, method = task
    return episode.run(n, x, ship, method)


class ResumeError(Exception):
    """A finished generation of a partial file is not the one the sampler draws now."""


def search(sampler, budget, generation, ship, method, jobs=1, progress=print, pool=None,
           done=None, record=None):
    """Rows (one per simulation: n_targets, x, the episode's dict, generation) of ``sampler``
    run for ``budget`` simulations. ``done``: finished generations ({'<sampler>:<g>': record},
    as ``record`` got them) whose episodes are not run again: the sampler draws them anew (its
    draws depend only on its seed and the scores) and takes their recorded results.
    ``record(key, samples, out, reran)`` is called after each generation that ran."""
    rows, t0, g = [], time.perf_counter(), 0
    while len(rows) < budget:
        samples = sampler.propose(min(generation, budget - len(rows)))
        key = f'{sampler.name}:{g}'
        if done and key in done:
            out, reran = done[key]['out'], done[key]['reran']
            if _drawn(samples) != done[key]['samples']:
                raise ResumeError(f'generation {g} of {sampler.name} draws other encounters '
                                  'than the partial file holds')
        else:
            tasks = [(n, x, ship, method) for n, x in samples]
            out = list(pool.map(_run, tasks)) if pool is not None else [_run(t) for t in tasks]
            reran = getattr(pool, 'reruns', [[]])[-1] if pool is not None else []
            if record is not None:
                record(key, _drawn(samples), out, reran)
        sampler.update(samples, [o['score'] for o in out])
        rows += [{'generation': g, 'n_targets': int(n), 'x': [float(v) for v in x], **o,
                  'reran': None if reran is None else k in reran}
                 for k, ((n, x), o) in enumerate(zip(samples, out))]
        fails = sum(r['failure'] for r in rows)
        progress(f'{sampler.name}: generation {g}, {len(rows)}/{budget} sims, {fails} failures, '
                 f'best domain index {min(r["score"] for r in rows):.3f}, '
                 f'{time.perf_counter() - t0:.0f} s')
        g += 1
    return rows


def _drawn(samples):
    """Samples as the partial file holds them (JSON keeps every float exactly)."""
    return [[int(n), [float(v) for v in x]] for n, x in samples]


def summary(rows, ship, method):
    """Per-sampler figures for the results file: sims, failures, distinct failures, each per
    1,000 sims (scaled from the budget), and every failure with its parameters."""
    failures = [r for r in rows if r['failure']]
    kept = distinct.distinct([(r['n_targets'], r['x']) for r in failures])
    per_k = 1000.0 / len(rows)
    return {
        'sims': len(rows), 'failures': len(failures), 'distinct_failures': len(kept),
        'collisions': sum(r['collision'] for r in rows),
        'failures_per_1000': len(failures) * per_k,
        'distinct_failures_per_1000': len(kept) * per_k,
        'first_failure_sim': next((i + 1 for i, r in enumerate(rows) if r['failure']), None),
        'min_domain_index': min(r['score'] for r in rows),
        'min_distance_m': min(r['min_distance_m'] for r in rows),
        'wall_s_mean': sum(r['wall_s'] for r in rows) / len(rows),
        'sim_s_mean': sum(r['end_s'] for r in rows) / len(rows),
        'reran_sims': (None if any(r.get('reran') is None for r in rows) else
                       [i for i, r in enumerate(rows) if r.get('reran')]),
        'failure_list': [{'index': rows.index(r), 'distinct': i in kept, 'generation':
                          r['generation'], 'collision': r['collision'],
                          'min_distance_m': r['min_distance_m'], 'domain_index': r['score'],
                          't_min_s': r['t_min_s'], 'x': r['x'],
                          **encounter.describe(r['n_targets'], r['x'])}
                         for i, r in enumerate(failures)],
    }
