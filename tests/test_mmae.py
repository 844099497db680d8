"""The MMAE bank against an independent numpy bank of Kalman filters (unequal state sizes,
log-space Bayes with a floor, fusion, reset), and its typed errors."""

import casadi as ca
import numpy as np
import pytest
from scipy.special import logsumexp
from scipy.stats import multivariate_normal
from test_ukf import P0, X0, A, B, C, Q, R, linear_plant

from uvsym.errors import ObserverError
from uvsym.observers.ekf import ekf, extended_filter
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
    """Two Kalman filters (3 and 4 states), Bayes in log space with the floor, fusion of a, b, c, reset;
    also each filter's NIS r^T S^-1 r and the bias's posterior standard deviation."""
    models = [(A, B, C, Q, X0.copy(), P0.copy()), (A4, B4, C4, Q4, X04.copy(), P04.copy())]
    states = [[m[4], m[5]] for m in models]
    logp = np.log(np.asarray(prior) / np.sum(prior))
    probabilities, fused_all, nis_all, std_all = [], [], [], []
    for y, u in zip(Y, U):
        posts, logliks, nis = [], [], []
        for (_, _, Cm, _, _, _), (x, P) in zip(models, states):
            S = Cm @ P @ Cm.T + R
            K = P @ Cm.T @ np.linalg.inv(S)
            logliks.append(multivariate_normal(Cm @ x, S).logpdf(y))
            nis.append((y - Cm @ x) @ np.linalg.solve(S, y - Cm @ x))
            posts.append([x + K @ (y - Cm @ x), P - K @ S @ K.T])
        logp = logp + np.array(logliks)
        logp = np.maximum(logp - logsumexp(logp), np.log(p_min))
        logp = logp - logsumexp(logp)
        p = np.exp(logp)
        nis_all.append(nis)
        std_all.append(np.sqrt(posts[1][1][3, 3]))
        fused = p[0] * posts[0][0] + p[1] * posts[1][0][:3]
        if reset:
            posts[0][0] = fused.copy()
            posts[1][0][:3] = fused
        states = [[Am @ x + Bm @ u, Am @ P @ Am.T + Qm] for (Am, Bm, _, Qm, _, _), (x, P) in zip(models, posts)]
        probabilities.append(p)
        fused_all.append(fused)
    return np.array(probabilities), np.array(fused_all), np.array(nis_all), np.array(std_all)


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
    p_expected, fused_expected, nis_expected, std_expected = numpy_bank(Y, U, 1e-3, (0.9, 0.1), reset)
    names = bank.publishes.names
    np.testing.assert_allclose(OUT[:, [names.index("p_plain"), names.index("p_biased")]], p_expected, atol=1e-9)
    np.testing.assert_allclose(OUT[:, [names.index(f"{s}_hat") for s in "abc"]], fused_expected, atol=1e-9)
    np.testing.assert_allclose(OUT[:, [names.index("nis_plain"), names.index("nis_biased")]], nis_expected,
                               rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(OUT[:, names.index("biased.bias_std")], std_expected, rtol=1e-7)
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


def scalar_filter(name, gain=1.0, *, dt=0.1, k0=1.0, extra=0):
    """EKF of a' = -k a + f (plus ``extra`` decaying states e0, e1, ...), y = (a, gain a), R = I, P0 = I."""
    n = 1 + extra
    x = signals(("a", "m", "position"), *[(f"e{i}", "-") for i in range(extra)], group="state")
    plant = system(name, "", x=x, u=signals(("f", "N")), p=signals(("k", "1/s")), p0=[k0],
                   rhs=lambda x, u, d, p: -p[0] * x + ca.vertcat(u, ca.SX.zeros(extra)),
                   y=signals(("y1", "m"), ("y2", "m")), output=lambda x, u, p: ca.vertcat(x[0], gain * x[0]))
    return extended_filter(plant, dt=dt, Q=0.01 * np.eye(n), R=np.eye(2), P0=np.eye(n), x0=np.ones(n), name=name)


def test_log_normalised_takes_its_shift_also_from_the_first_entry():
    v = np.array([900.0, 0.0, -3.0])  # the largest first: a shift from the others alone overflows exp
    got = np.asarray(ca.Function("f", [s := ca.SX.sym("v", 3)], [log_normalised(s)])(v)).ravel()
    np.testing.assert_allclose(got, [0.0, -900.0, -903.0], atol=1e-12)


def test_the_bank_labels_its_state_and_takes_name_parameters_and_signals_from_the_first_model():
    bank = mmae_bank({"one": scalar_filter("one", k0=1.5), "two": scalar_filter("two", 0.5, k0=2.0)})
    assert bank.name == "mmae"
    assert bank.state.names == ("one.a_hat", "one.P.a.a", "two.a_hat", "two.P.a.a", "logp.one", "logp.two")
    assert bank.state.units == ("m", "m m", "m", "m m", "-", "-")
    assert bank.state.descriptions[-2:] == ("log probability of model one", "log probability of model two")
    assert bank.state.group == "state"
    np.testing.assert_array_equal(bank.p0, [1.5])  # the first model's default k, not the second's 2.0
    assert (bank.params.names, bank.params.group) == (("k",), "parameter")
    assert (bank.reads_y.names, bank.reads_y.group, bank.reads_u.group) == (("y1", "y2"), "measurement", "input")
    described = dict(zip(bank.publishes.names, bank.publishes.descriptions))
    assert [described[n] for n in ("p_one", "pd_margin", "skipped")] == [
        "probability of model one", "smallest relative Cholesky pivot of the bank's step (> 0: P.D.)",
        "1 where y_k had a NaN and the updates were skipped"]


@pytest.mark.parametrize("order", [("twin", "half"), ("half", "twin")])
def test_pd_margin_is_the_smallest_pivot_over_every_model(order):
    # first update, P = 1, R = I: S = [[2, g], [g, 1 + g^2]], relative pivots 1 and 1 - g^2 / (2 (1 + g^2)):
    # 3/4 for g = 1 (twin), 0.9 for g = 1/2 (half); the scalar predictions' pivots are 1
    gains = {"twin": 1.0, "half": 0.5}
    bank = mmae_bank({m: scalar_filter(m, gains[m]) for m in order})
    _, OUT = run_filter(bank, np.array([[0.3, -0.2]]), np.array([[0.0]]))
    assert OUT[0, bank.publishes.names.index("pd_margin")] == pytest.approx(0.75, abs=1e-9)


def test_a_model_with_own_states_first_publishes_them_as_a_lone_filter_would():
    deep = scalar_filter("deep", extra=5)
    bank = mmae_bank({"deep": deep, "one": scalar_filter("one", 0.5)}, reset=False)  # the filters run apart
    rng = np.random.default_rng(4)
    Y, U = rng.normal(size=(6, 2)), rng.normal(size=(6, 1))
    alone = ekf(deep.system, dt=0.1, Q=0.01 * np.eye(6), R=np.eye(2), P0=np.eye(6), x0=np.ones(6), name="deep")
    own = [f"e{i}_hat" for i in range(5)]
    got = run_filter(bank, Y, U)[1][:, [bank.publishes.names.index(f"deep.{n}") for n in own]]
    np.testing.assert_allclose(got, run_filter(alone, Y, U)[1][:, alone.publishes.indices(own)], atol=1e-12)
    np.testing.assert_allclose(got[:, 0], np.exp(-0.1 * np.arange(6)), rtol=1e-6)  # e' = -e from 1, unmeasured


def test_a_six_state_model_may_come_last():
    bank = mmae_bank({"one": scalar_filter("one"), "deep": scalar_filter("deep", extra=5)})
    assert bank.state.size == (1 + 1) + (6 + 21) + 2  # x, tril(P) of each model, then the log-probabilities
    assert bank.state.names[-3:] == ("deep.P.e4.e4", "logp.one", "logp.deep")
    _, OUT = run_filter(bank, np.array([[0.3, -0.2]]), np.array([[0.0]]))
    assert OUT[0, bank.publishes.indices(["p_one", "p_deep"])].sum() == pytest.approx(1.0, abs=1e-12)


def test_bad_bank_arguments_are_named_word_for_word():
    one, two = scalar_filter("one"), scalar_filter("two", 0.5)
    with pytest.raises(ObserverError, match=r"^observer name 'no good' must start with a letter"):
        mmae_bank({"one": one, "two": two}, name="no good")
    for p_min in (0.0, 0.5):  # the open interval (0, 1/2) for two models
        with pytest.raises(ObserverError, match=rf"^mmae: p_min must be in \(0, 1/2\), got {p_min}$"):
            mmae_bank({"one": one, "two": two}, p_min=p_min)
    for prior in ((1.0, 1.0, 1.0), (1.0, 0.0), (None, 1.0), ("x", 1.0)):
        with pytest.raises(ObserverError) as error:
            mmae_bank({"one": one, "two": two}, prior=prior)
        assert str(error.value) == "mmae: prior must be 2 positive probabilities (one, two)"
    with pytest.raises(ObserverError) as error:
        mmae_bank({"one": one, "two": object()})
    assert str(error.value) == "model two: expected a GaussianFilter (unscented_filter, extended_filter), got object"
    apart = extended_filter(system("apart", "", x=signals(("z", "m"), group="state"), u=signals(("f", "N")),
                                   p=signals(("k", "1/s")), rhs=lambda x, u, d, p: -x,
                                   y=signals(("y1", "m"), ("y2", "m")), output=lambda x, u, p: ca.vertcat(x, x)),
                            dt=0.1, Q=1.0, R=np.eye(2), P0=1.0)
    with pytest.raises(ObserverError) as error:
        mmae_bank({"one": one, "apart": apart})
    assert str(error.value) == "the bank's models share no state to fuse"


def test_an_unnormalised_prior_is_normalised():
    bank = mmae_bank({"one": scalar_filter("one"), "two": scalar_filter("two", 0.5)}, prior=(3, 1))
    np.testing.assert_allclose(bank.initial_state([0.0, 0.0], [0.0])[-2:], np.log([0.75, 0.25]), rtol=1e-15)


def test_sample_periods_agree_to_one_part_in_a_million_million_of_the_first():
    dt = 2.0**-43 / 1e-12  # 1e-12 dt is 2^-43 exactly, and dt + 2^-43 is a float 2^-43 away from dt
    assert 1e-12 * dt == 2.0**-43 and (dt + 2.0**-43) - dt == 2.0**-43
    bank = mmae_bank({"one": scalar_filter("one", dt=dt), "two": scalar_filter("two", 0.5, dt=dt + 2.0**-43)})
    assert bank.dt == dt  # on the boundary: accepted
    with pytest.raises(ObserverError, match="^model two is sampled every 0.1 s, the first model every 0.1 s$"):
        mmae_bank({"one": scalar_filter("one"), "two": scalar_filter("two", 0.5, dt=0.1 + 5e-13)})
    # the bank runs and is described at the first model's period, here just below a 6-digit rounding boundary
    early, late = 0.10000049999999999, 0.1000005
    assert (f"{early:g}", f"{late:g}") == ("0.1", "0.100001") and late - early < 1e-12 * early
    bank = mmae_bank({"one": scalar_filter("one", dt=early), "two": scalar_filter("two", 0.5, dt=late)})
    assert bank.dt == early and bank.description.endswith("sampled every 0.1 s")
