"""Interval enclosure, property-based: every supported operation, boxes that straddle 0, subnormal,
huge (1e300), zero-width and out-of-domain boxes, against mpmath at 60 digits (the oracle)."""

from __future__ import annotations

import time

import casadi as ca
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from uvsym.errors import VerificationError
from uvsym.verify.enclosure_check import OPERATIONS, enclosure_violations
from uvsym.verify.interval import IntervalFunction

UNARY = [name for name in OPERATIONS if name not in ("add", "sub", "mul", "div", "fmin", "fmax")]
BINARY = ["add", "sub", "mul", "div", "fmin", "fmax"]


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


@pytest.mark.parametrize("name", sorted(UNARY))
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(box=boxes(), seed=st.integers(0, 2**16))
def test_unary_operations_enclose_their_exact_values(name, box, seed):
    assert enclosure_violations(name, [box], np.random.default_rng(seed)) == []


@pytest.mark.parametrize("name", sorted(BINARY))
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(a=boxes(), b=boxes(), seed=st.integers(0, 2**16))
def test_binary_operations_enclose_their_exact_values(name, a, b, seed):
    assert enclosure_violations(name, [a, b], np.random.default_rng(seed)) == []


def test_the_oracle_catches_an_unsound_bound(monkeypatch):
    """The check itself can fail: exp without outward rounding misses exp(1) on a point box."""
    import uvsym.verify.interval_arithmetic as arithmetic

    monkeypatch.setattr(arithmetic, "round_down", lambda x, ulps=1: np.nextafter(x, np.inf))
    assert enclosure_violations("exp", [(1.0, 1.0)], np.random.default_rng(0))


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
