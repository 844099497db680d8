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
from scipy.linalg import solve_discrete_lyapunov

from uvsym.verify.certificate import Certificate

__all__ = ["discrete_lyapunov_decrease", "lyapunov_decrease", "exact_positive_definite"]


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


def discrete_lyapunov_decrease(claim: str, Ad: np.ndarray, rho: float, set_description: str,
                               expected: str = "proved") -> Certificate:
    """Certificate that ``e_{k+1} = Ad e_k`` contracts at rate rho: ``V = e^T P e`` with
    ``V_{k+1} <= rho^2 V_k``, i.e. ``P > 0`` and ``rho^2 P - Ad^T P Ad > 0`` (Stein inequality).

    P solves ``(Ad / rho')^T P (Ad / rho') - P = -I`` (scipy) for rho' slightly above the spectral
    radius, and is re-checked without the solver in exact rationals (LDL^T), as for the
    continuous case. An eigenvalue of modulus >= rho refutes the claim (the counterexample).
    """
    started = time.perf_counter()
    Ad = np.atleast_2d(np.asarray(Ad, dtype=float))
    eigenvalues, vectors = np.linalg.eig(Ad)
    k = int(np.argmax(np.abs(eigenvalues)))
    radius = float(np.abs(eigenvalues[k]))
    if radius >= rho:
        return Certificate(claim, set_description, "eigenvalue of the sampled map", "refuted", expected,
                           margin=rho - radius, seconds=time.perf_counter() - started,
                           counterexample={"A": Ad.tolist(), "eigenvalue_modulus": radius, "rho": rho,
                                           "eigenvector_real": vectors[:, k].real.tolist()})
    scaled = Ad / (0.5 * (radius + rho))
    P = solve_discrete_lyapunov(scaled.T, np.eye(Ad.shape[0]))
    P_exact, A_exact = _rational(0.5 * (P + P.T)), _rational(Ad)
    n, r2 = Ad.shape[0], Fraction(rho) ** 2
    AtPA = [[sum(A_exact[k][i] * sum(P_exact[k][m] * A_exact[m][j] for m in range(n)) for k in range(n))
             for j in range(n)] for i in range(n)]
    ok_P, margin_P = exact_positive_definite(P_exact)
    ok_S, margin_S = exact_positive_definite([[r2 * P_exact[i][j] - AtPA[i][j] for j in range(n)] for i in range(n)])
    ok = ok_P and ok_S
    return Certificate(claim, set_description, "discrete Lyapunov (Stein) inequality, P from scipy, re-checked by "
                       "exact rational LDL^T", "proved" if ok else "inconclusive", expected,
                       margin=float(min(margin_P, margin_S)), seconds=time.perf_counter() - started,
                       reason="" if ok else "the solver's P failed the exact re-check",
                       details={"spectral_radius": radius, "P": P.tolist()})
