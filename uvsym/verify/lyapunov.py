"""Quadratic Lyapunov certificates for linear error dynamics ``e' = A(theta) e``, A over a polytope.

``lyapunov_decrease`` looks for ``P = P^T > 0`` with ``A_i^T P + P A_i + 2 gamma P <= 0`` at every
vertex A_i (then ``V = e^T P e`` satisfies ``V' <= -2 gamma V`` for every A in the polytope) by an
LMI solved with cvxpy and Clarabel, then re-checks the answer without the solver: P is rounded to
rationals and ``P`` and ``-(A_i^T P + P A_i + 2 gamma P)`` are shown positive definite by exact
rational LDL^T factorisation (every pivot > 0). The margin is the smallest pivot ratio found. If
some vertex has an eigenvalue with real part above ``-gamma`` no such P exists: the claim is
refuted and the eigenpair is the counterexample.
"""

from __future__ import annotations

import time
from fractions import Fraction

import cvxpy as cp
import numpy as np

from uvsym.verify.certificate import Certificate

__all__ = ["lyapunov_decrease", "exact_positive_definite"]


def exact_positive_definite(matrix: list[list[Fraction]]) -> tuple[bool, Fraction]:
    """(positive definite?, smallest LDL^T pivot) of a symmetric rational matrix, exactly."""
    a = [row[:] for row in matrix]
    n = len(a)
    smallest = None
    for k in range(n):
        pivot = a[k][k]
        smallest = pivot if smallest is None or pivot < smallest else smallest
        if pivot <= 0:
            return False, pivot
        for i in range(k + 1, n):
            factor = a[i][k] / pivot
            for j in range(k, n):
                a[i][j] -= factor * a[k][j]
    return True, smallest


def _rational(matrix: np.ndarray) -> list[list[Fraction]]:
    return [[Fraction(float(v)) for v in row] for row in np.asarray(matrix, dtype=float)]


def lyapunov_decrease(claim: str, vertices: list[np.ndarray], gamma: float, set_description: str,
                      expected: str = "proved") -> Certificate:
    """Certificate that ``V = e^T P e`` decreases at rate ``2 gamma`` for every A in the hull of ``vertices``."""
    started = time.perf_counter()
    n = vertices[0].shape[0]
    for A in vertices:
        eigenvalues, vectors = np.linalg.eig(A)
        k = int(np.argmax(eigenvalues.real))
        if eigenvalues[k].real > -gamma:
            return Certificate(claim, set_description, "eigenvalue of a vertex", "refuted", expected,
                               margin=float(-gamma - eigenvalues[k].real), seconds=time.perf_counter() - started,
                               counterexample={"A": np.asarray(A).tolist(), "gamma": gamma,
                                               "eigenvalue_real": float(eigenvalues[k].real),
                                               "eigenvector_real": vectors[:, k].real.tolist()})
    P = cp.Variable((n, n), symmetric=True)
    scale = max(1.0, max(float(np.max(np.abs(A))) for A in vertices))
    constraints = [P >> np.eye(n)]
    constraints += [-(A.T @ P + P @ A + 2 * gamma * P) / scale >> 1e-6 * np.eye(n) for A in vertices]
    problem = cp.Problem(cp.Minimize(cp.trace(P)), constraints)
    try:
        problem.solve(solver=cp.CLARABEL)
    except cp.SolverError as exc:
        return Certificate(claim, set_description, "LMI (cvxpy, Clarabel)", "inconclusive", expected,
                           seconds=time.perf_counter() - started, reason=f"solver failed: {exc}")
    if P.value is None or problem.status not in ("optimal", "optimal_inaccurate"):
        return Certificate(claim, set_description, "LMI (cvxpy, Clarabel)", "inconclusive", expected,
                           seconds=time.perf_counter() - started, reason=f"LMI status {problem.status}")
    P_exact = _rational(0.5 * (P.value + P.value.T))
    ok, margin = exact_positive_definite(P_exact)
    margins = [margin]
    for A in vertices:
        A_exact = _rational(A)
        Q = [[-(sum(A_exact[k][i] * P_exact[k][j] for k in range(n)) + sum(P_exact[i][k] * A_exact[k][j]
                                                                            for k in range(n))
                + 2 * Fraction(gamma) * P_exact[i][j]) for j in range(n)] for i in range(n)]
        vertex_ok, vertex_margin = exact_positive_definite(Q)
        ok, margins = ok and vertex_ok, margins + [vertex_margin]
    status = "proved" if ok else "inconclusive"
    return Certificate(claim, set_description,
                       f"LMI (cvxpy, Clarabel) at {len(vertices)} vertices, re-checked by exact rational LDL^T",
                       status, expected, margin=float(min(margins)), seconds=time.perf_counter() - started,
                       reason="" if ok else "the solver's P failed the exact re-check",
                       details={"P": np.asarray(P.value).tolist()})
