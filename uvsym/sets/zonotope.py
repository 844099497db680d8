"""Zonotopes ``<c, G> = {c + G xi : xi in [-1, 1]^m}`` (Kuehn 1998; Combastel 2005).

c: (n,) centre, G: (n, m) generator matrix, m >= 0. The operations used by set-valued
thresholds (Yang, Hu & Zhang, eqs. 4-6):

- affine map ``M <c, G> + b = <M c + b, M G>`` (exact);
- Minkowski sum ``<c1, G1> + <c2, G2> = <c1 + c2, [G1 G2]>`` (exact; the generators stay
  independent, so the same noise entering twice must enter as one generator of a joint set);
- interval hull ``c +- sum_j |G_{:, j}|`` (the smallest box holding the zonotope);
- support function ``h(a) = a^T c + ||G^T a||_1`` and point containment (a linear program:
  ``x in Z`` iff ``G xi = x - c`` has a solution with ``||xi||_inf <= 1``).

Order reduction (bounding the number of generators while enclosing the set) is in
:mod:`uvsym.sets.reduction`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog

from uvsym.errors import SetError

__all__ = ["Zonotope", "box", "finite_matrix"]


def finite_matrix(value, what: str, shape: tuple | None = None) -> np.ndarray:
    """``value`` as a float array, SetError naming ``what`` unless finite (and of ``shape``: None
    entries match any size)."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SetError(f"{what} must be a numeric array, got {type(value).__name__}") from None
    if shape is not None:
        if array.ndim != len(shape) or any(s is not None and s != a for s, a in zip(shape, array.shape)):
            wanted = "(" + ", ".join("any" if s is None else str(s) for s in shape) + ")"
            raise SetError(f"{what} must have shape {wanted}, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise SetError(f"{what} must be finite (no NaN or infinity), got {array.tolist()}")
    return array


@dataclass(frozen=True)
class Zonotope:
    """``<center, generators>``: center (n,), generators (n, m) (module docstring)."""

    center: np.ndarray
    generators: np.ndarray

    def __post_init__(self):
        c = finite_matrix(self.center, "zonotope center", (None,))
        G = finite_matrix(self.generators, "zonotope generators", (None, None)) if np.size(self.generators) \
            else np.zeros((c.size, 0))
        if G.shape[0] != c.size:
            raise SetError(f"zonotope generators have {G.shape[0]} rows but the center has {c.size} entries")
        for name, value in (("center", c), ("generators", G)):
            value = np.array(value)
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    @classmethod
    def trusted(cls, center: np.ndarray, generators: np.ndarray) -> Zonotope:
        """A zonotope from arrays already known to be finite and conforming (results of operations
        on checked zonotopes), without re-checking them."""
        zonotope = object.__new__(cls)
        fields = zonotope.__dict__  # past the frozen __setattr__: half the time of object.__setattr__
        fields["center"], fields["generators"] = center, generators
        return zonotope

    @property
    def dimension(self) -> int:
        """n."""
        return self.center.size

    @property
    def order(self) -> int:
        """The number of generators m."""
        return self.generators.shape[1]

    def map(self, M, b=None) -> Zonotope:
        """``M Z + b``: M (k, n), b (k,) or None."""
        M = finite_matrix(M, "map matrix", (None, self.dimension))
        b = np.zeros(M.shape[0]) if b is None else finite_matrix(b, "map offset", (M.shape[0],))
        return Zonotope.trusted(M @ self.center + b, M @ self.generators)

    def __add__(self, other: Zonotope) -> Zonotope:
        """Minkowski sum with another zonotope of the same dimension (independent generators)."""
        if not isinstance(other, Zonotope):
            return NotImplemented
        if other.dimension != self.dimension:
            raise SetError(f"Minkowski sum of zonotopes of dimensions {self.dimension} and {other.dimension}")
        return Zonotope.trusted(self.center + other.center, np.hstack([self.generators, other.generators]))

    def interval_hull(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper), each (n,): the smallest box holding the zonotope."""
        radius = np.sum(np.abs(self.generators), axis=1)
        return self.center - radius, self.center + radius

    def support(self, direction) -> float:
        """``h(a) = max_{z in Z} a^T z = a^T c + ||G^T a||_1``."""
        a = finite_matrix(direction, "direction", (self.dimension,))
        return float(a @ self.center + np.sum(np.abs(self.generators.T @ a)))

    def contains(self, point, tolerance: float = 1e-9) -> bool:
        """True when ``point`` (n,) lies in the zonotope (linear program, HiGHS), allowing
        ``||xi||_inf <= 1 + tolerance``; SetError unless ``tolerance`` is finite and >= 0."""
        if not 0.0 <= tolerance < np.inf:
            raise SetError(f"containment tolerance must be finite and >= 0, got {tolerance}")
        x = finite_matrix(point, "point", (self.dimension,))
        lower, upper = self.interval_hull()
        slack = tolerance * (1.0 + np.abs(upper - lower))
        if np.any(x < lower - slack) or np.any(x > upper + slack):
            return False
        m = self.order
        if m == 0:
            return bool(np.all(np.abs(x - self.center) <= slack))
        # minimise t subject to G xi = x - c, -t <= xi_j <= t: variables (xi, t)
        cost = np.zeros(m + 1)
        cost[-1] = 1.0
        ones = np.ones((m, 1))
        A_ub = np.vstack([np.hstack([np.eye(m), -ones]), np.hstack([-np.eye(m), -ones])])
        result = linprog(cost, A_ub=A_ub, b_ub=np.zeros(2 * m), A_eq=np.hstack([self.generators, np.zeros((
            self.dimension, 1))]), b_eq=x - self.center, bounds=[(None, None)] * m + [(0, None)], method="highs")
        return bool(result.status == 0 and result.x[-1] <= 1.0 + tolerance)


def box(lower, upper) -> Zonotope:
    """The box ``lower <= x <= upper`` as a zonotope (one generator per non-degenerate axis).

    SetError for NaN or infinite bounds, bounds of different sizes or ``lower > upper``."""
    lo = finite_matrix(lower, "box lower bound", (None,))
    hi = finite_matrix(upper, "box upper bound", (lo.size,))
    if np.any(lo > hi):
        raise SetError(f"box lower bound exceeds the upper bound at entries {np.flatnonzero(lo > hi).tolist()}")
    radius = (hi - lo) / 2
    axes = np.flatnonzero(radius > 0)
    G = np.zeros((lo.size, axes.size))
    G[axes, np.arange(axes.size)] = radius[axes]
    return Zonotope((hi + lo) / 2, G)
