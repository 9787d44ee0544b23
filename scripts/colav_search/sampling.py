"""Samplers over the unit box [0, 1]^D with a categorical parameter beside it (pure numpy/scipy).

``Uniform``: every draw uniform on the box, the category uniform: plain Monte Carlo.

``CrossEntropy``: the cross-entropy method for rare events (Rubinstein 1997, "Optimization of
computer simulation models with rare events", European Journal of Operational Research 99;
Rubinstein & Kroese 2004, "The Cross-Entropy Method"; de Boer, Kroese, Mannor & Rubinstein
2005, "A tutorial on the cross-entropy method", Annals of Operations Research 134), as O'Kelly
et al. 2018 ("Scalable end-to-end autonomous vehicle testing via rare-event simulation",
NeurIPS) apply it to falsify a driving policy. The sampling density is a product of independent
one-dimensional densities: a normal truncated to [0, 1] per dimension (wrapped onto [0, 1) for a
circular one) and a categorical distribution for the category. Each generation draws
``generation`` vectors, runs them, and scores each (lower is closer to failure; a failure is a
score below ``level``). The elite set is the samples at or below the level
gamma = max(the ``elite_fraction`` quantile of the scores, ``level``): once more than that
fraction fail, the elites are exactly the failures. The density's parameters are refitted to
the elites (mean and standard deviation per dimension, circular mean and spread for a circular
one, frequencies for the category) and smoothed, theta <- alpha theta_fit + (1 - alpha)
theta_old (de Boer et al., section 3.1), with a floor on each standard deviation and each
category's probability so that the search keeps exploring. A dimension that the category
switches off (a target slot beyond the target count) is refitted only on the elites that use
it; with fewer than ``min_elites`` of those it keeps its parameters. The first generation is
uniform (the density starts as the box's own).

Both samplers draw again a vector that ``feasible`` rejects (rejection sampling: both then
sample the same region), with their own seeded numpy Generator: the same seed, the same draws.
"""
import numpy as np
from scipy.stats import truncnorm

_MAX_TRIES = 10000


def _draw(rng, propose_one, feasible):
    for _ in range(_MAX_TRIES):
        n, x = propose_one(rng)
        if feasible is None or feasible(n, x):
            return n, x
    raise RuntimeError(f'no feasible draw in {_MAX_TRIES} tries: the density left the region')


class Uniform:
    """Uniform draws on the box and over ``categories`` (module docstring)."""

    name = 'uniform'

    def __init__(self, dim, categories, seed, feasible=None):
        self.dim, self.categories = int(dim), tuple(categories)
        self.rng = np.random.default_rng(seed)
        self.feasible = feasible

    def _one(self, rng):
        return self.categories[int(rng.integers(len(self.categories)))], rng.random(self.dim)

    def propose(self, count):
        return [_draw(self.rng, self._one, self.feasible) for _ in range(int(count))]

    def update(self, samples, scores):
        """Nothing: the density never changes."""


class CrossEntropy:
    """The cross-entropy method (module docstring). ``active(category)`` gives the boolean mask
    of the dimensions a category uses (default all); ``circular`` the mask of circular ones."""

    name = 'cross_entropy'

    def __init__(self, dim, categories, seed, feasible=None, circular=None, active=None,
                 level=1.0, elite_fraction=0.2, smoothing=0.7, sigma_floor=0.05,
                 probability_floor=0.05, min_elites=2):
        self.dim, self.categories = int(dim), tuple(categories)
        self.rng = np.random.default_rng(seed)
        self.feasible = feasible
        self.circular = np.zeros(self.dim, bool) if circular is None else np.asarray(circular)
        self.active = active or (lambda c: np.ones(self.dim, bool))
        self.level, self.elite_fraction = float(level), float(elite_fraction)
        self.smoothing, self.sigma_floor = float(smoothing), float(sigma_floor)
        self.probability_floor, self.min_elites = float(probability_floor), int(min_elites)
        self.mean = np.full(self.dim, 0.5)
        self.sigma = np.full(self.dim, np.inf)        # inf: still uniform in that dimension
        self.probabilities = np.full(len(self.categories), 1.0 / len(self.categories))
        self.history = []                             # (gamma, elites) per update

    def _one(self, rng):
        c = self.categories[int(rng.choice(len(self.categories), p=self.probabilities))]
        x = np.empty(self.dim)
        for i in range(self.dim):
            m, s = self.mean[i], self.sigma[i]
            if not np.isfinite(s):
                x[i] = rng.random()
            elif self.circular[i]:
                x[i] = (m + s * rng.standard_normal()) % 1.0
            else:
                a, b = (0.0 - m) / s, (1.0 - m) / s
                x[i] = float(truncnorm.rvs(a, b, loc=m, scale=s, random_state=rng))
        return c, x

    def propose(self, count):
        return [_draw(self.rng, self._one, self.feasible) for _ in range(int(count))]

    def update(self, samples, scores):
        """Refit the density to the elites of one generation: ``samples`` [(category, x)],
        ``scores`` (lower: closer to failure)."""
        scores = np.asarray(scores, dtype=float)
        gamma = max(float(np.quantile(scores, self.elite_fraction)), self.level)
        elite = [s for s, v in zip(samples, scores) if v <= gamma]
        self.history.append((gamma, len(elite)))
        if not elite:
            return
        a = self.smoothing
        freq = np.array([sum(c == k for c, _ in elite) for k in self.categories], float)
        p = a * freq / freq.sum() + (1.0 - a) * self.probabilities
        p = np.maximum(p, self.probability_floor)
        self.probabilities = p / p.sum()
        xs = np.array([x for _, x in elite])
        used = np.array([self.active(c) for c, _ in elite])
        for i in range(self.dim):
            v = xs[used[:, i], i]
            if v.size < self.min_elites:
                continue
            if self.circular[i]:
                z = np.exp(2j * np.pi * v).mean()
                m = (np.angle(z) / (2.0 * np.pi)) % 1.0
                r = min(max(abs(z), 1e-12), 1.0)
                s = np.sqrt(-2.0 * np.log(r)) / (2.0 * np.pi)   # wrapped normal's sigma
            else:
                m, s = float(v.mean()), float(v.std())
            if np.isfinite(self.sigma[i]):
                old_m, old_s = self.mean[i], self.sigma[i]
            else:   # from uniform: its mean and standard deviation
                old_m, old_s = 0.5, 1.0 / np.sqrt(12.0)
            if self.circular[i]:
                d = ((m - old_m + 0.5) % 1.0) - 0.5
                self.mean[i] = (old_m + a * d) % 1.0
            else:
                self.mean[i] = a * m + (1.0 - a) * old_m
            self.sigma[i] = max(a * s + (1.0 - a) * old_s, self.sigma_floor)
