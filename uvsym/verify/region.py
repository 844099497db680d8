"""Lyapunov decrease of a nonlinear system on a box, by interval branch-and-bound over the CasADi graph.

Claim: ``V'(x) = dV/dx f(x) <= -gamma x^T x`` for every x in the box ``lower <= x <= upper``
(which holds the equilibrium x = 0), i.e. ``W(x) = V'(x) + gamma x^T x <= 0``, with V' derived
by differentiating V along f (CasADi), nothing typed.

- Outside a small cube ``|x|_inf <= rho`` around the equilibrium: branch-and-bound. A box is
  proved when an upper bound of W on it is negative: the plain interval extension of W's graph
  (:class:`~uvsym.verify.interval.IntervalFunction`, outward rounding), or, where W is smooth and
  defined on the box, the mean-value form ``W(c) + grad W(box) (box - c)`` (its products and sum
  rounded upward), whichever is lower. A box that is not proved has its centre checked (a
  rigorous interval evaluation at the point: a lower bound above 0 is a counterexample; a point
  where W may be undefined, e.g. sqrt of a negative, ends the search as inconclusive) and is then
  bisected along its widest side. A box where W may be undefined is never proved.
- The cube itself, where W vanishes to second order and intervals cannot separate it from 0, is
  covered by the linearisation: with ``W(0) = 0`` and ``grad W(0) = 0`` (checked), Taylor's theorem
  gives ``W(x) = x^T H(xi) x / 2`` with xi in the cube, and the interval Hessian ``Hc +- Delta`` over
  the cube is shown negative definite by an exact rational LDL^T factorisation of
  ``-(Hc + r I)``, r a rational upper bound of ``|Delta|_F`` (an integer square root: no rounding,
  no underflow or overflow at any scale). If that fails rho is halved (up to ``HALVINGS`` times).
  Should it fail at every size (or W(0), grad W(0) not be exactly 0), the branch-and-bound still
  searches the rest of the box for a counterexample before the claim is called inconclusive.
"""

from __future__ import annotations

import math
import time
from fractions import Fraction

import casadi as ca
import numpy as np

from uvsym.errors import VerificationError
from uvsym.progress import ProgressBar
from uvsym.verify.certificate import Certificate
from uvsym.verify.interval import IntervalFunction, Intervals
from uvsym.verify.interval_arithmetic import round_up
from uvsym.verify.lyapunov import exact_positive_definite

__all__ = ["region_decrease"]

HALVINGS = 6


def _format_box(lower, upper, labels) -> str:
    return ", ".join(f"{lo:g} <= {name} <= {hi:g}" for name, lo, hi in zip(labels, lower, upper))


class _Decrease:
    """W, its gradient and Hessian as interval functions, and the rigorous point check."""

    def __init__(self, W: ca.SX, x: ca.SX):
        self.W = IntervalFunction(ca.Function("W", [x], [W]))
        self.grad = IntervalFunction(ca.Function("grad_W", [x], [ca.densify(ca.gradient(W, x))]))
        self.hess = IntervalFunction(ca.Function("hess_W", [x], [ca.densify(ca.vec(ca.hessian(W, x)[0]))]))
        self.n = x.numel()

    def upper_bound(self, lo, hi) -> np.ndarray:
        """An upper bound of W on each box (k,): the lower of the plain and the mean-value forms;
        +inf where W may be undefined on the box."""
        plain = self.W(lo, hi)
        bound = np.where(plain.defined, plain.hi[:, 0], np.inf)
        if np.any(plain.smooth & plain.defined):
            centre = 0.5 * (lo + hi)
            at_centre = self.W(centre, centre)
            slope = self.grad(lo, hi)
            # a side of width 0 (its centre exact) has half-width 0, not rounded up: its slope never counts
            half = np.where((lo == hi) & (centre == lo), 0.0, round_up(np.maximum(hi - centre, centre - lo)))
            steep = np.maximum(np.abs(slope.lo), np.abs(slope.hi))
            with np.errstate(all="ignore"):
                spread = np.zeros(len(lo))
                for j in range(self.n):  # |x_j - c_j| <= half_j, each product and partial sum rounded up
                    spread = round_up(spread + np.where(half[:, j] == 0, 0.0, round_up(steep[:, j] * half[:, j])))
                mean_value = round_up(at_centre.hi[:, 0] + spread)
            usable = plain.smooth & plain.defined & slope.defined & at_centre.defined & ~np.isnan(mean_value)
            bound = np.where(usable, np.minimum(bound, mean_value), bound)
        return bound

    def at_equilibrium(self) -> tuple[Intervals, Intervals, Intervals]:
        """Bounds of W, grad W and vec(Hessian of W) at x = 0."""
        zero = np.zeros((1, self.n))
        return self.W(zero, zero), self.grad(zero, zero), self.hess(zero, zero)

    def certainly_positive(self, points) -> np.ndarray:
        """(k,) True where W(point) > 0 rigorously."""
        value = self.W(points, points)
        return value.defined & (value.lo[:, 0] > 0)

    def maybe_undefined(self, points) -> np.ndarray:
        """(k,) True where W may be undefined at the point (an operation at the edge of its domain)."""
        return ~self.W(points, points).defined


def _sqrt_above(value: Fraction) -> Fraction:
    """A rational r >= sqrt(value) (value >= 0), exactly, less than 2^-64 / denominator above it (0 for 0):
    sqrt(p / q) = sqrt(p q 2^128) / (q 2^64), its integer square root rounded up."""
    scaled = (value.numerator * value.denominator) << 128
    root = math.isqrt(scaled)
    return Fraction(root if root * root == scaled else root + 1, value.denominator << 64)


def _cube_certificate(decrease: _Decrease, rho: float) -> tuple[bool, Fraction | None]:
    """Whether the interval Hessian on ``|x|_inf <= rho`` is negative definite (exactly), and the pivot."""
    lo, hi = np.full((1, decrease.n), -rho), np.full((1, decrease.n), rho)
    hessian = decrease.hess(lo, hi)
    value = decrease.W(lo, hi)
    if not (value.smooth[0] and value.defined[0] and hessian.smooth[0] and hessian.defined[0]):
        return False, None
    n = decrease.n
    H_lo, H_hi = hessian.lo[0].reshape(n, n), hessian.hi[0].reshape(n, n)
    H_lo, H_hi = np.minimum(H_lo, H_lo.T), np.maximum(H_hi, H_hi.T)
    if not np.all(np.isfinite(H_lo) & np.isfinite(H_hi)):
        return False, None
    centre = [[(Fraction(float(a)) + Fraction(float(b))) / 2 for a, b in zip(ra, rb)] for ra, rb in zip(H_lo, H_hi)]
    radius_sq = sum(((Fraction(float(b)) - Fraction(float(a))) / 2) ** 2 for a, b in zip(H_lo.ravel(), H_hi.ravel()))
    radius = _sqrt_above(radius_sq)
    negated = [[-centre[i][j] - (radius if i == j else 0) for j in range(n)] for i in range(n)]
    return exact_positive_definite(negated)


def _equilibrium_counterexample(decrease: _Decrease, gradient: Intervals, hessian: Intervals,
                                scale: np.ndarray) -> np.ndarray | None:
    """A point near 0 where W > 0 rigorously, when the gradient or Hessian of W at 0 allows one."""
    with np.errstate(invalid="ignore"):  # inf - inf where undefined: caught just below
        g = 0.5 * (gradient.lo[0] + gradient.hi[0])
        H = 0.5 * (hessian.lo[0] + hessian.hi[0]).reshape(decrease.n, decrease.n)
    if not (np.all(np.isfinite(g)) and np.all(np.isfinite(H))):
        return None
    eigenvalues, vectors = np.linalg.eigh(0.5 * (H + H.T))
    directions = [g] if np.any(g != 0) else []
    directions += [vectors[:, -1]] if eigenvalues[-1] > 0 else []
    for direction in directions:
        direction = direction / np.max(np.abs(direction) / scale)
        for t in 0.5 ** np.arange(1, 40):
            points = np.array([t * direction, -t * direction])
            positive = decrease.certainly_positive(points)
            if np.any(positive):
                return points[int(np.argmax(positive))]
    return None


def _inputs(V, x_dot, x, gamma, lower, upper, rho, labels) -> tuple:
    """Validated (V, x_dot, x, gamma, lower, upper, rho, labels); VerificationError naming the argument."""
    for name, value in (("V", V), ("x_dot", x_dot), ("x", x)):
        if not isinstance(value, ca.SX):
            raise VerificationError(f"{name} must be a CasADi SX expression, got {type(value).__name__}")
    if not x.is_column() or not all(s.is_symbolic() for s in ca.vertsplit(x)):
        raise VerificationError("x must be a column vector of SX symbols")
    n = x.numel()
    free = sorted({s.name() for s in ca.symvar(ca.vertcat(ca.vec(V), ca.vec(x_dot)))} - {s.name() for s in
                                                                                          ca.vertsplit(x)})
    if free:
        raise VerificationError(f"V and x_dot may depend on x only; free symbol(s) {', '.join(free)} (substitute "
                                "their values first)")
    if x_dot.numel() != n or V.numel() != 1:
        raise VerificationError(f"V must be scalar and x_dot have {n} entries, got {V.shape} and {x_dot.shape}")
    box = []
    for name, bound in (("lower", lower), ("upper", upper)):
        try:
            bound = np.asarray(bound, dtype=float).ravel()
        except (TypeError, ValueError):
            raise VerificationError(f"{name} must be {n} numbers, got {bound!r}") from None
        if bound.shape != (n,) or not np.all(np.isfinite(bound)):
            raise VerificationError(f"{name} must be {n} finite numbers (like x), got {bound}")
        box.append(bound)
    lower, upper = box
    if not (np.all(lower < 0) and np.all(upper > 0)):
        raise VerificationError(f"the box must hold the equilibrium x = 0 inside: lower {lower}, upper {upper}")
    try:
        gamma, rho = float(gamma), float(rho)
    except (TypeError, ValueError):
        raise VerificationError(f"gamma and rho must be numbers, got {gamma!r} and {rho!r}") from None
    if not (np.isfinite(gamma) and gamma >= 0):
        raise VerificationError(f"gamma must be finite and >= 0, got {gamma}")
    if not (0 < rho < np.min(np.minimum(-lower, upper))):
        raise VerificationError(f"rho must satisfy 0 < rho < the box's half-widths, got {rho}")
    labels = tuple(labels) if labels is not None else tuple(s.name() for s in ca.vertsplit(x))
    if len(labels) != n:
        raise VerificationError(f"labels must have {n} entries, like x, got {len(labels)}")
    return gamma, lower, upper, rho, labels


def _taylor_cube(decrease: _Decrease, rho: float) -> tuple[float, Fraction | None, str]:
    """(cube half-side, pivot, "") where the Hessian argument holds, else (smallest cube tried, None, why)."""
    value_at_zero, gradient_at_zero, _ = decrease.at_equilibrium()
    exact_zero = (value_at_zero.defined[0] and gradient_at_zero.defined[0] and value_at_zero.lo[0, 0] == 0
                  and value_at_zero.hi[0, 0] == 0 and np.all(gradient_at_zero.lo == 0)
                  and np.all(gradient_at_zero.hi == 0))
    smallest = rho / 2**HALVINGS
    if not exact_zero:
        return smallest, None, ("W or its gradient at x = 0 is not exactly 0 in interval arithmetic (is x = 0 an "
                                "equilibrium of the loop?)")
    cube = rho
    for _ in range(HALVINGS + 1):
        proved, pivot = _cube_certificate(decrease, cube)
        if proved:
            return cube, pivot, ""
        cube /= 2
    return smallest, None, f"the interval Hessian of W is not negative definite on |x|_inf <= {smallest:g}"


def region_decrease(claim: str, V: ca.SX, x_dot: ca.SX, x: ca.SX, gamma: float, lower, upper, rho: float,
                    labels: tuple[str, ...] | None = None, set_description: str | None = None,
                    expected: str = "proved", max_boxes: int = 2_000_000, batch: int = 8192) -> Certificate:
    """Certificate for ``V' <= -gamma x^T x`` on the box (see the module docstring).

    V: scalar SX of x (n,); x_dot: (n,) SX of x, the closed loop; gamma >= 0 (units of V per s
    per unit of x^2); lower, upper: (n,) the box, holding 0; rho > 0: half-side of the cube around
    0 covered by the Hessian argument. The counterexample of a refuted claim is a point where
    ``V' + gamma x^T x > 0`` holds rigorously. VerificationError (naming the argument) for
    non-SX expressions, free symbols, non-finite or mis-sized bounds, or a bad gamma or rho.
    """
    started = time.perf_counter()
    gamma, lower, upper, rho, labels = _inputs(V, x_dot, x, gamma, lower, upper, rho, labels)
    V_dot = ca.jtimes(V, x, x_dot)
    decrease = _Decrease(V_dot + gamma * ca.dot(x, x), x)
    region = set_description or _format_box(lower, upper, labels)

    def certificate(status, method, **fields):
        return Certificate(claim, region, method, status, expected, seconds=time.perf_counter() - started, **fields)

    def counterexample(point):
        value = float(ca.Function("V_dot", [x], [V_dot])(point))
        return {"x": dict(zip(labels, map(float, point))), "V_dot": value, "gamma": gamma,
                "bound": float(-gamma * np.dot(point, point))}

    scale = np.minimum(-lower, upper)
    _, gradient_at_zero, hessian_at_zero = decrease.at_equilibrium()
    near_zero = _equilibrium_counterexample(decrease, gradient_at_zero, hessian_at_zero, scale)
    if near_zero is not None:
        return certificate("refuted", "W = V' + gamma x'x > 0 at a point near the equilibrium (interval evaluation)",
                           margin=float(-decrease.W(near_zero, near_zero).lo[0, 0]),
                           counterexample=counterexample(near_zero))
    cube, pivot, cube_failure = _taylor_cube(decrease, rho)
    search = _branch_and_bound(decrease, lower, upper, cube, scale, max_boxes, batch, claim, labels)
    boxes = search["boxes"]
    if "counterexample" in search:
        point = search["counterexample"]
        return certificate("refuted", "interval branch-and-bound over the CasADi graph (outward rounding)",
                           margin=float(-decrease.W(point, point).lo[0, 0]),
                           counterexample=counterexample(point), details={"boxes": boxes})
    if "undefined" in search:
        return certificate("inconclusive", "interval branch-and-bound over the CasADi graph",
                           reason=f"V' may be undefined (an operation at or beyond its domain) at "
                                  f"{_format_box(search['undefined'], search['undefined'], labels)}",
                           details={"boxes": boxes})
    if "open" in search:
        return certificate("inconclusive", "interval branch-and-bound over the CasADi graph",
                           reason=f"{boxes} boxes without a decision; e.g. {search['open']}", details={"boxes": boxes})
    if cube_failure:
        return certificate("inconclusive", "interval Hessian on a cube around the equilibrium",
                           reason=f"{cube_failure}; no counterexample outside it ({boxes} boxes)",
                           details={"boxes": boxes})
    method = (f"interval branch-and-bound over the CasADi graph (outward rounding, {boxes} boxes) outside "
              f"|x|_inf <= {cube:g}; inside it Taylor with the interval Hessian, exact rational LDL^T")
    return certificate("proved", method, margin=-search["worst"],
                       details={"boxes": boxes, "cube_half_side": cube, "cube_hessian_pivot": float(pivot)})


def _branch_and_bound(decrease: _Decrease, lower, upper, cube: float, scale, max_boxes: int, batch: int,
                      claim: str, labels) -> dict:
    """Boxes outside the cube: {"boxes", "worst"} when all are proved, plus "counterexample" (a
    point), "undefined" (a point) or "open" (a box, described) when the search stops."""
    queue_lo, queue_hi = lower[None, :], upper[None, :]
    boxes, worst, settled = 0, -np.inf, 0.0
    side_lengths = upper - lower  # progress in fractions of the box (no under- or overflow of volumes)

    def share(lo, hi) -> float:
        return float(np.sum(np.prod((hi - lo) / side_lengths, axis=1)))

    bar = ProgressBar(f"branch-and-bound {claim[:40]}")
    try:
        while len(queue_lo):
            lo, hi = queue_lo[:batch], queue_hi[:batch]
            queue_lo, queue_hi = queue_lo[batch:], queue_hi[batch:]
            outside = ~np.all((lo >= -cube) & (hi <= cube), axis=1)
            settled += share(lo[~outside], hi[~outside])
            lo, hi = lo[outside], hi[outside]
            boxes += len(lo)
            bound = decrease.upper_bound(lo, hi)
            done = bound < 0
            if np.any(done):
                worst = max(worst, float(np.max(bound[done])))
                settled += share(lo[done], hi[done])
            lo, hi = lo[~done], hi[~done]
            if not len(lo):
                continue
            centres = 0.5 * (lo + hi)
            positive = decrease.certainly_positive(centres)
            if np.any(positive):
                return {"boxes": boxes, "counterexample": centres[int(np.argmax(positive))]}
            undefined = decrease.maybe_undefined(centres)
            if np.any(undefined):
                return {"boxes": boxes, "undefined": centres[int(np.argmax(undefined))]}
            if boxes > max_boxes:
                return {"boxes": boxes, "open": _format_box(lo[0], hi[0], labels)}
            side = np.argmax((hi - lo) / scale, axis=1)
            rows = np.arange(len(lo))
            middle = 0.5 * (lo[rows, side] + hi[rows, side])
            left_hi, right_lo = hi.copy(), lo.copy()
            left_hi[rows, side], right_lo[rows, side] = middle, middle
            queue_lo = np.concatenate([queue_lo, lo, right_lo])
            queue_hi = np.concatenate([queue_hi, left_hi, hi])
            bar(settled)
    finally:
        bar.close()
    return {"boxes": boxes, "worst": worst}
