"""Interval operations on point boxes and small boxes, judged in exact rationals (``fractions.Fraction``).

Each double is a rational number, so the exact real result of +, -, *, / and integer powers of doubles is a
Fraction; an enclosure must contain it, and (outward rounding by one unit in the last place per rounded step,
as the module documents) must not be wider than a few ulps. Irrational results (x^(k/2)) are judged by
squaring the bounds: ``lo <= x^(k/2)`` exactly when ``lo^2 <= x^k`` for ``lo >= 0``.
"""

from __future__ import annotations

import math
import warnings
from fractions import Fraction

import casadi as ca
import numpy as np
import pytest

from uvsym.verify import interval_arithmetic as ia

RNG = np.random.default_rng(20261127)
# doubles of every magnitude and sign whose products, sums and quotients are mostly inexact
VALUES = np.concatenate([RNG.uniform(-10, 10, 24), RNG.normal(size=8) * 10.0 ** RNG.integers(-30, 30, 8),
                         [1 / 3, -2 / 3, 0.1, 0.7, 3.0, 1e-310, -1e300]])
PAIRS = [(float(x), float(y)) for x, y in zip(VALUES, np.roll(VALUES, 7))]


def box(*values):
    """Point boxes (lo = hi) of the given doubles: the (lo, hi) pair of (k,) arrays."""
    array = np.array(values, dtype=float)
    return array, array.copy()


def ulp(x: Fraction) -> Fraction:
    """The spacing of doubles at |x| (the smallest subnormal spacing near 0)."""
    return Fraction(math.ulp(float(abs(x))))


def assert_encloses(bounds, exact: Fraction, ulps: int):
    """lo <= exact <= hi, each bound within ``ulps`` outward steps of the float result (itself within half a
    spacing of the exact value)."""
    lo, hi = Fraction(float(bounds[0][0])), Fraction(float(bounds[1][0]))
    assert lo <= exact <= hi, f"[{float(lo)!r}, {float(hi)!r}] misses {exact}"
    assert exact - lo <= (ulps + 1) * ulp(exact) and hi - exact <= (ulps + 1) * ulp(exact), \
        f"[{float(lo)!r}, {float(hi)!r}] is wider than {ulps} ulps around {float(exact)!r}"


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_sums_enclose_the_exact_sum_and_stay_points_where_the_float_sum_is_exact(sign):
    rounded = 0
    for x, y in PAIRS:
        bounds = ia.signed_sum(box(x), box(y), sign)
        exact = Fraction(x) + int(sign) * Fraction(y)
        assert_encloses(bounds, exact, 1)
        if Fraction(x + sign * y) == exact:  # the float sum is exact: nothing to widen
            assert bounds[0][0] == bounds[1][0] == x + sign * y
        else:
            rounded += 1
            assert bounds[0][0] < bounds[1][0]
    assert rounded > 10  # the check saw inexact sums rounded either way


def test_a_sum_of_boxes_adds_lower_to_lower_and_upper_to_upper():
    a, b = (np.array([1.0]), np.array([2.0])), (np.array([-4.0]), np.array([0.5]))
    assert [v[0] for v in ia.signed_sum(a, b, 1.0)] == [-3.0, 2.5]  # exact sums, unwidened
    assert [v[0] for v in ia.signed_sum(a, b, -1.0)] == [0.5, 6.0]  # [1 - 0.5, 2 + 4]


def test_products_enclose_the_exact_product_of_point_boxes():
    below = above = 0
    for x, y in PAIRS:
        exact = Fraction(x) * Fraction(y)
        assert_encloses(ia.mul(box(x), box(y)), exact, 1)
        below += Fraction(x * y) < exact
        above += Fraction(x * y) > exact
    assert below > 5 and above > 5  # the float product was rounded down and up: both bounds were needed


def test_a_product_of_boxes_takes_the_extreme_corner_products():
    a, b = (np.array([-2.0]), np.array([3.0])), (np.array([-5.0]), np.array([4.0]))
    lo, hi = ia.mul(a, b)
    assert -15.0 - 2 * math.ulp(15.0) < lo[0] <= -15.0  # -15 = 3 * (-5) is the smallest corner
    assert 12.0 <= hi[0] < 12.0 + 2 * math.ulp(12.0)  # 12 = 3 * 4 > (-2)(-5) is the largest one


def test_a_zero_factor_gives_an_exact_zero_even_against_infinity():
    lo, hi = ia.mul(box(0.0, 0.0, 2.0), (np.array([7.5, -np.inf, 0.0]), np.array([7.5, np.inf, 0.0])))
    assert lo.tolist() == [0.0, 0.0, 0.0] and hi.tolist() == [0.0, 0.0, 0.0]


def test_quotients_enclose_the_exact_quotient():
    for x, y in PAIRS:
        if y != 0.0 and abs(x / y) < 1e300 and abs(x / y) > 1e-300:
            assert_encloses(ia.div(box(x), box(y)), Fraction(x) / Fraction(y), 1)


def test_division_by_a_box_holding_zero_is_unbounded_and_zero_over_a_box_is_zero():
    lo, hi = ia.div((np.array([1.0, 0.0]), np.array([2.0, 0.0])), (np.array([-1.0, 2.0]), np.array([1.0, 4.0])))
    assert (lo[0], hi[0]) == (-np.inf, np.inf)
    assert (lo[1], hi[1]) == (0.0, 0.0)
    lo, hi = ia.div((np.array([1.0]), np.array([2.0])), (np.array([0.0]), np.array([4.0])))  # 0 is an end
    assert (lo[0], hi[0]) == (-np.inf, np.inf)


@pytest.mark.parametrize("n", [2, 3, 4, 5, 7, 8, -1, -2, -3])
def test_integer_powers_enclose_the_exact_power(n):
    for x in [1 / 3, -0.7, 1.1, -1.3, 2.5, 0.9]:
        exact = Fraction(x) ** n
        # repeated squaring rounds outward at each of its <= 2 log2|n| + 2 products (and the division)
        assert_encloses(ia.power(box(x), float(n)), exact, 4 * abs(n) + 2)


def test_an_integer_power_of_a_box_straddling_zero():
    lo, hi = ia.power((np.array([-2.0]), np.array([3.0])), 2.0)
    assert Fraction(float(lo[0])) <= 0 <= Fraction(float(hi[0])) and 9 <= hi[0] <= 9 + 4 * math.ulp(9.0)
    assert lo[0] >= -4 * math.ulp(0.0)  # x^2 >= 0: at most a few subnormal spacings below 0
    lo, hi = ia.power((np.array([-2.0]), np.array([3.0])), 3.0)  # odd: from (-2)^3 or lower to 3^3
    assert lo[0] <= -8 and 27 <= hi[0] <= 27 + 8 * math.ulp(27.0)


def test_power_zero_is_one():
    lo, hi = ia.power((np.array([-3.0]), np.array([5.0])), 0.0)
    assert (lo[0], hi[0]) == (1.0, 1.0)


@pytest.mark.parametrize("k", [1, 3, 5, -1, -3])
def test_half_integer_powers_enclose_the_exact_root(k):
    """x^(k/2) is irrational for these x: the bounds squared must bracket x^k, exactly."""
    for x in [2.0, 3.0, 5.0, 7.0, 10.0, 0.3]:
        lo, hi = (float(v[0]) for v in ia.power(box(x), k / 2))
        exact_square = Fraction(x) ** k
        assert 0 < lo and Fraction(lo) ** 2 < exact_square < Fraction(hi) ** 2
        assert hi - lo <= 2 * (ia.LIBM_ULPS + 1) * math.ulp(x ** (k / 2))


def test_a_fractional_power_of_a_box_uses_its_ends_in_the_right_order():
    lo, hi = ia.power((np.array([4.0]), np.array([9.0])), 0.5)
    assert 2.0 - 1e-14 < lo[0] < 2.0 and 3.0 < hi[0] < 3.0 + 1e-14  # increasing: sqrt(4) to sqrt(9)
    lo, hi = ia.power((np.array([4.0]), np.array([16.0])), -0.5)
    assert 0.25 - 1e-15 < lo[0] < 0.25 and 0.5 < hi[0] < 0.5 + 1e-15  # decreasing: 16^-0.5 to 4^-0.5


def test_squares_enclose_the_exact_square_and_a_straddling_box_starts_at_zero():
    for x, _ in PAIRS:
        if abs(x) < 1e150:
            assert_encloses(ia.square(box(x)), Fraction(x) ** 2, 1)
    lo, hi = ia.square((np.array([-3.0, -0.5, 2.0, 0.0]), np.array([2.0, -0.25, 4.0, 0.0])))
    assert -math.ulp(0.0) <= lo[0] <= 0.0 and 9.0 <= hi[0] <= 9.0 + math.ulp(9.0)  # max(|-3|, |2|)^2
    assert 0.0625 - 1e-17 <= lo[1] <= 0.0625 <= hi[1] <= 0.25 + 1e-16  # [(-0.25)^2, (-0.5)^2]
    assert 4.0 - 1e-15 <= lo[2] <= 4.0 and 16.0 <= hi[2] <= 16.0 + 1e-14
    assert (lo[3], hi[3]) == (0.0, 0.0)  # an exact zero is not widened


def test_twice_is_exact_and_rounding_moves_by_whole_ulps():
    lo, hi = ia.twice(box(0.1, -3.7))
    assert lo.tolist() == hi.tolist() == [0.2, -7.4]
    assert ia.round_up(1.0, 2) == 1.0 + 2 * math.ulp(1.0) and ia.round_down(1.0, 3) == 1.0 - 3 * math.ulp(1.0) / 2
    assert ia.round_down(np.float64(0.0)) == -math.ulp(0.0) and ia.round_up(np.float64(0.0)) == math.ulp(0.0)


def test_library_functions_round_outward_by_their_ulps():
    lo, hi = ia.increasing(np.exp)(box(1.0))
    assert Fraction(float(lo[0])) < Fraction(float(hi[0])) and hi[0] - lo[0] == pytest.approx(
        2 * ia.LIBM_ULPS * math.ulp(math.e), rel=0.5)
    assert lo[0] < math.e < hi[0]


def test_sine_over_a_peak_reaches_one_and_elsewhere_stays_below():
    lo, hi = ia.periodic((np.array([1.0, 0.1, 4.0]), np.array([2.0, 0.2, 5.0])), np.sin, math.pi / 2,
                         -math.pi / 2)
    assert hi[0] == 1.0 and math.sin(1.0) - 1e-15 < lo[0] <= math.sin(1.0)  # [1, 2] holds pi/2
    assert math.sin(0.2) <= hi[1] < math.sin(0.2) + 1e-15 and lo[1] <= math.sin(0.1)
    assert lo[2] == -1.0 and hi[2] >= max(math.sin(4.0), math.sin(5.0))  # [4, 5] holds 3 pi / 2
    lo, hi = ia.periodic((np.array([0.0]), np.array([7.0])), np.sin, math.pi / 2, -math.pi / 2)
    assert (lo[0], hi[0]) == (-1.0, 1.0)  # wider than 2 pi


def test_comparisons_are_decided_only_when_the_boxes_settle_them():
    def decided(op, a, b):
        (lo, hi), undecided = ia.compare(op, (np.array([a[0]]), np.array([a[1]])), (np.array([b[0]]),
                                                                                    np.array([b[1]])))
        return None if undecided[0] else (lo[0], hi[0])

    assert decided(ca.OP_LT, (0, 1), (2, 3)) == (1.0, 1.0)
    assert decided(ca.OP_LT, (0, 2), (2, 3)) is None  # 2 < 2 is false, 0 < 2 true
    assert decided(ca.OP_LT, (2, 3), (1, 2)) == (0.0, 0.0)
    assert decided(ca.OP_LE, (0, 2), (2, 3)) == (1.0, 1.0)
    assert decided(ca.OP_LE, (2, 3), (1, 2)) is None
    assert decided(ca.OP_EQ, (2, 2), (2, 2)) == (1.0, 1.0)
    assert decided(ca.OP_EQ, (1, 2), (3, 4)) == (0.0, 0.0)
    assert decided(ca.OP_EQ, (1, 3), (2, 2)) is None
    assert decided(ca.OP_EQ, (2, 2), (2, 3)) is None  # a point against a box that holds it and more
    assert decided(ca.OP_NE, (1, 2), (3, 4)) == (1.0, 1.0)
    assert decided(ca.OP_NE, (2, 2), (2, 2)) == (0.0, 0.0)


def test_truth_clean_and_zero_tests():
    nonzero, zero = ia.truth((np.array([0.5, -2.0, 0.0, -1.0]), np.array([1.0, -1.0, 0.0, 1.0])))
    assert nonzero.tolist() == [True, True, False, False] and zero.tolist() == [False, False, True, False]
    lo, hi = ia.clean(np.array([np.nan, 1.0]), np.array([2.0, np.nan]))
    assert lo.tolist() == [-np.inf, 1.0] and hi.tolist() == [2.0, np.inf]
    assert ia.holds_zero((np.array([-1.0, 0.0, 0.5]), np.array([1.0, 2.0, 1.0]))).tolist() == [True, True, False]
    assert ia.is_zero((np.array([0.0, 0.0]), np.array([0.0, 1.0]))).tolist() == [True, False]


def test_overflowing_sums_and_doublings_keep_a_finite_bound_on_the_finite_side():
    big = np.finfo(float).max
    lo, hi = ia.signed_sum(box(1e308), box(1e308), 1.0)
    assert (lo[0], hi[0]) == (big, np.inf)  # 2e308 is above every double: the largest one is a lower bound
    lo, hi = ia.signed_sum(box(-1e308), box(1e308), -1.0)
    assert (lo[0], hi[0]) == (-np.inf, -big)
    lo, hi = ia.twice((np.array([big, -big, 1.0]), np.array([big, -big, 2.0])))
    assert lo.tolist() == [big, -np.inf, 2.0] and hi.tolist() == [np.inf, -big, 4.0]


def test_products_and_quotients_with_unbounded_or_negative_boxes():
    lo, hi = ia.mul((np.array([0.0]), np.array([1.0])), (np.array([1.0]), np.array([np.inf])))
    assert -math.ulp(0.0) <= lo[0] <= 0.0 and hi[0] == np.inf  # 0 * inf counts as 0, not NaN
    lo, hi = ia.div((np.array([1.0]), np.array([2.0])), (np.array([-4.0]), np.array([-2.0])))
    assert -1.0 - 2 * math.ulp(1.0) <= lo[0] <= -1.0 and -0.25 <= hi[0] <= -0.25 + 2 * math.ulp(0.25)
    lo, hi = ia.power((np.array([-1.0]), np.array([2.0])), -2.0)  # 1 / x^2 over a box holding 0
    assert (lo[0], hi[0]) == (-np.inf, np.inf)


def test_fractional_powers_clip_the_box_at_zero():
    lo, hi = ia.power((np.array([-1.0]), np.array([4.0])), 2.5)
    assert -math.ulp(0.0) * 8 <= lo[0] <= 0.0 and 32.0 <= hi[0] <= 32.0 + 8 * math.ulp(32.0)
    lo, hi = ia.power((np.array([0.0]), np.array([4.0])), -1.5)
    assert 0.125 - 8 * math.ulp(0.125) <= lo[0] <= 0.125 and hi[0] == np.inf


def test_far_from_zero_a_sine_gets_the_whole_range():
    lo, hi = ia.periodic((np.array([999999.5]), np.array([1000000.5])), np.sin, math.pi / 2, -math.pi / 2)
    assert (lo[0], hi[0]) == (-1.0, 1.0)  # one end beyond 1e6 is enough
    lo, hi = ia.periodic((np.array([1e7]), np.array([1e7 + 0.1])), np.sin, math.pi / 2, -math.pi / 2)
    assert (lo[0], hi[0]) == (-1.0, 1.0)
    lo, hi = ia.periodic((np.array([-1e7 - 0.1]), np.array([-1e7])), np.cos, 0.0, math.pi)
    assert (lo[0], hi[0]) == (-1.0, 1.0)


def test_even_functions_take_the_larger_end_and_zero_inside():
    lo, hi = ia.even((np.array([-3.0, 1.0, -2.0]), np.array([1.0, 2.0, -1.0])), np.square)
    assert lo.tolist() == [0.0, 1.0, 1.0] and hi.tolist() == [9.0, 4.0, 4.0]


def test_exact_zeros_replace_the_bounds_only_where_an_operand_is_zero():
    result = (np.array([-1.0, -1.0, -1.0]), np.array([1.0, 1.0, 1.0]))
    a = (np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 1.0]))
    b = (np.array([2.0, 2.0, 0.0]), np.array([3.0, 3.0, 0.0]))
    lo, hi = ia.exact_zeros(result, a, b, value=1.0)
    assert lo.tolist() == [1.0, -1.0, 1.0] and hi.tolist() == [1.0, 1.0, 1.0]
    lo, hi = ia.exact_zeros(result, a)
    assert lo.tolist() == [0.0, -1.0, -1.0] and hi.tolist() == [0.0, 1.0, 1.0]


def test_indicators_of_decided_and_undecided_boxes():
    (lo, hi), undecided = ia.indicator(np.array([True, False, False]), np.array([False, True, False]))
    assert lo.tolist() == [1.0, 0.0, 0.0] and hi.tolist() == [1.0, 0.0, 1.0]
    assert undecided.tolist() == [False, False, True]


# --- quotients and powers: outward rounding (mutation survivors) -----------------------------------------------------


def test_quotients_of_several_boxes_are_bounded_box_by_box():
    """[1, 2] / [1, 2] = [0.5, 2] and [1, 2] / [4, 8] = [0.125, 0.5]: exact in doubles (TwoProduct shows
    q y = x), so not widened; [1, 2] / [3, 3] = [1/3, 2/3] is not exact: rounded out by one ulp."""
    lo, hi = ia.div((np.array([1.0, 1.0, 1.0]), np.array([2.0, 2.0, 2.0])),
                    (np.array([1.0, 4.0, 3.0]), np.array([2.0, 8.0, 3.0])))
    assert lo.tolist() == [0.5, 0.125, math.nextafter(1 / 3, 0)]
    assert hi.tolist() == [2.0, 0.5, math.nextafter(2 / 3, 1)]


def test_exact_products_and_quotients_stay_unwidened_and_inexact_ones_enclose():
    """x / 0.5 and x * 2 are exact (an equilibrium stays exactly 0 after a division by L = 0.5); 0.1 * 3 is
    not: its bounds hold the exact product of the doubles, checked in rationals."""
    from fractions import Fraction

    point = (np.array([3.0, 0.1]), np.array([3.0, 0.1]))
    lo, hi = ia.div(point, (np.array([0.5, 0.5]), np.array([0.5, 0.5])))
    assert lo.tolist() == hi.tolist() == [6.0, 0.2]
    lo, hi = ia.mul(point, (np.array([2.0, 3.0]), np.array([2.0, 3.0])))
    assert lo[0] == hi[0] == 6.0
    assert Fraction(lo[1]) < Fraction(0.1) * 3 < Fraction(hi[1])
    huge = (np.array([1e300]), np.array([1e300]))  # beyond the safe range: widened, never trusted exact
    lo, hi = ia.mul(huge, (np.array([2.0 ** 10]), np.array([2.0 ** 10])))
    assert lo[0] < 1e300 * 2 ** 10 < hi[0]


def test_a_fractional_power_rounds_both_ends_out_by_the_library_ulps():
    """9^0.5 = 3 and 4^-0.5 = 0.5 exactly (pow is exact there); each bound moves LIBM_ULPS doubles outward."""
    n = ia.LIBM_ULPS
    lo, hi = ia.power((np.array([9.0]), np.array([9.0])), 0.5)
    assert (lo[0], hi[0]) == (3.0 - n * math.ulp(3.0), 3.0 + n * math.ulp(3.0))
    lo, hi = ia.power((np.array([4.0]), np.array([4.0])), -0.5)
    assert hi[0] == 0.5 + n * math.ulp(0.5)


def test_a_negative_fractional_power_of_a_box_reaching_zero_is_unbounded_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lo, hi = ia.power((np.array([0.0]), np.array([4.0])), -0.5)
    assert lo[0] == 0.5 - ia.LIBM_ULPS * math.ulp(0.5) / 2 and hi[0] == np.inf
