"""The exact re-check behind Lyapunov certificates: LDL^T pivots of definite, semidefinite and indefinite
matrices worked out by hand, and ``lyapunov_decrease`` fed a chosen solver answer (cvxpy's solve replaced),
so that a P the solver calls optimal but that fails the exact check cannot become a proof."""

from __future__ import annotations

import re
from dataclasses import replace
from fractions import Fraction

import cvxpy as cp
import numpy as np
import pytest

from uvsym.errors import VerificationError
from uvsym.verify.certificate import Certificate
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
    solver_answer(2 * np.eye(2), "optimal_inaccurate")  # an inaccurate answer is re-checked like any other
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
    unstable = np.array([[-1.0, 0.0], [0.0, 0.5]])  # the unstable eigenvalue second
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


def test_a_P_left_by_a_solver_that_failed_is_not_rechecked(solver_answer):
    """Status infeasible with P = I still in the variable: the answer is the solver's failure (Routh-Hurwitz then
    proves the single stable vertex), not a proof by that P."""
    solver_answer(np.eye(2), "infeasible")
    certificate = lyapunov_decrease("V decreases", [MINUS_I], 0.5, "one matrix")
    assert certificate.status == "proved" and certificate.details == {"lmi": "LMI status infeasible"}


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
    assert np.linalg.eigvalsh(P).min() > 1.0 - 1e-6  # normalised to P >= I, so that margins compare
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


def _timed(certificate):
    """The certificate with its run time zeroed, after checking that one was measured."""
    assert isinstance(certificate.seconds, float) and 0 < certificate.seconds < 60
    return replace(certificate, seconds=0.0)


def test_a_discrete_refutation_names_the_eigenvalue_by_modulus():
    """diag(0.2, -0.9): modulus 0.9 >= rho = 0.5 (its real part, -0.9, would not show it), the second one."""
    certificate = discrete_lyapunov_decrease("contracts", np.diag([0.2, -0.9]), 0.5, "one map", expected="refuted")
    assert _timed(certificate) == Certificate(
        "contracts", "one map", "Schur test of the sampled map (Moebius map and Routh-Hurwitz in exact rationals): "
        "an eigenvalue of modulus >= rho", "refuted", "refuted", margin=pytest.approx(-0.4),
        counterexample={"A": [[0.2, 0.0], [0.0, -0.9]], "eigenvalue_modulus": pytest.approx(0.9), "rho": 0.5,
                        "eigenvector_real": [0.0, 1.0], "exact_test": "Schur"})


def test_a_discrete_proof_carries_the_stein_P_or_falls_back_to_the_schur_test(monkeypatch):
    a, rho = 0.5, 0.8
    p = 1.0 / (1.0 - (a / ((a + rho) / 2)) ** 2)  # scipy's P = p I (see the closed-form margin above)
    certificate = discrete_lyapunov_decrease("contracts", a * np.eye(2), rho, "one map", expected="checked")
    np.testing.assert_allclose(certificate.details.pop("P"), p * np.eye(2), rtol=1e-12, atol=1e-12)
    assert _timed(certificate) == Certificate(
        "contracts", "one map", "discrete Lyapunov (Stein) inequality, P from scipy, re-checked by exact rational "
        "LDL^T", "proved", "checked", margin=pytest.approx(p * (rho**2 - a**2)),
        details={"spectral_radius": pytest.approx(a)})
    import uvsym.verify.lyapunov as lyapunov

    for failure in (np.linalg.LinAlgError("singular"), ValueError("bad"), None):
        def broken(A, Q, failure=failure):
            if failure is None:
                return np.full((2, 2), np.nan)
            raise failure
        monkeypatch.setattr(lyapunov, "solve_discrete_lyapunov", broken)
        certificate = discrete_lyapunov_decrease("contracts", a * np.eye(2), rho, "one map", expected="refuted")
        assert _timed(certificate) == Certificate(
            "contracts", "one map", "Schur test in exact rationals (spectral radius < rho, so P exists by "
            "Lyapunov's theorem)", "proved", "refuted",
            details={"spectral_radius": pytest.approx(a), "stein": "scipy's P failed the exact re-check"})


def test_a_P_with_an_indefinite_stein_matrix_is_not_the_proof(monkeypatch):
    """Ad = 0.5 I, rho = 0.8 with scipy answering P = diag(1, -1): P > 0 fails exactly; a Jordan block with P = I:
    the Stein matrix fails. Either way the proof is the exact Schur test, not that P."""
    import uvsym.verify.lyapunov as lyapunov

    monkeypatch.setattr(lyapunov, "solve_discrete_lyapunov", lambda A, Q: np.diag([1.0, -1.0]))
    certificate = discrete_lyapunov_decrease("contracts", 0.5 * np.eye(2), 0.8, "one map")
    assert certificate.status == "proved" and "stein" in certificate.details and certificate.margin is None
    # P = I > 0 but, for the Jordan block, 0.64 I - Ad^T Ad = [[0.39, -0.5], [-0.5, -0.61]] is indefinite
    monkeypatch.setattr(lyapunov, "solve_discrete_lyapunov", lambda A, Q: np.eye(2))
    certificate = discrete_lyapunov_decrease("contracts", np.array([[0.5, 1.0], [0.0, 0.5]]), 0.8, "one map")
    assert certificate.status == "proved" and "stein" in certificate.details and certificate.margin is None


@pytest.mark.parametrize("Ad, rho, message", [
    (np.ones((2, 3)), 0.5, "Ad must be square, got 2x3"),
    ([[np.nan]], 0.5, "Ad has entries that are not finite (NaN or inf)"),
    (np.eye(2), 0.0, "rho must be positive, got 0.0"),
    (np.eye(2), -0.5, "rho must be positive, got -0.5"),
    (np.eye(2), "fast", "rho must be a number, got 'fast'"),
    (np.eye(2), np.inf, "rho must be finite, got inf"),
])
def test_discrete_claims_name_the_argument_at_fault(Ad, rho, message):
    with pytest.raises(VerificationError, match=f"^{re.escape(message)}$"):
        discrete_lyapunov_decrease("contracts", Ad, rho, "one map")


@pytest.mark.parametrize("vertices, gamma, message", [
    (np.eye(2), 0.5, "vertices must be a list of matrices, got one matrix (wrap it in a list)"),
    ([], 0.5, "vertices must be a non-empty list of square matrices, got list"),
    ("A", 0.5, "vertices must be a non-empty list of square matrices, got str"),
    ([np.eye(2), np.eye(3)], 0.5, "vertices[1] must be 2x2 like vertices[0], got 3x3"),
    ([np.eye(2), np.ones((2, 3))], 0.5, "vertices[1] must be 2x2 like vertices[0], got 2x3"),
    ([np.eye(2), [[np.inf, 0.0], [0.0, 1.0]]], 0.5, "vertices[1] has entries that are not finite (NaN or inf)"),
    ([-np.eye(2)], None, "gamma must be a number, got None"),
    ([-np.eye(2)], np.nan, "gamma must be finite, got nan"),
])
def test_continuous_claims_name_the_argument_at_fault(vertices, gamma, message):
    with pytest.raises(VerificationError, match=f"^{re.escape(message)}$"):
        lyapunov_decrease("decreases", vertices, gamma, "one matrix")


def test_each_continuous_outcome_states_its_method_and_keeps_the_expected_label(solver_answer):
    solver_answer(np.eye(2))
    proved = lyapunov_decrease("V decreases", [MINUS_I, MINUS_I], 0.25, "two vertices", expected="refuted")
    assert _timed(proved) == Certificate(
        "V decreases", "two vertices", "LMI (cvxpy, Clarabel) at 2 vertices, re-checked by exact rational LDL^T",
        "proved", "refuted", margin=1.0, details={"P": [[1.0, 0.0], [0.0, 1.0]]})
    refuted = lyapunov_decrease("too fast", [MINUS_I], 1.5, "one matrix", expected="refuted")
    assert _timed(refuted) == Certificate(
        "too fast", "one matrix", "Routh-Hurwitz on det(sI - A - gamma I) of a vertex, in exact rationals: an "
        "eigenvalue with real part >= -gamma (no P satisfies the strict LMI)", "refuted", "refuted",
        margin=pytest.approx(-0.5),
        counterexample={"A": MINUS_I.tolist(), "gamma": 1.5, "eigenvalue_real": -1.0, "eigenvector_real": [1.0, 0.0],
                        "exact_test": "Routh-Hurwitz"})
    solver_answer([[7.0, 1.0], [1.0, 1.0 / 7.0]])
    fallback = lyapunov_decrease("V decreases", [MINUS_I], 0.5, "one matrix", expected="checked")
    assert _timed(fallback) == Certificate(
        "V decreases", "one matrix", "Routh-Hurwitz on det(sI - A - gamma I) in exact rationals (A + gamma I "
        "Hurwitz, so P exists by Lyapunov's theorem)", "proved", "checked",
        details={"lmi": "the solver's P failed the exact re-check"})
    solver_answer(None, "infeasible")
    undecided = lyapunov_decrease("hull", [MINUS_I, 2 * MINUS_I], 0.5, "two vertices", expected="refuted")
    assert _timed(undecided) == Certificate(
        "hull", "two vertices", "LMI (cvxpy, Clarabel)", "inconclusive", "refuted",
        reason="every vertex is stable at rate gamma (exact Routh-Hurwitz), but no common P: LMI status infeasible")


def test_the_conditions_decided_are_the_strict_ones_the_docstrings_state():
    A = np.diag([-1.0, -2.0])  # P = I gives A'P + PA + 2P = diag(0, -2): <= 0 holds, < 0 does not
    assert lyapunov_decrease("at rate 1", [A], 1.0, "one matrix").status == "refuted"
    assert lyapunov_decrease("just below rate 1", [A], 0.999, "one matrix").status == "proved"
    Ad = np.diag([0.5, 0.25])  # V+ = rho^2 V on the first axis at rho = 0.5: only the non-strict bound holds
    assert discrete_lyapunov_decrease("at rate 0.5", Ad, 0.5, "one matrix").status == "refuted"
    assert discrete_lyapunov_decrease("just above", Ad, 0.5001, "one matrix").status == "proved"
