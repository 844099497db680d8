"""Type-generic matrix helpers: the same code builds numpy arrays or CasADi expressions.

Numeric inputs (floats, lists, numpy) give numpy float arrays; any CasADi ``SX``/``MX``/``DM``
input gives a CasADi matrix. Model builders use these so one formula serves both.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

__all__ = ["is_casadi", "stack", "block", "matvec", "entries", "rk4", "rk4_stage_times", "as_column",
           "has_nan_constant", "balanced_sum"]

_CASADI_TYPES = (ca.SX, ca.MX, ca.DM)


def is_casadi(*values) -> bool:
    """True when any value (or any element of a list/tuple value) is a CasADi matrix."""
    for value in values:
        if isinstance(value, _CASADI_TYPES):
            return True
        if isinstance(value, (list, tuple)) and is_casadi(*value):
            return True
    return False


def stack(rows):
    """Matrix from a list of rows of scalars: CasADi if any entry is CasADi, else numpy."""
    if is_casadi(*[entry for row in rows for entry in row]):
        return ca.vertcat(*[ca.horzcat(*row) for row in rows])
    return np.array(rows, dtype=float)


def block(rows):
    """Matrix from a list of rows of matrix blocks (like ``np.block``), CasADi if any is."""
    if is_casadi(*[b for row in rows for b in row]):
        return ca.vertcat(*[ca.horzcat(*[ca.DM(b) if isinstance(b, np.ndarray) else b for b in row])
                            for row in rows])
    return np.block(rows)


def matvec(A, x):
    """A @ x for numpy or CasADi operands."""
    if is_casadi(A, x):
        return ca.mtimes(ca.DM(A) if isinstance(A, np.ndarray) else A, x)
    return np.asarray(A, dtype=float) @ np.asarray(x, dtype=float).reshape(-1)


def entries(vector, n: int, name: str = "vector"):
    """The n entries of a vector as a list; ValueError naming ``name`` on a size mismatch."""
    if isinstance(vector, _CASADI_TYPES):
        if vector.numel() != n:
            raise ValueError(f"{name} must have {n} entries, got shape {vector.shape}")
        return [vector[i] for i in range(n)]
    array = np.asarray(vector, dtype=float).reshape(-1)
    if array.size != n:
        raise ValueError(f"{name} must have {n} entries, got {array.size}")
    return list(array)


def balanced_sum(vector):
    """The sum of a column vector's (n,) entries as a balanced tree of additions: the value of ``sum1`` to
    rounding, but ceil(log2 n) additions deep instead of n - 1, so straight-line generated C runs the
    additions side by side instead of waiting on each one (a dot product of 70 terms: 7 latencies, not 69)."""
    if vector.shape[1] != 1:
        raise ValueError(f"balanced_sum sums a column vector, got shape {vector.shape}")
    n = vector.shape[0]
    if n <= 2:
        return ca.sum1(vector)
    half = (n + 1) // 2
    return balanced_sum(vector[:half]) + balanced_sum(vector[half:])


def rk4(ode, s, h: float, steps: int, *args, t=0.0):
    """``steps`` classical RK4 steps of ``s' = ode(s, *args, t)`` over ``h`` seconds (symbolic)."""
    dh = h / steps
    for i in range(steps):
        ti = t + i * dh
        k1 = ode(s, *args, ti)
        k2 = ode(s + dh / 2 * k1, *args, ti + dh / 2)
        k3 = ode(s + dh / 2 * k2, *args, ti + dh / 2)
        k4 = ode(s + dh * k3, *args, ti + dh)
        s = s + dh / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return s


def rk4_stage_times(t: np.ndarray, h: float, steps: int) -> np.ndarray:
    """(len(t), 2 steps + 1) the distinct stage times of :func:`rk4` (``steps`` steps over ``h`` s) from each
    start time t (s), formed as it forms them: node j at ``(t + (j // 2) dh) + dh / 2`` for odd j, dh = h / steps."""
    dh = h / steps
    return np.column_stack([t + (j // 2) * dh + (dh / 2 if j % 2 else 0.0) for j in range(2 * steps + 1)])


def as_column(value) -> ca.SX:
    """An SX column from what a user's equation returned (SX, numbers, or a list of them);
    TypeError naming the type otherwise."""
    try:
        return ca.vec(ca.vertcat(*value) if isinstance(value, (list, tuple)) else ca.SX(value))
    except (NotImplementedError, TypeError, RuntimeError):
        raise TypeError(f"expected a CasADi expression or a list of them, got {type(value).__name__}") from None


def has_nan_constant(function: ca.Function) -> bool:
    """True when an SX Function's graph holds a NaN constant (e.g. math.sin applied to a symbol)."""
    return any(function.instruction_id(k) == ca.OP_CONST and np.isnan(function.instruction_constant(k))
               for k in range(function.n_instructions()))
