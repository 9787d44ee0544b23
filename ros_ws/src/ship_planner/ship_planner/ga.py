"""Real-coded genetic algorithm (minimisation on the unit box [0, 1]^n).

After Lee 2004, Chapter 3 (a real-coded GA picks the waypoints, trading navigational distance
against propulsive energy loss); its operators are not legible in the source's OCR, so these are
textbook ones: tournament selection (Goldberg & Deb 1991), BLX-alpha crossover (Eshelman &
Schaffer 1993), non-uniform mutation (Michalewicz 1992), elitism, plus our segment-shift
mutation that moves a stretch of consecutive genes (waypoints along a route) together, and an
optional pattern-search ``refine``. Stops after ``generations`` or when the best cost has not
improved by more than ``rel_tol`` (relative) for ``stall_generations``. Deterministic for a given
``seed`` (numpy Generator). ``cost`` is vectorised: (P, n) array -> (P,) costs.
``minimize_box`` runs the same GA over any box of real parameters (the guidance tuning of
ship_autopilot.guidance_tuning uses it).

The operators and their parameters in full: ros_ws/src/ship_planner/doc/route_planning.md.
"""
from dataclasses import dataclass, field

import numpy as np


@dataclass
class GAResult:
    """Best genes, their cost, best cost per generation, generations run, cost evaluations, why
    the run stopped. Callers may refine x afterwards and record the GA's own cost in ga_cost."""
    x: np.ndarray
    cost: float
    history: list = field(default_factory=list)
    generations: int = 0
    evaluations: int = 0
    stopped: str = ''
    ga_cost: float = None
    refine_calls: int = 0
    feasible: bool = True


def minimize(cost, n_var, population=60, generations=300, elite=2, tournament=3, crossover_rate=0.9,
             blx_alpha=0.3, mutation_rate=None, mutation_shape=3.0, shift_rate=0.5, shift_sigma=0.3,
             stall_generations=60, rel_tol=1e-6, initial=None, seed=0, progress=None, progress_every=25):
    """Minimise cost over [0, 1]^n_var. initial: optional (m, n_var) individuals to seed the first
    population (the rest are uniform random). progress(generation, best_cost) every
    progress_every generations and at the end."""
    n = int(n_var)
    if n < 1:
        raise ValueError(f'n_var must be >= 1, got {n_var}')
    pop_n = int(population)
    if pop_n < 4 or pop_n % 2:
        raise ValueError(f'population must be an even number >= 4, got {population}')
    if not 0 <= elite < pop_n:
        raise ValueError(f'elite must be in [0, population), got {elite}')
    pm = 1.0 / n if mutation_rate is None else float(mutation_rate)
    rng = np.random.default_rng(seed)

    pop = rng.random((pop_n, n))
    if initial is not None:
        init = np.clip(np.atleast_2d(np.asarray(initial, dtype=float)), 0.0, 1.0)[:pop_n]
        pop[:len(init)] = init
        rest = init[rng.integers(0, len(init), pop_n - len(init))]
        for _ in range(3):
            rest = _shift(rest, rng, shift_sigma, rng.random(len(rest)) < 0.7)
        pop[len(init):] = rest
    f = np.asarray(cost(pop), dtype=float)
    evaluations = pop_n
    best = int(np.argmin(f))
    history = [float(f[best])]
    last_gain, stopped = 0, 'generations'
    g = 0
    for g in range(1, int(generations) + 1):
        order = np.argsort(f, kind='stable')
        elites = pop[order[:elite]]
        n_child = pop_n - elite
        n_pairs = (n_child + 1) // 2
        # tournament selection of 2 parents per pair
        entrants = rng.integers(0, pop_n, size=(2 * n_pairs, tournament))
        winners = entrants[np.arange(2 * n_pairs), np.argmin(f[entrants], axis=1)]
        pa, pb = pop[winners[0::2]], pop[winners[1::2]]
        # BLX-alpha crossover
        lo, hi = np.minimum(pa, pb), np.maximum(pa, pb)
        span = hi - lo
        cross = rng.random(n_pairs) < crossover_rate
        c1 = np.where(cross[:, None], rng.uniform(lo - blx_alpha * span, hi + blx_alpha * span), pa)
        c2 = np.where(cross[:, None], rng.uniform(lo - blx_alpha * span, hi + blx_alpha * span), pb)
        children = np.clip(np.concatenate([c1, c2])[:n_child], 0.0, 1.0)
        # non-uniform mutation
        mutate = rng.random(children.shape) < pm
        if mutate.any():
            shrink = (1.0 - rng.random(children.shape) ** ((1.0 - g / (generations + 1)) ** mutation_shape))
            up = rng.random(children.shape) < 0.5
            step = np.where(up, (1.0 - children) * shrink, -children * shrink)
            children = np.where(mutate, children + step, children)
        children = _shift(children, rng, shift_sigma * (1.0 - g / (generations + 1)),
                          rng.random(len(children)) < shift_rate)
        pop = np.concatenate([elites, np.clip(children, 0.0, 1.0)])
        f = np.concatenate([f[order[:elite]], np.asarray(cost(pop[elite:]), dtype=float)])
        evaluations += n_child
        best = int(np.argmin(f))
        history.append(float(f[best]))
        if history[-1] < history[last_gain] - rel_tol * max(abs(history[last_gain]), 1e-12):
            last_gain = g
        if progress is not None and g % progress_every == 0:
            progress(g, history[-1])
        if g - last_gain >= stall_generations:
            stopped = 'stall'
            break
    if progress is not None and g % progress_every:
        progress(g, history[-1])
    return GAResult(pop[best].copy(), float(f[best]), history, g, evaluations, stopped)


def minimize_box(cost, lower, upper, shift_rate=0.0, **kw):
    """``minimize`` over the box [lower, upper] (arrays of n bounds, lower < upper): the genes
    stay in [0, 1] and are mapped linearly, so every operator works as for the routes; cost
    takes (P, n) points in the box's own units. The segment-shift mutation, which moves
    neighbouring waypoints together, means nothing for unrelated genes and is off by default.
    Returns the GAResult with x in the box's units."""
    lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    if lo.ndim != 1 or lo.shape != hi.shape or not np.all(np.isfinite(lo) & np.isfinite(hi)) \
            or not np.all(hi > lo):
        raise ValueError(f'lower and upper must be finite 1-D bounds with upper > lower, got {lower}, {upper}')
    span = hi - lo
    res = minimize(lambda z: cost(lo + z * span), len(lo), shift_rate=shift_rate, **kw)
    res.x = lo + res.x * span
    return res


def _shift(x, rng, sigma, which):
    """Segment-shift mutation of the rows selected by which (doc/route_planning.md), clipped to [0, 1]."""
    m, n = x.shape
    centre = rng.integers(0, n, m)
    half = rng.integers(1, max(2, n // 2 + 1), m)
    scale = sigma * 10.0 ** rng.uniform(-3.0, 0.0, m)       # many scales: coarse and fine moves
    amount = rng.normal(0.0, 1.0, m) * scale * which
    k = np.arange(n)[None, :]
    u = np.abs(k - centre[:, None]) / half[:, None]
    taper = np.where(u < 1.0, np.cos(0.5 * np.pi * u) ** 2, 0.0)
    return np.clip(x + amount[:, None] * taper, 0.0, 1.0)


def refine(cost, x, step=0.05, min_step=1e-4, max_calls=3000):
    """Local refinement of a GA result (a memetic last step): pattern search with stretch moves.

    The moves are: every stretch of 1, 2, 4, ... consecutive genes (up to all of them) shifted by
    +h or -h together, clipped to [0, 1]. All moves are evaluated in one vectorised call, the best
    improving one is taken; when none improves, h halves, down to min_step.
    Returns (x, cost, calls)."""
    x = np.clip(np.asarray(x, dtype=float).copy(), 0.0, 1.0)
    n = len(x)
    fx = float(cost(x[None])[0])
    widths = sorted({min(2 ** k, n) for k in range(int(np.ceil(np.log2(max(n, 1)))) + 1)})
    masks = np.array([[(i <= k < i + w) for k in range(n)] for w in widths for i in range(n - w + 1)], dtype=float)
    h, calls = float(step), 0
    while h >= min_step and calls < max_calls:
        rows = np.clip(np.concatenate([x + h * masks, x - h * masks]), 0.0, 1.0)
        f = np.asarray(cost(rows), dtype=float)
        calls += 1
        j = int(np.argmin(f))
        if f[j] < fx - 1e-9 * max(abs(fx), 1.0):
            x, fx = rows[j], float(f[j])
        else:
            h *= 0.5
    return x, fx, calls
