"""Single operations replayed by :class:`uvsym.verify.interval.IntervalFunction`: domain edges (exactly at the
edge, one ulp inside, one ulp outside), kinks of the non-smooth operations, truth tables of the logic operations
and the outward steps of the library functions.

Expected values come from the mathematics of each operation (its domain, where it is non-smooth, Kleene's
three-valued logic for boxes of 0/1 values) or from exact rationals (``fractions.Fraction``) and mpmath; every
test builds its own Function (no shared fixture), so that each is credited with the code it runs.
"""

from __future__ import annotations

from fractions import Fraction

import casadi as ca
import mpmath
import numpy as np
import pytest

from uvsym.errors import VerificationError
from uvsym.verify.interval import IntervalFunction
from uvsym.verify.interval_arithmetic import LIBM_ULPS

TINY = np.nextafter(0.0, 1.0)  # the smallest positive double: one ulp above 0


def run(build, *bounds):
    """Bounds of ``build(x)`` (x a symbolic 2-vector) over boxes given as ((lo0, lo1), (hi0, hi1)); a (lo, hi)
    pair of floats is the box [lo, hi] of x0 with x1 = [0, 0]."""
    x = ca.SX.sym("x", 2)
    pairs = [((b[0], 0.0), (b[1], 0.0)) if np.isscalar(b[0]) else b for b in bounds]
    lo = np.array([p[0] for p in pairs], dtype=float)
    hi = np.array([p[1] for p in pairs], dtype=float)
    return IntervalFunction(ca.Function("f", [x], [build(x)]))(lo, hi)


def ulps_between(x: float, y: float) -> int:
    """Number of doubles from x up to y, both positive and finite (their bit patterns are ordered like them)."""
    return int(np.array(y).view(np.int64)) - int(np.array(x).view(np.int64))


# --- domains: exactly at the edge, one ulp inside, one ulp outside ----------------------------------------------

def test_sqrt_is_defined_from_zero_on():
    boxes = [(0.0, 1.0), (TINY, 1.0), (-TINY, 1.0), (np.nextafter(1.0, 0.0), 4.0), (1.0, 4.0)]
    assert run(lambda x: ca.sqrt(x[0]), *boxes).defined.tolist() == [True, True, False, True, True]


def test_log_needs_a_positive_argument():
    boxes = [(0.0, 1.0), (TINY, 1.0), (-TINY, 1.0), (np.nextafter(1.0, 0.0), 2.0), (1.0, 2.0)]
    assert run(lambda x: ca.log(x[0]), *boxes).defined.tolist() == [False, True, False, True, True]


def test_log1p_needs_an_argument_above_minus_one():
    boxes = [(-1.0, 0.0), (np.nextafter(-1.0, 0.0), 0.0), (np.nextafter(-1.0, -2.0), 0.0), (-1.5, 0.0),
             (0.0, 1.0)]
    assert run(lambda x: ca.log1p(x[0]), *boxes).defined.tolist() == [False, True, False, False, True]


def power_boxes(exponent, *bases):
    """x0 ** x1 (OP_POW) with x1 fixed at ``exponent``, one box of x0 per (lo, hi) in ``bases``."""
    return [((lo, exponent), (hi, exponent)) for lo, hi in bases]


@pytest.mark.parametrize("build", [lambda x: x[0] ** x[1], lambda x: ca.constpow(x[0], 1.5)],
                         ids=["pow", "constpow"])
def test_positive_fractional_power_is_defined_from_zero_on(build):
    bases = [(0.0, 1.0), (TINY, 1.0), (-TINY, 1.0), (np.nextafter(1.0, 0.0), 2.0), (1.0, 2.0)]
    assert run(build, *power_boxes(1.5, *bases)).defined.tolist() == [True, True, False, True, True]


def test_power_below_one_is_defined_from_zero_on():
    # x^0.5 on [0, 1] is sqrt: defined at 0 (only negative exponents exclude 0)
    bases = [(0.0, 1.0), (TINY, 1.0), (-TINY, 1.0), (0.5, 2.0)]
    result = run(lambda x: x[0] ** x[1], *power_boxes(0.5, *bases))
    assert result.defined.tolist() == [True, True, False, True]


@pytest.mark.parametrize("build", [lambda x: x[0] ** x[1], lambda x: ca.constpow(x[0], -0.5)],
                         ids=["pow", "constpow"])
def test_negative_fractional_power_needs_a_positive_base(build):
    bases = [(0.0, 1.0), (TINY, 1.0), (-TINY, 1.0), (np.nextafter(1.0, 0.0), 2.0), (0.5, 2.0)]
    assert run(build, *power_boxes(-0.5, *bases)).defined.tolist() == [False, True, False, True, True]


def test_negative_integer_power_is_undefined_only_where_the_box_holds_zero():
    bases = [(-1.0, 1.0), (0.0, 1.0), (-1.0, 0.0), (TINY, 1.0), (-1.0, -TINY), (-2.0, -1.0)]
    defined = [run(lambda x: x[0] ** x[1], box).defined[0] for box in power_boxes(-2.0, *bases)]
    assert defined == [False, False, False, True, True, True]


@pytest.mark.parametrize("exponent", [0.0, 2.0, 3.0])
def test_nonnegative_integer_power_is_defined_everywhere(exponent):
    result = run(lambda x: x[0] ** x[1], *power_boxes(exponent, (-1.0, 1.0)))
    assert result.defined.tolist() == [True]
    if exponent == 0.0:  # x^0 = 1 for every x, 0 included (IEEE pow(0, 0) = 1)
        assert (result.lo[0, 0], result.hi[0, 0]) == (1.0, 1.0)


def test_an_empty_batch_passes_through_a_power():
    x = ca.SX.sym("x", 2)
    result = IntervalFunction(ca.Function("f", [x], [x[0] ** x[1]]))(np.zeros((0, 2)), np.zeros((0, 2)))
    assert result.lo.shape == result.hi.shape == (0, 1) and result.defined.shape == result.smooth.shape == (0,)


def test_power_with_a_varying_exponent_is_refused_by_name():
    message = r"^interval power needs a constant, finite exponent$"
    with pytest.raises(VerificationError, match=message):  # the exponent spans [1, 2] within one box
        run(lambda x: x[0] ** x[1], ((1.0, 1.0), (2.0, 2.0)))
    with pytest.raises(VerificationError, match=message):  # a point exponent, but 2 in one box and 3 in the other
        run(lambda x: x[0] ** x[1], ((1.0, 2.0), (2.0, 2.0)), ((1.0, 3.0), (2.0, 3.0)))


# --- outward steps: 1 ulp for the correctly rounded sqrt, LIBM_ULPS for library functions ------------------------

def test_sqrt_moves_one_ulp_outward_from_exact_roots():
    result = run(lambda x: ca.sqrt(x[0]), (0.25, 4.0), (0.0, 0.25))
    # sqrt(0.25) = 0.5 and sqrt(4) = 2 exactly; doubles are 2^-54 apart in [0.25, 0.5), 2^-51 in [2, 4),
    # 2^-53 in [0.5, 1)
    assert Fraction(result.lo[0, 0]) == Fraction(1, 2) - Fraction(1, 2**54)
    assert Fraction(result.hi[0, 0]) == 2 + Fraction(1, 2**51)
    assert Fraction(result.hi[1, 0]) == Fraction(1, 2) + Fraction(1, 2**53)  # clipped at 0 below, not above


@pytest.mark.parametrize(("build", "exact"), [(lambda x: ca.log(x[0]), mpmath.log), (ca.cosh, mpmath.cosh)],
                         ids=["log", "cosh"])
def test_library_functions_move_libm_ulps_outward(build, exact):
    """log and cosh are increasing on [2, 4]: the bounds are the library values at 2 and 4, LIBM_ULPS doubles
    further out, and they enclose the exact values."""
    result = run(lambda x: build(x[0]), (2.0, 4.0))
    lo, hi = result.lo[0, 0], result.hi[0, 0]
    at_2, at_4 = float(exact(2)), float(exact(4))  # correctly rounded: within an ulp of the library's values
    assert abs(ulps_between(lo, at_2) - LIBM_ULPS) <= 1
    assert abs(ulps_between(at_4, hi) - LIBM_ULPS) <= 1
    with mpmath.workdps(40):
        assert mpmath.mpf(lo) < exact(2) and exact(4) < mpmath.mpf(hi)


def test_sin_reaches_one_only_where_the_box_holds_a_peak():
    # sin is increasing on [-pi/2, pi/2]: [1, 1.2] and [-1.2, -1] hold neither pi/2 nor -pi/2
    result = run(lambda x: ca.sin(x[0]), (1.0, 1.2), (-1.2, -1.0), (1.5, 1.6), (-1.6, -1.5))
    with mpmath.workdps(40):
        assert mpmath.sin(1.2) < result.hi[0, 0] < mpmath.sin(1.2) + 1e-15
        assert mpmath.sin(-1.2) - 1e-15 < result.lo[1, 0] < mpmath.sin(-1.2)
    assert result.hi[2, 0] == 1.0 and result.lo[3, 0] == -1.0


# --- non-smooth operations: bounds, and a kink only where it lies inside the box ---------------------------------

def table(build, rows):
    """Check ``build`` against rows of (box, lo, hi, smooth): one box per row."""
    result = run(build, *[row[0] for row in rows])
    got = list(zip(result.lo[:, 0].tolist(), result.hi[:, 0].tolist(), result.smooth.tolist()))
    assert got == [row[1:] for row in rows]


def test_fabs_bounds_and_kink():
    # |x| is smooth on a box that only touches 0; the lower bound is the distance of the box from 0
    table(lambda x: ca.fabs(x[0]), [
        ((1.0, 2.0), 1.0, 2.0, True), ((0.5, 1.0), 0.5, 1.0, True), ((0.0, 1.0), 0.0, 1.0, True),
        ((-1.0, 0.0), 0.0, 1.0, True), ((-2.0, -1.0), 1.0, 2.0, True), ((-1.0, 2.0), 0.0, 2.0, False),
        ((-2.0, 0.5), 0.0, 2.0, False)])


def test_fabs_of_the_point_zero_is_what_casadi_evaluates():
    """A point box [+0, +0] gives CasADi's own value there, sign bit included (IEEE fabs(+0) = +0)."""
    x = ca.SX.sym("x")
    value = float(ca.Function("f", [x], [ca.fabs(x)])(0.0))
    result = run(lambda x: ca.fabs(x[0]), (0.0, 0.0))
    for bound in (result.lo[0, 0], result.hi[0, 0]):
        assert bound == value and np.signbit(bound) == np.signbit(value)


def test_sign_bounds_and_kink():
    # sign jumps at 0: a box holding 0 and any other point has a kink (a point box [0, 0] has none)
    table(lambda x: ca.sign(x[0]), [
        ((-1.0, 1.0), -1.0, 1.0, False), ((1.0, 2.0), 1.0, 1.0, True), ((-2.0, -1.0), -1.0, -1.0, True),
        ((0.0, 1.0), 0.0, 1.0, False), ((-1.0, 0.0), -1.0, 0.0, False), ((0.5, 1.0), 1.0, 1.0, True),
        ((-1.0, 0.5), -1.0, 1.0, False), ((0.0, 0.0), 0.0, 0.0, True)])


def test_floor_and_ceil_bounds_and_kink():
    table(lambda x: ca.floor(x[0]), [((0.5, 0.7), 0.0, 0.0, True), ((0.5, 1.5), 0.0, 1.0, False)])
    table(lambda x: ca.ceil(x[0]), [((0.5, 0.7), 1.0, 1.0, True), ((0.5, 1.5), 1.0, 2.0, False)])


def test_fmin_and_fmax_have_a_kink_where_the_boxes_meet():
    # boxes (x0, x1): one inside the other either way round, touching at 1, and apart
    rows = [((0.0, 1.0), (3.0, 2.0)), ((1.0, 0.0), (2.0, 3.0)), ((0.0, 1.0), (1.0, 2.0)), ((0.0, 2.0), (1.0, 3.0))]
    table(lambda x: ca.fmin(x[0], x[1]), [
        (rows[0], 0.0, 2.0, False), (rows[1], 0.0, 2.0, False), (rows[2], 0.0, 1.0, False),
        (rows[3], 0.0, 1.0, True)])
    table(lambda x: ca.fmax(x[0], x[1]), [
        (rows[0], 1.0, 3.0, False), (rows[1], 1.0, 3.0, False), (rows[2], 1.0, 2.0, False),
        (rows[3], 2.0, 3.0, True)])


# --- logic: boxes of a condition that is certainly nonzero, certainly zero, or either ----------------------------

TRUTH_BOXES = {"nonzero": (0.5, 2.0), "negative": (-2.0, -1.0), "zero": (0.0, 0.0), "either": (-1.0, 1.0)}
TRUTH_SETS = {"nonzero": {True}, "negative": {True}, "zero": {False}, "either": {False, True}}


@pytest.mark.parametrize(("build", "connective"), [(ca.logic_and, all), (ca.logic_or, any)], ids=["and", "or"])
def test_logic_connectives_follow_three_valued_logic(build, connective):
    """The result over a pair of boxes is the set of truth values over every choice of the operands' truth
    values: 0 and 1 both possible make [0, 1] and a kink."""
    rows = []
    for a, b in [(a, b) for a in TRUTH_BOXES for b in TRUTH_BOXES]:
        values = {connective((p, q)) for p in TRUTH_SETS[a] for q in TRUTH_SETS[b]}
        box = ((TRUTH_BOXES[a][0], TRUTH_BOXES[b][0]), (TRUTH_BOXES[a][1], TRUTH_BOXES[b][1]))
        rows.append((box, float(min(values)), float(max(values)), len(values) == 1))
    table(lambda x: build(x[0], x[1]), rows)


def test_if_else_zero_is_the_value_the_zero_or_their_hull():
    # if_else(c, v, 0): v where c is certainly nonzero, 0 where c is certainly 0, the hull of v and 0 otherwise
    table(lambda x: ca.if_else(x[0], x[1], 0), [
        (((1.0, 1.0), (1.0, 2.0)), 1.0, 2.0, True), (((1.0, -2.0), (1.0, -1.0)), -2.0, -1.0, True),
        (((0.0, 1.0), (0.0, 2.0)), 0.0, 0.0, True), (((0.0, -2.0), (0.0, -1.0)), 0.0, 0.0, True),
        (((0.0, -2.0), (1.0, 0.5)), -2.0, 0.5, False), (((0.0, 1.0), (1.0, 2.0)), 0.0, 2.0, False),
        (((0.0, -2.0), (1.0, -1.0)), -2.0, 0.0, False)])
