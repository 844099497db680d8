"""Unit checks of the exact rational stability tests: characteristic polynomials worked out by hand, and the
Schur (spectral radius) test on its boundary, where an eigenvalue of A / rho equals 1 and the Moebius image of
the characteristic polynomial loses its leading coefficient."""

from __future__ import annotations

from fractions import Fraction

import pytest

from uvsym.verify.exact import characteristic_polynomial, schur


def F(rows):
    return [[Fraction(v) for v in row] for row in rows]


@pytest.mark.parametrize("matrix, expected", [
    ([[5]], [1, -5]),  # s - 5
    ([[1, 2], [3, 4]], [1, -5, -2]),  # s^2 - trace s + det, det = 4 - 6
    ([[0, 1], [-2, -3]], [1, 3, 2]),  # companion form of s^2 + 3 s + 2
    ([[1, 0, 0], [0, 2, 0], [0, 0, 3]], [1, -6, 11, -6]),  # (s - 1)(s - 2)(s - 3)
    ([[Fraction(1, 2), 1], [0, Fraction(-1, 3)]], [1, Fraction(-1, 6), Fraction(-1, 6)]),  # (s - 1/2)(s + 1/3)
])
def test_characteristic_polynomial_is_monic_with_the_hand_coefficients(matrix, expected):
    assert characteristic_polynomial(F(matrix)) == [Fraction(v) for v in expected]


@pytest.mark.parametrize("matrix, rho, expected", [
    ([[1]], 1, False),  # eigenvalue exactly on the circle: q(s) = (s + 1) - (s - 1) = 2 has degree 0 < 1
    ([[2]], 2, False),  # the same after scaling by rho
    ([[1, 0], [0, Fraction(1, 2)]], 1, False),  # q = 2 (s / 2 + 3 / 2) = s + 3: degree 1 < 2
    ([[Fraction(1, 2)]], 1, True),
    ([[-1]], 1, False),  # eigenvalue -1 on the circle: q = 2 s, a zero coefficient
    ([[Fraction(1, 2), 0], [0, Fraction(-1, 2)]], 1, True),
    ([[Fraction(3, 2), 0], [0, Fraction(1, 4)]], 1, False),  # one eigenvalue outside the disc
    ([[Fraction(3, 2), 0], [0, Fraction(1, 4)]], 2, True),  # inside once rho = 2
])
def test_schur_decides_the_spectral_radius_against_rho_on_and_off_the_boundary(matrix, rho, expected):
    assert schur(F(matrix), Fraction(rho)) is expected
