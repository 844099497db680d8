"""Unknown-input observer: design against hand derivations and simulation, typed condition errors,
bank decoupling, zonotope bands, exact existence claims."""

from __future__ import annotations

import time
from fractions import Fraction

import numpy as np
import pytest
from scipy.linalg import expm

from uvsym.errors import ModelError, ObserverError, SetDivergenceError, SetError, UIOConditionError
from uvsym.observers.uio import uio_conditions, uio_matrices, uio_observer, unobservable_modes
from uvsym.observers.uio_bank import isolate, outside_band, residual_bands, uio_bank
from uvsym.systems import signals
from uvsym.testing import assert_proved, assert_refuted
from uvsym.verify.uio import exact_zoh, uio_existence_claim

A3 = np.array([[0.9, 0.1, 0.2], [0.0, 0.8, 0.2], [0.1, 0.0, 0.7]])
B3 = np.array([[1.0], [0.0], [0.5]])
D3 = np.array([[0.0], [1.0], [0.0]])
C3 = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
H = 0.01  # s


def _double_integrator():
    """Sampled double integrator with the input as unknown input: G, D (hand ZOH)."""
    return np.array([[1.0, H], [0.0, 1.0]]), np.array([[H ** 2 / 2], [H]])


def _group(prefix: str, n: int, group: str):
    return signals(*((f"{prefix}{i}", "-") for i in range(n)), group=group)


def test_design_satisfies_the_decoupling_identities_and_places_the_poles():
    poles = [0.2, 0.3, 0.4]
    d = uio_matrices(A3, B3, C3, D3, poles=poles)
    np.testing.assert_allclose(d.M @ C3 @ D3, np.eye(1), atol=1e-12)
    np.testing.assert_allclose(d.T @ D3, 0, atol=1e-12)
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(d.F).real), poles, atol=1e-9)
    np.testing.assert_allclose(d.F, d.T @ A3 - d.K1 @ C3, atol=1e-12)
    np.testing.assert_allclose(d.K, d.K1 + d.F @ d.Q, atol=1e-12)


def test_observer_error_is_F_to_the_k_whatever_the_unknown_input():
    """Plant driven by a large random unknown input; the Observer's CasADi step gives e_k = F^k e_0."""
    d = uio_matrices(A3, B3, C3, D3, poles=[0.2, 0.3, 0.4])
    obs = uio_observer(d, states=_group("x", 3, "state"), outputs=_group("y", 2, "output"),
                       inputs=_group("u", 1, "input"), dt=H)
    rng = np.random.default_rng(0)
    N = 30
    x = np.zeros((N, 3))
    x[0] = [0.3, -0.2, 0.5]
    u, dist = rng.normal(size=(N, 1)), 100 * rng.normal(size=(N, 1))
    for k in range(N - 1):
        x[k + 1] = A3 @ x[k] + B3 @ u[k] + D3 @ dist[k]
    Y = x @ C3.T
    _, out = obs.run(Y, u)
    xhat, residual = out[:, :3], out[:, 3:]
    e0 = x[0] - xhat[0]
    np.testing.assert_allclose(xhat[0], 0.0 + 0 * e0)  # starts at the prior 0
    for k in range(N):
        np.testing.assert_allclose(x[k] - xhat[k], np.linalg.matrix_power(d.F, k) @ e0, atol=1e-9)
    np.testing.assert_allclose(residual, (x - xhat) @ C3.T, atol=1e-9)


def test_sampling_zero_makes_the_angle_only_observer_fail_with_its_eigenvalue():
    """Hand derivation: T G = [[0, 0], [-2/h, -1]], eigenvalue -1 with eigenvector (0, 1), C v = 0."""
    G, D = _double_integrator()
    with pytest.raises(UIOConditionError, match="not detectable") as info:
        uio_conditions(G, [[1.0, 0.0]], D)
    assert info.value.eigenvalues and abs(info.value.eigenvalues[0] + 1) < 1e-9
    h = Fraction(1, 100)  # exact sampling: T G = [[0, 0], [-b/a, 1 - b h/a]] for D = (a, b) = (h^2/2, h)
    exact_G, exact_D = [[Fraction(1), h], [Fraction(0), Fraction(1)]], [[h * h / 2], [h]]
    claim = uio_existence_claim("double integrator, position only", exact_G, [[1.0, 0.0]], exact_D,
                                expected="refuted")
    assert_refuted(claim)
    assert claim.counterexample["unobservable_eigenvalue"] == -1.0
    assert claim.counterexample["eigenvector"][0] == 0.0
    # the doubles as given: a = fl(fl(0.01^2)/2), b = 0.01, so 1 - b h/a = -1 + 1.26e-17 exactly (Fraction by
    # hand), inside the unit circle: no exact eigenvector at -1 exists, the claim must not be refuted
    assert uio_existence_claim("doubles", G.tolist(), [[1.0, 0.0]], D.tolist()).status != "refuted"


def test_rank_condition_failure_names_the_ranks():
    with pytest.raises(UIOConditionError, match=r"rank\(C D\) = 0 but rank\(D\) = 1") as info:
        uio_conditions(np.eye(2) * 0.5, [[0.0, 1.0]], [[1.0], [0.0]])
    assert info.value.ranks == (0, 1)
    assert_refuted(uio_existence_claim("C D = 0", np.eye(2) * 0.5, [[0.0, 1.0]], [[1.0], [0.0]], expected="refuted"))


def test_full_measurement_existence_is_proved_exactly():
    G, D = _double_integrator()
    d = uio_matrices(G, D, np.eye(2), D, poles=[0.5, 0.6])
    assert_proved(uio_existence_claim("double integrator, both states", G, np.eye(2), D, K1=d.K1))


def test_exact_zoh_matches_scipy_on_a_chain_of_integrators():
    A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    B = np.array([[0.0], [0.0], [2.0]])
    Ad, Bd = exact_zoh(A, B, Fraction(1, 100))
    reference = expm(np.block([[A, B], [np.zeros((1, 4))]]) * 0.01)
    np.testing.assert_allclose(np.array(Ad, dtype=float), reference[:3, :3], rtol=1e-14)
    np.testing.assert_allclose(np.array(Bd, dtype=float), reference[:3, 3:], rtol=1e-14)
    assert Ad[0][2] == Fraction(1, 20000)


def test_poles_that_cannot_be_placed_are_an_error():
    """(C, T A) detectable but not observable: x3 never reaches the outputs (eigenvalue 0.7)."""
    A = np.array([[0.9, 0.1, 0.0], [0.0, 0.8, 0.2], [0.1, 0.0, 0.7]])
    with pytest.raises(ObserverError, match="cannot be placed"):
        uio_matrices(A, B3, C3, D3, poles=[0.2, 0.3, 0.4])


def test_bad_designs_are_typed_errors():
    with pytest.raises(ObserverError, match="C must be"):
        uio_matrices(A3, B3, np.eye(2), D3, poles=[0.1, 0.2, 0.3])
    with pytest.raises(ObserverError, match="finite"):
        uio_matrices(A3, B3, C3, [[0.0], [np.nan], [0.0]], poles=[0.1, 0.2, 0.3])
    with pytest.raises(ObserverError, match="exactly one of poles"):
        uio_matrices(A3, B3, C3, D3)
    with pytest.raises(ObserverError, match="not stable"):
        uio_matrices(A3, B3, C3, D3, K1=np.zeros((3, 2)) - 5.0)
    with pytest.raises(ObserverError, match="unknown time domain"):
        uio_conditions(A3, C3, D3, time="hybrid")


def test_continuous_conditions_use_the_left_half_plane():
    A = np.array([[0.0, 1.0], [0.0, 0.0]])
    with pytest.raises(UIOConditionError, match="Re lambda >= 0"):
        uio_conditions(A, [[1.0, 0.0]], [[1.0], [0.0]], time="continuous")


def test_bank_observer_i_ignores_actuator_i_only():
    rng = np.random.default_rng(2)
    A, B = np.eye(4) * 0.9 + 0.05 * rng.normal(size=(4, 4)), rng.normal(size=(4, 3))
    D = rng.normal(size=(4, 1))
    bank = uio_bank(A, B, np.eye(4), D, [0.3, 0.4, 0.5, 0.6], states=_group("x", 4, "state"),
                    outputs=_group("y", 4, "output"), inputs=_group("u", 3, "input"), dt=H)
    assert bank.decoupled == ("u0", "u1", "u2")
    for i, d in enumerate(bank.designs):
        for j in range(3):
            effect = np.linalg.norm(d.C @ d.T @ B[:, j])
            assert (effect < 1e-10) if i == j else (effect > 1e-3)


def test_bands_enclose_sampled_residuals_and_reject_bad_bounds():
    d = uio_matrices(A3, B3, np.eye(3), D3, poles=[0.2, 0.3, 0.4])
    vbar, ebar = np.array([0.01, 0.02, 0.01]), np.full(3, 0.05)
    bands = residual_bands(d, vbar, ebar, 40, generators=24)
    rng = np.random.default_rng(3)
    runs = 50
    e = rng.uniform(-1, 1, (3, runs)) * ebar[:, None]
    v = rng.choice([-1.0, 1.0], (40, 3, runs)) * vbar[None, :, None]
    residuals = np.zeros((40, 3, runs))
    for k in range(40):  # e_{k+1} = F e_k - K1 v_k - Q v_{k+1}, r_k = C e_k + v_k (hand derivation)
        if k:
            e = d.F @ e - d.K1 @ v[k - 1] - d.Q @ v[k]
        else:
            e = e - d.Q @ v[0]
        residuals[k] = d.C @ e + v[k]
    assert not outside_band(residuals, bands).any()
    assert outside_band(residuals + 10 * vbar[None, :, None], bands).all()
    assert isolate(np.array([[False, True], [False, False]]), ["a", "b"], 0, 2) == ["a"]
    with pytest.raises(SetError, match="noise bound"):
        residual_bands(d, [0.01, np.nan, 0.01], ebar, 10, 24)
    with pytest.raises(SetError, match="noise bound must be finite"):  # an unbounded channel
        residual_bands(d, [0.01, np.inf, 0.01], ebar, 10, 24)
    with pytest.raises(SetError, match="non-negative"):
        residual_bands(d, [0.01, -0.01, 0.01], ebar, 10, 24)
    with pytest.raises(SetError, match=r"^initial error bound must be non-negative, got \[0.05, -0.05, 0.05\]$"):
        residual_bands(d, vbar, [0.05, -0.05, 0.05], 10, 24)
    with pytest.raises(SetError, match="initial error bound"):
        residual_bands(d, vbar, [0.1, 0.1], 10, 24)
    with pytest.raises(SetError, match="dimension 6"):
        residual_bands(d, vbar, ebar, 10, 4)


def _small_observer(**options):
    d = uio_matrices(A3, B3, C3, D3, poles=[0.2, 0.3, 0.4])
    groups = {"states": _group("x", 3, "state"), "outputs": _group("y", 2, "output"),
              "inputs": _group("u", 1, "input")}
    return d, uio_observer(d, **{**groups, **options}, dt=H)


def test_observer_signal_names_and_description():
    _, obs = _small_observer(name="bank_a")
    assert obs.state.names == ("z_x0", "z_x1", "z_x2")
    assert obs.publishes.names == ("x0_hat", "x1_hat", "x2_hat", "r_y0", "r_y1")
    assert obs.description == ("unknown-input observer decoupling 1 direction(s): "
                               "z+ = F z + J u + K y, xhat = z + Q y")


def test_observer_refuses_a_bad_name_and_signals_of_the_wrong_size_word_for_word():
    with pytest.raises(ObserverError, match=r"^observer name '2uio' must start with a letter"):
        _small_observer(name="2uio")
    d = uio_matrices(A3, B3, C3, D3, poles=[0.2, 0.3, 0.4])
    with pytest.raises(ObserverError, match=r"^uio: outputs has 3 signals, the design 2$"):
        uio_observer(d, states=_group("x", 3, "state"), outputs=_group("y", 3, "output"),
                     inputs=_group("u", 1, "input"), dt=H)


def test_matrix_errors_name_the_matrix():
    with pytest.raises(ObserverError, match=r"^UIO: A must be a numeric matrix, got str$"):
        unobservable_modes("A", C3)
    with pytest.raises(ObserverError, match=r"^UIO: A must be square, got shape \(2, 3\)$"):
        uio_conditions(np.ones((2, 3)), C3, D3)
    with pytest.raises(ObserverError, match=r"^UIO: K1 must be a \(3, 2\) matrix, got shape \(3, 3\)$"):
        uio_matrices(A3, B3, C3, D3, K1=np.zeros((3, 3)))


def test_rank_tolerance_is_relative_to_the_largest_singular_value():
    """A = diag(1e10, 1), C = (0, 1e-3): at lambda = 1, [A - I; C] has singular values 1e10 - 1 and 1e-3,
    a ratio of 1e-13 < 1e-9, so the mode counts as unobservable (as does 1e10, which C never sees)."""
    modes = unobservable_modes(np.diag([1e10, 1.0]), [[0.0, 1e-3]])
    assert sorted(m.real for m in modes) == [1.0, 1e10]


def test_bank_errors_name_the_matrix_or_the_actuator():
    groups = {"states": _group("x", 3, "state"), "outputs": _group("y", 2, "output"), "dt": H}
    with pytest.raises(ObserverError, match=r"^uio: B has 1 columns but 2 inputs are named$"):
        uio_bank(A3, B3, C3, D3, [0.1, 0.2, 0.3], inputs=_group("u", 2, "input"), **groups)
    with pytest.raises(ObserverError, match=r"^UIO: B must be a numeric matrix, got str$"):
        uio_bank(A3, "B", C3, D3, [0.1, 0.2, 0.3], inputs=_group("u", 1, "input"), **groups)
    with pytest.raises(ObserverError, match=r"^UIO: D must be a \(3, any\) matrix, got shape \(2, 1\)$"):
        uio_bank(A3, B3, C3, [1.0, 0.0], [0.1, 0.2, 0.3], inputs=_group("u", 1, "input"), **groups)
    # decoupling [D, B_0] = [e1, e3] from y = (x1, x2): rank(C [e1 e3]) = 1, rank([e1 e3]) = 2
    with pytest.raises(UIOConditionError, match=r"^bank, observer decoupling u0: UIO: rank\(C D\) = 1 but "
                                                r"rank\(D\) = 2: ") as info:
        uio_bank(0.5 * np.eye(3), [[0.0], [0.0], [1.0]], C3, [1.0, 0.0, 0.0], [0.1, 0.2, 0.3], name="bank",
                 inputs=_group("u", 1, "input"), **groups)
    assert info.value.ranks == (1, 2)


def test_bands_keep_the_reduction_maps_and_stop_a_wrapping_rotation_at_ten_times():
    d = uio_matrices(A3, B3, np.eye(3), D3, poles=[0.2, 0.3, 0.4])
    bands = residual_bands(d, [0.01] * 3, [0.05] * 3, 5, generators=24)
    assert len(bands.reductions) == 4  # one coefficient map per step after the first
    r = 0.95 * np.exp(0.3j)
    rotation = uio_matrices(A3, B3, np.eye(3), D3, poles=[r, r.conjugate(), 0.1])
    with pytest.raises(SetDivergenceError, match=r"exceeds 10 times the exact set's"):
        residual_bands(rotation, [0.01] * 3, [0.05] * 3, 40, generators=6)


def test_claim_fields_say_where_how_and_why():
    G, D = _double_integrator()
    d = uio_matrices(G, D, np.eye(2), D, poles=[0.5, 0.6])
    proved = uio_existence_claim("both states", G, np.eye(2), D, K1=d.K1)
    assert proved.set == "the matrices' double entries taken as exact rationals"
    assert proved.method == ("exact rank (fraction elimination); T D = 0 exactly; F = T G - K1 C Schur stable by "
                             "a discrete Lyapunov certificate (X from scipy, exact rational LDL^T)")
    assert proved.details.keys() == {"rank_CD", "spectral_radius_F"} and proved.details["rank_CD"] == 1
    assert proved.details["spectral_radius_F"] == pytest.approx(0.6, abs=1e-9)  # the largest pole placed
    refuted = uio_existence_claim("C D = 0", np.eye(2) * 0.5, [[0.0, 1.0]], [[1.0], [0.0]], set_description="s",
                                  expected="refuted")
    assert refuted.set == "s" and refuted.counterexample == {"rank_CD": 0, "rank_D": 1}
    # every state measured, so nothing is unobservable, but K1 = 0 leaves G1 = diag(1.5, 0) unstable
    stuck = uio_existence_claim("no gain", np.diag([1.5, 0.5]), np.eye(2), [[0.0], [1.0]], K1=np.zeros((2, 2)),
                                expected="inconclusive")
    assert stuck.status == "inconclusive"
    assert stuck.reason == "neither a certified gain nor an exact unobservable eigenvector with |lambda| >= 1 was found"


def test_claim_takes_a_nested_list_of_doubles_exactly():
    """D = (0.1, 0.3) as a list: in double arithmetic T D is not exactly 0; taken exactly it is, and
    T G has the eigenvalue 0 (T projects out D) and one below 1 with K1 = 0 and C = I: proved."""
    G, D = [[1.0, 0.01], [0.0, 1.0]], [[0.1], [0.3]]
    listed = uio_existence_claim("listed", G, [[1.0, 0.0], [0.0, 1.0]], D, K1=np.zeros((2, 2)))
    assert listed.status == "proved"
    assert listed.margin == uio_existence_claim("array", np.array(G), np.eye(2), np.array(D),
                                                K1=np.zeros((2, 2))).margin


def test_bank_decouples_every_column_of_a_two_column_disturbance():
    """D (4, 2) and one actuator: each observer decouples [D B_i], three directions, T [D B_i] = 0."""
    rng = np.random.default_rng(4)
    A, B, D = np.eye(4) * 0.9 + 0.05 * rng.normal(size=(4, 4)), rng.normal(size=(4, 1)), rng.normal(size=(4, 2))
    bank = uio_bank(A, B, np.eye(4), D, [0.3, 0.4, 0.5, 0.6], states=_group("x", 4, "state"),
                    outputs=_group("y", 4, "output"), inputs=_group("u", 1, "input"), dt=H)
    (design,) = bank.designs
    assert design.D.shape == (4, 3)
    np.testing.assert_allclose(design.T @ np.hstack([D, B]), 0, atol=1e-12)


def test_a_placement_accurate_relative_to_a_large_plant_is_accepted():
    """T A of norm ~1e3: placed eigenvalues are only accurate to ~1e-10 ||T A|| (backward-stable eigvals), i.e.
    ~1e-7 absolute near poles of 1e-3; that is a placement, not a failure, within the check's 1e-6."""
    d = uio_matrices(1000 * A3, B3, C3, D3, poles=[1e-3, -1e-3, 0.0])
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(d.F).real), [-1e-3, 0.0, 1e-3], rtol=0, atol=1e-6)


def test_observer_starts_at_the_prior_and_names_a_wrong_state_count():
    """xhat_0 = z_0 + Q y_0 = (prior - Q y_0) + Q y_0 = prior, whatever y_0 is."""
    prior = [0.3, -0.2, 0.5]
    _, obs = _small_observer(prior=prior)
    _, out = obs.run(np.array([[1.0, 2.0], [0.5, -1.0]]), np.zeros((2, 1)))
    np.testing.assert_allclose(out[0, :3], prior, atol=1e-12)
    d = uio_matrices(A3, B3, C3, D3, poles=[0.2, 0.3, 0.4])
    with pytest.raises(ObserverError, match=r"^uio: states has 2 signals, the design 3$"):
        uio_observer(d, states=_group("x", 2, "state"), outputs=_group("y", 2, "output"),
                     inputs=_group("u", 1, "input"), dt=H)


def test_bank_observers_are_named_after_their_actuator():
    B = np.array([[1.0, 0.0], [0.0, 0.0], [0.5, 1.0]])
    bank = uio_bank(A3, B, np.eye(3), D3, [0.1, 0.2, 0.3], states=_group("x", 3, "state"),
                    outputs=_group("y", 3, "output"), inputs=_group("u", 2, "input"), dt=H, name="bank")
    assert tuple(obs.name for obs in bank.observers) == ("bank_u0", "bank_u1")


def test_zero_noise_bands_are_the_initial_error_through_F_and_the_tolerance_scales_with_the_width():
    """C = I. With vbar = 0: r_k = F^k e_0, hull +-|F^k| ebar (no reduction in 5 steps of 3 generators).
    r_0 = e_0 + v_0: hull +-(ebar + vbar) = +-0.06, width 0.12, so tolerance 0.1 allows 0.1 * 1.12 beyond it."""
    d = uio_matrices(A3, B3, np.eye(3), D3, poles=[0.2, 0.3, 0.4])
    ebar = np.array([0.05, 0.02, 0.01])
    quiet = residual_bands(d, np.zeros(3), ebar, 5, generators=24)
    for k in range(5):
        radius = np.abs(np.linalg.matrix_power(d.F, k)) @ ebar
        np.testing.assert_allclose(quiet.upper[k], radius, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(quiet.lower[k], -radius, rtol=1e-12, atol=1e-15)
    with pytest.raises(SetError, match=r"^noise bound must be non-negative, got \[0\.01, -0\.01, 0\.01\]$"):
        residual_bands(d, [0.01, -0.01, 0.01], ebar, 10, 24)
    bands = residual_bands(d, [0.01] * 3, [0.05] * 3, 1, generators=24)
    np.testing.assert_allclose(bands.upper[0], [0.06] * 3, rtol=1e-12)
    r = np.array([[0.165, 0.0, -0.165], [0.18, 0.0, 0.0], [0.0, -0.18, 0.0]])[:, :, None]
    assert outside_band(r[:1], bands, tolerance=0.1).tolist() == [[False]]  # 0.165 < 0.06 + 0.112
    for row in r[1:]:
        assert outside_band(row[None], bands, tolerance=0.1).tolist() == [[True]]  # 0.18 > 0.172


def test_residuals_that_are_not_numbers_are_a_typed_error():
    d = uio_matrices(A3, B3, np.eye(3), D3, poles=[0.2, 0.3, 0.4])
    bands = residual_bands(d, [0.01] * 3, [0.05] * 3, 2, generators=24)
    with pytest.raises(SetError, match=r"^residuals must be numbers in an \(N, p\[, runs\]\) array, got \[\['a'"):
        outside_band([["a", "b", "c"]], bands)
    with pytest.raises(SetError, match=r"^residuals must be numbers"):
        outside_band([[0.0, 0.0, 0.0], [0.0]], bands)


def test_claim_margins_methods_evidence_and_time_are_stated():
    """Proved: G1 = T G = diag(0.5, 0) (T = diag(1, 0) removes D = e2), K1 = 0, F = G1: X = diag(4/3, 1) and
    X - F^T X F = I, smallest LDL^T pivot 1. Refuted: G = diag(2, 0.5) gives G1 = diag(2, 0), the eigenvalue 2
    with v = e1 and C v = 0 for C = (0, 1): margin 1 - 2 = -1."""
    before = time.perf_counter()
    proved = uio_existence_claim("stable", np.diag([0.5, 0.5]), np.eye(2), [[0.0], [1.0]], K1=np.zeros((2, 2)))
    elapsed = time.perf_counter() - before
    assert proved.status == "proved" and proved.margin == pytest.approx(1.0, abs=1e-12)
    assert 0.0 <= proved.seconds <= elapsed
    refuted = uio_existence_claim("unstable", np.diag([2.0, 0.5]), [[0.0, 1.0]], [[0.0], [1.0]], expected="refuted")
    assert refuted.status == "refuted" and refuted.margin == -1.0
    assert refuted.method == "PBH test in exact rationals: G1 v = lambda v and C v = 0 for |lambda| >= 1"
    assert refuted.counterexample == {"unobservable_eigenvalue": 2.0, "eigenvalue_modulus": 2.0, "rho": 1.0,
                                      "eigenvector": [1.0, 0.0]}
    assert refuted.counterexample_summary() == "the sampled map has an eigenvalue of modulus 2 >= 1"


def test_bands_with_fewer_outputs_than_states_are_the_observers_exact_residual_hull():
    """C (2, 3): no reduction in 3 steps, so the band is the exact hull of r_k over the box of (e_0, v_0..v_2).

    The residual the Observer publishes is linear in (e_0, v): plant at rest (x = 0, y = v), prior -e_0. Its
    coefficients come from runs on unit vectors; the hull radius is sum_j |coefficient_j| * bound_j."""
    d, _ = _small_observer()
    ebar, vbar, steps = np.array([0.05, 0.02, 0.01]), np.array([0.01, 0.03]), 3
    bands = residual_bands(d, vbar, ebar, steps, generators=24)
    assert bands.upper.shape == (steps, 2)
    radius = np.zeros((steps, 2))
    for j in range(3):
        _, obs = _small_observer(prior=-np.eye(3)[j])
        _, out = obs.run(np.zeros((steps, 2)), np.zeros((steps, 1)))
        radius += np.abs(out[:, 3:]) * ebar[j]
    _, obs = _small_observer()
    for k in range(steps):
        for j in range(2):
            y = np.zeros((steps, 2))
            y[k, j] = 1.0
            _, out = obs.run(y, np.zeros((steps, 1)))
            radius += np.abs(out[:, 3:]) * vbar[j]
    np.testing.assert_allclose(bands.upper, radius, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(bands.lower, -radius, rtol=1e-9, atol=1e-15)
    with pytest.raises(SetError, match=r"^noise bound must have shape \(2\), got \(3,\)$"):
        residual_bands(d, [0.01] * 3, ebar, steps, 24)
    with pytest.raises(SetError, match=r"^initial error bound must have shape \(3\), got \(2,\)$"):
        residual_bands(d, vbar, [0.1, 0.1], steps, 24)
    assert residual_bands(d, vbar, ebar, steps, 24, track=False).reductions == []


def test_outside_band_edges_are_inside_and_wrong_shapes_are_named():
    """The hull is closed: a residual on its edge (tolerance 0) is no alarm, a step beyond it is."""
    d = uio_matrices(A3, B3, C3, D3, poles=[0.2, 0.3, 0.4])
    bands = residual_bands(d, [0.01, 0.03], [0.05] * 3, 2, generators=24)
    for edge in (bands.lower, bands.upper):
        assert outside_band(edge, bands, tolerance=0.0).tolist() == [False, False]
    beyond = bands.upper + np.array([[0.0, 0.0], [0.0, 1e-9]])
    assert outside_band(beyond, bands, tolerance=0.0).tolist() == [False, True]
    for bad, shape in ((np.zeros((3, 2)), r"\(3, 2\)"), (np.zeros((2, 3)), r"\(2, 3\)"), (np.zeros(2), r"\(2,\)")):
        with pytest.raises(SetError, match=r"^residuals must be \(N, 2\[, runs\]\) with N <= 2, got " + shape + "$"):
            outside_band(bad, bands)


def test_size_and_option_errors_name_the_matrix_the_free_dimension_and_every_choice():
    with pytest.raises(ObserverError, match=r"^UIO: C must be a \(any, 3\) matrix, got shape \(2, 2\)$"):
        uio_conditions(A3, np.eye(2), D3)
    with pytest.raises(ObserverError, match=r"^UIO: A must be a numeric matrix, got str$"):
        uio_conditions("A", C3, D3)
    with pytest.raises(ObserverError, match=r"^UIO: D must be a \(3, any\) matrix, got shape \(2, 1\)$"):
        uio_conditions(A3, C3, [[1.0], [0.0]])
    with pytest.raises(ObserverError, match=r"^UIO: unknown time domain 'Discrete'; known: discrete, continuous$"):
        uio_conditions(A3, C3, D3, time="Discrete")
    with pytest.raises(ObserverError, match=r"^UIO: B must be a \(3, any\) matrix, got shape \(2, 1\)$"):
        uio_matrices(A3, [[1.0], [0.0]], C3, D3, poles=[0.2, 0.3, 0.4])
    with pytest.raises(ObserverError, match=r"^UIO: B must be a numeric matrix, got str$"):
        uio_matrices(A3, "B", C3, D3, poles=[0.2, 0.3, 0.4])
    with pytest.raises(ObserverError, match=r"^UIO: C must be a numeric matrix, got str$"):
        unobservable_modes(A3, "C")
    with pytest.raises(ObserverError, match=r"^UIO: A must be square, got shape \(2, 3\)$"):
        unobservable_modes(np.ones((2, 3)), [[1.0, 0.0, 0.0]])
    with pytest.raises(ObserverError, match=r"^UIO: C must be a \(any, 2\) matrix, got shape \(1, 3\)$"):
        unobservable_modes(np.eye(2), [[1.0, 0.0, 0.0]])
    with pytest.raises(ObserverError, match=r"^UIO: unknown time domain 'hybrid'; known: discrete, continuous$"):
        unobservable_modes(np.eye(2), [[1.0, 0.0]], time="hybrid")


def test_rank_tolerance_is_absolute_below_one_and_a_singular_value_on_it_is_zero():
    """A = I/2, D = e1, C = (c, 0): C D = (c), one singular value c; the tolerance is 1e-9 * max(1, c) = 1e-9.
    c = 1e-9 sits on it (rank 0 < rank D = 1), c = 1.5e-9 is above it (M = 1/c, T = diag(0, 1))."""
    with pytest.raises(UIOConditionError, match=r"^UIO: rank\(C D\) = 0 but rank\(D\) = 1: the unknown input cannot "
                                                r"be decoupled from these outputs$") as info:
        uio_conditions(0.5 * np.eye(2), [[1e-9, 0.0]], [[1.0], [0.0]])
    assert info.value.ranks == (0, 1)
    M, _, T, _ = uio_conditions(0.5 * np.eye(2), [[1.5e-9, 0.0]], [[1.0], [0.0]])
    np.testing.assert_allclose(M, [[1 / 1.5e-9]], rtol=1e-12)
    np.testing.assert_allclose(T, np.diag([0.0, 1.0]), atol=1e-12)


def test_no_unknown_input_leaves_the_plant_as_it_is():
    """D with no columns: M is (0, p), Q = D M = 0, T = I, A1 = A (a plain Luenberger observer)."""
    M, Q, T, A1 = uio_conditions(A3, C3, np.zeros((3, 0)))
    assert M.shape == (0, 2)
    np.testing.assert_array_equal(Q, np.zeros((3, 2)))
    np.testing.assert_array_equal(T, np.eye(3))
    np.testing.assert_array_equal(A1, A3)


def test_a_mode_on_the_stability_margin_counts_as_not_stable():
    """Unmeasured scalar modes (C = 0): discrete |lambda| >= 1 - 1e-9, continuous Re lambda >= -1e-9."""
    assert unobservable_modes([[1.0 - 1e-9]], [[0.0]]) == [1.0 - 1e-9]
    assert unobservable_modes([[-(1.0 - 1e-9)]], [[0.0]]) == [-(1.0 - 1e-9)]
    assert unobservable_modes([[1.0 - 2e-9]], [[0.0]]) == []
    assert unobservable_modes([[-1e-9]], [[0.0]], time="continuous") == [-1e-9]
    assert unobservable_modes([[-2e-9]], [[0.0]], time="continuous") == []


def test_not_detectable_lists_every_unobservable_mode_in_its_time_domain():
    """D = e3, C = e3^T: T = diag(1, 1, 0), T A = diag(2, 3, 0) for A = diag(2, 3, a); C sees only x3, so the
    eigenvalues 2 and 3 are unobservable (unstable in both time domains), 0 is stable in discrete time."""
    D, C = [[0.0], [0.0], [1.0]], [[0.0, 0.0, 1.0]]
    with pytest.raises(UIOConditionError, match=r"^UIO: \(C, T A\) is not detectable: eigenvalues with \|lambda\| >= 1 "
                                                r"unobservable from C: 2\+0j, 3\+0j$") as info:
        uio_conditions(np.diag([2.0, 3.0, 0.5]), C, D)
    assert info.value.ranks == (1, 1)
    assert info.value.eigenvalues == (2.0, 3.0)
    with pytest.raises(UIOConditionError, match=r"^UIO: \(C, T A\) is not detectable: eigenvalues with Re lambda >= 0 "
                                                r"unobservable from C: 2\+0j, 3\+0j$"):
        uio_conditions(np.diag([2.0, 3.0, -0.5]), C, D, time="continuous")


def test_continuous_design_by_hand_and_its_refusal_as_a_discrete_observer():
    """A = diag(-2, -1), C = (0, 1), D = e2, B = e1, K1 = e2: C D = 1 so M = 1, Q = e2, T = diag(1, 0),
    T A = diag(-2, 0), F = T A - K1 C = diag(-2, -1), J = T B = e1, K = K1 + F Q = e2 - e2 = 0. The mode -2 is
    unobservable: stable in continuous time, not in discrete time (|-2| >= 1)."""
    A, B, C, D, K1 = np.diag([-2.0, -1.0]), [[1.0], [0.0]], [[0.0, 1.0]], [[0.0], [1.0]], [[0.0], [1.0]]
    d = uio_matrices(A, B, C, D, K1=K1, time="continuous")
    assert d.time == "continuous"
    np.testing.assert_allclose(d.M, [[1.0]], atol=1e-12)
    np.testing.assert_allclose(d.Q, [[0.0], [1.0]], atol=1e-12)
    np.testing.assert_allclose(d.T, np.diag([1.0, 0.0]), atol=1e-12)
    np.testing.assert_allclose(d.A1, np.diag([-2.0, 0.0]), atol=1e-12)
    np.testing.assert_allclose(d.F, np.diag([-2.0, -1.0]), atol=1e-12)
    np.testing.assert_allclose(d.J, [[1.0], [0.0]], atol=1e-12)
    np.testing.assert_allclose(d.K, [[0.0], [0.0]], atol=1e-12)
    np.testing.assert_allclose(np.sort(d.eigenvalues.real), [-2.0, -1.0], atol=1e-12)
    with pytest.raises(UIOConditionError, match=r"unobservable from C: -2\+0j$"):
        uio_matrices(A, B, C, D, K1=K1)
    with pytest.raises(ObserverError, match=r"^uio: uio_observer runs a discrete design, got a continuous one$"):
        uio_observer(d, states=_group("x", 2, "state"), outputs=_group("y", 1, "output"),
                     inputs=_group("u", 1, "input"), dt=H)


def test_pole_errors_word_for_word_and_exact_rational_poles():
    with pytest.raises(ObserverError, match=r"^UIO: give exactly one of poles \(F's eigenvalues\) and K1 "
                                            r"\(the gain\)$"):
        uio_matrices(A3, B3, C3, D3, poles=[0.2, 0.3, 0.4], K1=np.zeros((3, 2)))
    with pytest.raises(ObserverError, match=r"^UIO: poles must be 3 finite eigenvalues, got 2$"):
        uio_matrices(A3, B3, C3, D3, poles=[0.2, 0.3])
    with pytest.raises(ObserverError, match=r"^UIO: poles must be 3 finite eigenvalues, got 3$"):
        uio_matrices(A3, B3, C3, D3, poles=[0.2, np.nan, 0.4])
    with pytest.raises(ObserverError, match=r"^UIO: poles must be numbers, got \['fast', 0\.3, 0\.4\]$"):
        uio_matrices(A3, B3, C3, D3, poles=["fast", 0.3, 0.4])
    with pytest.raises(ObserverError, match=r"^UIO: poles must be numbers, got 'fast'$"):
        uio_matrices(A3, B3, C3, D3, poles="fast")
    with pytest.raises(ObserverError, match=r"^UIO: poles cannot be placed: \S"):  # 3 times > rank C = 2
        uio_matrices(A3, B3, C3, D3, poles=[0.2, 0.2, 0.2])
    d = uio_matrices(A3, B3, C3, D3, poles=[Fraction(1, 5), Fraction(3, 10), Fraction(2, 5)])
    np.testing.assert_allclose(np.sort(d.eigenvalues.real), [0.2, 0.3, 0.4], atol=1e-9)


def test_a_partial_placement_names_the_eigenvalues_it_got():
    """A = diag(0.5, 0.6, a), C = (e1, e2)^T, D = e2: C's third column is 0, so e3 is an eigenvector of
    T A - K1 C with eigenvalue a = 0.1234567 whatever K1 is (stable: detectable, not observable); the placement
    puts -0.5 and 0.2 and keeps a in place of 0.3: sorted, a miss of at most 0.1 (< 1) that is still refused."""
    with pytest.raises(ObserverError, match=r"^UIO: poles cannot be placed \(placement needs \(C, T A\) observable, "
                                            r"not only detectable\); got eigenvalues "
                                            r"\[\(-0\.5\+0j\), \(0\.123457\+0j\), \(0\.2\+0j\)\]: give K1 instead$"):
        uio_matrices(np.diag([0.5, 0.6, 0.1234567]), [[1.0], [0.0], [0.0]], C3, D3, poles=[-0.5, 0.2, 0.3])


def test_an_unstable_gain_lists_every_unstable_eigenvalue():
    """C = I, D = e3: T = diag(1, 1, 0), F = T A - 0 C = diag(2, 3, 0) for A = diag(2, 3, 0.5)."""
    with pytest.raises(ObserverError, match=r"^UIO: F = T A - K1 C is not stable \(discrete\): eigenvalues "
                                            r"2\+0j, 3\+0j$"):
        uio_matrices(np.diag([2.0, 3.0, 0.5]), B3, np.eye(3), [[0.0], [0.0], [1.0]], K1=np.zeros((3, 3)))


def test_observer_groups_are_its_own_and_sizes_and_prior_are_named():
    """Whatever the groups given: state z, measurements, inputs; the published estimates and residuals are two
    groups, so their sum is a plain "signal" group."""
    d = uio_matrices(A3, B3, C3, D3, poles=[0.2, 0.3, 0.4])
    obs = uio_observer(d, states=_group("x", 3, "residual"), outputs=_group("y", 2, "estimate"),
                       inputs=_group("u", 1, "measurement"), dt=H)
    assert (obs.state.group, obs.reads_y.group, obs.reads_u.group, obs.publishes.group) == (
        "state", "measurement", "input", "signal")
    with pytest.raises(ObserverError, match=r"^uio: inputs has 2 signals, the design 1$"):
        uio_observer(d, states=_group("x", 3, "state"), outputs=_group("y", 2, "output"),
                     inputs=_group("u", 2, "input"), dt=H)
    with pytest.raises(ModelError, match=r"^uio: prior must have 3 entries \(x0, x1, x2\), got 2$"):
        _small_observer(prior=[1.0, 2.0])


# --- exact elimination helpers and claim fields (vuio1) ---

def test_row_echelon_is_reduced_exactly_and_skips_zero_columns():
    """By hand: [[1, 1], [1, 2]] and [[1, 1], [0, 1]] reduce to I; I3 stays I3; [[0, 1], [0, 2]] has its pivot in
    column 1; an empty matrix has no pivots."""
    from uvsym.verify.uio import _row_echelon
    one, eye2 = Fraction(1), [[Fraction(1), Fraction(0)], [Fraction(0), Fraction(1)]]
    assert _row_echelon([[one, one], [one, 2 * one]]) == (eye2, [0, 1])
    assert _row_echelon([[one, one], [0 * one, one]]) == (eye2, [0, 1])
    eye3 = [[Fraction(int(i == j)) for j in range(3)] for i in range(3)]
    assert _row_echelon(eye3) == (eye3, [0, 1, 2])
    assert _row_echelon([[0 * one, one], [0 * one, 2 * one]]) == ([[0, 1], [0, 0]], [1])
    assert _row_echelon([]) == ([], [])


def test_null_vector_is_in_the_kernel_exactly():
    """A v = 0 checked in rationals for a kernel of dimension 1 ([[1, 1]]) and 2 ([[1, 1, 1]])."""
    from uvsym.verify.uio import _null_vector
    for A in ([[Fraction(1), Fraction(1)]], [[Fraction(1), Fraction(1), Fraction(1)]]):
        v = _null_vector(A)
        assert any(v) and all(sum(a * b for a, b in zip(row, v)) == 0 for row in A)


def test_singular_inverse_and_non_nilpotent_zoh_are_named():
    from uvsym.errors import VerificationError
    from uvsym.verify.uio import _inverse
    with pytest.raises(VerificationError, match=r"^matrix is singular$"):
        _inverse([[Fraction(1), Fraction(2)], [Fraction(2), Fraction(4)]])
    with pytest.raises(VerificationError, match=r"^exact_zoh needs \[\[A, B\], \[0, 0\]\] nilpotent \(a chain of "
                                                r"integrators\); it is not$"):
        exact_zoh([[1.0]], [[0.0]], 0.1)


def test_claim_shapes_and_column_rank_are_named():
    from uvsym.errors import VerificationError
    with pytest.raises(VerificationError, match=r"^G must be \(n, n\), C \(p, n\), D \(n, q\); got 2x2, 1x3, 2x1$"):
        uio_existence_claim("C wide", np.eye(2), [[1.0, 0.0, 0.0]], [[0.0], [1.0]])
    with pytest.raises(VerificationError, match=r"^G must be \(n, n\), C \(p, n\), D \(n, q\); got 2x3, 1x2, 2x1$"):
        uio_existence_claim("G wide", np.ones((2, 3)), [[1.0, 0.0]], [[0.0], [1.0]])
    # D = [[1, 2], [0, 0]] has rank 1 < 2 columns; C = I keeps rank(C D) = 1
    with pytest.raises(VerificationError, match=r"^D must have full column rank \(2\), it has rank 1$"):
        uio_existence_claim("rank", np.eye(2), np.eye(2), [[1.0, 2.0], [0.0, 0.0]])


def test_rank_refutation_states_claim_status_margin_method_and_time():
    """C D = 0 but rank D = 1: margin rank(C D) - rank(D) = -1; expected left at its default "proved"."""
    refuted = uio_existence_claim("C D = 0", np.eye(2) * 0.5, [[0.0, 1.0]], [[1.0], [0.0]])
    assert (refuted.claim, refuted.status, refuted.expected) == ("C D = 0", "refuted", "proved")
    assert refuted.method == "exact rank (fraction elimination)" and refuted.margin == -1.0
    assert refuted.seconds > 0.0
    assert uio_existence_claim("C D = 0", np.eye(2) * 0.5, [[0.0, 1.0]], [[1.0], [0.0]],
                               expected="refuted").expected == "refuted"
    stuck = uio_existence_claim("no gain", np.diag([1.5, 0.5]), np.eye(2), [[0.0], [1.0]], K1=np.zeros((2, 2)),
                                expected="inconclusive")
    assert stuck.method == "exact rank; Lyapunov and PBH searches"


def test_a_complex_pair_does_not_hide_a_later_real_unobservable_eigenvalue():
    """G = blockdiag(rotation by 90 deg scaled 2, 2, 0.5), D = e4, C = e4^T: T = diag(1, 1, 1, 0), the pair +-2j
    (listed first) is skipped and the real eigenvalue 2 with v = e3 (C v = 0) refutes."""
    G = np.array([[0.0, -2.0, 0.0, 0.0], [2.0, 0.0, 0.0, 0.0], [0.0, 0.0, 2.0, 0.0], [0.0, 0.0, 0.0, 0.5]])
    claim = uio_existence_claim("pair first", G, [[0.0, 0.0, 0.0, 1.0]], [[0.0], [0.0], [0.0], [1.0]],
                                expected="refuted")
    assert claim.status == "refuted"
    assert claim.counterexample["unobservable_eigenvalue"] == 2.0
    assert claim.counterexample["eigenvector"] == [0.0, 0.0, 1.0, 0.0]


def test_an_eigenvalue_with_a_denominator_above_1000_is_not_rounded_onto():
    """G1 = diag(1002/1001, 0) exactly, e1 unobservable: the nearest rational with denominator <= 1000 is not an
    eigenvalue, so no exact eigenvector is found (the search stops at denominators of 1000)."""
    G = [[Fraction(1002, 1001), Fraction(0)], [Fraction(0), Fraction(1, 2)]]
    assert uio_existence_claim("1002/1001", G, [[0, 1]], [[0], [1]], expected="inconclusive").status == "inconclusive"


def test_a_defective_unobservable_eigenvalue_split_by_rounding_is_refuted():
    """G = blockdiag([[4, 9], [-1, -2]], 0.5): trace 2, determinant 1, so the block is a Jordan block at 1 (not
    diagonalisable); LAPACK returns 1 +- 2.7e-8 j. D = e3, C = e3^T: the exact eigenvector (-3, 1, 0) of G1 has
    C v = 0, so the claim is refuted at lambda = 1."""
    G = np.array([[4.0, 9.0, 0.0], [-1.0, -2.0, 0.0], [0.0, 0.0, 0.5]])
    assert min(abs(lam.imag) for lam in np.linalg.eigvals(G[:2, :2])) > 1e-9  # the premise: a split pair
    claim = uio_existence_claim("Jordan block", G, [[0.0, 0.0, 1.0]], [[0.0], [0.0], [1.0]], expected="refuted")
    assert claim.status == "refuted" and claim.counterexample["unobservable_eigenvalue"] == 1.0
    v = claim.counterexample["eigenvector"]
    assert v[2] == 0.0 and v[0] == -3 * v[1] != 0.0
