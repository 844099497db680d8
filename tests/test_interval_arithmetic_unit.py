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
import numpy as np

from uvsym.verify import interval_arithmetic as ia

LARGEST = np.nextafter(np.inf, 0.0)  # the largest finite double, found without numpy's finfo


def boxes(*bounds):
    """Boxes from (lo, hi) pairs of floats: the (lo, hi) pair of (k,) arrays."""
    lo, hi = zip(*bounds)
    return np.array(lo, dtype=float), np.array(hi, dtype=float)


def strict(operation, *args):
    """``operation(*args)`` with every numpy floating-point event and every warning turned into an error."""
    with warnings.catch_warnings(), np.errstate(all="warn"):
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
