"""Exact rational tests on matrices: stability by Routh-Hurwitz on the characteristic polynomial.

Every double converts to a :class:`~fractions.Fraction` exactly, so the tests below decide the
claim for the matrix as stored, with no rounding anywhere:

- :func:`characteristic_polynomial` by Faddeev-LeVerrier in rationals (coefficients highest first);
- :func:`hurwitz` whether every root has a negative real part (Routh array: every first-column
  entry positive; a zero or a sign change means a root on or right of the imaginary axis);
- :func:`shifted_hurwitz`: every eigenvalue of A has real part below ``-gamma`` (A + gamma I Hurwitz);
- :func:`schur`: every eigenvalue of A has modulus below ``rho``, by the Moebius map
  ``z = (s + 1) / (s - 1)`` that takes the unit disc to the open left half-plane.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from uvsym.errors import VerificationError

__all__ = ["as_fraction_matrix", "characteristic_polynomial", "hurwitz", "schur", "shifted_hurwitz"]

Matrix = list[list[Fraction]]


def as_fraction_matrix(matrix, name: str = "matrix") -> Matrix:
    """A square or rectangular matrix of Fractions: each double converted exactly (Fractions kept).

    VerificationError naming ``name`` for non-finite entries or a matrix that is not 2-D.
    """
    if (isinstance(matrix, list) and matrix and all(isinstance(row, list) for row in matrix) and matrix[0]
            and len({len(row) for row in matrix}) == 1
            and all(isinstance(v, Fraction) for row in matrix for v in row)):
        return [list(row) for row in matrix]
    try:
        array = np.atleast_2d(np.asarray(matrix, dtype=float))
    except (TypeError, ValueError, OverflowError) as exc:
        raise VerificationError(f"{name} must be a numeric matrix: {exc}") from None
    if array.ndim != 2 or array.size == 0:
        raise VerificationError(f"{name} must be a non-empty 2-D matrix, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise VerificationError(f"{name} has entries that are not finite (NaN or inf)")
    return [[Fraction(float(v)) for v in row] for row in array]


def matmul(a: Matrix, b: Matrix) -> Matrix:
    """Exact product of two rational matrices."""
    columns = list(zip(*b))
    return [[sum((x * y for x, y in zip(row, column)), Fraction(0)) for column in columns] for row in a]


def characteristic_polynomial(matrix: Matrix) -> list[Fraction]:
    """Coefficients of ``det(s I - A)``, highest power first (monic), exactly (Faddeev-LeVerrier)."""
    n = len(matrix)
    coefficients = [Fraction(1)]
    M = [[Fraction(0)] * n for _ in range(n)]
    for k in range(1, n + 1):
        AM = matmul(matrix, M)
        M = [[AM[i][j] + (coefficients[-1] if i == j else 0) for j in range(n)] for i in range(n)]
        AM = matmul(matrix, M)
        coefficients.append(-sum(AM[i][i] for i in range(n)) / k)
    return coefficients


def hurwitz(coefficients: list[Fraction]) -> bool:
    """Whether every root of the polynomial (coefficients highest first) has a negative real part."""
    c = list(coefficients)
    while c and c[0] == 0:  # a vanishing leading coefficient: the degree is lower
        c.pop(0)
    if not c:
        return False
    if c[0] < 0:
        c = [-v for v in c]
    if any(v <= 0 for v in c):  # a stable polynomial has every coefficient positive
        return False
    rows = [c[0::2], c[1::2]]
    for _ in range(len(c) - 2):
        above, current = rows[-2], rows[-1]
        if current[0] <= 0:
            return False
        width = len(above) - 1
        nxt = [(current[0] * (above[j + 1] if j + 1 < len(above) else 0)
                - above[0] * (current[j + 1] if j + 1 < len(current) else 0)) / current[0] for j in range(width)]
        rows.append(nxt or [Fraction(0)])
    return all(row[0] > 0 for row in rows[:len(c)])


def shifted_hurwitz(matrix: Matrix, gamma: Fraction) -> bool:
    """Every eigenvalue of A has real part ``< -gamma`` (A + gamma I is Hurwitz), exactly."""
    n = len(matrix)
    shifted = [[matrix[i][j] + (gamma if i == j else 0) for j in range(n)] for i in range(n)]
    return hurwitz(characteristic_polynomial(shifted))


def schur(matrix: Matrix, rho: Fraction) -> bool:
    """Every eigenvalue of A has modulus ``< rho`` (rho > 0), exactly.

    With p the characteristic polynomial of A / rho, ``q(s) = (s - 1)^n p((s + 1) / (s - 1))`` has
    its roots in the open left half-plane exactly when p has its roots in the open unit disc
    (and degree n exactly when p(1) != 0; otherwise 1 is an eigenvalue of A / rho).
    """
    n = len(matrix)
    p = characteristic_polynomial([[v / rho for v in row] for row in matrix])
    q = [Fraction(0)] * (n + 1)  # highest first
    for k, a in enumerate(reversed(p)):  # a is the coefficient of z^k
        term = [Fraction(1)]
        for factor in [[1, 1]] * k + [[1, -1]] * (n - k):  # (s + 1)^k (s - 1)^(n - k)
            term = [sum((term[i] * factor[j - i] for i in range(len(term)) if 0 <= j - i < 2), Fraction(0))
                    for j in range(len(term) + 1)]
        q = [qi + a * ti for qi, ti in zip(q, term)]
    return q[0] != 0 and hurwitz(q)
