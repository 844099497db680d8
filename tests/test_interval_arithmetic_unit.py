"""Unit tests of single interval operations at their edge cases: overflow of 2 x, the outward steps of library
functions, truth values of boxes touching 0, and comparisons of overlapping boxes.

Expected bounds are closed forms in exact rationals (``fractions.Fraction``): a double next to 1 is 1 -+ k 2^-53
(below) or 1 + k 2^-52 (above), the smallest subnormal is 2^-1074, the largest finite double is the one just
below inf. A box is the (lo, hi) pair of (k,) arrays.
"""

from __future__ import annotations

import warnings
from fractions import Fraction

import casadi as ca
import mpmath
import numpy as np

from uvsym.verify import interval_arithmetic as ia

LARGEST = np.nextafter(np.inf, 0.0)  # the largest finite double, found without numpy's finfo


def boxes(*bounds):
    """Boxes from (lo, hi) pairs of floats: the (lo, hi) pair of (k,) arrays."""
    lo, hi = zip(*bounds)
    return np.array(lo, dtype=float), np.array(hi, dtype=float)


def strict(operation, *args, under="warn"):
    """``operation(*args)`` with every numpy floating-point event (but underflow if ``under="ignore"``: the step
    from 0 to a subnormal) and every warning turned into an error."""
    with warnings.catch_warnings(), np.errstate(all="warn", under=under):
        warnings.simplefilter("error")
        return operation(*args)


def test_twice_overflow_moves_the_bound_inward_silently():
    lo, hi = strict(ia.twice, boxes((1.5, 3.0), (1e308, np.inf), (-np.inf, -1e308), (-1e308, 1e308)))
    # 2 x is exact below overflow; 2e308 exceeds every double, so the largest double is the sound lower bound
    assert Fraction(LARGEST) < 2 * Fraction(1e308)
    np.testing.assert_array_equal(lo, [3.0, LARGEST, -np.inf, -np.inf])
    np.testing.assert_array_equal(hi, [6.0, np.inf, -LARGEST, np.inf])


def test_increasing_steps_out_libm_ulps_by_default():
    lo, hi = ia.increasing(np.exp)(boxes((0.0, 0.0)))  # exp(0) = 1 exactly
    assert ia.LIBM_ULPS == 4
    assert Fraction(lo[0]) == 1 - Fraction(4, 2**53)
    assert Fraction(hi[0]) == 1 + Fraction(4, 2**52)
    lo, hi = ia.increasing(np.exp, 2)(boxes((0.0, 0.0)))
    assert (Fraction(lo[0]), Fraction(hi[0])) == (1 - Fraction(2, 2**53), 1 + Fraction(2, 2**52))


def test_increasing_outside_the_domain_gives_unbounded_bounds_silently():
    lo, hi = strict(ia.increasing(np.log), boxes((0.0, 1.0), (-1.0, 1.0)))  # log(0) = -inf, log(-1) = nan
    np.testing.assert_array_equal(lo, [-np.inf, -np.inf])
    assert [Fraction(h) for h in hi] == [4 * Fraction(1, 2**1074)] * 2  # log(1) = 0, four subnormal steps up


def test_truth_of_boxes_touching_zero():
    nonzero, zero = ia.truth(boxes((-1.0, 0.0), (0.0, 0.0), (0.0, 1.0), (-0.0, 0.0), (0.5, 1.0), (-2.0, -1.0)))
    np.testing.assert_array_equal(nonzero, [False, False, False, False, True, True])
    np.testing.assert_array_equal(zero, [False, True, False, True, False, False])


def test_less_or_equal_of_overlapping_touching_and_disjoint_boxes():
    a = boxes((0.0, 1.0), (0.0, 1.0), (3.0, 4.0))
    b = boxes((0.5, 2.0), (1.0, 2.0), (1.0, 2.0))
    (lo, hi), undecided = ia.compare(ca.OP_LE, a, b)
    # overlap: either; a touches b from below: a <= b for all points; a above b: never
    np.testing.assert_array_equal(lo, [0.0, 1.0, 0.0])
    np.testing.assert_array_equal(hi, [1.0, 1.0, 0.0])
    np.testing.assert_array_equal(undecided, [True, False, False])


def test_equality_needs_two_equal_point_boxes():
    a = boxes((1.0, 2.0), (1.0, 1.0), (1.0, 1.0))
    b = boxes((1.0, 1.0), (1.0, 1.0), (2.0, 3.0))
    # a box holding b's point: undecided; equal points: equal; disjoint: different
    (lo, hi), undecided = ia.compare(ca.OP_EQ, a, b)
    np.testing.assert_array_equal(lo, [0.0, 1.0, 0.0])
    np.testing.assert_array_equal(hi, [1.0, 1.0, 0.0])
    np.testing.assert_array_equal(undecided, [True, False, False])
    (lo, hi), undecided = ia.compare(ca.OP_NE, a, b)
    np.testing.assert_array_equal(lo, [0.0, 0.0, 1.0])
    np.testing.assert_array_equal(hi, [1.0, 0.0, 1.0])
    np.testing.assert_array_equal(undecided, [True, False, False])


TINY = Fraction(1, 2**1074)  # the smallest subnormal double


def test_is_zero_needs_both_bounds_zero():
    np.testing.assert_array_equal(ia.is_zero(boxes((-1.0, 0.0), (0.0, 0.0), (0.0, 1.0), (-0.0, 0.0))),
                                  [False, True, False, True])


def test_signed_sum_overflow_and_inf_minus_inf_are_silent():
    # 1e308 + 1e308 = 2e308 exceeds every double: the largest double is the sound lower bound, inf the upper;
    # inf - inf (nan) becomes the widest bound
    assert Fraction(LARGEST) < 2 * Fraction(1e308)
    lo, hi = strict(ia.signed_sum, boxes((1e308, 1e308), (0.0, np.inf)), boxes((1e308, 1e308), (0.0, np.inf)), -1.0,
                    under="ignore")
    assert (lo[0], hi[0]) == (0.0, 0.0)  # 1e308 - 1e308 = 0 exactly
    assert (lo[1], hi[1]) == (-np.inf, np.inf)
    lo, hi = strict(ia.signed_sum, boxes((1e308, 1e308)), boxes((1e308, 1e308)), 1.0)
    assert (lo[0], hi[0]) == (LARGEST, np.inf)


def test_mul_zero_times_infinity_is_silent_and_the_zero_wins():
    # x in [0, 1], y <= -1: x y <= 0 with 0 reached at x = 0, so the upper bound is 0 one subnormal step up;
    # x y is unbounded below
    lo, hi = strict(ia.mul, boxes((0.0, 1.0), (0.0, 0.0)), boxes((-np.inf, -1.0), (-np.inf, np.inf)),
                    under="ignore")
    assert lo[0] == -np.inf and Fraction(hi[0]) == TINY
    assert (lo[1], hi[1]) == (0.0, 0.0)  # an exact zero factor: exactly 0


def test_periodic_of_an_unbounded_box_is_silent_and_whole():
    lo, hi = strict(ia.periodic, boxes((0.0, np.inf), (-np.inf, np.inf)), np.sin, np.pi / 2, -np.pi / 2)
    np.testing.assert_array_equal(lo, [-1.0, -1.0])
    np.testing.assert_array_equal(hi, [1.0, 1.0])


def test_periodic_point_box_steps_out_libm_ulps_both_ways():
    # sin(0.5) = 0.479...: doubles in [1/4, 1/2) are 2^-54 apart; no peak (pi/2) or trough (-pi/2) in the box
    lo, hi = ia.periodic(boxes((0.5, 0.5)), np.sin, np.pi / 2, -np.pi / 2)
    libm = Fraction(float(np.sin(0.5)))
    assert Fraction(1, 4) < libm < Fraction(1, 2)
    assert Fraction(lo[0]) == libm - 4 * Fraction(1, 2**54)
    assert Fraction(hi[0]) == libm + 4 * Fraction(1, 2**54)
    exact = mpmath.sin(mpmath.mpf(0.5))
    assert mpmath.mpf(lo[0]) < exact < mpmath.mpf(hi[0])


def test_periodic_without_a_peak_keeps_the_endpoint_range():
    # sin on [3, 4]: pi/2 and 3 pi/2 = 4.712... lie outside, so sin is monotone there: [sin 4, sin 3]
    lo, hi = ia.periodic(boxes((3.0, 4.0)), np.sin, np.pi / 2, -np.pi / 2)
    assert mpmath.mpf(lo[0]) <= mpmath.sin(4) and mpmath.sin(4) - mpmath.mpf(lo[0]) < 1e-15
    assert mpmath.mpf(hi[0]) >= mpmath.sin(3) and mpmath.mpf(hi[0]) - mpmath.sin(3) < 1e-15


def test_periodic_near_a_peak_is_capped_at_one_exactly():
    # 1e-8 short of pi/2 (or past -pi/2): sin is within 1e-16 of +-1, the outward steps would cross +-1,
    # and |sin| <= 1 caps them
    lo, hi = ia.periodic(boxes((0.0, np.pi / 2 - 1e-8), (-np.pi / 2 + 1e-8, 0.0)), np.sin, np.pi / 2, -np.pi / 2)
    assert hi[0] == 1.0 and lo[1] == -1.0
    assert lo[0] <= 0.0 <= hi[1]


def test_periodic_far_from_zero_gives_the_whole_range():
    # |x| >= 1e6 at either end: [-1, 1] although sin is monotone on these half-unit boxes
    a = boxes((-1e6, -1e6 + 0.5), (1e6 - 0.5, 1e6))
    lo, hi = ia.periodic(a, np.sin, np.pi / 2, -np.pi / 2)
    np.testing.assert_array_equal(lo, [-1.0, -1.0])
    np.testing.assert_array_equal(hi, [1.0, 1.0])
