"""Interval enclosure, property-based: every supported operation, boxes that straddle 0, subnormal,
huge (1e300), zero-width and out-of-domain boxes, against mpmath at 60 digits (the oracle)."""

from __future__ import annotations

import time
from types import SimpleNamespace

import casadi as ca
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from uvsym.errors import VerificationError
from uvsym.verify import enclosure_check
from uvsym.verify.borderline import identity_cases, region_cases
from uvsym.verify.enclosure_check import BINARY, BOX_KINDS, OPERATIONS, enclosure_violations, random_box
from uvsym.verify.interval import IntervalFunction

UNARY = [name for name in OPERATIONS if name not in BINARY]


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


def test_random_boxes_of_each_kind_have_the_ends_they_are_named_for():
    """200 boxes per kind: finite ends in order; moderate within 50, straddle within 3 and across 0, subnormal
    within 2.2e-308 of 0 on both sides, huge between 1e299 and 10^308.2 (some below 1e300) on both sides,
    zero width and any at magnitudes from below 1e-100 to above 1e100; moderate boxes of positive
    width on both sides of 0."""
    rng = np.random.default_rng(8)
    ends = {kind: np.array([random_box(rng, kind) for _ in range(200)]) for kind in BOX_KINDS}
    for kind, box in ends.items():
        assert np.isfinite(box).all() and (box[:, 0] <= box[:, 1]).all(), kind
    assert (np.abs(ends["moderate"]) <= 50).all() and (np.abs(ends["straddle"]) <= 3).all()
    assert ends["moderate"].min() < -25 and ends["moderate"].max() > 25 and (np.diff(ends["moderate"]) > 0).all()
    assert ((ends["straddle"][:, 0] < 0) & (ends["straddle"][:, 1] > 0)).any()
    assert (np.abs(ends["subnormal"]) <= 2.2e-308).all()
    assert ends["subnormal"].min() < 0 < ends["subnormal"].max()
    huge = np.abs(ends["huge"])
    assert (1e299 <= huge).all() and (huge <= 10.0 ** 308.2).all() and (huge < 1e300).any()
    assert ends["huge"].min() < 0 < ends["huge"].max()
    zero = ends["zero width"]
    assert (zero[:, 0] == zero[:, 1]).all() and np.abs(zero).min() < 1e-100 and np.abs(zero).max() > 1e100
    anything = np.abs(ends["any"])
    assert anything.min() < 1e-100 and anything.max() > 1e100


def _fake_bounds(lo: float, hi: float):
    """An interval function that answers [lo, hi] (defined) on every box, to test the check itself."""
    return lambda name: lambda lower, upper: SimpleNamespace(lo=np.array([[lo]]), hi=np.array([[hi]]),
                                                             defined=np.array([True]))


def test_the_oracle_samples_zero_and_reports_the_exact_value_to_20_digits(monkeypatch):
    """x^2 on [-1, 1] claimed in [1e-300, 1]: the ends give 1 and random inner points exceed 1e-300 (by far), so
    only the point 0 is outside; exp(1) = 2.71828182845904523536... claimed in [2, 2.5]: printed to 20 digits."""
    monkeypatch.setattr(enclosure_check, "_interval_function", _fake_bounds(1e-300, 1.0))
    violations = enclosure_violations("sq", [(-1.0, 1.0)], np.random.default_rng(0))
    assert len(violations) == 7  # the point 0 of the first box with each of the 7 points of the (0, 0) box
    assert set(violations) == {"sq on [(-1.0, 1.0), (0.0, 0.0)]: 0.0 at [0.0, 0.0] outside "
                               "[1e-300, 1.0]"}
    monkeypatch.setattr(enclosure_check, "_interval_function", _fake_bounds(2.0, 2.5))
    violations = enclosure_violations("exp", [(1.0, 1.0)], np.random.default_rng(0))
    assert violations and set(violations) == {"exp on [(1.0, 1.0), (0.0, 0.0)]: 2.7182818284590452354 at "
                                              "[1.0, 0.0] outside [2.0, 2.5]"}


def test_region_cases_failing_at_zero_have_boxes_at_scales_1e_minus_6_to_1e6():
    """The at-zero cases draw scale = 10^U(-6, 6) and box ends scale * U(0.5, 2): every end's magnitude lies
    in [5e-7, 2e6], and 100 cases reach both below 1e-5 and above 1e5."""
    cases = [c for c in region_cases(600, seed=1) if c.name.startswith("at_zero")]
    ends = np.abs(np.concatenate([np.concatenate([c.lower, c.upper]) for c in cases]))
    assert len(cases) == 100 and ends.min() >= 5e-7 and ends.max() <= 2e6
    assert ends.min() < 1e-5 and ends.max() > 1e5


def test_true_cancelling_identities_agree_where_they_saturate():
    """1 - tanh(y) = 2 / (exp(2 y) + 1) exactly: for y << 0 both are 2, for y >> 0 both are below 1e-17
    (y = x + c, c in [20, 200]; x = -400, -100, 0, 50 cover both tails)."""
    cases = [c for c in identity_cases(50, seed=2) if c.holds]
    assert len(cases) == 10 and all(c.kind == "cancelling" for c in cases)
    for case in cases:
        f = ca.Function("f", case.inputs, [case.lhs, case.rhs])
        for x in (-400.0, -100.0, 0.0, 50.0):
            lhs, rhs = (float(v) for v in f(x))
            assert abs(lhs - rhs) <= 1e-12 * (1 + abs(rhs)), (x, lhs, rhs)
        lhs, rhs = (float(v) for v in f(-400.0))
        assert lhs == rhs == 2.0


def test_a_seed_names_its_random_box():
    """Each draw is U(a, b) = a + (b - a) r with r = random() of the stream (and N = standard_normal()):
    zero width is N 10^U(-300, 300) at both ends, straddle sorts two U(-3, 3), any sorts two N 10^U(-320, 308)."""
    for seed in range(6):
        twin = np.random.default_rng(seed)
        value = twin.standard_normal() * 10.0 ** (-300 + 600 * twin.random())
        assert random_box(np.random.default_rng(seed), "zero width") == (value, value)
        twin = np.random.default_rng(seed)
        ends = sorted(-3 + 6 * twin.random() for _ in range(2))
        assert random_box(np.random.default_rng(seed), "straddle") == tuple(ends)
        twin = np.random.default_rng(seed)
        ends = sorted(twin.standard_normal() * 10.0 ** (-320 + 628 * twin.random()) for _ in range(2))
        assert random_box(np.random.default_rng(seed), "any") == tuple(ends)


def test_sampled_points_of_finite_and_overflowing_boxes():
    """[1, 2]: both ends and 4 points strictly inside (no 0); [-1e308, 1e308], whose width overflows to inf:
    both ends, 2 points in (-1e308, 0), 2 in (0, 1e308) and 0, all finite."""
    for seed in range(20):
        points = enclosure_check._points(1.0, 2.0, np.random.default_rng(seed))
        assert len(points) == 6 and points[:2] == [1.0, 2.0] and all(1 < p < 2 for p in points[2:])
        points = enclosure_check._points(-1e308, 1e308, np.random.default_rng(seed))
        assert len(points) == 7 and points[:2] == [-1e308, 1e308] and points[-1] == 0.0
        assert all(-1e308 < p < 0 for p in points[2:4]) and all(0 < p < 1e308 for p in points[4:6])


def test_points_outside_the_domain_are_each_reported_and_the_others_still_checked(monkeypatch):
    """sqrt on [-1, 1] claimed defined in [5, 6]: each of the 7 x 7 points (7 per box, the second box padded
    with (0, 0)) is a violation, outside the domain (x < 0) or below 5 (sqrt(x) <= 1)."""
    monkeypatch.setattr(enclosure_check, "_interval_function", _fake_bounds(5.0, 6.0))
    violations = enclosure_violations("sqrt", [(-1.0, 1.0)], np.random.default_rng(0))
    assert len(violations) == 49
    assert "sqrt on [(-1.0, 1.0), (0.0, 0.0)]: [-1.0, 0.0] is outside the domain, box defined" in violations
    assert "sqrt on [(-1.0, 1.0), (0.0, 0.0)]: 1.0 at [1.0, 0.0] outside [5.0, 6.0]" in violations


def test_the_oracle_works_with_203_bits(monkeypatch):
    """60 digits are 203 bits in mpmath ((60 + 1) log2(10) rounded): 1 + 2^-200 is exact there and above a
    claimed [1, 1], 1 + 2^-205 rounds to 1 (half an ulp of 1 is 2^-203) and passes."""
    monkeypatch.setattr(enclosure_check, "_interval_function", _fake_bounds(1.0, 1.0))
    for exponent, caught in ((-200, True), (-205, False)):
        tiny = 2.0 ** exponent
        assert bool(enclosure_violations("add", [(1.0, 1.0), (tiny, tiny)], np.random.default_rng(0))) is caught
