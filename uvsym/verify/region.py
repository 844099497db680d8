"""Lyapunov decrease of a nonlinear system on a box, by interval branch-and-bound over the CasADi graph.

Claim: ``V'(x) = dV/dx f(x) <= -gamma x^T x`` for every x in the box ``lower <= x <= upper``
(which holds the equilibrium x = 0), i.e. ``W(x) = V'(x) + gamma x^T x <= 0``, with V' derived
by differentiating V along f (CasADi), nothing typed.

- Outside a small cube ``|x|_inf <= rho`` around the equilibrium: branch-and-bound. A box is
  proved when an upper bound of W on it is negative: the plain interval extension of W's graph
  (:class:`~uvsym.verify.interval.IntervalFunction`, outward rounding), or, where W is smooth on
  the box, the mean-value form ``W(c) + grad W(box) (box - c)``, whichever is lower. A box that is
  not proved has its centre checked (a rigorous interval evaluation at the point: a lower bound
  above 0 is a counterexample) and is then bisected along its widest side.
- The cube itself, where W vanishes to second order and intervals cannot separate it from 0, is
  covered by the linearisation: with ``W(0) = 0`` and ``grad W(0) = 0`` (checked), Taylor's theorem
  gives ``W(x) = x^T H(xi) x / 2`` with xi in the cube, and the interval Hessian ``Hc +- Delta`` over
  the cube is shown negative definite by an exact rational LDL^T factorisation of
  ``-(Hc + |Delta|_F I)``. If that fails rho is halved (up to ``HALVINGS`` times).
"""

from __future__ import annotations

import time
from fractions import Fraction

import casadi as ca
import numpy as np

from uvsym.errors import VerificationError
from uvsym.progress import ProgressBar
from uvsym.verify.certificate import Certificate
from uvsym.verify.interval import IntervalFunction, Intervals
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
        """An upper bound of W on each box (k,): the lower of the plain and the mean-value forms."""
        plain = self.W(lo, hi)
        bound = plain.hi[:, 0]
        if np.any(plain.smooth):
            centre = 0.5 * (lo + hi)
            at_centre = self.W(centre, centre).hi[:, 0]
            slope = self.grad(lo, hi)
            half = np.maximum(hi - centre, centre - lo)
            with np.errstate(invalid="ignore"):
                spread = np.nansum(np.maximum(np.abs(slope.lo), np.abs(slope.hi)) * half, axis=1)
            # the products and the sum are rounded: widen upward by far more than their few ulps
            mean_value = at_centre + spread + 1e-12 * (np.abs(at_centre) + spread) + 1e-300
            mean_value = np.where(np.isfinite(mean_value), mean_value, np.inf)
            bound = np.where(plain.smooth, np.minimum(bound, mean_value), bound)
        return bound

    def at_equilibrium(self) -> tuple[Intervals, Intervals, Intervals]:
        """Bounds of W, grad W and vec(Hessian of W) at x = 0."""
        zero = np.zeros((1, self.n))
        return self.W(zero, zero), self.grad(zero, zero), self.hess(zero, zero)

    def certainly_positive(self, points) -> np.ndarray:
        """(k,) True where W(point) > 0 rigorously."""
        return self.W(points, points).lo[:, 0] > 0


def _cube_certificate(decrease: _Decrease, rho: float) -> tuple[bool, Fraction | None]:
    """Whether the interval Hessian on ``|x|_inf <= rho`` is negative definite (exactly), and the pivot."""
    lo, hi = np.full((1, decrease.n), -rho), np.full((1, decrease.n), rho)
    hessian = decrease.hess(lo, hi)
    if not (decrease.W(lo, hi).smooth[0] and hessian.smooth[0]):
        return False, None
    n = decrease.n
    H_lo, H_hi = hessian.lo[0].reshape(n, n), hessian.hi[0].reshape(n, n)
    H_lo, H_hi = np.minimum(H_lo, H_lo.T), np.maximum(H_hi, H_hi.T)
    if not np.all(np.isfinite(H_lo) & np.isfinite(H_hi)):
        return False, None
    centre = [[(Fraction(float(a)) + Fraction(float(b))) / 2 for a, b in zip(ra, rb)] for ra, rb in zip(H_lo, H_hi)]
    radius_sq = sum(((Fraction(float(b)) - Fraction(float(a))) / 2) ** 2 for a, b in zip(H_lo.ravel(), H_hi.ravel()))
    radius = Fraction(float(np.sqrt(float(radius_sq)))) * Fraction(1001, 1000)  # above the Frobenius norm
    if radius * radius < radius_sq:
        radius = radius * 2
    negated = [[-centre[i][j] - (radius if i == j else 0) for j in range(n)] for i in range(n)]
    return exact_positive_definite(negated)


def _equilibrium_counterexample(decrease: _Decrease, gradient: Intervals, hessian: Intervals,
                                scale: np.ndarray) -> np.ndarray | None:
    """A point near 0 where W > 0 rigorously, when the gradient or Hessian of W at 0 allows one."""
    g = 0.5 * (gradient.lo[0] + gradient.hi[0])
    H = 0.5 * (hessian.lo[0] + hessian.hi[0]).reshape(decrease.n, decrease.n)
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


def region_decrease(claim: str, V: ca.SX, x_dot: ca.SX, x: ca.SX, gamma: float, lower, upper, rho: float,
                    labels: tuple[str, ...] | None = None, set_description: str | None = None,
                    expected: str = "proved", max_boxes: int = 2_000_000, batch: int = 8192) -> Certificate:
    """Certificate for ``V' <= -gamma x^T x`` on the box (see the module docstring).

    V: scalar SX of x (n,); x_dot: (n,) SX of x, the closed loop; gamma >= 0 (units of V per s
    per unit of x^2); lower, upper: (n,) the box, holding 0; rho > 0: half-side of the cube around
    0 covered by the Hessian argument. The counterexample of a refuted claim is a point where
    ``V' + gamma x^T x > 0`` holds rigorously.
    """
    started = time.perf_counter()
    n = x.numel()
    lower, upper = np.asarray(lower, dtype=float).ravel(), np.asarray(upper, dtype=float).ravel()
    labels = tuple(labels) if labels is not None else tuple(s.name() for s in ca.vertsplit(x))
    if lower.shape != (n,) or upper.shape != (n,) or len(labels) != n:
        raise VerificationError(f"the box and labels must have {n} entries, like x")
    if not (np.all(np.isfinite(lower)) and np.all(np.isfinite(upper)) and np.all(lower < 0) and np.all(upper > 0)):
        raise VerificationError(f"the box must be finite and hold the equilibrium x = 0 inside: {lower} .. {upper}")
    if not (0 < rho < np.min(np.minimum(-lower, upper))) or not gamma >= 0:
        raise VerificationError(f"need 0 < rho < the box's half-widths and gamma >= 0, got rho {rho}, gamma {gamma}")
    if x_dot.numel() != n or V.numel() != 1:
        raise VerificationError(f"V must be scalar and x_dot have {n} entries, got {V.shape} and {x_dot.shape}")
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
    value_at_zero, gradient_at_zero, hessian_at_zero = decrease.at_equilibrium()
    near_zero = _equilibrium_counterexample(decrease, gradient_at_zero, hessian_at_zero, scale)
    if near_zero is not None:
        return certificate("refuted", "W = V' + gamma x'x > 0 at a point near the equilibrium (interval evaluation)",
                           margin=float(-decrease.W(near_zero, near_zero).lo[0, 0]),
                           counterexample=counterexample(near_zero))
    if value_at_zero.hi[0, 0] > 0 or np.any(gradient_at_zero.lo != 0) or np.any(gradient_at_zero.hi != 0):
        return certificate("inconclusive", "Taylor expansion at the equilibrium",
                           reason="W or its gradient at x = 0 is not exactly 0 in interval arithmetic "
                                  "(is x = 0 an equilibrium of the loop?), and no counterexample was found")
    cube, pivot = rho, None
    for _ in range(HALVINGS + 1):
        proved, pivot = _cube_certificate(decrease, cube)
        if proved:
            break
        cube /= 2
    else:
        return certificate("inconclusive", "interval Hessian on a cube around the equilibrium",
                           reason=f"the interval Hessian of W is not negative definite on |x| <= {cube * 2:g}")

    queue_lo, queue_hi = lower[None, :], upper[None, :]
    boxes, worst, settled, volume = 0, -np.inf, 0.0, float(np.prod(upper - lower))
    bar = ProgressBar(f"branch-and-bound {claim[:40]}")
    try:
        while len(queue_lo):
            lo, hi = queue_lo[:batch], queue_hi[:batch]
            queue_lo, queue_hi = queue_lo[batch:], queue_hi[batch:]
            outside = ~np.all((lo >= -cube) & (hi <= cube), axis=1)
            settled += float(np.sum(np.prod(hi[~outside] - lo[~outside], axis=1)))
            lo, hi = lo[outside], hi[outside]
            boxes += len(lo)
            bound = decrease.upper_bound(lo, hi)
            done = bound < 0
            if np.any(done):
                worst = max(worst, float(np.max(bound[done])))
                settled += float(np.sum(np.prod(hi[done] - lo[done], axis=1)))
            lo, hi = lo[~done], hi[~done]
            centres = 0.5 * (lo + hi)
            positive = decrease.certainly_positive(centres) if len(lo) else np.zeros(0, dtype=bool)
            if np.any(positive):
                point = centres[int(np.argmax(positive))]
                return certificate("refuted", "interval branch-and-bound over the CasADi graph (outward rounding)",
                                   margin=float(-decrease.W(point, point).lo[0, 0]),
                                   counterexample=counterexample(point), details={"boxes": boxes})
            if boxes > max_boxes:
                return certificate("inconclusive", "interval branch-and-bound over the CasADi graph",
                                   reason=f"{boxes} boxes without a decision; e.g. {_format_box(lo[0], hi[0], labels)}",
                                   details={"boxes": boxes})
            side = np.argmax((hi - lo) / scale, axis=1)
            rows = np.arange(len(lo))
            middle = 0.5 * (lo[rows, side] + hi[rows, side])
            left_hi, right_lo = hi.copy(), lo.copy()
            left_hi[rows, side], right_lo[rows, side] = middle, middle
            queue_lo = np.concatenate([queue_lo, lo, right_lo])
            queue_hi = np.concatenate([queue_hi, left_hi, hi])
            bar(settled / volume)
    finally:
        bar.close()
    method = (f"interval branch-and-bound over the CasADi graph (outward rounding, {boxes} boxes) outside "
              f"|x|_inf <= {cube:g}; inside it Taylor with the interval Hessian, exact rational LDL^T")
    return certificate("proved", method, margin=-worst,
                       details={"boxes": boxes, "cube_half_side": cube, "cube_hessian_pivot": float(pivot)})
