"""The LMS-FIR monitor, its double criterion and the step-size claim, against independent oracles."""

from __future__ import annotations

import warnings
from fractions import Fraction
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from uvsym.codegen import find_compiler
from uvsym.codegen.estimators import exported_observer
from uvsym.codegen.observer_sets import ObserverSet
from uvsym.errors import ObserverError, StepSizeWarning, VerificationError
from uvsym.observers.lms import check_mu, lms_monitor, lms_step, mu_bound
from uvsym.observers.lms_supervisor import SubstitutionSupervisor, double_criterion, switch_flag
from uvsym.systems.signals import signals
from uvsym.verify.lms import lms_step_claim

Y = signals(("y", "m", "sensor"), group="output")
U = signals(("u", "-", "input"), group="input")
REF = signals(("r", "m", "reference"), group="input")


def monitor(M=4, mu=0.01, window=5, hold=1, confirm=3, eps0=1.0, r0=2.0, reference=None):
    return lms_monitor(Y, U, order=M, mu=mu, eps0=eps0, r0=r0, dt=0.1, window=window, hold=hold, confirm=confirm,
                       reference=reference)


def regressors(u: np.ndarray, M: int) -> np.ndarray:
    """(N, M) rows [u_{k-1}, ..., u_{k-M}] (zeros before the start)."""
    padded = np.concatenate([np.zeros(M), u])
    return np.array([padded[k:k + M][::-1] for k in range(len(u))])


def test_lms_identifies_a_known_fir_filter():
    rng = np.random.default_rng(0)
    M, N = 4, 3000
    true = np.array([0.5, -0.3, 0.2, 0.1])
    u = rng.uniform(-1, 1, N)
    y = regressors(u, M) @ true
    obs = monitor(M=M, mu=0.05, eps0=1e6, r0=1e6)
    S, OUT = obs.run(y[:, None], u[:, None])
    np.testing.assert_allclose(S[-1, :M], true, atol=1e-6)  # the weights are the state's first M entries
    assert np.abs(OUT[-100:, obs.publishes.index("e_y")]).max() < 1e-6


def test_one_step_is_the_descending_lms_update_with_a_reference():
    rng = np.random.default_rng(1)
    M = 3
    obs = monitor(M=M, mu=0.02, reference=REF, window=4)
    s = obs.initial_state([0.0], [0.0, 0.0])
    C, hist = rng.normal(size=M), rng.normal(size=M)
    s[:M], s[M:2 * M] = C, hist
    y, u, r = 1.3, 0.4, 0.9
    s_next, out = (np.asarray(v).ravel() for v in obs.step(s, y, [u, r], obs.p0))
    d = C @ hist
    e = d - (y - r)
    np.testing.assert_allclose(s_next[:M], C - 2 * 0.02 * e * hist, rtol=1e-14)
    np.testing.assert_allclose(s_next[M:2 * M], [u, hist[0], hist[1]])
    names = obs.publishes.names
    assert out[names.index("y_fir")] == pytest.approx(r + d) and out[names.index("e_y")] == pytest.approx(e)
    assert out[names.index("eps2_y")] == pytest.approx(e ** 2)


def test_R_is_the_squared_z_score_of_the_newest_weight_sum_in_its_window():
    rng = np.random.default_rng(2)
    M, n, N = 3, 6, 80
    obs = monitor(M=M, mu=0.1, window=n, eps0=1e6, r0=1e6)
    u, y = rng.normal(size=N), rng.normal(size=N)
    S, OUT = obs.run(y[:, None], u[:, None])
    sums = S[:-1, :M].sum(axis=1)  # sum of the weights in use at each sample
    R = OUT[:, obs.publishes.index("R_y")]
    assert np.all(R[:n - 1] == 0.0)  # not before the window is full
    for k in range(n - 1, N):
        window = sums[k - n + 1:k + 1]
        assert R[k] == pytest.approx((window[-1] - window.mean()) ** 2 / window.var(), rel=1e-9)


def test_a_single_large_error_gives_R_exactly_n_minus_1_and_hold_filters_it():
    M, n, spike = 2, 8, 25
    true = np.array([0.5, -0.25])
    u = np.array([1.0, 2.0, -1.0, 0.0, 3.0] * 8)  # dyadic values: the healthy error is exactly 0
    y = regressors(u, M) @ true
    y[spike] += 5.0
    for hold, fires in ((1, True), (2, False)):
        obs = monitor(M=M, mu=0.01, window=n, hold=hold, eps0=1.0, r0=n - 1.5)
        s0 = obs.initial_state([0.0], [0.0])
        s0[:M] = true
        _, OUT = obs.run(y[:, None], u[:, None], s0=s0)
        R = OUT[:, obs.publishes.index("R_y")]
        assert R[spike + 1] == pytest.approx(n - 1, rel=1e-9)  # closed form: one outlier among n
        assert np.all(R[:spike + 1] == 0.0)  # constant weights: no spread, no statistic
        assert bool(OUT[:, obs.publishes.index("alarm_R_y")].any()) is fires
        assert OUT[spike, obs.publishes.index("alarm_eps2_y")] == 1.0


def decide_sequence(a_e, a_r, confirm=3):
    decide = double_criterion(confirm)
    d, rows = np.zeros(3), []
    for e, r in zip(a_e, a_r):
        d_next, snapshot, released = (np.asarray(v).ravel() for v in decide(d, e, r))
        rows.append((*d_next, snapshot[0], released[0]))
        d = d_next
    return np.array(rows)  # frozen, age, fault, snapshot, released


def test_double_criterion_confirms_a_fault_only_when_R_fires_within_the_window():
    zeros = [0] * 10
    both = decide_sequence([0, 1, 1, 1, 1, 1, 0, 0, 0, 0], [0, 0, 0, 1, 0, 0, 0, 0, 0, 0])
    assert list(both[:, 3]) == [0, 1] + [0] * 8  # one snapshot, at the first eps2 alarm
    assert list(both[:, 2]) == [0, 0, 0, 1, 1, 1, 1, 1, 1, 1]  # confirmed when R fires, then latched
    only_eps = decide_sequence([0, 1, 0, 0, 0, 0, 1, 0, 0, 0], zeros)
    assert list(only_eps[:, 4]) == [0, 0, 0, 0, 1, 0, 0, 0, 0, 1]  # released confirm = 3 samples after each
    assert list(only_eps[:, 0]) == [0, 1, 1, 1, 0, 0, 1, 1, 1, 0]  # and frozen anew by the next alarm
    assert not only_eps[:, 2].any()
    only_r = decide_sequence(zeros, [0, 1, 1, 1, 0, 0, 0, 0, 0, 0])
    assert not only_r[:, [0, 2, 3]].any()
    late = decide_sequence([0, 1] + [0] * 8, [0] * 5 + [1] + [0] * 4)
    assert not late[:, 2].any()


def test_frozen_filter_predicts_with_the_weights_of_the_alarm_sample():
    rng = np.random.default_rng(3)
    M, N, onset = 3, 60, 40
    u = rng.uniform(-1, 1, N)
    y = regressors(u, M) @ np.array([0.3, 0.2, -0.1]) + 0.01 * rng.normal(size=N)
    y[onset:] += 2.0
    obs = monitor(M=M, mu=0.2, eps0=0.5, r0=1e6, confirm=100)
    S, OUT = obs.run(y[:, None], u[:, None])
    names = obs.publishes.names
    assert np.flatnonzero(OUT[:, names.index("alarm_eps2_y")])[0] == onset
    frozen = S[onset, :M]  # weights in use at the alarm sample, before its update
    expected = regressors(u, M)[onset:] @ frozen
    np.testing.assert_allclose(OUT[onset:, names.index("y_sub")], expected, rtol=1e-12)
    assert not np.allclose(S[-1, :M], frozen)  # the live filter kept learning


@pytest.mark.parametrize("argument, kwargs", [
    ("order M", {"M": 0}), ("mu", {"mu": 0.0}), ("mu", {"mu": -1.0}), ("eps0", {"eps0": 0.0}), ("r0", {"r0": -2.0}),
    ("window n", {"window": 1}), ("hold", {"hold": 0}), ("confirm", {"confirm": 0}), ("order M", {"M": 2.5})])
def test_bad_settings_are_typed_errors_naming_the_argument(argument, kwargs):
    with pytest.raises(ObserverError, match=argument):
        monitor(**kwargs)


def test_monitor_reads_exactly_one_sensor_and_one_input():
    two = signals(("y1", "m"), ("y2", "m"), group="output")
    with pytest.raises(ObserverError, match="measured must be one signal"):
        lms_monitor(two, U, order=3, mu=0.1, eps0=1.0, r0=2.0, dt=0.1)
    with pytest.raises(ObserverError, match="reference must be one signal"):
        lms_monitor(Y, U, order=3, mu=0.1, eps0=1.0, r0=2.0, dt=0.1, reference=two)


def test_step_size_bound_and_warning():
    assert mu_bound(70, 0.25) == pytest.approx(1 / 17.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_mu(0.05, 70, 0.25)  # below 1/17.5: silent
    with pytest.warns(StepSizeWarning, match=r"bound 1 / \(M P_u\) = 0.05714"):
        check_mu(0.06, 70, 0.25)
    with pytest.raises(ObserverError, match="input power"):
        mu_bound(70, 0.0)


def test_step_claim_decides_the_inequality_exactly():
    u = np.array([1.0, 1.0, 1.0, 1.0])  # P_u = 1 exactly
    at_bound = lms_step_claim(0.25, 4, u, expected="refuted")  # mu M P_u = 1 exactly: not below
    assert at_bound.status == "refuted" and at_bound.details["mu_M_P_u"] == 1.0
    below = lms_step_claim(0.1, 3, np.array([0.1, -0.3, 0.2]))
    power = (Fraction(0.1) ** 2 + Fraction(-0.3) ** 2 + Fraction(0.2) ** 2) / 3
    assert below.status == "proved" and below.margin == pytest.approx(float(1 - Fraction(0.1) * 3 * power))
    with pytest.raises(VerificationError, match="mu"):
        lms_step_claim(-1.0, 3, u)
    with pytest.raises(VerificationError, match="input samples"):
        lms_step_claim(0.1, 3, np.array([np.nan]))


def test_beyond_the_bound_the_filter_diverges_below_it_converges():
    rng = np.random.default_rng(4)
    M, N = 8, 400
    u = rng.uniform(-1, 1, N)
    y = regressors(u, M) @ rng.normal(size=M)
    bound = mu_bound(M, float(np.mean(u ** 2)))
    sizes = {}
    for factor in (0.1, 2.0):
        S, _ = monitor(M=M, mu=factor * bound, eps0=1e300, r0=1e6).run(y[:, None], u[:, None])
        sizes[factor] = np.abs(S[-1, :M]).max()
    assert sizes[0.1] < 10 and sizes[2.0] > 1e6


def test_supervisor_substitutes_once_confirmed_and_logs():
    obs = monitor(M=2)
    names = obs.publishes.names
    flags = np.zeros((6, len(names)))
    flags[2:, names.index("frozen_y")] = 1
    flags[4:, names.index("fault_y")] = 1
    supervisor = SubstitutionSupervisor(obs)
    decision = supervisor.update(np.arange(6) * 0.1, {obs.name: flags})
    assert decision.channels == frozenset({"y"})
    assert [e.sample for e in supervisor.events[:2]] == [2, 4]
    with pytest.raises(ObserverError, match="substitute_on"):
        SubstitutionSupervisor(obs, substitute_on="never")


def test_supervisor_on_alarm_switches_in_at_the_freeze_and_back_at_the_release():
    obs = monitor(M=2)
    names = obs.publishes.names
    supervisor = SubstitutionSupervisor(obs, substitute_on="alarm")
    flags = np.zeros((1, len(names)))
    decisions = []
    for frozen, released in ((0, 0), (1, 0), (1, 0), (0, 1), (0, 0)):
        flags[0, names.index("frozen_y")], flags[0, names.index("disturbance_y")] = frozen, released
        decisions.append(supervisor.update(np.array([0.1 * len(decisions)]), {obs.name: flags.copy()}))
    assert decisions[0] is None and decisions[1].channels == frozenset({"y"})
    assert decisions[2] is None and decisions[3].channels == frozenset() and decisions[4] is None
    assert supervisor.first("no R alarm").sample == 3


def test_published_signals_do_not_depend_on_the_input_of_the_same_sample():
    # what lets a loop switch to the substitute within the sample: out_k needs y_k and r_k, never u_k
    obs = monitor(M=3, reference=REF)
    f = obs.step.raw
    s, y, u, p = (ca.SX.sym(n, f.numel_in(i)) for i, n in enumerate(("s", "y", "u", "p")))
    out = f(s, y, u, p)[1]
    names = obs.publishes.names
    on_u = ca.jacobian_sparsity(out, u[0]).get_triplet()[0]
    on_y = {names[row] for row in ca.jacobian_sparsity(out, y).get_triplet()[0]}
    assert on_u == [] and ca.jacobian_sparsity(f(s, y, u, p)[0], u[0]).nnz() == 1  # u_k: into U_next only
    assert {"y_sub", "fault_y", "frozen_y", "e_y", "eps2_y"} <= on_y


def test_switch_flag_names_the_monitor_flag_of_each_rule_and_a_logging_supervisor_takes_any_chunk():
    obs = monitor(M=2)
    assert (switch_flag("y"), switch_flag("y", "alarm")) == ("fault_y", "frozen_y")
    assert {switch_flag("y", rule) for rule in ("fault", "alarm")} <= set(obs.publishes.names)
    with pytest.raises(ObserverError, match="substitute_on must be one of fault, alarm, got 'never'"):
        switch_flag("y", "never")
    names = obs.publishes.names
    flags = np.zeros((8, len(names)))
    flags[1:4, names.index("frozen_y")] = 1
    flags[4, names.index("disturbance_y")] = 1
    flags[6:, names.index("frozen_y")] = flags[7:, names.index("fault_y")] = 1
    whole, by_sample = SubstitutionSupervisor(obs, correct=False), SubstitutionSupervisor(obs, correct=False)
    assert whole.update(np.arange(8) * 0.1, {obs.name: flags}) is None
    for i in range(8):
        assert by_sample.update(np.array([0.1 * i]), {obs.name: flags[i:i + 1]}) is None
    assert [(e.sample, e.what[:5]) for e in whole.events] == [(1, "eps2 "), (4, "no R "), (6, "eps2 "), (7, "R ala")]
    assert whole.events == by_sample.events


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler")
def test_generated_c_of_the_monitor_matches_python(tmp_path):
    from uvsym.codegen.check import check_package

    obs = monitor(M=5, reference=REF)
    exported = (exported_observer(obs),)
    ObserverSet("uvsym_lms_test", "LMS monitor", exported).write(tmp_path)
    check = check_package(tmp_path, list(exported), "uvsym_lms_test")
    assert check.max_relative_difference <= 1e-12


def test_mu_bound_names_itself_in_its_error():
    with pytest.raises(ObserverError, match=r"^mu_bound: order M must be an integer in \[1, 4096\], got 0$"):
        mu_bound(0, 1.0)


def test_the_bare_step_names_its_symbols_as_its_inputs():
    # the symbols are what the serialized function (hashed into a C package's manifest) holds
    f = lms_step(3)
    assert [str(v) for v in f.mx_in()] == ["C", "U", "target", "u", "mu"] == f.name_in()


def test_units_and_labels_of_the_monitor_follow_its_signals():
    force = signals(("tau", "N", "thrust"), group="input")
    obs = lms_monitor(Y, force, order=2, mu=0.01, eps0=1.0, r0=2.0, dt=0.1, window=3)
    state = obs.state
    assert state.group == "state"
    assert dict(zip(state.names, state.units)) == {
        "C_1": "m/N", "C_2": "m/N", "U_1": "N", "U_2": "N", "S_1": "m/N", "S_2": "m/N", "S_3": "m/N",
        "Cf_1": "m/N", "Cf_2": "m/N", "frozen": "-", "age": "samples", "fault": "-", "count": "samples",
        "above": "samples"}
    assert obs.params.units == ("1/(N)^2", "(m)^2", "-")
    assert obs.publishes.descriptions[0] == "live FIR prediction r + d"
    assert monitor(M=1).state.units[0] == "m"  # a dimensionless input: the weights carry y's unit


def test_supervisor_log_times_texts_and_half_set_flags():
    obs = monitor(M=2)
    names = obs.publishes.names
    flags = np.zeros((5, len(names)))
    flags[1:, names.index("frozen_y")] = 1
    flags[2, names.index("fault_y")] = 0.5  # not above 0.5: not set
    flags[3:, names.index("fault_y")] = 1
    supervisor = SubstitutionSupervisor(obs)
    decisions = [supervisor.update(np.array([0.25 * i]), {obs.name: flags[i:i + 1]}) for i in range(5)]
    assert [d is not None for d in decisions] == [False, False, False, True, False]
    assert [(e.t, e.sample, e.what) for e in supervisor.events] == [
        (0.25, 1, "eps2 alarm: filter frozen"), (0.75, 3, "R alarm: sensor fault confirmed"),
        (0.75, 3, "substitution on from the next sample")]
    assert all(isinstance(e.t, float) for e in supervisor.events)


def test_step_claim_reports_its_figures_method_and_counterexample():
    u = np.array([1.0, -1.0, 1.0, -1.0])  # P_u = 1 exactly
    refuted = lms_step_claim(0.25, 4, u, expected="refuted")  # mu M P_u = 1: the bound 1/(M P_u) = 1/4
    assert refuted.reason == "mu M P_u = 1 >= 1"
    assert refuted.counterexample == {"mu_M_P_u": 1.0, "bound": 0.25}
    assert refuted.details == {"mu": 0.25, "order": 4, "input_power": 1.0, "samples": 4, "mu_M_P_u": 1.0,
                               "bound": 0.25}
    assert refuted.method == ("exact rational arithmetic on the samples' binary values; stability of the filter "
                              "from the independence-theory bound (Widrow & Stearns 1985)")
    single = lms_step_claim(0.5, 1, [2, 0])  # M = 1 is an order; P_u = (4 + 0) / 2 = 2, mu M P_u = 1
    assert single.status == "refuted" and single.details["input_power"] == 2.0
    tap = lms_step_claim(0.125, 1, [2, 0])  # 0.125 * 2 = 1/4
    assert tap.status == "proved" and tap.margin == 0.75 and tap.reason == "" and tap.counterexample is None
    with pytest.raises(VerificationError, match="input samples u must be finite"):
        lms_step_claim(0.1, 2, [1.0, None])  # a missing sample


def test_an_order_one_filter_is_the_scalar_lms_update():
    # M = 1: d = c u_{k-1}, c+ = c - 2 mu (d - y) u_{k-1}; by hand from c = 0.5, u_{k-1} = 2, y = 3, mu = 0.1:
    # d = 1, e = -2, c+ = 0.5 + 0.4 * 2 = 1.3, and the regression vector becomes [u_k]
    C_next, U_next, d, e = (float(v) for v in lms_step(1)(0.5, 2.0, 3.0, -4.0, 0.1))
    assert (C_next, U_next, d, e) == pytest.approx((1.3, -4.0, 1.0, -2.0), rel=1e-15)


def test_a_zero_sample_period_is_refused_naming_it():
    with pytest.raises(ObserverError, match=r"^lms: sample period dt must be a positive, finite number, got 0\.0$"):
        lms_monitor(Y, U, order=2, mu=0.01, eps0=1.0, r0=2.0, dt=0.0)


def test_the_monitor_describes_its_criteria_flags_and_settings():
    obs = lms_monitor(Y, U, order=2, mu=0.01, eps0=1.0, r0=2.0, dt=0.1, window=3, hold=2, confirm=4)
    described = dict(zip(obs.publishes.names, obs.publishes.descriptions))
    assert described["eps2_y"] == "error criterion e^2" and described["fault_y"] == "fault confirmed"
    assert obs.description == ("LMS-FIR monitor of y: order 2, R window 3, hold 2, confirm 4 samples; "
                               "p = (mu, eps0, r0); sampled every 0.1 s")


def test_the_regressor_and_the_reference_are_both_inputs():
    obs = monitor(M=2, reference=REF)
    assert obs.reads_u.names == ("u", "r") and obs.reads_u.group == "input"
    with pytest.raises(ObserverError, match=r"^no input named \['v'\]; known: u, r$"):
        obs.initial_state([0.0], {"u": 0.0, "r": 0.0, "v": 1.0})


@pytest.mark.parametrize("confirm", [0, -3, True, 2.0])
def test_double_criterion_refuses_a_confirm_that_is_not_a_positive_integer(confirm):
    with pytest.raises(ObserverError, match=r"^double criterion: confirm must be a positive integer \(samples\)"):
        double_criterion(confirm)


def test_step_claim_of_a_silent_input_has_no_bound_and_states_its_claim():
    silent = lms_step_claim(0.1, 2, [0.0, 0.0, 0.0])  # P_u = 0: mu M P_u = 0 < 1 for any mu, no finite bound
    assert (silent.status, silent.margin, silent.details["bound"], silent.details["input_power"]) == (
        "proved", 1.0, None, 0.0)
    assert silent.claim == "LMS step mu = 0.1 below the mean-square bound 1 / (M P_u)"
    assert lms_step_claim(0.1, 2, [1.0], claim="mine").claim == "mine"


@pytest.mark.parametrize("kwargs, message", [
    ({"order": 0}, "sensor_mon: order M must be an integer in [1, 4096], got 0"),
    ({"window": 0}, "sensor_mon: window n must be an integer in [1, 4096], got 0"),
    ({"window": 1}, "sensor_mon: window n must be at least 2 samples (R needs a spread), got 1"),
    ({"confirm": 0}, "sensor_mon: confirm must be an integer in [1, 4096], got 0"),
    ({"hold": 0}, "sensor_mon: hold must be an integer in [1, 4096], got 0"),
    ({"mu": 0.0}, "sensor_mon: mu must be a positive, finite number, got 0.0"),
    ({"mu": True}, "sensor_mon: mu must be a positive, finite number, got True"),  # a flag is not a step
    ({"mu": "0.1"}, "sensor_mon: mu must be a positive, finite number, got '0.1'"),
    ({"eps0": float("inf")}, "sensor_mon: eps0 must be a positive, finite number, got inf"),
    ({"r0": -2.0}, "sensor_mon: r0 must be a positive, finite number, got -2.0")])
def test_bad_settings_give_the_full_message_with_the_monitor_name(kwargs, message):
    settings = {"order": 2, "mu": 0.01, "eps0": 1.0, "r0": 2.0, "dt": 0.1, "name": "sensor_mon"} | kwargs
    with pytest.raises(ObserverError) as info:
        lms_monitor(Y, U, **settings)
    assert str(info.value) == message


def test_bad_names_and_signals_of_the_monitor_are_refused_naming_them():
    with pytest.raises(ObserverError, match=r"^observer name '2lms' must start with a letter"):
        lms_monitor(Y, U, order=2, mu=0.01, eps0=1.0, r0=2.0, dt=0.1, name="2lms")
    two = signals(("u1", "-"), ("u2", "-"), group="input")
    with pytest.raises(ObserverError, match=r"^lms: regressor must be one signal \(a Signals of size 1\)"):
        lms_monitor(Y, two, order=2, mu=0.01, eps0=1.0, r0=2.0, dt=0.1)


def test_bare_step_and_bound_refuse_bad_arguments_naming_themselves():
    with pytest.raises(ObserverError, match=r"^lms_step: order M must be an integer in \[1, 4096\], got 0$"):
        lms_step(0)
    with pytest.raises(ObserverError, match=r"^mu_bound: input power P_u must be a positive, finite number, got 0\.0$"):
        mu_bound(4, 0.0)


def test_the_bare_step_names_itself_and_its_outputs_as_documented():
    f = lms_step(2)
    assert f.name() == "lms_fir_step" and f.name_out() == ["C_next", "U_next", "d", "e"]


def test_check_mu_warns_at_the_bound_itself_naming_mu_and_the_caller():
    # M = 4, P_u = 1/4: the bound 1 / (M P_u) is exactly 1, so mu = 1 is "at" it
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert check_mu(1.0, 4, 0.25) == 1.0
    assert len(caught) == 1 and caught[0].category is StepSizeWarning
    assert str(caught[0].message) == ("mu = 1 is at or beyond the mean-square stability bound 1 / (M P_u) = 1 "
                                      "(M = 4, input power P_u = 0.25): the LMS weights may diverge")
    # points at the caller: this file, or the wrapper mutmut puts between a test and a mutated function
    assert caught[0].filename == __file__ or "mutmut" in Path(caught[0].filename).parts
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_mu(0.875, 4, 0.25)  # just below: silent


def test_default_window_hold_and_confirm():
    obs = lms_monitor(Y, U, order=2, mu=0.01, eps0=1.0, r0=2.0, dt=0.1)
    assert "R window 20, hold 3, confirm 10 samples" in obs.description
    assert sum(name.startswith("S_") for name in obs.state.names) == 20


def test_parameters_publications_and_groups_of_the_monitor():
    y = signals(("psi", "rad", "heading"), group="output")  # groups other than the monitor's own
    u = signals(("delta", "-", "rudder"), group="output")
    r = signals(("psi_ref", "rad", "set-point"), group="signal")
    obs = lms_monitor(y, u, order=2, mu=0.01, eps0=1.0, r0=2.0, dt=0.1, reference=r)
    assert (obs.params.names, obs.params.units, obs.params.group) == (("mu", "eps0", "r0"), ("-", "(rad)^2", "-"),
                                                                      "parameter")
    assert obs.params.descriptions == ("LMS step", "threshold of eps^2", "threshold of R")
    assert (obs.reads_y.group, obs.reads_u.group, obs.publishes.group) == ("measurement", "input", "published")
    assert lms_monitor(y, u, order=2, mu=0.01, eps0=1.0, r0=2.0, dt=0.1).reads_u.group == "input"
    assert {n: (unit, text) for n, unit, text in zip(*(getattr(obs.publishes, a) for a in (
            "names", "units", "descriptions")))} == {
        "psi_fir": ("rad", "live FIR prediction r + d"),
        "psi_sub": ("rad", "substitute: the frozen filter's prediction while frozen"),
        "e_psi": ("rad", "prediction error d - (y - r)"), "eps2_psi": ("(rad)^2", "error criterion e^2"),
        "R_psi": ("-", "weight-drift criterion"), "alarm_eps2_psi": ("-", "eps^2 > eps0"),
        "alarm_R_psi": ("-", "R > r0"), "frozen_psi": ("-", "filter frozen"), "fault_psi": ("-", "fault confirmed"),
        "disturbance_psi": ("-", "freeze released: a disturbance")}


def test_an_input_without_unit_leaves_the_weights_in_the_unit_of_y():
    bare = signals(("u", "", "input"), group="input")
    obs = lms_monitor(Y, bare, order=1, mu=0.01, eps0=1.0, r0=2.0, dt=0.1, window=2)
    assert obs.state.units[:1] == ("m",) and obs.params.units == ("-", "(m)^2", "-")


def test_both_alarms_need_strictly_more_than_their_threshold():
    # M = 1, n = 2: s = [C, U, S_1, S_2, Cf, frozen, age, fault, count, above]. C = U = 1, y = 1.5: e = -0.5,
    # e^2 = 1/4. The window becomes (3, 1): two distinct values are each half their gap from the mean, so
    # their squared z-score is exactly 1 (= n - 1)
    obs = lms_monitor(Y, U, order=1, mu=0.01, eps0=1.0, r0=1.0, dt=0.1, window=2, hold=1, confirm=3)
    s = np.array([1.0, 1.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0])
    names = obs.publishes.names

    def alarms(eps0, r0):
        out = np.asarray(obs.step(s, 1.5, 0.0, [0.01, eps0, r0])[1]).ravel()
        assert out[names.index("R_y")] == 1.0 and out[names.index("eps2_y")] == 0.25
        return out[names.index("alarm_eps2_y")], out[names.index("alarm_R_y")]

    assert alarms(0.25, 1.0) == (0.0, 0.0)  # at the thresholds: no alarm
    assert alarms(0.2, 0.9) == (1.0, 1.0)


def test_a_released_freeze_hands_the_substitute_back_to_the_live_filter():
    # a one-sample disturbance of a perfectly trained filter: frozen from the spike, released confirm = 3
    # samples later; the live filter is an LMS loop written out here, the frozen one is the true filter
    M, N, spike, mu = 2, 20, 8, 1 / 64
    true = np.array([0.5, -0.25])
    u = np.array([1.0, 2.0, -1.0, 0.0, 3.0] * 4)
    y = regressors(u, M) @ true
    y[spike] += 4.0
    obs = monitor(M=M, mu=mu, eps0=4.0, r0=1e6, confirm=3)
    s0 = obs.initial_state([0.0], [0.0])
    s0[:M] = true
    _, OUT = obs.run(y[:, None], u[:, None], s0=s0)
    C, live = true.copy(), []
    for row, target in zip(regressors(u, M), y):
        live.append(C @ row)
        C = C - 2 * mu * (C @ row - target) * row
    names = obs.publishes.names
    frozen = np.zeros(N)
    frozen[spike:spike + 3] = 1.0
    np.testing.assert_array_equal(OUT[:, names.index("frozen_y")], frozen)
    assert list(np.flatnonzero(OUT[:, names.index("disturbance_y")])) == [spike + 3]
    sub = OUT[:, names.index("y_sub")]
    np.testing.assert_allclose(sub[spike + 1:spike + 3], regressors(u, M)[spike + 1:spike + 3] @ true, rtol=1e-12)
    release = spike + 3
    assert sub[release] == pytest.approx(live[release], rel=1e-12)
    assert abs(live[release] - regressors(u, M)[release] @ true) > 1e-3  # the two filters differ there


@pytest.mark.parametrize("mu, order, u, message", [
    (0, 2, [1.0], "lms step claim: mu must be positive and finite, got 0"),  # mu = 0 does not adapt
    (0.1, 0, [1.0], "lms step claim: order M must be a positive integer, got 0"),
    (0.1, 2.0, [1.0], "lms step claim: order M must be a positive integer, got 2.0"),
    (0.1, True, [1.0], "lms step claim: order M must be a positive integer, got True"),
    (0.1, 2, [], "lms step claim: the input samples u must be finite and at least one")])
def test_step_claim_refuses_bad_arguments_with_its_full_message(mu, order, u, message):
    with pytest.raises(VerificationError) as info:
        lms_step_claim(mu, order, u)
    assert str(info.value) == message


def test_step_claim_takes_a_column_of_samples_and_states_its_set_bound_and_expectation():
    import time

    u = np.array([[2.0], [0.0]])  # a recorded input as a run gives it, (N, 1): P_u = (4 + 0) / 2 = 2
    before = time.perf_counter()
    certificate = lms_step_claim(0.125, 2, u, expected="refuted")  # mu M P_u = 0.125 * 2 * 2 = 1/2
    elapsed = time.perf_counter() - before
    assert (certificate.status, certificate.expected, certificate.margin) == ("proved", "refuted", 0.5)
    assert certificate.details["bound"] == 0.25  # 1 / (M P_u) = 1 / 4
    assert certificate.set == "the recorded input (2 samples, P_u = 2), M = 2"
    assert 0.0 < certificate.seconds <= elapsed  # its own duration, measured around the call


# --- double criterion and supervisor: edge cases (mutation survivors) ------------------------------------------------


def test_double_criterion_names_its_inputs_outputs_and_state_symbols():
    decide = double_criterion(3)
    assert decide.name_in() == ["d", "a_e", "a_R"] and decide.name_out() == ["d_next", "snapshot", "released"]
    assert str(decide.sx_in(0)) == "[d_0, d_1, d_2]"  # the state symbol is d (3,), as documented


def test_R_alarm_exactly_confirm_samples_after_the_freeze_still_confirms_the_fault():
    # confirm = 3: freeze at sample 1 (age 0); R fires at sample 4, age 3 = confirm, the last sample allowed
    rows = decide_sequence([0, 1, 0, 0, 0, 0], [0, 0, 0, 0, 1, 0])
    assert list(rows[:, 1]) == [0, 0, 1, 2, 3, 4]  # age counts samples since the eps2 alarm
    assert list(rows[:, 2]) == [0, 0, 0, 0, 1, 1]  # confirmed at age 3 and latched
    assert not rows[:, 4].any()  # so never released as a disturbance


def test_supervisor_logs_the_switch_back_and_first_is_none_for_an_absent_event():
    obs = monitor(M=2)
    names = obs.publishes.names
    supervisor = SubstitutionSupervisor(obs, substitute_on="alarm")
    assert supervisor.first("substitution") is None  # an empty log
    for k, (frozen, released) in enumerate(((1, 0), (0, 1))):
        flags = np.zeros((1, len(names)))
        flags[0, names.index("frozen_y")], flags[0, names.index("disturbance_y")] = frozen, released
        supervisor.update(np.array([0.1 * k]), {obs.name: flags})
    assert [e.what for e in supervisor.events if e.what.startswith("substitution")] == [
        "substitution on from the next sample", "substitution off from the next sample"]
    assert supervisor.first("R alarm") is None  # no fault was confirmed
