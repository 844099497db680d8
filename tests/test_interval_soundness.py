"""Interval enclosure, property-based: every supported operation, boxes that straddle 0, subnormal,
huge (1e300), zero-width and out-of-domain boxes, against mpmath at 60 digits (the oracle)."""

from __future__ import annotations

import time

import casadi as ca
import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from uvsym.errors import VerificationError
from uvsym.verify.interval import IntervalFunction

X = ca.SX.sym("x", 2)
TINY = 5e-324
# name: (CasADi expression of x0 (and x1), the same in mpmath, domain of the arguments or None)
UNARY = {
    "neg": (lambda a: -a, lambda a: -a, None),
    "twice": (lambda a: 2 * a, lambda a: 2 * a, None),
    "sq": (lambda a: a * a, lambda a: a * a, None),
    "inv": (lambda a: 1 / a, lambda a: 1 / a, lambda a: a != 0),
    "sqrt": (ca.sqrt, mpmath.sqrt, lambda a: a >= 0),
    "log": (ca.log, mpmath.log, lambda a: a > 0),
    "log1p": (ca.log1p, mpmath.log1p, lambda a: a > -1),
    "exp": (ca.exp, mpmath.exp, None),
    "expm1": (ca.expm1, mpmath.expm1, None),
    "sin": (ca.sin, mpmath.sin, None),
    "cos": (ca.cos, mpmath.cos, None),
    "tanh": (ca.tanh, mpmath.tanh, None),
    "atan": (ca.atan, mpmath.atan, None),
    "sinh": (ca.sinh, mpmath.sinh, None),
    "asinh": (ca.asinh, mpmath.asinh, None),
    "cosh": (ca.cosh, mpmath.cosh, None),
    "fabs": (ca.fabs, abs, None),
    "pow3": (lambda a: a ** 3, lambda a: a ** 3, None),
    "pow8": (lambda a: a ** 8, lambda a: a ** 8, None),
    "pow1e6": (lambda a: a ** 1e6, lambda a: a ** 1000000, None),
    "pow-3": (lambda a: a ** -3, lambda a: a ** -3, lambda a: a != 0),
    "pow0.5": (lambda a: a ** 0.5, mpmath.sqrt, lambda a: a >= 0),
    "pow2.5": (lambda a: a ** 2.5, lambda a: a ** mpmath.mpf(2.5), lambda a: a >= 0),
    "pow-1.5": (lambda a: a ** -1.5, lambda a: a ** mpmath.mpf(-1.5), lambda a: a > 0),
}
BINARY = {
    "add": (lambda a, b: a + b, lambda a, b: a + b, None),
    "sub": (lambda a, b: a - b, lambda a, b: a - b, None),
    "mul": (lambda a, b: a * b, lambda a, b: a * b, None),
    "div": (lambda a, b: a / b, lambda a, b: a / b, lambda a, b: b != 0),
    "fmin": (ca.fmin, min, None),
    "fmax": (ca.fmax, max, None),
}
_FUNCTIONS = {name: IntervalFunction(ca.Function(name.replace("-", "m").replace(".", "_"), [X],
                                                 [f(X[0]) if name in UNARY else f(X[0], X[1])]))
              for name, (f, _, _) in (UNARY | BINARY).items()}


def _bound(kind: str):
    """Floats of one kind of box end."""
    return {"moderate": st.floats(-50, 50), "straddle": st.floats(-3, 3), "subnormal":
            st.floats(-2.2e-308, 2.2e-308), "huge": st.floats(1e299, 1.7e308) | st.floats(-1.7e308, -1e299),
            "any": st.floats(allow_nan=False, allow_infinity=False)}[kind]


@st.composite
def boxes(draw):
    """(lo, hi) of one box: both ends of one kind (zero width with probability 1/5)."""
    kind = draw(st.sampled_from(["moderate", "straddle", "subnormal", "huge", "any"]))
    a = draw(_bound(kind))
    b = a if draw(st.integers(0, 4)) == 0 else draw(_bound(kind))
    return min(a, b), max(a, b)


def _points(lo: float, hi: float, rng) -> list[float]:
    inner = [lo + (hi - lo) * t for t in rng.uniform(size=4)] if np.isfinite(hi - lo) else \
        [lo * t for t in rng.uniform(size=2)] + [hi * t for t in rng.uniform(size=2)]
    points = [lo, hi, *inner] + ([0.0] if lo <= 0 <= hi else [])
    return [p for p in points if lo <= p <= hi]


def _check(name: str, boxes_: list[tuple[float, float]], seed: int) -> None:
    _, oracle, domain = (UNARY | BINARY)[name]
    lo, hi = np.array([b[0] for b in boxes_] + [0.0] * (2 - len(boxes_))), \
        np.array([b[1] for b in boxes_] + [0.0] * (2 - len(boxes_)))
    bounds = _FUNCTIONS[name](lo, hi)
    rng = np.random.default_rng(seed)
    grids = [_points(a, b, rng) for a, b in boxes_]
    with mpmath.workdps(60):
        for point in (np.array(np.meshgrid(*grids)).reshape(len(boxes_), -1).T):
            args = [mpmath.mpf(float(p)) for p in point]
            if domain is not None and not domain(*args):
                assert not bounds.defined[0], f"{name} on {boxes_}: a point outside the domain, box not undefined"
                continue
            if not bounds.defined[0]:
                continue  # undefined boxes promise nothing (and are never provable)
            value = oracle(*args)
            assert bounds.lo[0, 0] <= value <= bounds.hi[0, 0], (
                f"{name} on {boxes_}: {mpmath.nstr(value, 20)} at {point.tolist()} outside "
                f"[{bounds.lo[0, 0]!r}, {bounds.hi[0, 0]!r}]")


@pytest.mark.parametrize("name", sorted(UNARY))
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(box=boxes(), seed=st.integers(0, 2**16))
def test_unary_operations_enclose_their_exact_values(name, box, seed):
    _check(name, [box], seed)


@pytest.mark.parametrize("name", sorted(BINARY))
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(a=boxes(), b=boxes(), seed=st.integers(0, 2**16))
def test_binary_operations_enclose_their_exact_values(name, a, b, seed):
    _check(name, [a, b], seed)


def test_library_functions_are_exact_at_zero_and_twice_rounds_outward():
    x = ca.SX.sym("x")
    for expression, value in ((ca.exp(x), 1.0), (ca.cos(x), 1.0), (ca.cosh(x), 1.0), (ca.sin(x), 0.0),
                              (ca.tanh(x), 0.0), (ca.exp(x) - 1, 0.0), (ca.sin(x) * ca.exp(x), 0.0)):
        bounds = IntervalFunction(ca.Function("f", [x], [expression]))([[0.0]], [[0.0]])
        assert bounds.lo[0, 0] == value == bounds.hi[0, 0]
    huge = np.finfo(float).max
    twice = IntervalFunction(ca.Function("f", [x], [2 * x]))([[huge]], [[huge]])
    assert twice.lo[0, 0] <= huge and twice.hi[0, 0] == np.inf  # 2 x > the largest double, never [inf, inf]


def test_division_by_a_box_holding_zero_is_undefined():
    x = ca.SX.sym("x", 2)
    ratio = IntervalFunction(ca.Function("f", [x], [x[0] / x[1]]))
    zero_over_zero = ratio([[0.0, 0.0]], [[0.0, 0.0]])
    assert not zero_over_zero.defined[0]  # 0 / 0 is not [0, 0]
    assert ratio([[0.0, 1.0]], [[0.0, 2.0]]).defined[0]
    assert ratio([[0.0, 1.0]], [[0.0, 2.0]]).hi[0, 0] == 0.0


def test_large_and_infinite_exponents():
    x = ca.SX.sym("x")
    started = time.perf_counter()
    bounds = IntervalFunction(ca.Function("f", [x], [x ** 1e12]))([[0.5]], [[1.5]])
    assert time.perf_counter() - started < 1.0 and bounds.lo[0, 0] <= 0.5 ** 1e12 and bounds.hi[0, 0] == np.inf
    with pytest.raises(VerificationError, match="finite exponent"):
        IntervalFunction(ca.Function("f", [x], [ca.constpow(x, np.inf)]))([[0.5]], [[1.5]])
