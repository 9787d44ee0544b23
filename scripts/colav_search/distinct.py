"""Which failures are distinct.

Two failures are the same failure if they have the same number of targets and their unit-box
parameter vectors (colav_search.encounter: meeting time, and per target the relative course,
speed ratio and CPA offset, each scaled to [0, 1] over its range) are within ``TOLERANCE`` of
each other in every used dimension (the largest difference, circular for the course), for some
order of the targets (the targets are interchangeable). A failure is distinct if it is not the
same as any failure counted before it (greedy, in the order found). The tolerance is a tenth of
each range: 36 deg of relative course, 0.13 of speed ratio, 200 m of CPA offset, 60 s of
meeting time.
"""
import itertools

import numpy as np

from colav_search import encounter

TOLERANCE = 0.1


def _slots(n, x):
    x = np.asarray(x, float)
    return [x[encounter.slot_dims(j)] for j in range(n)]


def _gap(a, b, circular):
    d = np.abs(np.asarray(a) - np.asarray(b))
    return np.where(circular, np.minimum(d, 1.0 - d), d)


def same(a, b, tolerance=TOLERANCE):
    """True if failures ``a`` and ``b`` ((n_targets, x)) are the same failure (docstring)."""
    (na, xa), (nb, xb) = a, b
    if na != nb or abs(xa[0] - xb[0]) > tolerance:
        return False
    circ = np.array([p[3] for p in encounter.PER_TARGET])
    sa, sb = _slots(na, xa), _slots(nb, xb)
    return any(all(_gap(p, q, circ).max() <= tolerance for p, q in zip(sa, perm))
               for perm in itertools.permutations(sb))


def distinct(failures, tolerance=TOLERANCE):
    """Indices into ``failures`` [(n_targets, x)] of the distinct ones (docstring)."""
    kept = []
    for i, f in enumerate(failures):
        if not any(same(f, failures[k], tolerance) for k in kept):
            kept.append(i)
    return kept
