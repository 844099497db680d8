"""Claims on the existence of a discrete unknown-input observer, decided in exact rational arithmetic.

For ``x_{k+1} = G x_k + H u_k + D d_k``, ``y = C x`` (module :mod:`uvsym.observers.uio`) the
double entries of G, C, D (and of a gain K1) are taken as the exact rationals they are, and

1. ``rank(C D) = rank(D)`` is decided by fraction-exact elimination; ``M = (C D)^+`` (D of full
   column rank), ``T = I - D M C`` and ``G1 = T G`` are formed exactly (so ``T D = 0`` exactly);
2. with a gain K1: ``F = G1 - K1 C`` is shown Schur stable by a discrete Lyapunov certificate,
   ``X > 0`` and ``X - F^T X F > 0`` by exact LDL^T (X from scipy, rounded to rationals), which
   proves ``(C, G1)`` detectable and the observer's error ``e+ = F e`` convergent: **proved**;
3. otherwise the real part of each eigenvalue of G1 with ``|lambda| >= 1`` that the PBH test finds
   unobservable (also of a complex one: rounding splits a defective real eigenvalue into a pair with an
   imaginary part near 1e-8) is rounded to a nearby simple rational ``lambda*``, and a vector v with
   ``G1 v = lambda* v`` and ``C v = 0`` is computed and checked in rationals: **refuted**, with lambda*
   and v as evidence.

:func:`exact_zoh` samples a continuous model exactly when its augmented matrix is nilpotent (a
chain of integrators, such as a rigid body linearised at rest), so that structural eigenvalues
(e.g. the sampling zero at -1 of a double integrator) are exact, not rounded.
"""

from __future__ import annotations

import time
from fractions import Fraction

import numpy as np
from scipy.linalg import solve_discrete_lyapunov

from uvsym.errors import VerificationError
from uvsym.observers.uio import unobservable_modes
from uvsym.verify.certificate import Certificate
from uvsym.verify.lyapunov import exact_positive_definite

__all__ = ["exact_zoh", "uio_existence_claim"]

Matrix = list[list[Fraction]]


def _rational(M) -> Matrix:
    """M as exact rationals: a nested list keeps its Fraction and int entries, every double is taken exactly."""
    if isinstance(M, list):
        return [[Fraction(v) for v in row] for row in M]
    return [[Fraction(float(v)) for v in row] for row in np.atleast_2d(np.asarray(M, dtype=float))]


def _mul(A: Matrix, B: Matrix) -> Matrix:
    columns = list(zip(*B))
    return [[sum((a * b for a, b in zip(row, col)), Fraction(0)) for col in columns] for row in A]


def _sub(A: Matrix, B: Matrix) -> Matrix:
    return [[a - b for a, b in zip(ra, rb)] for ra, rb in zip(A, B)]


def _eye(n: int, scale=Fraction(1)) -> Matrix:
    return [[scale if i == j else Fraction(0) for j in range(n)] for i in range(n)]


def _transpose(A: Matrix) -> Matrix:
    return [list(col) for col in zip(*A)]


def _row_echelon(A: Matrix) -> tuple[Matrix, list[int]]:
    """Reduced row echelon form and pivot columns, exactly."""
    R = [row[:] for row in A]
    pivots, row = [], 0
    for col in range(len(R[0]) if R else 0):
        found = next((i for i in range(row, len(R)) if R[i][col] != 0), None)
        if found is None:
            continue
        R[row], R[found] = R[found], R[row]
        R[row] = [v / R[row][col] for v in R[row]]
        for i in range(len(R)):
            if i != row and R[i][col] != 0:
                factor = R[i][col]
                R[i] = [a - factor * b for a, b in zip(R[i], R[row])]
        pivots.append(col)
        row += 1
        if row == len(R):
            break
    return R, pivots


def _null_vector(A: Matrix) -> list[Fraction] | None:
    """A non-zero v with A v = 0, or None when A has full column rank."""
    R, pivots = _row_echelon(A)
    free = [c for c in range(len(A[0])) if c not in pivots]
    if not free:
        return None
    v = [Fraction(0)] * len(A[0])
    v[free[0]] = Fraction(1)
    for r, c in enumerate(pivots):
        v[c] = -R[r][free[0]]
    return v


def _inverse(A: Matrix) -> Matrix:
    n = len(A)
    R, pivots = _row_echelon([row + unit for row, unit in zip(A, _eye(n))])
    if pivots[:n] != list(range(n)):
        raise VerificationError("matrix is singular")
    return [row[n:] for row in R]


def exact_zoh(A, B, dt) -> tuple[Matrix, Matrix]:
    """(Ad, Bd) of ``x' = A x + B u`` held over dt, exactly: ``expm(dt [[A, B], [0, 0]])`` as its
    finite series when that matrix is nilpotent. dt may be a Fraction (``Fraction(1, 100)``) or
    a float (taken exactly), > 0. VerificationError for another dt or when the augmented matrix is not
    nilpotent."""
    A, B = _rational(A), _rational(B)
    n, m = len(A), len(B[0])
    try:
        step = Fraction(dt)
    except (TypeError, ValueError, OverflowError):
        raise VerificationError(f"exact_zoh: dt must be a finite number of seconds, got {dt!r}") from None
    if not step > 0:
        raise VerificationError(f"exact_zoh: dt must be positive (s), got {dt!r}")
    Maug = [[step * v for v in ra + rb] for ra, rb in zip(A, B)] + [[Fraction(0)] * (n + m) for _ in range(m)]
    total, term = _eye(n + m), _eye(n + m)
    for k in range(1, n + m + 1):
        term = [[v / k for v in row] for row in _mul(term, Maug)]
        if all(v == 0 for row in term for v in row):
            return [row[:n] for row in total[:n]], [row[n:] for row in total[:n]]
        total = [[a + b for a, b in zip(ra, rb)] for ra, rb in zip(total, term)]
    raise VerificationError("exact_zoh needs [[A, B], [0, 0]] nilpotent (a chain of integrators); it is not")


def uio_existence_claim(claim: str, G, C, D, K1=None, set_description: str = "", expected: str = "proved") \
        -> Certificate:
    """Certificate that a discrete UIO decoupling D exists for (G, C) (module docstring).

    G (n, n), C (p, n), D (n, q): floats or Fraction matrices; K1 (n, p) the gain to certify."""
    started = time.perf_counter()
    G, C, D = (_rational(M) for M in (G, C, D))
    n = len(G)
    if len(G[0]) != n or len(C[0]) != n or len(D) != n:
        raise VerificationError(f"G must be (n, n), C (p, n), D (n, q); got {len(G)}x{len(G[0])}, "
                                f"{len(C)}x{len(C[0])}, {len(D)}x{len(D[0])}")
    setting = set_description or "the matrices' double entries taken as exact rationals"
    CD = _mul(C, D)
    rank_CD, rank_D = len(_row_echelon(CD)[1]), len(_row_echelon(D)[1])

    def done(status, method, **fields):
        return Certificate(claim, setting, method, status, expected, seconds=time.perf_counter() - started,
                           **fields)

    if rank_CD != rank_D:
        return done("refuted", "exact rank (fraction elimination)", margin=float(rank_CD - rank_D),
                    counterexample={"rank_CD": rank_CD, "rank_D": rank_D})
    if rank_D != len(D[0]):
        raise VerificationError(f"D must have full column rank ({len(D[0])}), it has rank {rank_D}")
    CDt = _transpose(CD)
    M = _mul(_inverse(_mul(CDt, CD)), CDt)
    T = _sub(_eye(n), _mul(D, _mul(M, C)))
    G1 = _mul(T, G)
    if K1 is not None:
        F = _sub(G1, _mul(_rational(K1), C))
        F_float = np.array([[float(v) for v in row] for row in F])
        X = _rational(solve_discrete_lyapunov(F_float.T, np.eye(n)))
        X = [[(X[i][j] + X[j][i]) / 2 for j in range(n)] for i in range(n)]
        ok_X, margin_X = exact_positive_definite(X)
        ok_S, margin_S = exact_positive_definite(_sub(X, _mul(_transpose(F), _mul(X, F))))
        if ok_X and ok_S:
            return done("proved", "exact rank (fraction elimination); T D = 0 exactly; F = T G - K1 C Schur "
                        "stable by a discrete Lyapunov certificate (X from scipy, exact rational LDL^T)",
                        margin=float(min(margin_X, margin_S)),
                        details={"rank_CD": rank_CD, "spectral_radius_F": float(max(abs(np.linalg.eigvals(F_float))))})
    G1_float = np.array([[float(v) for v in row] for row in G1])
    for lam in unobservable_modes(G1_float, np.array([[float(v) for v in row] for row in C])):
        candidate = Fraction(lam.real).limit_denominator(1000)
        v = _null_vector(_sub(G1, _eye(n, candidate)) + C)
        if v is not None and abs(candidate) >= 1:
            return done("refuted", "PBH test in exact rationals: G1 v = lambda v and C v = 0 for |lambda| >= 1",
                        margin=float(1 - abs(candidate)),
                        counterexample={"unobservable_eigenvalue": float(candidate), "eigenvalue_modulus":
                                        float(abs(candidate)), "rho": 1.0, "eigenvector": [float(x) for x in v]})
    return done("inconclusive", "exact rank; Lyapunov and PBH searches", reason="neither a certified gain nor an "
                "exact unobservable eigenvector with |lambda| >= 1 was found")
