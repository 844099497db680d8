"""Zonotope bands proved to hold every residual of their recursion, by outward-rounded interval arithmetic.

For ``xi_{k+1} = A xi_k + w_{k+1}``, ``xi_0 = c_0 + G_0 a``, ``w = c_W + G_W b`` (``||a||_inf,
||b||_inf <= 1``) and ``r_k = C xi_k`` (:mod:`uvsym.sets.propagation`),

    r_k = C c_k + C A^k G_0 a + sum_{j < k} C A^j G_W b_{k-j},      c_k = A c_{k-1} + c_W,

so every reachable ``r_k,i`` lies within ``(C c_k)_i +- rho_k,i`` with ``rho_k,i = sum |C A^k G_0|_i +
sum_{j<k} sum |C A^j G_W|_i`` (the exact set's hull, reached at a vertex). :func:`band_enclosure_claim`
encloses ``C c_k`` and bounds ``rho_k`` from above with the outward-rounded operations of
:mod:`uvsym.verify.interval_arithmetic` (the matrices' doubles taken as exact), then compares them with the
limits a decision uses: ``proved`` when, at every step and output, the enclosure lies inside; ``refuted``
when a rigorous lower bound of the reachable maximum (or an upper bound of the minimum) is outside, with
the step, the output and the vertex's bound as evidence; otherwise ``inconclusive``. This proves the
set arithmetic (the reductions only ever enlarge) for the recursion as stated; that the recursion is the
observer's error (the decoupling) is a separate claim.
"""

from __future__ import annotations

import time

import numpy as np

from uvsym.errors import VerificationError
from uvsym.sets import Zonotope
from uvsym.verify.certificate import Certificate
from uvsym.verify.interval_arithmetic import mul, signed_sum

__all__ = ["band_enclosure_claim", "reachable_hull"]


def _point(M) -> tuple[np.ndarray, np.ndarray]:
    M = np.asarray(M, dtype=float)
    return M, M


def _matmul(a, b):
    """Interval matrix product: a (n, m) and b (m, q) as (lo, hi) pairs; sums taken in order, rounded outward."""
    shape = (a[0].shape[0], a[0].shape[1], b[0].shape[1])
    lo, hi = mul(tuple(np.broadcast_to(x[:, :, None], shape) for x in a),
                 tuple(np.broadcast_to(x[None, :, :], shape) for x in b))
    total = (lo[:, 0, :], hi[:, 0, :])
    for j in range(1, shape[1]):
        total = signed_sum(total, (lo[:, j, :], hi[:, j, :]), 1.0)
    return total


def _row_sums(terms, largest: bool) -> np.ndarray:
    """(p,) bound of ``sum_j |x_ij|`` over intervals x (p, m): from above (largest) or from below."""
    lo, hi = terms
    if largest:
        size = np.maximum(np.abs(lo), np.abs(hi))
    else:
        size = np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(np.abs(lo), np.abs(hi)))
    total = (size[:, 0], size[:, 0])
    for j in range(1, size.shape[1]):
        total = signed_sum(total, (size[:, j], size[:, j]), 1.0)
    return total[1] if largest else total[0]


def reachable_hull(A, C, initial: Zonotope, noise: Zonotope, steps: int) -> dict[str, np.ndarray]:
    """Rigorous bounds, (steps, p) each, of the reachable ``r_k`` (module docstring): ``outer_lo``,
    ``outer_hi`` enclose every reachable value; ``inner_lo``, ``inner_hi`` are reached (a vertex
    attains values at least as far out)."""
    A, C = np.asarray(A, dtype=float), np.asarray(C, dtype=float)
    n = A.shape[0]
    if A.shape != (n, n) or C.ndim != 2 or C.shape[1] != n or initial.dimension != n or noise.dimension != n:
        raise VerificationError(f"band enclosure: A {A.shape}, C {C.shape} and zonotopes of dimension "
                                f"{initial.dimension}, {noise.dimension} do not conform")
    power = _point(C)  # C A^k, as an interval matrix
    center = _point(initial.center[:, None])
    outer_noise = inner_noise = np.zeros(C.shape[0])
    bounds = {key: np.zeros((steps, C.shape[0])) for key in ("outer_lo", "outer_hi", "inner_lo", "inner_hi")}
    for k in range(steps):
        if k:
            spread = _matmul(power, _point(noise.generators))
            outer_noise = signed_sum((outer_noise, outer_noise), (_row_sums(spread, True),) * 2, 1.0)[1]
            inner_noise = signed_sum((inner_noise, inner_noise), (_row_sums(spread, False),) * 2, 1.0)[0]
            power = _matmul(power, _point(A))
            center = signed_sum(_matmul(_point(A), center), _point(noise.center[:, None]), 1.0)
        spread = _matmul(power, _point(initial.generators))
        outer = signed_sum((outer_noise,) * 2, (_row_sums(spread, True),) * 2, 1.0)[1]
        inner = signed_sum((inner_noise,) * 2, (_row_sums(spread, False),) * 2, 1.0)[0]
        mid_lo, mid_hi = (v[:, 0] for v in _matmul(_point(C), center))
        bounds["outer_lo"][k] = signed_sum((mid_lo,) * 2, (outer,) * 2, -1.0)[0]
        bounds["outer_hi"][k] = signed_sum((mid_hi,) * 2, (outer,) * 2, 1.0)[1]
        bounds["inner_lo"][k] = signed_sum((mid_hi,) * 2, (inner,) * 2, -1.0)[1]
        bounds["inner_hi"][k] = signed_sum((mid_lo,) * 2, (inner,) * 2, 1.0)[0]
    return bounds


def band_enclosure_claim(claim: str, A, C, initial: Zonotope, noise: Zonotope, lower, upper,
                         set_description: str, expected: str = "proved") -> Certificate:
    """Every reachable ``r_k`` lies in ``[lower_k, upper_k]`` ((N, p) floats, the limits a decision
    compares residuals with), k = 0 .. N - 1 (module docstring). The margin is the smallest gap
    between a limit and the enclosure, relative to the band's width there."""
    started = time.perf_counter()
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    if lower.shape != upper.shape or lower.ndim != 2 or not np.all(np.isfinite(lower) & np.isfinite(upper)):
        raise VerificationError(f"band enclosure: lower and upper must be finite (N, p) arrays of one shape, "
                                f"got {lower.shape} and {upper.shape}")
    hull = reachable_hull(A, C, initial, noise, len(lower))
    method = ("interval arithmetic, outward-rounded, over C A^k and the generators (the exact set's hull at "
              f"every one of {len(lower)} steps; the matrices' doubles taken as exact)")
    width = np.maximum(upper - lower, 1e-300)
    gap = np.minimum(hull["outer_lo"] - lower, upper - hull["outer_hi"]) / width
    beyond = (hull["inner_hi"] > upper) | (hull["inner_lo"] < lower)
    seconds = time.perf_counter() - started
    if beyond.any():
        k, i = (int(v) for v in np.argwhere(beyond)[0])
        high = hull["inner_hi"][k, i] > upper[k, i]
        example = {"step": k, "output": i, "reached": float(hull["inner_hi"][k, i] if high else hull["inner_lo"][k, i]),
                   "limit": float(upper[k, i] if high else lower[k, i])}
        return Certificate(claim, set_description, method, "refuted", expected, margin=float(gap.min()),
                           seconds=seconds, counterexample=example)
    if np.all(gap >= 0):
        return Certificate(claim, set_description, method, "proved", expected, margin=float(gap.min()),
                           seconds=seconds)
    k, i = (int(v) for v in np.argwhere(gap < 0)[0])
    return Certificate(claim, set_description, method, "inconclusive", expected, margin=float(gap.min()),
                       seconds=seconds, reason=f"the enclosure leaves the band at step {k}, output {i}, "
                                               "but no vertex was shown to reach beyond it")
