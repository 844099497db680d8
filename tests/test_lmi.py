"""Block LMIs (uvsym.verify.lmi): proofs re-checked exactly, refutations by exact dual certificates,
compared with independent oracles (numpy eigenvalues, hand-built certificates)."""

from fractions import Fraction

import numpy as np
import pytest

from uvsym.errors import VerificationError
from uvsym.verify.lmi import _balance, block_lmi, dual_certificate, exact_positive_semidefinite, solve_block_lmi


def _check_dual_numerically(problem, Z):
    """The dual certificate's conditions in floating point, independently of the exact code."""
    Om = problem.float_omega()
    Z = np.array([[float(Fraction(v)) for v in row] for row in Z])
    assert np.linalg.eigvalsh(Z).min() >= -1e-12 and np.abs(Z).max() > 0
    M = Om @ Z + Z @ Om.T + 2 * float(problem.decay) * Z
    for i, (start, size) in enumerate(zip(problem.starts, problem.sizes)):
        block = slice(start, start + size)
        C = problem.float_output(i)
        if C.size:
            assert np.allclose(C @ Z[block, block], 0)
        assert np.linalg.eigvalsh(M[block, block]).min() >= -1e-9


def test_observable_pair_gets_a_gain_that_decays_faster_than_asked():
    A, C = np.array([[0.0, 1.0], [-2.0, -3.0]]), np.array([[1.0, 0.0]])
    gains, certificate = solve_block_lmi(block_lmi(A, [("e", C)], 4.0))
    assert certificate.status == "proved" and certificate.margin > 0
    assert np.linalg.eigvals(A - gains.K[0] @ C).real.max() < -4.0  # oracle: numpy eigenvalues
    # the certificate carries the gain and the Lyapunov matrix: P > 0 and He(P (A - K C)) + 8 P < 0 numerically
    K, P = np.array(certificate.details["K"][0]), np.array(certificate.details["P"][0])
    assert K.shape == (2, 1) and P.shape == (2, 2) and np.linalg.eigvalsh(P).min() > 0
    Q = P @ (A - K @ C)
    assert np.linalg.eigvalsh(Q + Q.T + 8.0 * P).max() < 0


def test_unobservable_unstable_mode_is_refuted_with_its_eigenvalue():
    A, C = np.array([[1.0, 0.0], [0.0, -3.0]]), np.array([[0.0, 1.0]])
    problem = block_lmi(A, [("e", C)], 0.0)
    gains, certificate = solve_block_lmi(problem, expected="refuted")
    assert gains is None and certificate.status == "refuted" and certificate.as_expected
    assert certificate.counterexample["modes"] == [{"block": "e", "eigenvalue": [1.0, 0.0]}]
    _check_dual_numerically(problem, certificate.counterexample["Z"])


def test_two_blocks_zero_mode_of_the_second_block_refutes_whatever_the_coupling():
    # block b = (speed, fault) measured as speed + 2 fault, no own dynamics: the direction (2, -1) is unseen
    Om = np.array([[-1.0, 5.0, 0.0], [3.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    problem = block_lmi(Om, [("a", [[Fraction(1)]]), ("b", [[Fraction(1), Fraction(2)]])])
    evidence = dual_certificate(problem)
    assert evidence is not None and {"block": "b", "eigenvalue": [0.0, 0.0]} in evidence["modes"]
    _check_dual_numerically(problem, evidence["Z"])
    # with a restoring term in the speed row the same structure is feasible
    Om[1, 1] = -1.0
    assert solve_block_lmi(block_lmi(Om, [("a", [[1.0]]), ("b", [[1.0, 2.0]])], 0.1))[1].status == "proved"


def test_coupled_problem_infeasible_only_jointly_is_refuted_by_the_dual_sdp():
    # each diagonal block alone is stable, but the skew coupling makes Omega unstable: [[-1, 3], [3, -1]]
    # has eigenvalues 2 and -4; with no measurement no gain helps
    problem = block_lmi(np.array([[-1.0, 3.0], [3.0, -1.0]]), [("a", np.zeros((1, 1))), ("b", np.zeros((1, 1)))])
    gains, certificate = solve_block_lmi(problem, expected="refuted")
    assert certificate.status == "refuted" and certificate.counterexample["source"].startswith("dual SDP")
    _check_dual_numerically(problem, certificate.counterexample["Z"])


def test_exact_semidefinite_agrees_with_eigenvalues_on_random_rational_matrices():
    rng = np.random.default_rng(3)
    for _ in range(40):
        G = rng.integers(-3, 4, size=(4, rng.integers(1, 5)))
        M = G @ G.T - (rng.integers(0, 2) * np.diag(rng.integers(0, 2, size=4)))
        exact = exact_positive_semidefinite([[Fraction(int(v)) for v in row] for row in M])
        assert exact == bool(np.linalg.eigvalsh(M.astype(float)).min() >= -1e-9)


@pytest.mark.parametrize("omega, blocks, decay, message", [
    (np.eye(3), [("e1", np.eye(2)), ("e2", [[1.0, 0.0]])], 0.0, "Omega must be \\(4, 4\\)"),
    (np.eye(2), [("e1", [[1.0]]), ("e1", [[1.0]])], 0.0, "distinct"),
    (np.eye(2), [("e1", [[np.nan]]), ("e2", [[1.0]])], 0.0, "block 'e1'.*finite"),
    (np.eye(2), [("e1", [[1.0]]), ("e2", "C")], 0.0, "block 'e2'"),
    (np.eye(2), [("e1", [[1.0]]), ("e2", [[1.0]])], -1.0, "decay must be >= 0"),
    (np.eye(2), [("e1", [[1.0]]), ("e2", [[1.0]])], float("inf"), "decay must be a finite number"),
    (np.eye(2), [("e1", [[1.0]]), ("e2", [[1.0]])], "fast", "decay must be a finite number"),
    (np.eye(2), [("e1", [[1.0]]), ("e2", np.zeros((0, 1)))], 0.0, "block 'e2'.*no rows"),
])
def test_mismatched_blocks_are_typed_errors_naming_the_block(omega, blocks, decay, message):
    with pytest.raises(VerificationError, match=message):
        block_lmi(omega, blocks, decay)


def test_ragged_rows_and_a_non_finite_omega_are_named():
    with pytest.raises(VerificationError, match=r"^block 'e1': output matrix C: rows of different lengths$"):
        block_lmi(np.eye(2), [("e1", [[Fraction(1)], [Fraction(1), Fraction(2)]])])
    with pytest.raises(VerificationError, match=r"^Omega must be finite"):
        block_lmi([[np.nan]], [("e1", [[1.0]])])


def test_dual_sdp_certificate_holds_at_the_decay_asked():
    """Omega = [[-2, 1.5], [1.5, -2]] (eigenvalues -0.5, -3.5), nothing measured, decay 0.6 > 0.5: infeasible.
    The block modes (-2) are faster than the decay, so only the dual SDP can certify; its Z must satisfy
    S_i = [Omega Z + Z Omega^T + 1.2 Z]_ii >= 0, i.e. Z_12 >= (2.8 / 3) Z_ii."""
    problem = block_lmi(np.array([[-2.0, 1.5], [1.5, -2.0]]), [("a", np.zeros((1, 1))), ("b", np.zeros((1, 1)))],
                        0.6)
    evidence = dual_certificate(problem)
    assert evidence is not None and evidence["source"] == "dual SDP (cvxpy, Clarabel), rounded"
    assert evidence["check"] == "Z >= 0, C_i Z_ii = 0, [Omega Z + Z Omega^T + 2 alpha Z]_ii >= 0 in exact rationals"
    Z = [[Fraction(v) for v in row] for row in evidence["Z"]]
    assert all(3 * Z[0][1] >= Fraction(28, 10) * Z[i][i] for i in range(2))
    _check_dual_numerically(problem, evidence["Z"])


def test_a_tiny_but_non_zero_measurement_has_no_dual_certificate():
    """Omega = 1, C = 1e-12: the gain K = 2e12 gives 1 - K C = -1, so the LMI is feasible and, by weak
    duality, no exact dual certificate exists, although the mode looks unobservable at the PBH tolerance."""
    assert dual_certificate(block_lmi([[1.0]], [("e", [[1e-12]])])) is None


def test_unroundable_unobservable_direction_is_inconclusive_with_method_and_reason():
    """Omega = 0.5 I, C = (1, 0.1): the unseen direction (-0.1, 1) makes the LMI infeasible, but a certificate
    needs Z = c v v^T with Z_12 / Z_22 the double -0.1 (denominator 2^55), which no rounding to denominators up
    to 10^9 gives: neither proved nor refuted."""
    gains, certificate = solve_block_lmi(block_lmi(0.5 * np.eye(2), [("e", [[1.0, 0.1]])]), "c",
                                         expected="refuted")
    assert gains is None and certificate.status == "inconclusive"
    assert certificate.expected == "refuted" and not certificate.as_expected
    assert certificate.method.startswith("block LMI (1 block) solved by cvxpy + Clarabel: no gain passed")
    assert certificate.reason == "neither a gain that passes the exact re-check nor a dual certificate was found"


def test_balancing_scales_by_powers_of_two_until_the_couplings_match():
    """Omega = [[0, 2^30], [1, 0]]: D^-1 Omega D has couplings 2^30 d1/d0 and d0/d1, equal for d0/d1 = 2^15."""
    D = _balance(block_lmi(np.array([[0.0, 2.0 ** 30], [1.0, 0.0]]), [("a", [[0.0]]), ("b", [[0.0]])]))
    assert D[0] / D[1] == 2.0 ** 15
    assert all(np.log2(d) == round(np.log2(d)) for d in D)


def test_a_mode_at_the_tolerance_edge_of_the_decay_is_still_tried():
    """Omega = [[0, 1], [0, -1e-9]], nothing measured, decay 0: modes at Re lambda >= -alpha - 1e-9 (scale 1)
    count, the edge included. Mode 0 gives Z = e1 e1^T (S = 0); mode -1e-9 has v = (1, -1e-9), whose
    v v^T rounds (denominator 1000) to the same e1 e1^T, so it certifies on its own as well."""
    evidence = dual_certificate(block_lmi([[0.0, 1.0], [0.0, -1e-9]], [("e", [[0.0, 0.0]])]))
    assert evidence["Z"] == [["1", "0"], ["0", "0"]]
    assert sorted(m["eigenvalue"][0] for m in evidence["modes"]) == [-1e-9, 0.0]


# --- dual candidates: edge cases (mutation survivors) ----------------------------------------------------------------


def test_a_dual_candidate_must_be_non_zero_and_semidefinite():
    """Omega = 1, nothing measured, decay 0: Z = 1 gives S = 2 Z = 2 >= 0 (a certificate); Z = 0 is the trivial
    point of every cone and Z = -1 is not semidefinite."""
    from uvsym.verify.lmi import _dual_holds
    problem = block_lmi([[1.0]], [("e", [[0.0]])], 0.0)
    assert _dual_holds(problem, [[Fraction(1)]])
    assert not _dual_holds(problem, [[Fraction(0)]]) and not _dual_holds(problem, [[Fraction(-1)]])


def test_a_mode_faster_than_the_decay_is_no_dual_candidate():
    """Omega = diag(0, -0.5), nothing measured, decay 0: only the mode 0 has Re lambda >= -alpha."""
    from uvsym.verify.lmi import _mode_candidates
    candidates = _mode_candidates(block_lmi(np.diag([0.0, -0.5]), [("e", [[0.0, 0.0]])], 0.0))
    assert [info["eigenvalue"] for _, info in candidates] == [[0.0, 0.0]]


def test_at_zero_decay_the_design_still_asks_for_a_strictly_positive_rate():
    """x' = -k x + ..., y = x, decay 0: the design at rate r needs 2 p (r - k) <= -1e-6 with p >= 1, so at the
    design rate 1e-6 the gain is k >= 1.5e-6 (at rate 0 alone, 5e-7 would do)."""
    gains, certificate = solve_block_lmi(block_lmi([[0.0]], [("e", [[1.0]])], 0.0))
    assert certificate.status == "proved" and gains.K[0][0, 0] > 1.4e-6
