"""uvsym.symbolic.balanced_sum: the sum of sum1, ceil(log2 n) additions deep."""

import math

import casadi as ca
import numpy as np
import pytest

from uvsym.symbolic import balanced_sum


def _depth(expression: ca.SX, seen: dict | None = None) -> int:
    """Additions on the longest path from the expression down to a symbol (``seen``: depths by node, for graphs
    that share subexpressions)."""
    seen = {} if seen is None else seen
    if expression.is_symbolic() or expression.is_constant():
        return 0
    node = expression.element_hash()
    if node not in seen:
        below = max(_depth(expression.dep(i), seen) for i in range(expression.n_dep()))
        seen[node] = below + (1 if expression.is_op(ca.OP_ADD) else 0)
    return seen[node]


@pytest.mark.parametrize("n", [1, 2, 3, 8, 70, 71])
def test_the_sum_is_sum1_to_rounding_and_log2_deep(n):
    x = ca.SX.sym("x", n)
    total = balanced_sum(x)
    integers = np.random.default_rng(n).integers(-1000, 1000, n).astype(float)  # exact sums: equal, not close
    assert float(ca.Function("f", [x], [total])(integers)) == integers.sum()
    reals = np.random.default_rng(n + 1).normal(size=n)
    assert float(ca.Function("f", [x], [total])(reals)) == pytest.approx(reals.sum(), rel=1e-14, abs=1e-14)
    assert _depth(total) == math.ceil(math.log2(n)) if n > 1 else _depth(total) == 0
    if n >= 8:
        assert _depth(ca.sum1(x)) == n - 1  # what the tree replaces


def test_the_lms_monitor_step_sums_in_trees_and_keeps_its_numbers():
    """The monitor's step (order 70) sums its dot products as trees: its prediction is 7 additions deep (not the
    69 of a chain), and the predictions equal the plain LMS recursion (a numpy loop) to rounding."""
    from uvsym.observers.lms import lms_monitor
    from uvsym.systems.signals import signals

    order, mu, N = 70, 0.001, 400
    monitor = lms_monitor(signals(("y", "-", "")), signals(("u", "-", "")), order=order, mu=mu, eps0=1e300,
                          r0=1e300, dt=0.2)
    s, y_, u_, p = (ca.SX.sym(name, monitor.step.raw.size1_in(i)) for i, name in enumerate("syup"))
    prediction = monitor.step.raw(s, y_, u_, p)[1][0]  # the live FIR prediction d (no reference: r = 0)
    assert _depth(prediction, {}) <= math.ceil(math.log2(order)) + 1
    rng = np.random.default_rng(5)
    u = rng.normal(size=N)
    y = np.convolve(u, rng.normal(size=8) * 0.3)[:N] + 0.01 * rng.normal(size=N)
    _, outputs = monitor.run(y[:, None], u[:, None], compiled=False)
    C, U, predictions = np.zeros(order), np.zeros(order), []
    for k in range(N):
        d = C @ U
        predictions.append(d)
        C = C - 2 * mu * (d - y[k]) * U
        U = np.concatenate([[u[k]], U[:-1]])
    np.testing.assert_allclose(outputs[:, 0], predictions, rtol=1e-12, atol=1e-12)
