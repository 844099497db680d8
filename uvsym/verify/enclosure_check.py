"""Interval enclosure checked against mpmath at 60 digits: the oracle of the interval soundness tests.

``OPERATIONS`` maps a name to (CasADi expression of x0 and x1, the same in mpmath, its domain or
None); :func:`enclosure_violations` evaluates the interval extension on boxes and returns every
sampled point (ends, inner points, 0) whose exact value falls outside the bounds, or that lies
outside the domain on a box not marked undefined. :func:`random_box` draws the box kinds that
break interval code: straddling 0, subnormal, huge (1e300), zero width, anything.
"""

from __future__ import annotations

import math
from functools import cache

import casadi as ca
import mpmath
import numpy as np

from uvsym.verify.interval import IntervalFunction

__all__ = ["BINARY", "BOX_KINDS", "OPERATIONS", "enclosure_violations", "random_box"]

OPERATIONS = {
    "neg": (lambda a, b: -a, lambda a, b: -a, None),
    "twice": (lambda a, b: 2 * a, lambda a, b: 2 * a, None),
    "sq": (lambda a, b: a * a, lambda a, b: a * a, None),
    "inv": (lambda a, b: 1 / a, lambda a, b: 1 / a, lambda a, b: a != 0),
    "sqrt": (lambda a, b: ca.sqrt(a), lambda a, b: mpmath.sqrt(a), lambda a, b: a >= 0),
    "log": (lambda a, b: ca.log(a), lambda a, b: mpmath.log(a), lambda a, b: a > 0),
    "log1p": (lambda a, b: ca.log1p(a), lambda a, b: mpmath.log1p(a), lambda a, b: a > -1),
    "exp": (lambda a, b: ca.exp(a), lambda a, b: mpmath.exp(a), None),
    "expm1": (lambda a, b: ca.expm1(a), lambda a, b: mpmath.expm1(a), None),
    "sin": (lambda a, b: ca.sin(a), lambda a, b: mpmath.sin(a), None),
    "cos": (lambda a, b: ca.cos(a), lambda a, b: mpmath.cos(a), None),
    "tanh": (lambda a, b: ca.tanh(a), lambda a, b: mpmath.tanh(a), None),
    "atan": (lambda a, b: ca.atan(a), lambda a, b: mpmath.atan(a), None),
    "sinh": (lambda a, b: ca.sinh(a), lambda a, b: mpmath.sinh(a), None),
    "asinh": (lambda a, b: ca.asinh(a), lambda a, b: mpmath.asinh(a), None),
    "cosh": (lambda a, b: ca.cosh(a), lambda a, b: mpmath.cosh(a), None),
    "fabs": (lambda a, b: ca.fabs(a), lambda a, b: abs(a), None),
    "pow3": (lambda a, b: a ** 3, lambda a, b: a ** 3, None),
    "pow8": (lambda a, b: a ** 8, lambda a, b: a ** 8, None),
    "pow1e6": (lambda a, b: a ** 1e6, lambda a, b: a ** 1000000, None),
    "pow-3": (lambda a, b: a ** -3, lambda a, b: a ** -3, lambda a, b: a != 0),
    "pow0.5": (lambda a, b: a ** 0.5, lambda a, b: mpmath.sqrt(a), lambda a, b: a >= 0),
    "pow2.5": (lambda a, b: a ** 2.5, lambda a, b: a ** mpmath.mpf(2.5), lambda a, b: a >= 0),
    "pow-1.5": (lambda a, b: a ** -1.5, lambda a, b: a ** mpmath.mpf(-1.5), lambda a, b: a > 0),
    "add": (lambda a, b: a + b, lambda a, b: a + b, None),
    "sub": (lambda a, b: a - b, lambda a, b: a - b, None),
    "mul": (lambda a, b: a * b, lambda a, b: a * b, None),
    "div": (lambda a, b: a / b, lambda a, b: a / b, lambda a, b: b != 0),
    "fmin": (lambda a, b: ca.fmin(a, b), lambda a, b: min(a, b), None),
    "fmax": (lambda a, b: ca.fmax(a, b), lambda a, b: max(a, b), None),
    "floor": (lambda a, b: ca.floor(a), lambda a, b: mpmath.floor(a), None),
    "ceil": (lambda a, b: ca.ceil(a), lambda a, b: mpmath.ceil(a), None),
    "sign": (lambda a, b: ca.sign(a), lambda a, b: mpmath.sign(a), None),
    # C's fmod is exact in doubles (the sign of a): the library's own value is the oracle at a float point
    "fmod": (lambda a, b: ca.fmod(a, b), lambda a, b: mpmath.mpf(math.fmod(float(a), float(b))),
             lambda a, b: b != 0),
    "copysign": (lambda a, b: ca.copysign(a, b), lambda a, b: abs(a) if b >= 0 else -abs(a), None),
}
BINARY = ("add", "sub", "mul", "div", "fmin", "fmax", "fmod", "copysign")
BOX_KINDS = ("moderate", "straddle", "subnormal", "huge", "zero width", "any")


@cache
def _interval_function(name: str) -> IntervalFunction:
    x = ca.SX.sym("x", 2)
    return IntervalFunction(ca.Function("op", [x], [OPERATIONS[name][0](x[0], x[1])]))


def random_box(rng, kind: str) -> tuple[float, float]:
    """(lo, hi) of one box of ``kind`` (one of BOX_KINDS)."""
    if kind == "zero width":
        value = float(rng.normal() * 10.0 ** rng.uniform(-300, 300))
        return value, value
    draw = {"moderate": lambda: rng.uniform(-50, 50), "straddle": lambda: rng.uniform(-3, 3),
            "subnormal": lambda: rng.uniform(-1, 1) * 2.2e-308,
            "huge": lambda: rng.choice([-1, 1]) * 10.0 ** rng.uniform(299, 308.2),
            "any": lambda: rng.normal() * 10.0 ** rng.uniform(-320, 308)}[kind]
    a, b = float(draw()), float(draw())
    return min(a, b), max(a, b)


def _points(lo: float, hi: float, rng) -> list[float]:
    width = hi - lo
    inner = [lo + width * t for t in rng.uniform(size=4)] if np.isfinite(width) else \
        [lo * t for t in rng.uniform(size=2)] + [hi * t for t in rng.uniform(size=2)]
    return [p for p in [lo, hi, *inner] + ([0.0] if lo <= 0 <= hi else []) if lo <= p <= hi]


def enclosure_violations(name: str, boxes: list[tuple[float, float]], rng) -> list[str]:
    """Descriptions of the sampled points where the interval extension of ``name`` is unsound on ``boxes``
    (one box per argument: one or two)."""
    _, oracle, domain = OPERATIONS[name]
    boxes = list(boxes) + [(0.0, 0.0)] * (2 - len(boxes))
    bounds = _interval_function(name)(np.array([b[0] for b in boxes]), np.array([b[1] for b in boxes]))
    lo, hi, defined = bounds.lo[0, 0], bounds.hi[0, 0], bool(bounds.defined[0])
    grids = [_points(a, b, rng) for a, b in boxes]
    violations = []
    with mpmath.workdps(60):
        for point in np.array(np.meshgrid(*grids)).reshape(2, -1).T:
            args = [mpmath.mpf(float(p)) for p in point]
            if domain is not None and not domain(*args):
                if defined:
                    violations.append(f"{name} on {boxes}: {point.tolist()} is outside the domain, box defined")
                continue
            if not defined:
                continue  # an undefined box promises nothing (and is never provable)
            value = oracle(*args)
            if not lo <= value <= hi:
                violations.append(f"{name} on {boxes}: {mpmath.nstr(value, 20)} at {point.tolist()} outside "
                                  f"[{float(lo)!r}, {float(hi)!r}]")
    return violations
