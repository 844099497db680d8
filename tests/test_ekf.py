"""The EKF: the Kalman filter on a linear system, its prediction the finite-difference
linearisation of the model on the Otter, efficiency augmentation, typed errors."""

import casadi as ca
import numpy as np
import pytest
from test_ukf import P0, X0, A, B, Q, R, kalman_filter, linear_plant

import uvsym
from uvsym.errors import CovarianceError, ObserverError
from uvsym.observers.ekf import ekf
from uvsym.observers.kalman import efficiency_augmented, run_filter, transition, unpacked
from uvsym.systems.signals import signals
from uvsym.systems.system import system


def test_ekf_is_the_kalman_filter_on_a_linear_system():
    rng = np.random.default_rng(1)
    Y, U = rng.normal(size=(120, 2)), rng.normal(size=(120, 1))
    S, OUT = run_filter(ekf(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, x0=X0), Y, U)
    posts, priors, logliks = kalman_filter(Y, U)
    np.testing.assert_allclose(OUT[:, :3], posts, rtol=0, atol=1e-10)
    np.testing.assert_allclose(unpacked(S[100, 3:], 3), priors[100], rtol=0, atol=1e-10)
    np.testing.assert_allclose(OUT[:, 5], logliks, rtol=1e-9)


def test_ekf_prediction_uses_the_finite_difference_jacobian_of_the_otter():
    otter, dt = uvsym.plant("otter3dof"), 0.05
    q, r, p0 = np.full(6, 1e-4), np.full(6, 1e-2), np.linspace(0.1, 0.6, 6)
    obs = ekf(otter, dt=dt, Q=q, R=r, P0=p0)
    x0, y0, u0 = np.array([1.0, 2.0, 0.3, 1.4, 0.2, 0.1]), np.array([1.1, 2.1, 0.31, 1.45, 0.15, 0.12]), [60.0, 45.0]
    s0 = np.concatenate([x0, unpacked_inverse(np.diag(p0))])
    s1, out = (np.asarray(v).ravel() for v in obs.step(s0, y0, u0, [0, 0]))
    P = np.diag(p0)
    x_post_expected = x0 + P @ np.linalg.solve(P + np.diag(r), y0 - x0)  # h = x: linear update
    np.testing.assert_allclose(out[:6], x_post_expected, atol=1e-12)
    P_post = P - P @ np.linalg.solve(P + np.diag(r), P)
    xs, us = ca.SX.sym("x", 6), ca.SX.sym("u", 2)
    F = ca.Function("F", [xs, us], [transition(otter, dt)(xs, us, ca.DM.zeros(2))])
    step = 1e-6
    A = np.column_stack([(np.asarray(F(x_post_expected + step * e, u0)) - np.asarray(F(x_post_expected - step * e, u0)))
                         .ravel() / (2 * step) for e in np.eye(6)])
    np.testing.assert_allclose(unpacked(s1[6:], 6), A @ P_post @ A.T + np.diag(q), rtol=1e-6, atol=1e-10)
    np.testing.assert_allclose(s1[:6], np.asarray(F(x_post_expected, u0)).ravel(), atol=1e-12)


def unpacked_inverse(P):
    """tril(P) column by column, the filter state's layout, written out independently."""
    return np.concatenate([P[j:, j] for j in range(P.shape[0])])


def test_efficiency_augmentation_scales_the_input_and_holds_the_efficiency():
    otter = uvsym.plant("otter3dof")
    left = efficiency_augmented(otter, ("T_L",))
    assert left.x.names[-1] == "alpha_T_L" and left.x_op[-1] == 1.0
    x, u = np.array([0, 0, 0.2, 1.0, 0.1, 0.05]), np.array([80.0, 50.0])
    got = np.asarray(left.f(np.append(x, 0.4), u, [], [0, 0])).ravel()
    np.testing.assert_allclose(got[:6], np.asarray(otter.f(x, [32.0, 50.0], [], [0, 0])).ravel(), atol=1e-12)
    assert got[6] == 0.0
    with pytest.raises(ObserverError, match="distinct inputs"):
        efficiency_augmented(otter, ("T_L", "T_L"))


def test_bad_ekf_input_is_refused():
    with pytest.raises(CovarianceError, match="P0"):
        ekf(linear_plant(), dt=0.1, Q=Q, R=R, P0=-np.eye(3))
    with pytest.raises(CovarianceError, match="R"):
        ekf(linear_plant(), dt=0.1, Q=Q, R=[1.0, np.nan], P0=P0)
    with pytest.raises(ObserverError, match="dt"):
        ekf(linear_plant(), dt=0.0, Q=Q, R=R, P0=P0)
    with pytest.raises(ObserverError, match="sampled every"):
        ekf(linear_plant(), dt=0.2, Q=Q, R=R, P0=P0)  # the plant is discrete at 0.1 s


def test_efficiency_augmentation_of_a_discrete_system_stays_discrete():
    plant = linear_plant()  # x+ = A x + B u at 0.1 s
    augmented = efficiency_augmented(plant, ("f",))
    assert augmented.discrete and augmented.dt == 0.1 and augmented.x.group == "state"
    assert augmented.x.descriptions[-1] == "efficiency of f (1 healthy)"
    x = np.array([1.0, 2.0, 3.0])
    got = np.asarray(augmented.f(np.append(x, 0.5), [4.0], [], [])).ravel()
    np.testing.assert_allclose(got, np.append(A @ x + B[:, 0] * 2.0, 0.5), atol=1e-14)  # alpha held


def test_filter_labels_its_state_residuals_and_diagnostics():
    bare = system("bare", "", x=signals(("a", "m")), u=signals(("f", "N")), rhs=lambda x, u, d, p: 0.5 * x + u,
                  dt=0.1, y=signals(("a_m", "m")), output=lambda x, u, p: x)  # groups left at "signal"
    obs = ekf(bare, dt=0.1, Q=1.0, R=1.0, P0=1.0)
    assert obs.state.group == "state"
    assert obs.publishes.names == ("a_hat", "r_a_m", "loglik", "pd_margin", "skipped")
    assert obs.publishes.descriptions[-1] == "1 where y_k had a NaN and the update was skipped"


def test_efficiency_augmentation_keeps_the_input_bounds():
    otter = uvsym.plant("otter3dof")  # thrust limits of both propellers
    left = efficiency_augmented(otter, ("T_L",))
    assert left.u_min.tolist() == otter.u_min.tolist() and left.u_max.tolist() == otter.u_max.tolist()
    assert np.all(np.isfinite(left.u_min))  # real bounds, not the unbounded default


def test_filter_describes_its_positive_definiteness_margin():
    obs = ekf(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0)
    described = dict(zip(obs.publishes.names, obs.publishes.descriptions))
    assert described["pd_margin"] == "smallest relative Cholesky pivot of the step (> 0: P.D.)"


def test_extended_filter_keeps_its_method_covariances_and_settings():
    from uvsym.observers.ekf import extended_filter

    filt = extended_filter(linear_plant(), dt=0.1, Q=[1.0, 2.0, 3.0], R=[4.0, 5.0], P0=P0)
    assert (filt.name, filt.method, filt.settings) == ("ekf", "ekf", {"steps": 1})
    np.testing.assert_array_equal(filt.Q, np.diag([1.0, 2.0, 3.0]))
    np.testing.assert_array_equal(filt.R, np.diag([4.0, 5.0]))
    obs = ekf(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0)
    assert obs.name == "ekf" and obs.description == "EKF of linear, sampled every 0.1 s"


def test_ekf_prediction_takes_the_requested_rk4_steps():
    # x' = -x: one RK4 step of h multiplies x by g(h) = 1 - h + h^2/2 - h^3/6 + h^4/24, and so does its Jacobian;
    # steps = 2 over dt = 0.5 is g(0.25)^2 = 0.6065..., one step would be g(0.5) = 0.6068...
    from uvsym.observers.ekf import extended_filter

    decay = system("decay", "", x=signals(("x", "m")), u=signals(("f", "N")), rhs=lambda x, u, d, p: -x + u)
    filt = extended_filter(decay, dt=0.5, Q=0.25, R=1.0, P0=1.0, steps=2)
    assert filt.settings == {"steps": 2}

    def g(h):
        return 1 - h + h**2 / 2 - h**3 / 6 + h**4 / 24

    x_next, P_next, _ = filt.predict(ca.DM(2.0), ca.DM(3.0), ca.DM(0.0), ca.DM.zeros(0))
    assert float(x_next) == pytest.approx(2.0 * g(0.25) ** 2, rel=1e-14)
    assert float(P_next) == pytest.approx(3.0 * g(0.25) ** 4 + 0.25, rel=1e-14)
