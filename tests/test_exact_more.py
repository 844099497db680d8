"""More unit checks of the exact rational tests: the Routh-Hurwitz decision on polynomials built from known roots
(degenerate degrees, negated polynomials, roots on the imaginary axis) and the typed errors of the matrix
conversion, with the name of the offending field in the message."""

from __future__ import annotations

import re
from fractions import Fraction

import numpy as np
import pytest

from uvsym.errors import VerificationError
from uvsym.verify.exact import as_fraction_matrix, hurwitz


def P(*coefficients):
    return [Fraction(v) for v in coefficients]


@pytest.mark.parametrize("coefficients, expected", [
    (P(1), True),  # a non-zero constant has no root at all
    (P(-5), True),  # the same after a sign flip
    (P(), False),  # the zero polynomial vanishes everywhere
    (P(0, 0), False),
    (P(0, 1, 1), True),  # leading zero: the polynomial is s + 1
    (P(0, 0, 2, 3), True),  # 2 s + 3
    (P(1, -1), False),  # s - 1: root at +1
    (P(-1, -3, -2), True),  # -(s + 1)(s + 2)
    (P(-1, 1), False),  # -(s - 1)
    (P(1, 3, 3, 1), True),  # (s + 1)^3
    (P(1, 6, 11, 6), True),  # (s + 1)(s + 2)(s + 3)
    (P(1, 1, 1, 1), False),  # (s + 1)(s^2 + 1): roots +-i on the axis
    (P(2, 2, 2, 2), False),  # 2 (s + 1)(s^2 + 1)
    (P(1, 2, 1, 12), False),  # (s + 3)(s^2 - s + 4): positive coefficients, roots 1/2 +- i sqrt(15)/2
    (P(1, 3, 8, 7, 5), True),  # (s^2 + s + 1)(s^2 + 2 s + 5)
    (P(1, 1, 5, 1, 4), False),  # (s^2 + 1)(s^2 + s + 4): roots +-i
    (P(1, 1, 2, 8), False),  # (s + 2)(s^2 - s + 4): positive coefficients, roots 1/2 +- i sqrt(15)/2
    (P(1, 4, 6, 4, 1), True),  # (s + 1)^4
])
def test_hurwitz_matches_the_roots_the_polynomial_was_built_from(coefficients, expected):
    assert hurwitz(coefficients) is expected


def test_non_finite_entry_is_named_with_the_default_field_name():
    with pytest.raises(VerificationError, match=r"^matrix has entries that are not finite"):
        as_fraction_matrix([[1.0, float("nan")]])


@pytest.mark.parametrize("bad", [[[1 + 2j]], [[10 ** 400]], [[1, 2], [3]]])
def test_non_real_or_unrepresentable_entries_raise_a_typed_error_naming_the_field(bad):
    with pytest.raises(VerificationError, match=r"^Ad must be a numeric matrix: "):
        as_fraction_matrix(bad, "Ad")


@pytest.mark.parametrize("bad, shape", [(np.zeros((1, 1, 1)), "(1, 1, 1)"), ([[]], "(1, 0)"), ([], "(1, 0)")])
def test_empty_or_three_dimensional_input_is_rejected_with_its_shape(bad, shape):
    with pytest.raises(VerificationError, match=r"^Ad must be a non-empty 2-D matrix, got shape " + re.escape(shape)):
        as_fraction_matrix(bad, "Ad")


def test_doubles_convert_exactly():
    assert as_fraction_matrix([[0.1, -2]], "Ad") == [[Fraction(3602879701896397, 36028797018963968), Fraction(-2)]]


def test_ragged_fraction_rows_are_rejected_not_passed_through():
    with pytest.raises(VerificationError, match=r"^Ad must be a numeric matrix: "):
        as_fraction_matrix([[Fraction(1), Fraction(2)], [Fraction(3)]], "Ad")


def test_a_flat_list_of_fractions_is_read_as_one_row():
    assert as_fraction_matrix([Fraction(1, 2), Fraction(-3)], "Ad") == [[Fraction(1, 2), Fraction(-3)]]
