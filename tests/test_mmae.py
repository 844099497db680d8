"""The MMAE bank against an independent numpy bank of Kalman filters (unequal state sizes,
log-space Bayes with a floor, fusion, reset), and its typed errors."""

import casadi as ca
import numpy as np
import pytest
from scipy.special import logsumexp
from scipy.stats import multivariate_normal
from test_ukf import P0, X0, A, B, C, Q, R, linear_plant

from uvsym.errors import ObserverError
from uvsym.observers.ekf import extended_filter
from uvsym.observers.kalman import run_filter
from uvsym.observers.mmae import log_normalised, mmae_bank
from uvsym.observers.ukf import unscented_filter
from uvsym.systems.signals import signals
from uvsym.systems.system import system

E = np.array([0.0, 0.2, 0.1])  # where the bias model's constant input enters
A4 = np.block([[A, E[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]])
B4, C4 = np.vstack([B, [[0.0]]]), np.hstack([C, np.zeros((2, 1))])
Q4, P04, X04 = np.diag([0.01, 0.02, 0.005, 1e-3]), np.diag([2.0, 2.0, 2.0, 0.5]), np.append(X0, 0.0)


def biased_plant():
    x = signals(("a", "m"), ("b", "m/s"), ("c", "-"), ("bias", "N"), group="state")
    return system("biased", "linear plant with a constant input bias as a state", x=x,
                  u=signals(("f", "N"), group="input"),
                  rhs=lambda x, u, d, p: ca.mtimes(ca.DM(A4), x) + ca.mtimes(ca.DM(B4), u),
                  y=signals(("a_m", "m"), ("c_m", "-"), group="output"),
                  output=lambda x, u, p: ca.mtimes(ca.DM(C4), x), dt=0.1)


def numpy_bank(Y, U, p_min, prior, reset):
    """Two Kalman filters (3 and 4 states), Bayes in log space with the floor, fusion of a, b, c, reset."""
    models = [(A, B, C, Q, X0.copy(), P0.copy()), (A4, B4, C4, Q4, X04.copy(), P04.copy())]
    states = [[m[4], m[5]] for m in models]
    logp = np.log(np.asarray(prior) / np.sum(prior))
    probabilities, fused_all = [], []
    for y, u in zip(Y, U):
        posts, logliks = [], []
        for (_, _, Cm, _, _, _), (x, P) in zip(models, states):
            S = Cm @ P @ Cm.T + R
            K = P @ Cm.T @ np.linalg.inv(S)
            logliks.append(multivariate_normal(Cm @ x, S).logpdf(y))
            posts.append([x + K @ (y - Cm @ x), P - K @ S @ K.T])
        logp = logp + np.array(logliks)
        logp = np.maximum(logp - logsumexp(logp), np.log(p_min))
        logp = logp - logsumexp(logp)
        p = np.exp(logp)
        fused = p[0] * posts[0][0] + p[1] * posts[1][0][:3]
        if reset:
            posts[0][0] = fused.copy()
            posts[1][0][:3] = fused
        states = [[Am @ x + Bm @ u, Am @ P @ Am.T + Qm] for (Am, Bm, _, Qm, _, _), (x, P) in zip(models, posts)]
        probabilities.append(p)
        fused_all.append(fused)
    return np.array(probabilities), np.array(fused_all)


@pytest.mark.parametrize("make", [unscented_filter, extended_filter])
@pytest.mark.parametrize("reset", [True, False])
def test_bank_equals_a_numpy_bank_of_kalman_filters(make, reset):
    rng = np.random.default_rng(3)
    U = rng.normal(size=(200, 1))
    x, Y = np.append(X0, 0.0), []
    for k in range(200):  # data from the biased plant, bias switching on half way
        x[3] = 0.0 if k < 100 else 2.0
        Y.append(C4 @ x + rng.multivariate_normal(np.zeros(2), R))
        x = A4 @ x + B4 @ U[k]
    Y = np.array(Y)
    filters = {"plain": make(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, x0=X0, name="plain"),
               "biased": make(biased_plant(), dt=0.1, Q=Q4, R=R, P0=P04, x0=X04, name="biased")}
    bank = mmae_bank(filters, p_min=1e-3, prior=(0.9, 0.1), reset=reset)
    _, OUT = run_filter(bank, Y, U)
    p_expected, fused_expected = numpy_bank(Y, U, 1e-3, (0.9, 0.1), reset)
    names = bank.publishes.names
    np.testing.assert_allclose(OUT[:, [names.index("p_plain"), names.index("p_biased")]], p_expected, atol=1e-9)
    np.testing.assert_allclose(OUT[:, [names.index(f"{s}_hat") for s in "abc"]], fused_expected, atol=1e-9)
    assert "biased.bias_hat" in names and p_expected[150:, 1].min() > 0.95  # the data do discriminate
    assert p_expected.min() >= 1e-3 * 0.99  # the floor holds (up to the renormalisation)


def test_log_normalised_is_log_softmax():
    v = np.array([-1e4, 3.0, 2.5, -700.0])
    got = np.asarray(ca.Function("f", [s := ca.SX.sym("v", 4)], [log_normalised(s)])(v)).ravel()
    np.testing.assert_allclose(got, v - logsumexp(v), atol=1e-12)


def test_bad_banks_are_refused():
    plain = unscented_filter(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, name="plain")
    other = extended_filter(biased_plant(), dt=0.1, Q=Q4, R=R, P0=P04, name="other")
    with pytest.raises(ObserverError, match="at least two"):
        mmae_bank({"plain": plain})
    with pytest.raises(ObserverError, match="p_min"):
        mmae_bank({"plain": plain, "other": other}, p_min=0.6)
    with pytest.raises(ObserverError, match="prior"):
        mmae_bank({"plain": plain, "other": other}, prior=(1.0, -1.0))
    with pytest.raises(ObserverError, match="GaussianFilter"):
        mmae_bank({"plain": plain, "other": object()})
    slow = unscented_filter(system("slow", "", x=signals(("a", "m"), group="state"), u=signals(("f", "N")),
                                   rhs=lambda x, u, d, p: x, dt=0.2, y=signals(("a_m", "m"), ("c_m", "-")),
                                   output=lambda x, u, p: ca.vertcat(x, x)), dt=0.2, Q=1.0, R=R, P0=1.0)
    with pytest.raises(ObserverError, match="sampled every"):
        mmae_bank({"plain": plain, "slow": slow})


def test_a_nan_measurement_leaves_the_probabilities_and_says_so():
    rng = np.random.default_rng(5)
    Y, U = rng.normal(size=(30, 2)), rng.normal(size=(30, 1))
    Y[12, 0] = np.nan
    bank = mmae_bank({"plain": extended_filter(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, name="plain"),
                      "biased": unscented_filter(biased_plant(), dt=0.1, Q=Q4, R=R, P0=P04, name="biased")})
    S, OUT = run_filter(bank, Y, U)
    names = bank.publishes.names
    assert OUT[:, names.index("skipped")].tolist() == [float(k == 12) for k in range(30)]
    np.testing.assert_array_equal(S[13, -2:], S[12, -2:])  # log-probabilities carried over unchanged
    assert OUT[12, names.index("loglik_plain")] == 0.0 and np.all(np.isfinite(OUT))


def test_log_normalised_takes_its_shift_from_every_entry():
    v = np.array([0.0, 900.0, -3.0])  # the largest in the second place: exp(900) alone would overflow
    got = np.asarray(ca.Function("f", [s := ca.SX.sym("v", 3)], [log_normalised(s)])(v)).ravel()
    np.testing.assert_allclose(got, [-900.0, 0.0, -903.0], atol=1e-12)  # exp(-900) is 0 next to 1


def test_a_model_reading_other_signals_is_named_with_both_lists():
    plain = unscented_filter(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, name="plain")
    other = unscented_filter(system("other", "", x=signals(("a", "m"), group="state"), u=signals(("f", "N")),
                                    rhs=lambda x, u, d, p: x, dt=0.1, y=signals(("a_m", "m"), ("z_m", "-")),
                                    output=lambda x, u, p: ca.vertcat(x, x)), dt=0.1, Q=1.0, R=R, P0=1.0)
    with pytest.raises(ObserverError) as error:
        mmae_bank({"plain": plain, "other": other})
    assert str(error.value) == ("model other reads y = ('a_m', 'z_m'), the first model ('a_m', 'c_m'); "
                                "a bank's models read the same signals")


def test_the_bank_resets_by_default_and_labels_what_it_publishes():
    filters = {"plain": extended_filter(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, name="plain"),
               "biased": unscented_filter(biased_plant(), dt=0.1, Q=Q4, R=R, P0=P04, name="biased")}
    bank = mmae_bank(filters)
    assert bank.description == ("MMAE bank of EKF/UKF models plain, biased (floor 0.001, federated reset), "
                                "sampled every 0.1 s")
    assert mmae_bank(filters, reset=False).description.endswith("(floor 0.001, no reset), sampled every 0.1 s")
    units = dict(zip(bank.publishes.names, bank.publishes.units))
    assert [units[n] for n in ("loglik_plain", "loglik_biased", "pd_margin", "skipped", "p_plain")] == ["-"] * 5
    rng = np.random.default_rng(8)
    Y, U = rng.normal(size=(15, 2)), rng.normal(size=(15, 1))
    default, reset = (run_filter(b, Y, U)[1] for b in (bank, mmae_bank(filters, reset=True)))
    np.testing.assert_array_equal(default, reset)


def test_a_bad_model_name_is_refused_as_a_model_name():
    plain = extended_filter(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, name="plain")
    with pytest.raises(ObserverError, match=r"^model name 'no good' must start with a letter"):
        mmae_bank({"plain": plain, "no good": plain})


def test_the_bank_reads_inputs_and_parameters_by_name():
    plain = extended_filter(linear_plant(), dt=0.1, Q=Q, R=R, P0=P0, name="plain")
    bank = mmae_bank({"plain": plain, "again": plain})
    assert (bank.reads_u.group, bank.params.group) == ("input", "parameter")
    with pytest.raises(ObserverError, match=r"^no parameter named \['k'\]; known: none$"):
        bank.parameters({"k": 1.0})
    with pytest.raises(ObserverError, match=r"^no input named \['g'\]; known: f$"):
        bank.initial_state([0.0, 0.0], {"f": 0.0, "g": 1.0})
