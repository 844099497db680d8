"""The UKF: exactly the Kalman filter on a linear Gaussian system, consistent (NEES) on the Otter,
and typed errors for bad input."""

import casadi as ca
import numpy as np
import pytest
from scipy.stats import chi2, multivariate_normal

import uvsym
from uvsym.errors import CovarianceError, ObserverError
from uvsym.observers.kalman import run_filter, transition, unpacked
from uvsym.observers.ukf import passive_last, ukf, unscented_filter, unscented_weights
from uvsym.systems.signals import signals
from uvsym.systems.system import system

A = np.array([[1.0, 0.1, 0.0], [-0.2, 0.9, 0.05], [0.0, 0.1, 0.95]])
B = np.array([[0.0], [0.1], [0.3]])
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
Q = np.diag([0.01, 0.02, 0.005])
R = np.array([[0.1, 0.02], [0.02, 0.2]])
P0 = 2.0 * np.eye(3)
X0 = np.array([1.0, -1.0, 0.5])


def linear_plant():
    x = signals(("a", "m"), ("b", "m/s"), ("c", "-"), group="state")
    return system("linear", "x+ = A x + B u, y = C x", x=x, u=signals(("f", "N"), group="input"),
                  rhs=lambda x, u, d, p: ca.mtimes(ca.DM(A), x) + ca.mtimes(ca.DM(B), u),
                  y=signals(("a_m", "m"), ("c_m", "-"), group="output"),
                  output=lambda x, u, p: ca.mtimes(ca.DM(C), x), dt=0.1)


def kalman_filter(Y, U):
    """Textbook Kalman filter (numpy): posteriors, priors' covariances and log-likelihoods."""
    x, P = X0.copy(), P0.copy()
    posts, priors, logliks = [], [], []
    for y, u in zip(Y, U):
        priors.append(P.copy())
        S = C @ P @ C.T + R
        K = P @ C.T @ np.linalg.inv(S)
        logliks.append(multivariate_normal(C @ x, S).logpdf(y))
        x, P = x + K @ (y - C @ x), P - K @ S @ K.T
        posts.append(x.copy())
        x, P = A @ x + B @ u, A @ P @ A.T + Q
    return np.array(posts), priors, np.array(logliks)


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(0)
    return rng.normal(size=(150, 2)), rng.normal(size=(150, 1))


@pytest.mark.parametrize("closed_form", [True, False])
@pytest.mark.parametrize("alpha, beta, kappa", [(1.0, 2.0, 0.0), (0.5, 2.0, 1.0), (0.1, 0.0, 0.0)])
def test_ukf_is_the_kalman_filter_on_a_linear_gaussian_system(data, alpha, beta, kappa, closed_form):
    Y, U = data
    obs = ukf(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, x0=X0, alpha=alpha, beta=beta, kappa=kappa,
              affine_closed_form=closed_form)
    S, OUT = run_filter(obs, Y, U)
    posts, priors, logliks = kalman_filter(Y, U)
    np.testing.assert_allclose(OUT[:, :3], posts, rtol=0, atol=1e-10)
    for k in (0, 1, 50, 149):
        np.testing.assert_allclose(unpacked(S[k, 3:], 3), priors[k], rtol=0, atol=1e-10)
    np.testing.assert_allclose(OUT[:, obs.publishes.index("loglik")], logliks, rtol=1e-9, atol=0)
    assert np.all(OUT[:, obs.publishes.index("pd_margin")] > 0) and not OUT[:, -1].any()


def test_weights_are_the_scaled_unscented_transform():
    n, alpha, beta, kappa = 7, 0.3, 2.0, 1.0
    lam = alpha**2 * (n + kappa) - n
    scale, w_m, w_c = unscented_weights(n, alpha, beta, kappa)
    assert scale == pytest.approx(np.sqrt(n + lam))
    assert w_m.sum() == pytest.approx(1.0) and w_m[0] == pytest.approx(lam / (n + lam))
    assert w_c[0] == pytest.approx(lam / (n + lam) + 1 - alpha**2 + beta)
    np.testing.assert_allclose(w_m[1:], 1 / (2 * (n + lam)))


def test_positions_go_last_in_the_square_root_order():
    otter = uvsym.plant("otter3dof")
    order = passive_last(otter, lambda x, u, p: otter.f(x, u, [], p))
    assert [otter.x.names[i] for i in order[-2:]] == ["x", "y"]


@pytest.mark.parametrize("alpha", [0.0, -0.5, 1.5, float("nan")])
def test_alpha_outside_the_unit_interval_is_refused(alpha):
    with pytest.raises(ObserverError, match="alpha"):
        ukf(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, alpha=alpha)


@pytest.mark.parametrize("argument, value", [("P0", np.diag([1.0, -1.0, 1.0])), ("Q", np.diag([0.0, 0.0, -1e-6])),
                                             ("R", np.array([[1.0, 2.0], [2.0, 1.0]])),
                                             ("R", np.array([[1.0, 0.5], [0.0, 1.0]])), ("Q", np.eye(2))])
def test_covariances_that_are_indefinite_or_malformed_are_refused(argument, value):
    """Indefinite, not symmetric or of the wrong size (a semi-definite one, such as Q = 0, is a covariance)."""
    options = {"Q": Q, "R": R, "P0": P0, argument: value}
    with pytest.raises(CovarianceError, match=argument):
        ukf(linear_plant(), dt=0.1, **options)


def test_measurements_of_the_wrong_size_are_refused(data):
    obs = ukf(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0)
    with pytest.raises(ObserverError, match=r"measurements Y must be \(N, 2\)"):
        run_filter(obs, np.zeros((5, 3)), np.zeros((5, 1)))


def test_a_nan_measurement_skips_the_update_and_says_so(data):
    Y, U = data
    Y = Y[:20].copy()
    Y[7, 1] = np.nan
    obs = ukf(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, x0=X0)
    S, OUT = run_filter(obs, Y, U[:20])
    assert OUT[:, obs.publishes.index("skipped")].tolist() == [float(k == 7) for k in range(20)]
    np.testing.assert_allclose(OUT[7, :3], S[7, :3], atol=1e-14)  # posterior = prior
    np.testing.assert_allclose(S[8, :3], A @ S[7, :3] + B @ U[7], atol=1e-12)  # prediction made
    assert OUT[7, obs.publishes.index("loglik")] == 0.0 and np.all(np.isfinite(OUT))


def test_a_covariance_that_is_no_longer_positive_definite_raises_naming_the_sample(data):
    Y, U = data
    obs = ukf(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0)
    s0 = np.concatenate([X0, [1.0, 2.0, 0.0, 1.0, 0.0, 1.0]])  # tril of [[1, 2, 0], [2, 1, 0], [0, 0, 1]]
    with pytest.raises(CovarianceError, match=r"sample 0 \(t = 0 s"):
        run_filter(obs, Y[:5], U[:5], s0=s0)
    out = obs.step(s0, Y[0], U[0], [])[1]  # and the step itself stays finite
    assert np.all(np.isfinite(np.asarray(out)))


def test_nees_of_the_otter_ukf_is_within_its_chi_square_bounds():
    """Monte Carlo: 40 runs of 150 samples of the Otter driven with the filter's own Q and R;
    the average NEES over runs at each sample lies within its 99 % chi-square band (Bar-Shalom's
    test) at >= 95 % of the samples, and the overall average within 10 % of the state size."""
    otter, dt, runs, steps = uvsym.plant("otter3dof"), 0.05, 40, 150
    q = np.array([1e-4, 1e-4, 1e-5, 1e-4, 1e-4, 1e-5])
    r = np.array([0.05, 0.05, 0.0035, 0.02, 0.02, 0.0035]) ** 2
    p0 = np.array([0.5, 0.5, 0.05, 0.1, 0.1, 0.05]) ** 2
    obs = ukf(otter, dt=dt, Q=q, R=r, P0=p0, x0=[0, 0, 0, 1.5, 0, 0])
    x, u, p = ca.SX.sym("x", 6), ca.SX.sym("u", 2), ca.SX.sym("p", 2)
    step = ca.Function("F", [x, u, p], [transition(otter, dt)(x, u, p)])
    rng = np.random.default_rng(7)
    wave = 10 * np.sin(0.3 * dt * np.arange(steps))
    U = np.column_stack([58 + wave, 58 - wave])
    nees = np.empty((runs, steps))
    for k in range(runs):
        xk = np.array([0, 0, 0, 1.5, 0, 0]) + np.sqrt(p0) * rng.standard_normal(6)
        X, Y = [], []
        for i in range(steps):
            X.append(xk)
            Y.append(xk + np.sqrt(r) * rng.standard_normal(6))
            xk = np.asarray(step(xk, U[i], [0, 0])).ravel() + np.sqrt(q) * rng.standard_normal(6)
        S, OUT = run_filter(obs, np.array(Y), U)
        for i in range(steps):
            e = np.array(X[i]) - OUT[i, :6]
            nees[k, i] = e @ np.linalg.solve(_posterior(S[i], np.diag(r)), e)
    low, high = chi2.ppf([0.005, 0.995], runs * 6) / runs
    inside = np.mean((nees.mean(axis=0) > low) & (nees.mean(axis=0) < high))
    assert inside >= 0.95
    assert abs(nees.mean() / 6 - 1) < 0.1


def _posterior(s, R):
    """P_{k|k} from the prior P_{k|k-1} held in the state s: with y = x the update is linear, and
    the UKF's equals the closed form ``P - P (P + R)^-1 P``."""
    P = unpacked(s[6:], 6)
    return P - P @ np.linalg.solve(P + R, P)


def test_settings_say_whether_the_update_was_in_closed_form():
    closed = unscented_filter(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0).settings["affine_closed_form"]
    by_points = unscented_filter(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0,
                                 affine_closed_form=False).settings["affine_closed_form"]
    assert (closed, by_points) == (True, False)
    sine = system("sine", "", x=signals(("a", "m"), group="state"), u=signals(("f", "N")),
                  rhs=lambda x, u, d, p: x, dt=0.1, y=signals(("s", "-")), output=lambda x, u, p: ca.sin(x))
    assert unscented_filter(sine, dt=0.1, Q=1.0, R=1.0, P0=1.0).settings["affine_closed_form"] is False


def test_the_default_name_is_ukf():
    assert unscented_filter(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0).name == "ukf"
    assert ukf(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0).name == "ukf"


@pytest.mark.parametrize("beta", [float("inf"), float("-inf"), float("nan")])
def test_a_beta_that_is_not_finite_is_refused_with_its_value(beta):
    with pytest.raises(ObserverError, match=rf"^UKF beta must be a finite number, got {beta!r}$"):
        unscented_weights(3, 1.0, beta, 0.0)


@pytest.mark.parametrize("kappa", [-3.0, -3, -4.5, float("inf"), float("nan")])
def test_a_kappa_with_n_plus_kappa_not_positive_or_not_finite_is_refused(kappa):
    """n = 3: kappa = -3 is the boundary n + kappa = 0 (refused), -4.5 beyond it."""
    message = rf"^UKF kappa must be finite with n \+ kappa > 0 \(n = 3\), got {kappa!r}$"
    with pytest.raises(ObserverError, match=message):
        unscented_weights(3, 1.0, 2.0, kappa)


@pytest.mark.parametrize("kappa", [-2.5, 5.0])
def test_a_kappa_just_above_minus_n_or_above_n_is_accepted(kappa):
    """n = 3, alpha = 1: lambda = kappa, so w_i = 1 / (2 (3 + kappa)) and w_m0 = kappa / (3 + kappa)."""
    scale, w_m, w_c = unscented_weights(3, 1.0, 2.0, kappa)
    assert scale == pytest.approx(np.sqrt(3 + kappa))
    np.testing.assert_allclose(w_m, [kappa / (3 + kappa)] + [1 / (2 * (3 + kappa))] * 6, rtol=1e-14)


def test_passive_states_are_found_through_input_and_parameter_differences():
    """a+ = a + (f - g) b, b+ = b + (k - c) c, c+ = c: b enters a's update and c enters b's (through
    differences of two inputs and of two parameters), nothing reads a: order b, c, a."""
    x = signals(("a", "m"), ("b", "m"), ("c", "m"), group="state")
    plant = system("mix", "", x=x, u=signals(("f", "N"), ("g", "N"), group="input"),
                   p=signals(("k", "-"), ("c", "-"), group="parameter"), p0=[1.0, 2.0], dt=0.1,
                   rhs=lambda x, u, d, p: ca.vertcat(x[0] + (u[0] - u[1]) * x[1], x[1] + (p[0] - p[1]) * x[2], x[2]))
    assert passive_last(plant, transition(plant, 0.1)) == [1, 2, 0]


def scalar_plant(**options):
    """x' = -x (continuous; 1/s), y = x: one input that nothing reads."""
    return system("decay", "x' = -x", x=signals(("a", "m"), group="state"), u=signals(("f", "N"), group="input"),
                  rhs=lambda x, u, d, p: -x, **options)


@pytest.mark.parametrize("steps", [None, 2])
def test_a_continuous_system_is_predicted_by_rk4_with_the_steps_asked(steps):
    """Scalar Kalman filter by hand: K = P0 / (P0 + R), then x^- = g x, P^- = g^2 P + Q with the
    RK4 factor g = 1 - h + h^2/2 - h^3/6 + h^4/24 of x' = -x per step of h = dt / steps (default 1);
    rtol 1e-10 for the relative jitter of 1e-12 in the factorisations."""
    dt, q, r, p0, x0, y = 0.5, 0.01, 0.2, 0.3, 1.0, 1.4
    options = {} if steps is None else {"steps": steps}
    obs = ukf(scalar_plant(), dt=dt, Q=q, R=r, P0=p0, x0=[x0], **options)
    S, OUT = run_filter(obs, [[y]], [[0.0]])
    k = steps or 1
    h = dt / k
    g = (1 - h + h**2 / 2 - h**3 / 6 + h**4 / 24) ** k
    x_post, p_post = x0 + p0 / (p0 + r) * (y - x0), p0 * r / (p0 + r)
    np.testing.assert_allclose(OUT[0, 0], x_post, rtol=1e-10)
    np.testing.assert_allclose(S[1], [g * x_post, g**2 * p_post + q], rtol=1e-10)


def test_the_closed_form_update_reports_no_factorisation_margin_of_its_own():
    """Scalar linear filter: the closed-form update factorises nothing (margin 1 by convention) and
    every relative pivot of a 1 x 1 factorisation is a (1 + jitter) / a >= 1: the margin is exactly 1."""
    obs = ukf(scalar_plant(), dt=0.5, Q=0.01, R=0.2, P0=0.3, x0=[1.0])
    OUT = run_filter(obs, [[1.4], [0.9]], [[0.0], [0.0]])[1]
    assert OUT[:, obs.publishes.index("pd_margin")].tolist() == [1.0, 1.0]


def test_the_sigma_point_update_of_a_square_law_sensor_matches_the_hand_transform():
    """x+ = x, y = x^2, alpha = 1, beta = 2, kappa = 0 (n = 1): sigma points x, x +- s (s^2 = P),
    weights w_m = (0, 1/2, 1/2), w_c = (2, 1/2, 1/2), so z = x^2 + P, P_zz = 2 P^2 + 4 x^2 P + R,
    P_xz = 2 x P (negative for x < 0: the sign of the gain); rtol 1e-10 for the factorisations' jitter."""
    square = system("square", "x+ = x, y = x^2", x=signals(("a", "m"), group="state"),
                    u=signals(("f", "N"), group="input"), rhs=lambda x, u, d, p: x, dt=0.1,
                    y=signals(("a2", "m2"), group="output"), output=lambda x, u, p: x**2)
    q, r, p0, y = 0.01, 0.1, 0.5, 2.0
    for x0 in (1.0, -1.0):
        S, OUT = run_filter(ukf(square, dt=0.1, Q=q, R=r, P0=p0, x0=[x0]), [[y]], [[0.0]])
        P_zz, P_xz = 2 * p0**2 + 4 * x0**2 * p0 + r, 2 * x0 * p0
        x_post, p_post = x0 + P_xz / P_zz * (y - x0**2 - p0), p0 - P_xz**2 / P_zz
        np.testing.assert_allclose(OUT[0, :2], [x_post, y - x0**2 - p0], rtol=1e-10)
        np.testing.assert_allclose(S[1], [x_post, p_post + q], rtol=1e-10)


def test_the_predicted_covariance_is_exactly_symmetric():
    """P^- = sum w_c dX dX^T + Q is symmetric bit for bit (its upper triangle mirrors the lower)."""
    filt = unscented_filter(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0)
    x, L, u = ca.SX.sym("x", 3), ca.SX.sym("L", 3, 3), ca.SX.sym("u")
    P = ca.mtimes(ca.tril(L), ca.tril(L).T)
    predicted = ca.Function("predicted", [x, L, u], [filt.predict(x, P, u, ca.SX(0, 1))[1]])
    rng = np.random.default_rng(3)
    for _ in range(5):
        M = np.asarray(predicted(rng.normal(size=3), rng.normal(size=(3, 3)) + 3 * np.eye(3), rng.normal()))
        assert np.array_equal(M, M.T)


def test_the_filter_records_its_method_noise_and_settings():
    """Q and R given as variances are kept as the diagonal matrices (what banks of filters read)."""
    filt = unscented_filter(scalar_plant(), dt=0.5, Q=[0.01], R=0.2, P0=0.3, steps=3)
    assert filt.method == "ukf" and filt.settings["steps"] == 3
    np.testing.assert_array_equal(filt.Q, [[0.01]])
    np.testing.assert_array_equal(filt.R, [[0.2]])


def test_the_description_gives_the_defaults_and_the_sample_period():
    """Defaults of the scaled transform for a Gaussian prior: alpha = 1, beta = 2, kappa = 0."""
    obs = ukf(scalar_plant(), dt=0.5, Q=0.01, R=0.2, P0=0.3)
    assert obs.description == "UKF of decay (alpha 1, beta 2, kappa 0), sampled every 0.5 s"
    assert ukf(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, alpha=0.5, kappa=1.5).description == (
        "UKF of linear (alpha 0.5, beta 2, kappa 1.5), sampled every 0.1 s")


# --- square-root factors and covariance units: edge cases (mutation survivors) ---------------------------------------


def test_the_factor_of_an_indefinite_matrix_is_the_documented_diagonal_fallback():
    from uvsym.observers.kalman import cholesky
    factor, margin = cholesky(ca.SX(ca.DM([[1.0, 2.0], [2.0, 1.0]])))  # eigenvalues 3 and -1
    # fallback diag(sqrt(|a_jj| + 1)) = sqrt(2) I; second pivot 1 - 4 < 0, so the margin is clipped at -1
    np.testing.assert_allclose(np.array(ca.evalf(ca.densify(factor))), np.sqrt(2.0) * np.eye(2), rtol=1e-12)
    assert float(ca.evalf(margin)) == -1.0


def test_covariance_units_drop_dimensionless_factors():
    from uvsym.observers.kalman import covariance_signals
    P = covariance_signals(signals(("c", "-"), ("a", "m"), group="state"))
    assert P.names == ("P.c.c", "P.a.c", "P.a.a") and P.units == ("-", "m", "m m")


def test_the_efficiency_augmented_system_describes_itself_and_names_its_parameters():
    from uvsym.observers.kalman import efficiency_augmented
    plant = linear_plant()
    augmented = efficiency_augmented(plant, ("f",))
    assert augmented.description == "x+ = A x + B u, y = C x; efficiencies of f as random-walk states"
    gain = system("gain", "x' = -k x + f", x=signals(("a", "m"), group="state"), u=signals(("f", "m/s"), group="input"),
                  p=signals(("k", "1/s"), group="parameter"), rhs=lambda x, u, d, p: -p * x + u, p0=[1.0])
    f = efficiency_augmented(gain, ("f",)).f  # symbols named as the arguments, as printed in its expressions
    assert [str(f.sx_in(i)) for i in range(4)] == ["[x_0, x_1]", "u", "0x1", "p"]
