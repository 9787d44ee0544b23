"""MSS-style RK4 (rk4.m): exact on the 4th-order Taylor polynomial, input held, both paths."""
import numpy as np

from ship_sim.integrators import rk4_step, rk4_step_floats


def test_linear_system_gives_the_fourth_order_taylor_polynomial():
    # For xdot = A x + B u, one RK4 step is exactly x+ = P(hA) x + h Q(hA) B u with
    # P(M) = I + M + M^2/2 + M^3/6 + M^4/24 and Q(M) = I + M/2 + M^2/6 + M^3/24.
    A = np.array([[-0.3, 1.0], [-2.0, -0.1]])
    B = np.array([[0.0], [1.5]])
    x, u, h = np.array([1.0, -0.5]), np.array([0.7]), 0.2
    M = h * A
    identity = np.eye(2)
    P = identity + M + M @ M / 2 + M @ M @ M / 6 + M @ M @ M @ M / 24
    Q = identity + M / 2 + M @ M / 6 + M @ M @ M / 24
    expected = P @ x + h * Q @ B @ u
    got = rk4_step(lambda x, u: x @ A.T + u @ B.T, x, u, h)
    np.testing.assert_allclose(got, expected, rtol=1e-14)


def test_global_error_is_fourth_order():
    # xdot = -x^2, x(0) = 1 -> x(t) = 1/(1+t); halving h divides the error at t = 2 by ~16.
    def f(x, u):
        return -x * x

    def error(h):
        x = np.array([1.0])
        for _ in range(int(round(2.0 / h))):
            x = rk4_step(f, x, None, h)
        return abs(x[0] - 1.0 / 3.0)

    ratio = error(0.1) / error(0.05)
    assert 14.0 < ratio < 18.0


def test_input_is_held_over_the_step():
    # xdot = u: the step is exactly x + h u whatever the stages.
    got = rk4_step_floats(lambda x, u: [u[0], u[1]], [1.0, 2.0], [0.5, -4.0], 0.1)
    assert got == [1.0 + 0.1 * 0.5, 2.0 - 0.1 * 4.0]


def test_float_path_equals_array_path_and_batches():
    def f(x, u):
        return np.stack([x[..., 1], -np.sin(x[..., 0]) + u[..., 0]], axis=-1)

    def f_floats(x, u):
        return (x[1], -np.sin(x[0]) + u[0])

    x, u = np.array([0.4, -0.2]), np.array([0.1])
    one = rk4_step(f, x, u, 0.05)
    np.testing.assert_allclose(rk4_step_floats(f_floats, x.tolist(), u.tolist(), 0.05), one,
                               rtol=1e-15)
    batch = rk4_step(f, np.stack([x, 2 * x]), np.stack([u, u]), 0.05)
    np.testing.assert_array_equal(batch[0], one)
    np.testing.assert_array_equal(batch[1], rk4_step(f, 2 * x, u, 0.05))
