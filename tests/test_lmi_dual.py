"""Block LMIs (uvsym.verify.lmi): input checks of block_lmi, the exact semidefinite test, the dual certificate's
products, candidates (block modes, dual SDP) and the balancing scaling, each against a hand-derived value."""

import warnings
from fractions import Fraction

import cvxpy as cp
import numpy as np
import pytest
import sympy

from uvsym.errors import VerificationError
from uvsym.verify.lmi import (
    CHECK,
    BlockLMI,
    _balance,
    _blkdiag_products,
    _mode_candidates,
    _rounded,
    _sdp_candidate,
    block_lmi,
    dual_certificate,
    exact_positive_semidefinite,
)

F = Fraction

# --- block_lmi: exact data and the errors that name the argument ---------------------------------------------------


def test_sympy_rationals_are_taken_exactly():
    R = sympy.Rational
    problem = block_lmi(sympy.Matrix([[R(1, 2), R(-3, 4)], [0, R(5, 3)]]), [("e", sympy.Matrix([[R(2, 3), 7]]))])
    assert problem.omega == ((F(1, 2), F(-3, 4)), (F(0), F(5, 3)))
    assert problem.outputs == (((F(2, 3), F(7)),),) and problem.sizes == (2,)


@pytest.mark.parametrize("omega, blocks, message", [
    (sympy.Matrix([[sympy.sqrt(2)]]), [("e", [[1.0]])], r"^Omega: a sympy matrix must hold rationals only$"),
    ([[1.0]], [("e", [[1 + 2j]])], r"^block 'e': output matrix C must be a numeric matrix, got list$"),
    ([[1.0]], [("e", [[1.0, "x"]])], r"^block 'e': output matrix C must be a numeric matrix, got list$"),
    ([[1.0]], [("e", [1.0])], r"^block 'e': output matrix C must be a 2-D matrix, got shape \(1,\)$"),
    ([[1.0]], [("", [[1.0]])], r"^blocks need distinct non-empty names, got \[''\]$"),
    ([[1.0]], [(1, [[1.0]])], r"^blocks need distinct non-empty names, got \[1\]$"),
    (np.eye(2), [("e1", [[1.0]]), ("e2", [[]])], r"^blocks \['e2'\] have no columns \(their size\)$"),
    (np.eye(2), [("e1", [[1.0]]), ("e2", sympy.zeros(0, 0))], r"^blocks \['e2'\] have no columns \(their size\)$"),
    ([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [("e1", [[1.0]]), ("e2", [[1.0]])],
     r"^Omega must be \(2, 2\) for blocks \{'e1': 1, 'e2': 1\}, got \(2, 3\)$"),
    (sympy.zeros(0, 0), [("e1", [[1.0]]), ("e2", [[1.0]])],
     r"^Omega must be \(2, 2\) for blocks \{'e1': 1, 'e2': 1\}, got \(0, 0\)$"),
])
def test_bad_block_data_is_a_typed_error_with_its_message(omega, blocks, message):
    with pytest.raises(VerificationError, match=message):
        block_lmi(omega, blocks)


# --- exact products and rounding ------------------------------------------------------------------------------------


def test_a_non_symmetric_matrix_is_not_semidefinite_even_if_its_symmetric_part_is():
    """[[1, 2], [0, 1]] has the symmetric part [[1, 1], [1, 1]] >= 0, but only symmetric matrices qualify."""
    assert exact_positive_semidefinite([[F(1), F(1)], [F(1), F(1)]])
    assert not exact_positive_semidefinite([[F(1), F(2)], [F(0), F(1)]])


def test_dual_products_by_hand():
    """Omega = [[1, 2], [3, 4]], C = (1, 1), decay 1/2, Z = [[2, 1], [1, 3]]: Omega Z = [[4, 7], [10, 15]],
    S = Omega Z + Z Omega^T + Z = [[10, 18], [18, 33]], C Z = (3, 4)."""
    problem = block_lmi([[1.0, 2.0], [3.0, 4.0]], [("e", [[1.0, 1.0]])], 0.5)
    CZ, S = _blkdiag_products(problem, [[F(2), F(1)], [F(1), F(3)]])
    assert S == [[[F(10), F(18)], [F(18), F(33)]]] and CZ == [[[F(3), F(4)]]]


def test_rounding_symmetrises_and_scales_to_a_largest_entry_of_one():
    """[[2, 1], [0, 4]]: symmetric part [[2, 1/2], [1/2, 4]], divided by 4."""
    assert _rounded(np.array([[2.0, 1.0], [0.0, 4.0]]), 1000) == [[F(1, 2), F(1, 8)], [F(1, 8), F(1)]]


# --- block-mode candidates: tolerances scale with the block's and the sensor's largest entry ------------------------


def _eigenvalues(problem):
    return [info["eigenvalue"] for _, info in _mode_candidates(problem)]


def test_mode_tolerances_are_relative_to_at_least_one():
    """One state, Omega = 0: the PBH residual is |C|, unobservable at the tolerance 1e-9 (scale max(1, |C|) = 1)
    only strictly below it; a mode at -1.5e-9 is faster than -alpha - 1e-9 whatever is measured."""
    assert _eigenvalues(block_lmi([[0.0]], [("e", [[1e-10]])])) == [[0.0, 0.0]]
    assert _eigenvalues(block_lmi([[0.0]], [("e", [[1e-9]])])) == []
    assert _eigenvalues(block_lmi([[-1.5e-9]], [("e", [[0.0]])])) == []
    assert _eigenvalues(block_lmi([[-1e-9]], [("e", [[0.0]])])) == [[-1e-9, 0.0]]


def test_a_block_with_no_output_rows_uses_scale_one():
    """A BlockLMI built directly with an empty C_i (no injection): the mode 0 counts, -1.5e-9 does not."""
    def problem(value):
        return BlockLMI(("e",), ((F(value),),), ((),), (1,), F(0))
    assert _eigenvalues(problem(0.0)) == [[0.0, 0.0]]
    assert _eigenvalues(problem(-1.5e-9)) == []


@pytest.mark.parametrize("omega, C", [
    (np.diag([-5e-7, 1000.0]), [[0.0, 1.0]]),  # scale 1000 from the block: the edge is -1e-6
    (np.diag([-5e-7, -1.0]), [[0.0, 1000.0]]),  # scale 1000 from the sensor
])
def test_the_decay_edge_grows_with_the_largest_entry(omega, C):
    """The unmeasured mode -5e-7 is within 1e-9 * 1000 of the decay 0, so it is a candidate; the others are either
    measured (1000) or faster (-1)."""
    assert _eigenvalues(block_lmi(omega, [("e", C)])) == [[-5e-7, 0.0]]


def test_the_pbh_tolerance_grows_with_the_largest_entry():
    """Omega = diag(0, 1000), C = (1e-8, 0): at lambda = 0 the smallest singular value is 1e-8 < 1e-9 * 1000."""
    assert [0.0, 0.0] in _eigenvalues(block_lmi(np.diag([0.0, 1000.0]), [("e", [[1e-8, 0.0]])]))


def test_modes_slower_than_the_decay_count_and_a_fast_mode_does_not_stop_the_search():
    """Decay 1: the mode 0 has Re lambda >= -1. Omega = diag(-0.5, 0) at decay 0: -0.5 is skipped, 0 still found."""
    assert _eigenvalues(block_lmi([[0.0]], [("e", [[0.0]])], 1.0)) == [[0.0, 0.0]]
    assert _eigenvalues(block_lmi(np.diag([-0.5, 0.0]), [("e", [[0.0, 0.0]])])) == [[0.0, 0.0]]


def test_a_mode_direction_is_scaled_to_a_largest_entry_of_one():
    """Omega = 0 (2x2), C = (2, -1): the unseen direction is (1, 2), scaled to (1/2, 1): Z = [[1/4, 1/2], [1/2, 1]]."""
    candidates = _mode_candidates(block_lmi(np.zeros((2, 2)), [("e", [[2.0, -1.0]])]))
    assert len(candidates) == 2  # the double eigenvalue 0, once per eigenvalue
    for Z, _ in candidates:
        assert np.allclose(Z, [[0.25, 0.5], [0.5, 1.0]], atol=1e-12)


# --- dual certificates: which source, and none when the LMI is feasible ---------------------------------------------


def test_a_failing_mode_does_not_stop_the_search_for_one_that_certifies():
    """Block a (Omega_aa = 0.5 I, C = (1, 0.1)) has an unseen direction that no rounding makes exact; block b
    (Omega_bb = 1, unmeasured) certifies with Z = e3 e3^T (S_b = 2 >= 0)."""
    omega = np.zeros((3, 3))
    omega[0, 0] = omega[1, 1] = 0.5
    omega[2, 2] = 1.0
    evidence = dual_certificate(block_lmi(omega, [("a", [[1.0, 0.1]]), ("b", [[0.0]])]))
    assert evidence == {"Z": [["0", "0", "0"], ["0", "0", "0"], ["0", "0", "1"]],
                        "modes": [{"block": "b", "eigenvalue": [1.0, 0.0]}],
                        "source": "modes that no gain moves (PBH)",
                        "check": "Z >= 0, C_i Z_ii = 0, [Omega Z + Z Omega^T + 2 alpha Z]_ii >= 0 in exact rationals"}


def test_a_dual_sdp_certificate_lists_no_modes():
    """[[-1, 3], [3, -1]] unmeasured: unstable only jointly (eigenvalue 2), so the dual SDP certifies, no mode."""
    evidence = dual_certificate(block_lmi(np.array([[-1.0, 3.0], [3.0, -1.0]]), [("a", [[0.0]]), ("b", [[0.0]])]))
    assert evidence["modes"] == [] and evidence["source"] == "dual SDP (cvxpy, Clarabel), rounded"
    assert evidence["check"] == CHECK
    # Z itself, in rationals: symmetric, >= 0, nonzero, and the 1x1 diagonal blocks of Omega Z + Z Omega^T >= 0
    (z11, z12), (z21, z22) = [[Fraction(v) for v in row] for row in evidence["Z"]]
    assert z12 == z21 and z11 >= 0 and z22 >= 0 and z11 * z22 >= z12**2 and (z11, z22) != (0, 0)
    assert -z11 + 3 * z12 >= 0 and 3 * z12 - z22 >= 0


def test_a_stable_unmeasured_state_has_no_certificate_and_no_sdp_candidate():
    """Omega = -1, nothing measured: P = 1 proves the LMI, so the dual SDP (S = -2 Z >= 0, tr Z = 1) is infeasible."""
    problem = block_lmi([[-1.0]], [("e", [[0.0]])])
    assert _sdp_candidate(problem) is None
    assert dual_certificate(problem) is None


def test_the_sdp_candidate_is_symmetric_with_unit_trace():
    """Omega = [[-2, 1.5], [1.5, -2]], unmeasured, decay 0.6: the dual SDP is feasible (eigenvalue -0.5 > -0.6);
    its Z is normalised by tr Z = 1 and is a symmetric matrix variable."""
    Z = _sdp_candidate(block_lmi(np.array([[-2.0, 1.5], [1.5, -2.0]]), [("a", [[0.0]]), ("b", [[0.0]])], 0.6))
    assert Z.shape == (2, 2) and np.array_equal(Z, Z.T)
    assert abs(np.trace(Z) - 1.0) < 1e-6


def test_the_dual_sdp_uses_clarabel_and_silences_only_its_inaccuracy_warning(monkeypatch):
    """The source says Clarabel; the solver's "Solution may be inaccurate" is not shown, any other warning is."""
    seen = {}

    def fake_solve(self, *args, **kwargs):
        seen.update(kwargs)
        warnings.warn("Solution may be inaccurate. Try another solver, adjusting the solver settings, or solve with "
                      "verbose=True for more information.", UserWarning, stacklevel=2)
        warnings.warn("an unrelated warning", UserWarning, stacklevel=2)

    monkeypatch.setattr(cp.Problem, "solve", fake_solve)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert _sdp_candidate(block_lmi([[1.0]], [("e", [[0.0]])])) is None  # no solution set
    assert [str(w.message) for w in caught] == ["an unrelated warning"]
    assert seen == {"solver": cp.CLARABEL}


# --- balancing ------------------------------------------------------------------------------------------------------


def test_balancing_is_clipped_to_two_to_the_twenty():
    """Omega = [[0, 2^80], [1, 0]] would need d0 / d1 = 2^40 (couplings 2^80 d1/d0 = d0/d1); the scaling stays in
    [2^-20, 2^20]. The transpose needs d0 / d1 = 2^-40."""
    blocks = [("a", [[0.0]]), ("b", [[0.0]])]
    assert _balance(block_lmi(np.array([[0.0, 2.0 ** 80], [1.0, 0.0]]), blocks)).tolist() == [2.0 ** 20, 1.0]
    assert _balance(block_lmi(np.array([[0.0, 1.0], [2.0 ** 80, 0.0]]), blocks)).tolist() == [2.0 ** -20, 1.0]


def test_balancing_keeps_each_state_in_place():
    """State 0 is decoupled; states 1 and 2 have couplings 2^30 d2/d1 and d1/d2, equal for d1/d2 = 2^15.
    (A permutation that isolates state 0 must not move the scale factors to other states.)"""
    omega = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 2.0 ** 30], [0.0, 1.0, 0.0]])
    D = _balance(block_lmi(omega, [("a", [[0.0]]), ("b", [[0.0]]), ("c", [[0.0]])]))
    assert D[0] == 1.0 and D[1] / D[2] == 2.0 ** 15


@pytest.mark.parametrize("c0", [0.0, 1.0])
def test_balancing_counts_omega_diagonal_plus_the_sensor_gain(c0):
    """Omega = [[1, 2^11], [0, 0]], C_0 = c0: the matrix balanced is S = Omega + diag(max |C_i|), whose state 0
    has a non-zero row and column (the diagonal 1 + c0); after balancing its row and column norms are within a
    factor 4 (unbalanced: 2^11 against 1 + c0)."""
    omega = np.array([[1.0, 2.0 ** 11], [0.0, 0.0]])
    D = _balance(block_lmi(omega, [("a", [[c0]]), ("b", [[0.0]])]))
    S = omega + np.diag([c0, 0.0])
    B = S * D[None, :] / D[:, None]
    assert np.linalg.norm(B[0]) < 4 * np.linalg.norm(B[:, 0])
