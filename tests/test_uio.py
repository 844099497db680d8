"""Unknown-input observer: design against hand derivations and simulation, typed condition errors,
bank decoupling, zonotope bands, exact existence claims."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from scipy.linalg import expm

from uvsym.errors import ObserverError, SetError, UIOConditionError
from uvsym.observers.uio import uio_conditions, uio_matrices, uio_observer
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
    claim = uio_existence_claim("double integrator, position only", G, [[1.0, 0.0]], D, expected="refuted")
    assert_refuted(claim)
    assert claim.counterexample["unobservable_eigenvalue"] == -1.0
    assert claim.counterexample["eigenvector"][0] == 0.0


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
    with pytest.raises(SetError, match="initial error bound"):
        residual_bands(d, vbar, [0.1, 0.1], 10, 24)
    with pytest.raises(SetError, match="dimension 6"):
        residual_bands(d, vbar, ebar, 10, 4)
