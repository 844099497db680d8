"""Outward-rounded interval arithmetic on arrays of boxes: each interval is a pair (lo, hi) of (k,) arrays.

Every rounded result moves outward by one unit in the last place (``numpy.nextafter``; library
functions by ``LIBM_ULPS``), overflow included; results that are exact anyway (TwoSum-exact sums,
2 x without overflow, TwoProduct-exact products and quotients, products and quotients with an exact
0) stay unwidened. Integer powers go by
repeated squaring, each step outward-rounded. :mod:`uvsym.verify.interval` replays a CasADi graph
with these operations (and says where a box leaves an operation's domain).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

__all__ = ["LIBM_ULPS", "clean", "compare", "div", "even", "exact_zeros", "increasing", "indicator", "is_zero",
           "holds_zero", "mul", "periodic", "power", "round_down", "round_up", "signed_sum", "square", "truth",
           "twice"]

LIBM_ULPS = 4


def round_down(x, ulps: int = 1):
    """x moved ``ulps`` floats towards -inf (array or float)."""
    for _ in range(ulps):
        x = np.nextafter(x, -np.inf)
    return x


def round_up(x, ulps: int = 1):
    """x moved ``ulps`` floats towards +inf (array or float)."""
    for _ in range(ulps):
        x = np.nextafter(x, np.inf)
    return x


def clean(lo, hi):
    """NaN bounds (0 * inf, inf - inf) become the widest bound."""
    return np.where(np.isnan(lo), -np.inf, lo), np.where(np.isnan(hi), np.inf, hi)


def is_zero(a):
    """Per box: the interval ``a`` = (lo, hi) is exactly [0, 0]."""
    return (a[0] == 0) & (a[1] == 0)


def exact_zeros(result, a, b=None, value: float = 0.0):
    """``result`` with the exact ``value`` where an operand is exactly 0 (no rounding to widen there)."""
    zero = is_zero(a) if b is None else is_zero(a) | is_zero(b)
    return np.where(zero, value, result[0]), np.where(zero, value, result[1])


def twice(a):
    """2 a: exact, except where it overflows (a bound of inf from a finite one moves inward)."""
    with np.errstate(over="ignore"):
        lo, hi = 2.0 * a[0], 2.0 * a[1]
    return (np.where(np.isposinf(lo) & np.isfinite(a[0]), np.finfo(float).max, lo),
            np.where(np.isneginf(hi) & np.isfinite(a[1]), -np.finfo(float).max, hi))


def _rounded_sum(x, y, direction: float):
    """x + y rounded towards ``direction`` (+-inf): left as it is where the float sum is exact.

    Exactness by Knuth's TwoSum: the rounding error of ``s = x + y`` is
    ``(x - (s - (s - x))) + (y - (s - x))``, exactly, barring overflow.
    """
    with np.errstate(all="ignore"):
        total = x + y
        y_part = total - x
        error = (x - (total - y_part)) + (y - y_part)
    exact = (error == 0) & np.isfinite(total)
    return np.where(exact, total, np.nextafter(total, direction))


def signed_sum(a, b, sign: float):
    """a + sign b with bounds rounded outward only where the float sums are inexact."""
    b_lo, b_hi = (b[0], b[1]) if sign > 0 else (-b[1], -b[0])
    return clean(_rounded_sum(a[0], b_lo, -np.inf), _rounded_sum(a[1], b_hi, np.inf))


_SPLIT = 2.0 ** 27 + 1.0  # Veltkamp's splitter: x = high + low, each with at most 26 significant bits
_SAFE = (2.0 ** -480, 2.0 ** 480)  # magnitudes where the split and the error term neither overflow nor underflow


def _product_exact(x, y, product):
    """Where the float product ``x * y`` is exact: Dekker's TwoProduct error is 0, for factors (and a
    product) of magnitude within ``_SAFE`` (elsewhere: not known exact)."""
    with np.errstate(all="ignore"):
        def split(v):
            c = _SPLIT * v
            high = c - (c - v)
            return high, v - high

        (xh, xl), (yh, yl) = split(x), split(y)
        error = ((xh * yh - product) + xh * yl + xl * yh) + xl * yl
        safe = np.ones_like(product, dtype=bool)
        for v in (x, y, product):
            safe &= (np.abs(v) >= _SAFE[0]) & (np.abs(v) <= _SAFE[1])
    return safe & (error == 0)


def _outward(candidates, exact):
    """Bounds of the exact values of the float results ``candidates`` (4, k): a min and a max rounded
    outward, but not an exact result."""
    low = np.where(exact, candidates, round_down(candidates)).min(axis=0)
    high = np.where(exact, candidates, round_up(candidates)).max(axis=0)
    return low, high


def mul(a, b):
    """a b, each of the four products rounded outward where it is not exact (TwoProduct)."""
    pairs = [(a[0], b[0]), (a[0], b[1]), (a[1], b[0]), (a[1], b[1])]
    with np.errstate(invalid="ignore", over="ignore"):
        products = np.stack([x * y for x, y in pairs])
    products = np.where(np.isnan(products), 0.0, products)  # 0 * inf: a zero factor wins
    exact = np.stack([_product_exact(x, y, p) for (x, y), p in zip(pairs, products)])
    return exact_zeros(_outward(products, exact), a, b)


def holds_zero(b):
    """Per box: the interval ``b`` = (lo, hi) contains 0."""
    return (b[0] <= 0.0) & (b[1] >= 0.0)


def div(a, b):
    """a / b; where b holds 0 the box is undefined (the caller marks it) and the bounds unbounded."""
    pairs = [(a[0], b[0]), (a[0], b[1]), (a[1], b[0]), (a[1], b[1])]
    with np.errstate(all="ignore"):
        quotients = np.stack([x / y for x, y in pairs])
    # q = x / y is exact where q y is exactly x (TwoProduct): a division by a power of 2, or a multiple
    with np.errstate(all="ignore"):
        exact = np.stack([_product_exact(q, y, q * y) & (q * y == x) for (x, y), q in zip(pairs, quotients)])
    bounds = clean(*_outward(quotients, exact))  # inf/inf: unbounded
    lo, hi = exact_zeros(bounds, a)
    straddles = holds_zero(b)
    return np.where(straddles, -np.inf, lo), np.where(straddles, np.inf, hi)


def even(a, function):
    """An even function increasing on x >= 0 (x^2, cosh, x^4)."""
    f_lo, f_hi = function(np.abs(a[0])), function(np.abs(a[1]))
    lo = np.where(a[0] >= 0, f_lo, np.where(a[1] <= 0, f_hi, function(np.zeros_like(a[0]))))
    return lo, np.maximum(f_lo, f_hi)


def increasing(function, ulps: int = LIBM_ULPS):
    """Interval extension of an increasing ``function``: its endpoint values widened by ``ulps`` floats
    (the libm error bound)."""
    def apply(a):
        with np.errstate(all="ignore"):
            return clean(round_down(function(a[0]), ulps), round_up(function(a[1]), ulps))
    return apply


def periodic(a, function, peak: float, trough: float):
    """sin or cos: endpoint values, and +-1 where the box holds a peak or a trough."""
    with np.errstate(all="ignore"):
        f0, f1 = function(a[0]), function(a[1])
    lo, hi = round_down(np.minimum(f0, f1), LIBM_ULPS), round_up(np.maximum(f0, f1), LIBM_ULPS)
    two_pi = 2.0 * np.pi
    slack = 1e-9  # rounding of the peak positions: when in doubt the box holds one
    holds_peak = np.floor((a[1] - peak) / two_pi + slack) >= np.ceil((a[0] - peak) / two_pi - slack)
    holds_trough = np.floor((a[1] - trough) / two_pi + slack) >= np.ceil((a[0] - trough) / two_pi - slack)
    # far from 0 the peak test loses precision: such boxes get the whole range
    wide = ~(np.abs(a[0]) < 1e6) | ~(np.abs(a[1]) < 1e6) | (a[1] - a[0] >= two_pi)
    hi = np.where(holds_peak | wide, 1.0, np.minimum(hi, 1.0))
    lo = np.where(holds_trough | wide, -1.0, np.maximum(lo, -1.0))
    return lo, hi


def truth(a):
    """(certainly nonzero, certainly zero) per box."""
    return (a[0] > 0) | (a[1] < 0), (a[0] == 0) & (a[1] == 0)


def indicator(true, false):
    """Interval of a 0/1 value, and whether it is undecided (a kink inside the box)."""
    undecided = ~true & ~false
    return (np.where(true, 1.0, 0.0), np.where(false, 0.0, 1.0)), undecided


def compare(op, a, b):
    """Interval of the 0/1 result of CasADi comparison ``op`` (<, <=, ==, !=) on intervals a and b, and
    whether it is undecided per box (:func:`indicator`)."""
    if op == ca.OP_LT:
        return indicator(a[1] < b[0], a[0] >= b[1])
    if op == ca.OP_LE:
        return indicator(a[1] <= b[0], a[0] > b[1])
    point_equal = (a[0] == a[1]) & (b[0] == b[1]) & (a[0] == b[0])
    disjoint = (a[1] < b[0]) | (b[1] < a[0])
    if op == ca.OP_EQ:
        return indicator(point_equal, disjoint)
    return indicator(disjoint, point_equal)


def square(a):
    """a^2: an even function, 0 kept exact, bounds rounded outward."""
    lo, hi = even(a, np.square)
    return exact_zeros(clean(round_down(lo), round_up(hi)), a)


def power(a, exponent: float):
    """a^exponent for a finite constant exponent: integers by repeated squaring (outward at each
    step), others through the library pow (needs a >= 0, > 0 for a negative exponent)."""
    ones = (np.ones_like(a[0]), np.ones_like(a[0]))
    if exponent == np.floor(exponent):
        n = abs(int(exponent))
        result, base = ones, a
        while n:
            if n & 1:
                result = mul(result, base)
            n >>= 1
            if n:
                base = square(base)
        return div(ones, result) if exponent < 0 else result
    if exponent > 0:
        lo, hi = np.maximum(a[0], 0.0) ** exponent, np.maximum(a[1], 0.0) ** exponent
    else:
        with np.errstate(divide="ignore"):
            lo, hi = np.maximum(a[1], 0.0) ** exponent, np.maximum(a[0], 0.0) ** exponent
    return clean(round_down(lo, LIBM_ULPS), round_up(hi, LIBM_ULPS))
