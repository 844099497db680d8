"""Quadratic Lyapunov certificates for linear error dynamics ``e' = A(theta) e``, A over a polytope.

Every condition here is strict, and that is what is decided. ``lyapunov_decrease`` looks for
``P = P^T > 0`` with ``A_i^T P + P A_i + 2 gamma P < 0`` (negative definite) at every vertex A_i
(then ``V = e^T P e`` satisfies ``V' < -2 gamma V`` for every e != 0 and every A in the polytope:
decay at a rate strictly above gamma; an eigenvalue on ``Re s = -gamma`` refutes it, as
``A = diag(-1, -2)`` at ``gamma = 1``, where only the non-strict ``<= 0`` holds) by an
LMI solved with cvxpy and Clarabel, then re-checks the answer without the solver: P is rounded to
rationals and ``P`` and ``-(A_i^T P + P A_i + 2 gamma P)`` are shown positive definite by exact
rational LDL^T factorisation (every pivot > 0). The margin is the smallest pivot ratio found.

Only when that fails is the claim decided otherwise. Refutation is exact: a common P needs every
vertex to have all eigenvalues left of ``-gamma``,
which :func:`uvsym.verify.exact.shifted_hurwitz` decides by Routh-Hurwitz on the characteristic
polynomial in rationals (never by a floating-point eigenvalue, which is wrong for non-normal and
defective matrices). For a single vertex that test is also a proof (Lyapunov's theorem gives P)
when the solver's P fails the re-check. Vertices may be given as Fraction matrices (the exact
``A - L C`` of a synthesis).
"""

from __future__ import annotations

import time
import warnings
from fractions import Fraction

import cvxpy as cp
import numpy as np
from scipy.linalg import solve_discrete_lyapunov

from uvsym.errors import VerificationError
from uvsym.verify.certificate import Certificate
from uvsym.verify.exact import as_fraction_matrix, matmul, schur, shifted_hurwitz

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


def _rate(value, name: str) -> Fraction:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise VerificationError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(value):
        raise VerificationError(f"{name} must be finite, got {value}")
    return Fraction(value)


def _vertices(vertices) -> list[list[list[Fraction]]]:
    """The vertices as exact square matrices of one size; VerificationError naming ``vertices`` otherwise."""
    if isinstance(vertices, np.ndarray) and vertices.ndim == 2:
        raise VerificationError("vertices must be a list of matrices, got one matrix (wrap it in a list)")
    if not isinstance(vertices, (list, tuple)) or not vertices:
        raise VerificationError(f"vertices must be a non-empty list of square matrices, got {type(vertices).__name__}")
    exact = [as_fraction_matrix(A, f"vertices[{i}]") for i, A in enumerate(vertices)]
    n = len(exact[0])
    for i, A in enumerate(exact):
        if len(A) != n or any(len(row) != n for row in A):
            raise VerificationError(f"vertices[{i}] must be {n}x{n} like vertices[0], got {len(A)}x{len(A[0])}")
    return exact


def _eigen_witness(A: np.ndarray, by_modulus: bool) -> tuple[float, list[float]]:
    """The floating-point eigenvalue (real part or modulus) furthest out, with its eigenvector: an
    illustration of an exact refutation, not its evidence."""
    eigenvalues, vectors = np.linalg.eig(A)
    key = np.abs(eigenvalues) if by_modulus else eigenvalues.real
    k = int(np.argmax(key))
    return float(key[k]), vectors[:, k].real.tolist()


def lyapunov_decrease(claim: str, vertices: list[np.ndarray], gamma: float, set_description: str,
                      expected: str = "proved") -> Certificate:
    """Certificate that ``V = e^T P e`` decreases faster than at rate ``2 gamma`` (``V' < -2 gamma V``
    for e != 0, the strict LMI of the module docstring) for every A in the hull of ``vertices``.

    vertices: non-empty list of (n, n) arrays or Fraction matrices; gamma: finite rate (1/s).
    VerificationError for a single matrix, non-finite entries or mismatched sizes.
    """
    started = time.perf_counter()
    exact = _vertices(vertices)
    gamma_exact = _rate(gamma, "gamma")
    gamma = float(gamma_exact)
    floats = [np.array([[float(v) for v in row] for row in A]) for A in exact]
    n = len(exact[0])
    P = cp.Variable((n, n), symmetric=True)
    scale = max(1.0, max(float(np.max(np.abs(A))) for A in floats))
    constraints = [P >> np.eye(n)]
    constraints += [-(A.T @ P + P @ A + 2 * gamma * P) / scale >> 1e-6 * np.eye(n) for A in floats]
    problem = cp.Problem(cp.Minimize(cp.trace(P)), constraints)
    try:
        with warnings.catch_warnings():  # an inaccurate solution is re-checked exactly below
            warnings.filterwarnings("ignore", message="Solution may be inaccurate")
            problem.solve(solver=cp.CLARABEL)
    except cp.SolverError as exc:
        problem = None
        failure = f"solver failed: {exc}"
    if problem is not None and (P.value is None or problem.status not in ("optimal", "optimal_inaccurate")):
        failure = f"LMI status {problem.status}"
    elif problem is not None:
        P_exact = _rational(0.5 * (P.value + P.value.T))
        ok, margin = exact_positive_definite(P_exact)
        margins = [margin]
        for A_exact in exact:
            AtP = matmul([list(c) for c in zip(*A_exact)], P_exact)
            Q = [[-(AtP[i][j] + AtP[j][i] + 2 * gamma_exact * P_exact[i][j]) for j in range(n)] for i in range(n)]
            vertex_ok, vertex_margin = exact_positive_definite(Q)
            ok, margins = ok and vertex_ok, margins + [vertex_margin]
        if ok:
            where = "1 vertex" if len(exact) == 1 else f"{len(exact)} vertices"
            return Certificate(claim, set_description, f"LMI (cvxpy, Clarabel) at {where}, re-checked "
                               "by exact rational LDL^T", "proved", expected, margin=float(min(margins)),
                               seconds=time.perf_counter() - started, details={"P": np.asarray(P.value).tolist()})
        failure = "the solver's P failed the exact re-check"
    for A, A_exact in zip(floats, exact):
        if not shifted_hurwitz(A_exact, gamma_exact):
            real, vector = _eigen_witness(A, by_modulus=False)
            return Certificate(claim, set_description, "Routh-Hurwitz on det(sI - A - gamma I) of a vertex, in exact "
                               "rationals: an eigenvalue with real part >= -gamma (no P satisfies the strict LMI)",
                               "refuted", expected,
                               margin=float(-gamma - real), seconds=time.perf_counter() - started,
                               counterexample={"A": A.tolist(), "gamma": gamma, "eigenvalue_real": real,
                                               "eigenvector_real": vector, "exact_test": "Routh-Hurwitz"})
    if len(exact) == 1:  # A + gamma I is Hurwitz (shown above): Lyapunov's theorem gives P
        return Certificate(claim, set_description, "Routh-Hurwitz on det(sI - A - gamma I) in exact rationals "
                           "(A + gamma I Hurwitz, so P exists by Lyapunov's theorem)", "proved", expected,
                           seconds=time.perf_counter() - started, details={"lmi": failure})
    return Certificate(claim, set_description, "LMI (cvxpy, Clarabel)", "inconclusive", expected,
                       seconds=time.perf_counter() - started,
                       reason=f"every vertex is stable at rate gamma (exact Routh-Hurwitz), but no common P: {failure}")


def discrete_lyapunov_decrease(claim: str, Ad: np.ndarray, rho: float, set_description: str,
                               expected: str = "proved") -> Certificate:
    """Certificate that ``e_{k+1} = Ad e_k`` contracts faster than at rate rho: ``V = e^T P e`` with
    ``V_{k+1} < rho^2 V_k`` for e != 0, i.e. ``P > 0`` and ``rho^2 P - Ad^T P Ad > 0`` (the strict
    Stein inequality; an eigenvalue of modulus exactly rho refutes it).

    The spectral radius is first decided exactly (:func:`uvsym.verify.exact.schur`): radius >= rho
    refutes the claim. Then P solves ``(Ad / rho')^T P (Ad / rho') - P = -I`` (scipy) for rho'
    between the spectral radius and rho, and is re-checked in exact rationals (LDL^T); should that
    fail, the exact Schur test is the proof (P exists by Lyapunov's theorem).
    """
    started = time.perf_counter()
    A_exact = as_fraction_matrix(Ad, "Ad")
    if len(A_exact) != len(A_exact[0]):
        raise VerificationError(f"Ad must be square, got {len(A_exact)}x{len(A_exact[0])}")
    rho_exact = _rate(rho, "rho")
    if rho_exact <= 0:
        raise VerificationError(f"rho must be positive, got {rho}")
    Ad = np.array([[float(v) for v in row] for row in A_exact])
    radius, vector = _eigen_witness(Ad, by_modulus=True)
    if not schur(A_exact, rho_exact):
        return Certificate(claim, set_description, "Schur test of the sampled map (Moebius map and Routh-Hurwitz "
                           "in exact rationals): an eigenvalue of modulus >= rho", "refuted", expected,
                           margin=rho - radius, seconds=time.perf_counter() - started,
                           counterexample={"A": Ad.tolist(), "eigenvalue_modulus": radius, "rho": float(rho),
                                           "eigenvector_real": vector, "exact_test": "Schur"})
    scaled = Ad / (0.5 * (min(radius, float(rho)) + float(rho)))
    try:
        with warnings.catch_warnings():  # an ill-conditioned P is re-checked exactly below
            warnings.simplefilter("ignore")
            P = solve_discrete_lyapunov(scaled.T, np.eye(Ad.shape[0]))
    except (np.linalg.LinAlgError, ValueError):
        P = None
    if P is not None and np.all(np.isfinite(P)):
        P_exact = _rational(0.5 * (P + P.T))
        n, r2 = Ad.shape[0], rho_exact ** 2
        AtPA = matmul(matmul([list(c) for c in zip(*A_exact)], P_exact), A_exact)
        ok_P, margin_P = exact_positive_definite(P_exact)
        ok_S, margin_S = exact_positive_definite([[r2 * P_exact[i][j] - AtPA[i][j] for j in range(n)]
                                                  for i in range(n)])
        if ok_P and ok_S:
            return Certificate(claim, set_description, "discrete Lyapunov (Stein) inequality, P from scipy, "
                               "re-checked by exact rational LDL^T", "proved", expected,
                               margin=float(min(margin_P, margin_S)), seconds=time.perf_counter() - started,
                               details={"spectral_radius": radius, "P": P.tolist()})
    return Certificate(claim, set_description, "Schur test in exact rationals (spectral radius < rho, so P exists by "
                       "Lyapunov's theorem)", "proved", expected, seconds=time.perf_counter() - started,
                       details={"spectral_radius": radius, "stein": "scipy's P failed the exact re-check"})
