"""Two math backends so each model's equations are written once and run on floats or arrays.

A model writes its equations against an ``ops`` object (``ops.sin(a)``, ``ops.sat(a, lim)``,
...) plus the arithmetic operators and the builtin ``abs``, which work on both. It is then
evaluated with

- ``FLOAT_OPS``: Python floats and the ``math`` module. This is the single-vessel fast path:
  numpy's per-call overhead on a 0-d value dominates a 7-state model, while plain float
  arithmetic is far cheaper per operation (doc/results/performance.md).
- ``ARRAY_OPS``: numpy arrays with any leading batch shape (thousands of vessels at once).

``sat`` is the symmetric saturation MSS codes as ``if abs(a) >= lim, a = sign(a)*lim; end``
(same value as clipping to [-lim, lim]; NaN passes through unchanged in both).
"""
import math

import numpy as np


def _float_sat(a, lim):
    if a > lim:
        return lim
    if a < -lim:
        return -lim
    return a


def _float_where(cond, a, b):
    return a if cond else b


def _float_sign(a):
    return 1.0 if a > 0 else -1.0 if a < 0 else a   # 0.0, -0.0 and NaN as numpy.sign


def _array_sat(a, lim):
    return np.minimum(np.maximum(a, -lim), lim)


class _Ops:
    """A namespace of elementwise functions (no state)."""

    def __init__(self, **funcs):
        self.__dict__.update(funcs)


#: Scalar backend: arguments and results are Python floats.
FLOAT_OPS = _Ops(sin=math.sin, cos=math.cos, sqrt=math.sqrt, atan=math.atan,
                 atan2=math.atan2, hypot=math.hypot, sat=_float_sat, where=_float_where,
                 sign=_float_sign)

#: Array backend: arguments are numpy arrays (or floats) that broadcast together.
ARRAY_OPS = _Ops(sin=np.sin, cos=np.cos, sqrt=np.sqrt, atan=np.arctan,
                 atan2=np.arctan2, hypot=np.hypot, sat=_array_sat, where=np.where,
                 sign=np.sign)
