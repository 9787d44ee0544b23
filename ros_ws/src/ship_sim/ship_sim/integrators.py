"""Fixed-step fourth-order Runge-Kutta, exactly as MSS ``LIBRARY/numericalMethods/rk4.m``.

Source: Fossen, Marine Systems Simulator (github.com/cybergalactic/MSS, commit 736a3d1),
``rk4.m``: the input is held constant over the step (sample and hold) and

    k1 = f(x, u),  k2 = f(x + h/2 k1, u),  k3 = f(x + h/2 k2, u),  k4 = f(x + h k3, u)
    x+ = x + (h/6) (k1 + 2 k2 + 2 k3 + k4)

evaluated in the same order as MSS so results agree to rounding. Time h in seconds.

Two entry points, same arithmetic:

- ``rk4_step(f, x, u, h)``: numpy arrays, any leading batch axes (``f`` is e.g. ``model.rhs``).
  Use it for many vessels at once.
- ``rk4_step_floats(f, x, u, h)``: one vessel as a sequence of Python floats, ``f`` returning a
  sequence of floats (e.g. ``model.rhs_scalar``); returns a list. Use it for a single vessel,
  where numpy's per-call overhead would dominate. ``VesselModel`` subclasses built on
  ``MssShip`` offer ``model.step(x, u, h)``, which picks the right path.
"""


def rk4_step(f, x, u, h):
    """One RK4 step of xdot = f(x, u) with u held constant; x, u numpy arrays (batched ok)."""
    k1 = f(x, u)
    k2 = f(x + 0.5 * h * k1, u)
    k3 = f(x + 0.5 * h * k2, u)
    k4 = f(x + h * k3, u)
    return x + (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4)


def rk4_step_floats(f, x, u, h):
    """One RK4 step on a single state given as floats; returns a list of floats."""
    hh = 0.5 * h
    k1 = f(x, u)
    k2 = f([a + hh * b for a, b in zip(x, k1)], u)
    k3 = f([a + hh * b for a, b in zip(x, k2)], u)
    k4 = f([a + h * b for a, b in zip(x, k3)], u)
    h6 = h / 6
    return [a + h6 * (b1 + 2 * b2 + 2 * b3 + b4)
            for a, b1, b2, b3, b4 in zip(x, k1, k2, k3, k4)]
