"""The exact re-check behind Lyapunov certificates: LDL^T pivots of definite, semidefinite and indefinite
matrices worked out by hand, and ``lyapunov_decrease`` fed a chosen solver answer (cvxpy's solve replaced),
so that a P the solver calls optimal but that fails the exact check cannot become a proof."""

from __future__ import annotations

from fractions import Fraction

import cvxpy as cp
import numpy as np
import pytest

from uvsym.verify.lyapunov import discrete_lyapunov_decrease, exact_positive_definite, lyapunov_decrease


def F(rows):
    return [[Fraction(v) for v in row] for row in rows]


@pytest.mark.parametrize("matrix, expected", [
    ([[4, 2], [2, 3]], (True, Fraction(2))),  # pivots 4 and 3 - 2 * 2 / 4 = 2
    ([[1, 0], [0, 5]], (True, Fraction(1))),
    ([[5, 0], [0, 1]], (True, Fraction(1))),  # the smallest pivot need not be the first
    ([[2, -1, 0], [-1, 2, -1], [0, -1, 2]], (True, Fraction(4, 3))),  # pivots 2, 3/2, 4/3
    ([[1, 1], [1, 1]], (False, Fraction(0))),  # semidefinite: second pivot exactly 0
    ([[0, 0], [0, 1]], (False, Fraction(0))),  # semidefinite: first pivot 0
    ([[1, 1, 0], [1, 1, 0], [0, 0, 1]], (False, Fraction(0))),
    ([[1, 2], [2, 1]], (False, Fraction(-3))),  # indefinite: 1 - 2 * 2 / 1
    ([[-1, 0], [0, 1]], (False, Fraction(-1))),
    ([[2, 1, 1], [1, 2, 1], [1, 1, -1]], (False, Fraction(-5, 3))),  # pivots 2, 3/2, -1 - 1/2 - 1/6
])
def test_ldlt_pivots_decide_definiteness_exactly(matrix, expected):
    assert exact_positive_definite(F(matrix)) == expected


def test_a_matrix_that_passes_the_float_check_fails_the_exact_one():
    """[[7, 1], [1, fl(1/7)]]: fl(1/7) < 1/7, so the determinant 7 fl(1/7) - 1 is negative, yet floating-point
    Cholesky factorises it."""
    c = 1.0 / 7.0
    assert Fraction(c) < Fraction(1, 7)
    np.linalg.cholesky(np.array([[7.0, 1.0], [1.0, c]]))  # the float check passes
    ok, pivot = exact_positive_definite(F([[7.0, 1.0], [1.0, c]]))
    assert not ok and pivot == Fraction(c) - Fraction(1, 7) and pivot < 0


@pytest.fixture
def solver_answer(monkeypatch):
    """``solver_answer(P, status)``: cvxpy's solve leaves ``P`` as the variable's value and ``status`` (or raises
    the exception given as ``status``)."""
    def install(P, status="optimal"):
        def solve(problem, *args, **kwargs):
            if isinstance(status, Exception):
                raise status
            if P is not None:
                problem.variables()[0].value = np.asarray(P, dtype=float)
            problem._status = status
        monkeypatch.setattr(cp.Problem, "solve", solve)
    return install


MINUS_I = np.array([[-1.0, 0.0], [0.0, -1.0]])


def test_a_solver_P_is_proved_with_the_smallest_pivot_as_margin(solver_answer):
    solver_answer(2 * np.eye(2))
    # Q = -(A^T P + P A + 2 gamma P) = (4 - 4 gamma) I = 3 I for gamma = 1/4: pivots of P 2, 2; of Q 3, 3
    certificate = lyapunov_decrease("V decreases", [MINUS_I], 0.25, "one matrix")
    assert certificate.status == "proved" and "exact rational LDL^T" in certificate.method
    assert certificate.margin == 2.0 and certificate.details["P"] == [[2.0, 0.0], [0.0, 2.0]]
    # gamma = 3/4: Q = (2 - 2 gamma) P = I, now the tighter
    assert lyapunov_decrease("V decreases", [MINUS_I], 0.75, "one matrix").margin == 1.0


def test_the_exact_check_uses_twice_gamma(solver_answer):
    """A = -I, gamma = 1.5, P = I: A^T P + P A + gamma P = -0.5 I < 0 but + 2 gamma P = I > 0, and -I + 1.5 I is
    not Hurwitz: the claim is false whatever the solver said."""
    solver_answer(np.eye(2))
    certificate = lyapunov_decrease("too fast", [MINUS_I], 1.5, "one matrix")
    assert certificate.status == "refuted"
    assert certificate.counterexample["eigenvalue_real"] == -1.0 and certificate.margin == pytest.approx(-0.5)


def test_a_semidefinite_decrease_is_not_a_proof(solver_answer):
    """A = -I, gamma = 1, P = I: Q = 0 exactly (every pivot 0); -I + I is not Hurwitz: refuted."""
    solver_answer(np.eye(2))
    assert lyapunov_decrease("borderline", [MINUS_I], 1.0, "one matrix").status == "refuted"


def test_every_vertex_is_rechecked(solver_answer):
    """P = I is fine for -I but not for the unstable second vertex, which refutes the claim."""
    solver_answer(np.eye(2))
    unstable = np.array([[0.5, 0.0], [0.0, -1.0]])
    certificate = lyapunov_decrease("hull", [MINUS_I, unstable], 0.1, "two vertices")
    assert certificate.status == "refuted" and certificate.counterexample["A"] == unstable.tolist()
    assert certificate.counterexample["eigenvalue_real"] == 0.5 and certificate.margin == pytest.approx(-0.6)


def test_a_P_failing_the_exact_check_falls_back_to_routh_hurwitz(solver_answer):
    """The solver's P = [[7, 1], [1, fl(1/7)]] is not positive definite exactly; -I is stable at rate 0.5, so one
    vertex is proved by Routh-Hurwitz (Lyapunov's theorem), not by that P."""
    solver_answer([[7.0, 1.0], [1.0, 1.0 / 7.0]])
    certificate = lyapunov_decrease("V decreases", [MINUS_I], 0.5, "one matrix")
    assert certificate.status == "proved" and "Routh-Hurwitz" in certificate.method
    assert certificate.details == {"lmi": "the solver's P failed the exact re-check"} and certificate.margin is None


def test_stable_vertices_without_a_common_P_are_inconclusive(solver_answer):
    solver_answer(None, "infeasible")
    other = np.array([[-2.0, 1.0], [0.0, -2.0]])
    certificate = lyapunov_decrease("hull", [MINUS_I, other], 0.5, "two vertices")
    assert certificate.status == "inconclusive" and "LMI status infeasible" in certificate.reason
    solver_answer(None, cp.SolverError("no progress"))
    certificate = lyapunov_decrease("one", [MINUS_I], 0.5, "one matrix")
    assert certificate.status == "proved" and certificate.details == {"lmi": "solver failed: no progress"}


def test_the_solver_is_asked_for_the_decrease_at_every_vertex():
    """The real LMI: its P satisfies P > 0 and A_i^T P + P A_i + 2 gamma P < 0 at both vertices (checked here in
    floats, independently of the certificate's own check)."""
    vertices = [np.array([[-1.0, 2.0], [0.0, -3.0]]), np.array([[-1.0, 0.0], [2.0, -3.0]])]
    certificate = lyapunov_decrease("hull", vertices, 0.4, "two vertices")
    assert certificate.status == "proved"
    P = np.array(certificate.details["P"])
    assert np.linalg.eigvalsh(P).min() > 0
    for A in vertices:
        assert np.linalg.eigvalsh(A.T @ P + P @ A + 0.8 * P).max() < 0


def test_a_discrete_contraction_has_the_closed_form_margin():
    """Ad = a I, rho: scipy's P = p I with p = 1 / (1 - (a / rho')^2), rho' = (a + rho) / 2; the Stein
    matrix rho^2 P - Ad^T P Ad = p (rho^2 - a^2) I is the smaller pivot."""
    a, rho = 0.5, 0.8
    p = 1.0 / (1.0 - (a / ((a + rho) / 2)) ** 2)
    certificate = discrete_lyapunov_decrease("contracts", a * np.eye(2), rho, "one matrix")
    assert certificate.status == "proved" and certificate.margin == pytest.approx(p * (rho**2 - a**2), rel=1e-9)
    assert certificate.details["spectral_radius"] == pytest.approx(a)


def test_a_discrete_map_at_the_rate_is_refuted_with_its_eigenvalue():
    jordan = np.array([[0.5, 1.0], [0.0, 0.5]])
    refuted = discrete_lyapunov_decrease("contracts", jordan, 0.5, "one matrix")
    assert refuted.status == "refuted" and refuted.counterexample["eigenvalue_modulus"] == pytest.approx(0.5)
    assert refuted.margin == pytest.approx(0.0, abs=1e-12)
    assert discrete_lyapunov_decrease("contracts", jordan, 0.6, "one matrix").status == "proved"
