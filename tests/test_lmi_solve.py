"""Block LMI solving (uvsym.verify.lmi: _solve, _exact_check, solve_block_lmi, block_lmi_claim): the solver's
answer in scaled coordinates mapped back, its optimum against closed forms, the exact re-check against hand
computations, and what the certificates say (claim, set, method, status, seconds)."""

import warnings
from fractions import Fraction
from types import SimpleNamespace

import cvxpy as cp
import numpy as np
import pytest

import uvsym.verify.lmi as lmi
from uvsym.errors import VerificationError
from uvsym.verify.lmi import BlockLMI, _exact_check, _solve, block_lmi, block_lmi_claim, solve_block_lmi

PROVED = ("block LMI (2 blocks) solved by cvxpy + Clarabel; its P and K re-checked by exact rational LDL^T "
          "(margin: the smallest pivot)")
REFUTED = ("block LMI (2 blocks) infeasible: a dual certificate Z (modes that no gain moves (PBH)) with Z >= 0, "
           "C_i Z_ii = 0, [Omega Z + Z Omega^T + 2 alpha Z]_ii >= 0 in exact rationals")


def _decays(problem, P, K, rate):
    """P_i > 0 and He(P A_cl) + 2 rate P < 0 for A_cl = Omega - blkdiag(K_i C_i), by numpy eigenvalues."""
    n = len(problem.omega)
    A, Pfull = problem.float_omega(), np.zeros((n, n))
    for i, (start, size) in enumerate(zip(problem.starts, problem.sizes)):
        block = slice(start, start + size)
        Pfull[block, block] = P[i]
        A[block, block] -= K[i] @ problem.float_output(i)
    Q = Pfull @ A
    return np.allclose(Pfull, Pfull.T) and np.linalg.eigvalsh(Pfull).min() > 0 and \
        np.linalg.eigvalsh(Q + Q.T + 2 * rate * Pfull).max() < 0


# --- _solve: scaled coordinates, optimum, blocks without a measurement --------------------------------------------


@pytest.mark.parametrize("omega, outputs, D", [
    # e2 drives e1 with gain 3: P = diag(p1, p2) needs p2 > 9 p1 at rate 0.5 (det of [[-p1, 3 p1], [3 p1, -p2]])
    ([[-1.0, 3.0], [0.0, -1.0]], ([[0.0]], [[0.0]]), [1.0, 4.0]),
    ([[-1.0, 3.0], [0.0, -1.0]], ([[0.0]], [[0.0]]), [4.0, 1.0]),
    # the same with e2 unstable and measured (a gain K2 > 1.5 is needed), e2 scaled down: C_2 D_2 = 1/4
    ([[-1.0, 3.0], [0.0, 1.0]], ([[0.0]], [[1.0]]), [1.0, 0.25]),
])
def test_a_solution_in_scaled_coordinates_decays_in_the_original_ones(omega, outputs, D):
    """Solved for D^-1 e (D diagonal, powers of two), the P, K mapped back satisfy the LMI for e itself."""
    problem = block_lmi(np.array(omega), [("a", outputs[0]), ("b", outputs[1])])
    solution = _solve(problem, 0.5, np.array(D))
    assert solution is not None
    P, K = solution
    assert [p.shape for p in P] == [(1, 1), (1, 1)] and [k.shape for k in K] == [(1, 1), (1, 1)]
    assert _decays(problem, P, K, 0.5)


def test_the_design_minimises_trace_p_plus_the_frobenius_norm_of_y():
    """Omega = 0 (2, 2), C = diag(1, 2), rate 1: the constraint is W + W^T >= c I for W = Y C, c = 2 + 1e-6 with
    P >= I; a larger P only tightens it, so P = I, and min ||W C^-1||_F = w11^2 + w21^2 + (w12^2 + w22^2) / 4 is
    W = c/2 I: K = Y = diag(c/2, c/4). (The spectral norm would leave K_22 anywhere in [c/4, c/2].)"""
    problem = block_lmi(np.zeros((2, 2)), [("e", np.diag([1.0, 2.0]))])
    P, K = _solve(problem, 1.0, np.ones(2))
    c = 2.0 + 1e-6
    assert np.allclose(P[0], np.eye(2), atol=1e-5)
    assert np.allclose(K[0], np.diag([c / 2, c / 4]), atol=1e-5)


def test_the_decay_term_is_twice_the_rate():
    """Omega = -1, nothing measured: 2 p (-1 + r) <= -1e-6 holds for r = 0.8 (with p = 1, the least trace);
    3 r p in place of 2 r p would make it infeasible."""
    problem = BlockLMI(("e",), ((Fraction(-1),),), ((),), (1,), Fraction(0))
    P, K = _solve(problem, 0.8, np.ones(1))
    assert abs(P[0][0, 0] - 1.0) < 1e-6 and K[0].shape == (1, 0)


def test_the_strict_margin_is_a_millionth():
    """Omega = -1, nothing measured, rate 0.9: -0.2 p <= -1e-6 with p >= 1 is met by p = 1 (a margin of 1 would
    need p >= 5)."""
    problem = block_lmi([[-1.0]], [("e", [[0.0]])])
    P, _ = _solve(problem, 0.9, np.ones(1))
    assert abs(P[0][0, 0] - 1.0) < 1e-6


def test_a_block_without_measurement_rows_gets_an_empty_gain():
    """A BlockLMI built directly with no rows in C_i (no injection): the gain is (n_i, 0) and the LMI is proved
    when Omega_ii is fast enough (Omega = -1, decay 0.5: 2 p (-1 + 0.5) < 0)."""
    problem = BlockLMI(("e",), ((Fraction(-1),),), ((),), (1,), Fraction(1, 2))
    gains, certificate = solve_block_lmi(problem)
    assert certificate.status == "proved" and gains.K[0].shape == (1, 0)
    assert _decays(problem, gains.P, gains.K, 0.5)
    assert certificate.details["K"] == [[[]]]


def test_only_the_inaccuracy_warning_of_the_solver_is_silenced(monkeypatch):
    """The solver's "Solution may be inaccurate" is expected near the boundary and silenced; any other
    warning of the solve still reaches the user."""
    solve = cp.Problem.solve

    def noisy(self, *args, **kwargs):
        warnings.warn("Solution may be inaccurate. Try another solver.", UserWarning, stacklevel=2)
        warnings.warn("something else happened", UserWarning, stacklevel=2)
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(cp.Problem, "solve", noisy)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert _solve(block_lmi([[-1.0]], [("e", [[1.0]])]), 0.5, np.ones(1)) is not None
    messages = [str(w.message) for w in caught]
    assert "something else happened" in messages and not any(m.startswith("Solution may") for m in messages)


# --- _exact_check: hand-computed pivots -----------------------------------------------------------------------


def test_exact_check_margin_is_the_smallest_pivot_of_p_and_of_minus_the_lmi():
    """Omega = 1, C = 1, K = 3, P = 2, decay 1/2: A_cl = -2, -(2 P A_cl + 2 alpha P) = -(-8 + 2) = 6;
    the pivots are 2 (P) and 6, the margin 2."""
    problem = block_lmi([[1.0]], [("e", [[1.0]])], 0.5)
    assert _exact_check(problem, [np.array([[2.0]])], [np.array([[3.0]])]) == (True, Fraction(2))


def test_exact_check_adds_the_decay_term():
    """Omega = 1, C = 1, K = 2 (A_cl = -1), P = 1: -(2 A_cl + 2 alpha) = 2 - 2 alpha: 1/2 at alpha = 3/4 (margin
    min(1, 1/2)), -1 at alpha = 3/2 (a gain decaying at rate 1 proves no decay 1.5)."""
    P, K = [np.array([[1.0]])], [np.array([[2.0]])]
    assert _exact_check(block_lmi([[1.0]], [("e", [[1.0]])], 0.75), P, K) == (True, Fraction(1, 2))
    assert _exact_check(block_lmi([[1.0]], [("e", [[1.0]])], 1.5), P, K) == (False, Fraction(-1))


def test_exact_check_rejects_a_p_that_is_not_positive_definite():
    """Omega = 1, K = 0, P = -1: -(2 P A) = 2 > 0 although P < 0, which proves nothing: rejected on P's pivot -1."""
    problem = block_lmi([[1.0]], [("e", [[1.0]])])
    assert _exact_check(problem, [np.array([[-1.0]])], [np.array([[0.0]])]) == (False, Fraction(-1))


def test_exact_check_names_a_non_finite_gain_or_lyapunov_matrix():
    problem = block_lmi([[1.0]], [("e", [[1.0]])])
    with pytest.raises(VerificationError, match=r"^K must be finite \(no NaN or infinity\)$"):
        _exact_check(problem, [np.array([[1.0]])], [np.array([[np.nan]])])
    with pytest.raises(VerificationError, match=r"^P must be finite \(no NaN or infinity\)$"):
        _exact_check(problem, [np.array([[np.inf]])], [np.array([[1.0]])])


# --- solve_block_lmi and block_lmi_claim: the certificates -----------------------------------------------------


def _clock(monkeypatch):
    """The module's clock reads 10 s at the start of solve_block_lmi and 12.5 s at its end: 2.5 s taken."""
    monkeypatch.setattr(lmi, "time", SimpleNamespace(perf_counter=iter([10.0, 12.5]).__next__))


def test_a_proved_certificate_says_what_where_how_and_carries_the_gains(monkeypatch):
    """diag(1, -1), a measured, b not, decay 0.5: b's mode -1 is fast enough and a gets a gain."""
    problem = block_lmi(np.diag([1.0, -1.0]), [("a", [[1.0]]), ("b", [[0.0]])], 0.5)
    _clock(monkeypatch)
    gains, certificate = solve_block_lmi(problem, expected="refuted")
    assert (certificate.claim, certificate.set, certificate.method) == ("block LMI", "blocks a, b; decay 0.5 1/s",
                                                                        PROVED)
    assert (certificate.status, certificate.expected) == ("proved", "refuted")
    assert certificate.seconds == 2.5
    assert gains.certificate is certificate
    assert [p.tolist() for p in gains.P] == certificate.details["P"]
    assert _decays(problem, gains.P, gains.K, 0.5)


def test_a_refuted_certificate_says_what_where_how(monkeypatch):
    """diag(1, -1), nothing measured, decay 0: a's mode 1 is unseen and unstable; the dual certificate is the mode's
    direction, Z = e1 e1^T."""
    problem = block_lmi(np.diag([1.0, -1.0]), [("a", [[0.0]]), ("b", [[0.0]])])
    _clock(monkeypatch)
    gains, certificate = solve_block_lmi(problem, "unseen mode", "a and b", expected="refuted")
    assert gains is None and certificate.status == "refuted"
    assert certificate.counterexample["Z"] == [["1", "0"], ["0", "0"]]
    assert (certificate.claim, certificate.set, certificate.method) == ("unseen mode", "a and b", REFUTED)
    assert certificate.seconds == 2.5


def test_an_inconclusive_certificate_says_what_and_where(monkeypatch):
    """0.5 I, C = (1, 0.1), one block: the unseen direction (-0.1, 1) cannot be rounded to a certificate (test_lmi)."""
    problem = block_lmi(0.5 * np.eye(2), [("e", [[1.0, 0.1]])])
    _clock(monkeypatch)
    gains, certificate = solve_block_lmi(problem, "c", expected="refuted")
    assert gains is None and certificate.status == "inconclusive"
    assert (certificate.claim, certificate.set) == ("c", "blocks e; decay 0 1/s")
    assert certificate.method == ("block LMI (1 block) solved by cvxpy + Clarabel: no gain passed the exact re-check, "
                                  "and no dual certificate was found")
    assert certificate.seconds == 2.5


def test_a_rate_the_solver_cannot_meet_with_margin_is_tried_at_the_rate_itself():
    """Omega = -1, nothing measured, decay 0.995: 1.01 * 0.995 > 1 is infeasible for the solver, 0.995 is not
    (2 p (-1 + 0.995) < 0), and the exact re-check at 0.995 proves it."""
    problem = block_lmi([[-1.0]], [("e", [[0.0]])], 0.995)
    gains, certificate = solve_block_lmi(problem)
    assert certificate.status == "proved" and _decays(problem, gains.P, gains.K, 0.995)


def test_at_zero_decay_the_design_rate_is_only_a_millionth():
    """x' = -K y with y = x (no own dynamics), decay 0: at the design rate r = 1e-6, with p = 1 the least trace,
    the least gain has 2 (r - K) = -1e-6: K = 1.5e-6 (a design rate near 1 would give K near 1)."""
    gains = solve_block_lmi(block_lmi([[0.0]], [("e", [[1.0]])], 0.0))[0]
    assert 1.4e-6 < gains.K[0][0, 0] < 1.6e-6


def test_block_lmi_claim_passes_claim_set_and_expected_on():
    problem = block_lmi([[-1.0]], [("e", [[1.0]])], 0.5)
    certificate = block_lmi_claim(problem, "fast")
    assert (certificate.claim, certificate.set, certificate.expected) == ("fast", "blocks e; decay 0.5 1/s", "proved")
    assert block_lmi_claim(problem, "fast", "the error e").set == "the error e"
