"""Actuator-fault observers, isolation, identification and correction (core paper, seeds/000)."""

from __future__ import annotations

from fractions import Fraction

import casadi as ca
import numpy as np
import pytest

from uvsym import fixed_thrusters, vectored_thrusters, vehicle
from uvsym.errors import ArgumentError, ConfigurationError, FaultError, IdentifiabilityError, ObserverError
from uvsym.faults import ActuatorFault, apply_actuator_faults
from uvsym.observers import KINDS, actuator_observer
from uvsym.observers.discrete import sampled_observer
from uvsym.observers.ftc import corrected_commands, linear_correction
from uvsym.observers.gains import design_gains, unobservable_channels
from uvsym.observers.identification import ActuatorFaultEstimate, actuator_values, configuration_at
from uvsym.observers.isolation import IsolationSettings, Isolator, predicted_faults
from uvsym.observers.supervisor import FaultDiagnosis

OTTER = "otter3dof"  # diagonal M: the paper's Assumption 1 holds


def _delivered(kind: str, f, tau_d):
    """Generalised force a fault of ``kind`` delivers for the desired tau_d (Definition 1)."""
    return {"proportional": f * tau_d, "bias": tau_d + f, "constant": f}[kind]


def _observer_run(model, observer, K, f, tau_d, T: float):
    """Integrate plant nu and observer x together (CVODES); returns f_hat(T) and f_hat(0)."""
    n = model.dof
    nu, x = ca.SX.sym("nu", n), ca.SX.sym("x", n)
    eta = ca.DM.zeros(n)
    tau = _delivered(observer.kind, ca.DM(f), ca.DM(tau_d))
    nu_dot = ca.mtimes(ca.DM(np.linalg.inv(model.M)), tau - model.h(eta, nu))
    x_dot, f_hat = observer.function(x, eta, nu, tau_d, K)
    ode = ca.Function("ode", [ca.vertcat(nu, x)], [ca.vertcat(nu_dot, x_dot)])
    integrator = ca.integrator("I", "cvodes", {"x": ca.vertcat(nu, x), "ode": ode(ca.vertcat(nu, x))}, 0.0, T,
                               {"abstol": 1e-12, "reltol": 1e-12})
    nu0 = np.array([1.0, 0.1, 0.05])[:n]
    x0 = -np.asarray(observer.function(np.zeros(n), eta, nu0, tau_d, K)[1]).ravel()  # f_hat(0) = 0
    end = np.asarray(integrator(x0=np.r_[nu0, x0])["xf"]).ravel()
    estimate = ca.Function("f_hat", [nu, x], [f_hat])
    return np.asarray(estimate(end[:n], end[n:])).ravel(), np.asarray(estimate(nu0, x0)).ravel()


@pytest.mark.parametrize("kind", KINDS)
def test_observer_error_decays_at_the_designed_rate(kind):
    model = vehicle(OTTER)
    observer = actuator_observer(model, kind)
    tau_d = np.array([60.0, 5.0, 20.0])
    f = {"proportional": np.array([0.7, 1.0, 0.9]), "bias": np.array([13.0, -2.0, 4.0]),
         "constant": np.array([30.0, 1.0, -5.0])}[kind]
    time_constant, T = 0.5, 1.5
    design = design_gains(observer, time_constant, tau_d)
    np.testing.assert_allclose(design.rates, 1 / time_constant, rtol=1e-12)
    f_hat_T, f_hat_0 = _observer_run(model, observer, design.K, f, tau_d, T)
    np.testing.assert_allclose(f_hat_0, 0.0, atol=1e-12)
    # e(T) = e(0) exp(-T / time constant) on every channel, e = f - f_hat
    np.testing.assert_allclose(f - f_hat_T, f * np.exp(-T / time_constant), rtol=1e-6, atol=1e-9)


def test_paper_rates_scale_with_the_square_of_the_mass():
    model = vehicle(OTTER)
    observer = actuator_observer(model, "bias")
    A = np.asarray(observer.error_matrix(np.ones(3), np.ones(3)))
    np.testing.assert_allclose(np.diag(A), -1 / np.diag(model.M) ** 2, rtol=1e-12)
    prop = actuator_observer(model, "proportional")
    tau_d = np.array([3.0, 2.0, 5.0])
    A = np.asarray(prop.error_matrix(tau_d, np.ones(3)))
    np.testing.assert_allclose(np.diag(A), -(tau_d / np.diag(model.M)) ** 2, rtol=1e-12)


def test_L_is_the_jacobian_of_R_not_typed():
    model = vehicle(OTTER)
    observer = actuator_observer(model, "proportional")
    nu, tau_d, K = np.array([1.0, 0.2, 0.1]), np.array([50.0, 4.0, 9.0]), np.array([2.0, 3.0, 4.0])
    expected = -np.diag(K) @ np.linalg.inv(model.M) @ np.diag(tau_d)  # the paper's L_p for diagonal M
    np.testing.assert_allclose(np.asarray(observer.L(nu, tau_d, K)), expected, rtol=1e-12)


def test_the_paper_proportional_observer_refuses_a_coupled_mass_matrix():
    model = vehicle("docking_auv")
    with pytest.raises(ObserverError, match="diagonal mass matrix"):
        actuator_observer(model, "proportional", "paper")
    momentum = actuator_observer(model, "proportional", "momentum")
    tau_d, K = np.array([8.0, 1.0, 2.0, 0.5, 1.0, 0.3]), np.ones(6)
    np.testing.assert_allclose(np.asarray(momentum.error_matrix(tau_d, K)), -np.diag(K * tau_d**2), atol=1e-9)


def test_the_paper_proportional_observer_forced_on_a_coupled_mass_matrix_is_the_printed_one():
    # R_p = -K M^-1 T_d nu (eq. 12) as printed, so L_p = -K M^-1 T_d; M^-1 and T_d do not commute for a coupled M
    model = vehicle("docking_auv")
    observer = actuator_observer(model, "proportional", "paper", require_assumption_1=False)
    tau_d, K = np.array([8.0, 1.0, 2.0, 0.5, 1.0, 0.3]), np.arange(1.0, 7.0)
    expected = -np.diag(K) @ np.linalg.inv(model.M) @ np.diag(tau_d)
    np.testing.assert_allclose(np.asarray(observer.L(np.zeros(6), tau_d, K)), expected, rtol=1e-12, atol=1e-15)


def test_unknown_kind_and_form_are_refused():
    with pytest.raises(ObserverError, match="unknown observer kind"):
        actuator_observer(vehicle(OTTER), "sliding")
    with pytest.raises(ObserverError, match="unknown observer form"):
        actuator_observer(vehicle(OTTER), "bias", "symmetric")


def test_zero_desired_action_is_reported_not_divided_by():
    model = vehicle(OTTER)
    observer = actuator_observer(model, "proportional")
    tau_d = np.array([40.0, 0.0, 10.0])
    assert unobservable_channels(observer, tau_d) == (1,)
    design = design_gains(observer, 0.5, tau_d)
    assert design.unobservable == (1,) and np.all(np.isfinite(design.K))
    with pytest.raises(ObserverError, match="nominal tau_d"):
        design_gains(observer, 0.5)


def test_exact_error_dynamics_add_the_dropped_term():
    model = vehicle(OTTER)
    observer = actuator_observer(model, "proportional")
    rng = np.random.default_rng(1)
    tau_sym, nu_sym = ca.SX.sym("tau_d", 3), ca.SX.sym("nu", 3)
    K = np.array([0.5, 2.0, 1.0])
    dR = ca.Function("dR", [nu_sym, tau_sym], [ca.jacobian(observer.R(nu_sym, tau_sym, K), tau_sym)])
    for _ in range(10):
        e, f, eta, nu, tau_d, tau_d_dot = (rng.standard_normal(3) for _ in range(6))
        exact = np.asarray(observer.error_dynamics(e, f, eta, nu, tau_d, tau_d_dot, K)).ravel()
        paper = np.asarray(observer.error_matrix(tau_d, K)) @ e
        dropped = np.asarray(dR(nu, tau_d)) @ tau_d_dot
        np.testing.assert_allclose(exact, paper + dropped, atol=1e-10)
        assert np.max(np.abs(dropped)) > 1e-3  # the term the paper drops is not zero


def test_sampled_data_observer_keeps_a_matched_constant_fault():
    model = vehicle(OTTER)
    observer = actuator_observer(model, "bias")
    K = design_gains(observer, 0.3).K
    dt, f = 0.01, np.array([5.0, -1.0, 2.0])
    sampled = sampled_observer(observer.function, dt)
    step = sampled.step
    eta, nu = np.zeros(3), np.array([1.0, 0.0, 0.0])

    def tau_d(t):
        return np.array([50 + 20 * np.sin(0.5 * t), 3 * np.cos(t), 10 * np.sin(0.3 * t)])

    s = sampled.initial_state(eta, nu, tau_d(0.0), K)
    s[:3] = f  # start at the true fault
    # the plant sees tau_d moving continuously (linearly) between samples, as actuators deliver it
    x, p, t = ca.SX.sym("nu", 3), ca.SX.sym("p", 6), ca.SX.sym("t")
    tau = p[:3] + (p[3:] - p[:3]) * t / dt
    ode = ca.mtimes(ca.DM(np.linalg.inv(model.M)), tau + f - model.h(ca.DM.zeros(3), x))
    plant = ca.integrator("p", "cvodes", {"x": x, "p": p, "t": t, "ode": ode}, 0.0, dt,
                          {"abstol": 1e-12, "reltol": 1e-12})
    # forward Euler on the observer state x, for comparison
    x_euler = f - np.asarray(observer.function(np.zeros(3), eta, nu, tau_d(0.0), K)[1]).ravel()
    worst = worst_euler = 0.0
    for k in range(1, 300):
        x_dot = np.asarray(observer.function(x_euler, eta, nu, tau_d((k - 1) * dt), K)[0]).ravel()
        nu = np.asarray(plant(x0=nu, p=np.r_[tau_d((k - 1) * dt), tau_d(k * dt)])["xf"]).ravel()
        s, f_hat = (np.asarray(v).ravel() for v in step(s, eta, nu, tau_d(k * dt), K))
        x_euler = x_euler + dt * x_dot
        f_euler = np.asarray(observer.function(x_euler, eta, nu, tau_d(k * dt), K)[1]).ravel()
        worst = max(worst, float(np.max(np.abs(f_hat - f))))
        worst_euler = max(worst_euler, float(np.max(np.abs(f_euler - f))))
    assert worst < 1e-3  # the motion between samples barely pulls a matched estimate off ...
    assert worst < worst_euler / 10  # ... an order of magnitude less than with forward Euler


def _synthetic(kind_true: str, kind_observer: str, T: float = 6.0, dt: float = 0.01):
    """Estimates of an exactly exponential matched observer, or of the wrong one, with varying tau_d."""
    model = vehicle(OTTER)
    observer = actuator_observer(model, kind_observer)
    t = np.arange(0.0, T, dt)
    tau_d = np.column_stack([50 + 20 * np.sin(0.7 * t), 5 + 2 * np.cos(0.5 * t), 10 + 4 * np.sin(0.9 * t)])
    K = design_gains(observer, 0.3, tau_d[0]).K
    f_p, f_a = np.array([0.8, 1.0, 1.0]), np.array([13.0, 0.0, 0.0])
    if kind_true == "bias":
        f_true = f_a if kind_observer == "bias" else (tau_d + f_a) / tau_d
    else:
        f_true = f_p if kind_observer == "proportional" else (f_p - 1) * tau_d
    # integrate e' = A(t) e exactly for the matched case; the mismatched "fault" drifts with tau_d. The rates
    # are the paper's closed form for a diagonal M (Theorems 1-2), not the observer's own error_matrix, which
    # isolation inverts: A = -K (M^-1 T_d)^2 for the proportional observer, -K M^-2 for the bias one
    m = np.diag(model.M)
    f_hat = np.zeros_like(tau_d)
    e = f_true[0] if np.ndim(f_true) == 2 else f_true.copy()
    for k in range(len(t)):
        target = f_true[k] if np.ndim(f_true) == 2 else f_true
        if k:
            A = -K * ((tau_d[k] / m) ** 2 if kind_observer == "proportional" else 1.0 / m**2)
            e = (target - f_hat[k - 1]) * np.exp(A * dt)
        f_hat[k] = target - e
    return observer, K, t, f_hat, tau_d


def test_matched_observer_settles_and_the_wrong_one_does_not():
    settings = IsolationSettings()
    observer, K, t, f_hat, tau_d = _synthetic("bias", "bias")
    matched, _ = predicted_faults(observer, K, t, f_hat, tau_d, settings)
    wrong_observer, K_w, t, f_hat_w, tau_d = _synthetic("bias", "proportional")
    wrong, _ = predicted_faults(wrong_observer, K_w, t, f_hat_w, tau_d, settings)
    late = t > 3.0
    assert np.nanvar(matched[late, 0]) < 1e-8
    np.testing.assert_allclose(matched[late, 0], 13.0, atol=1e-6)
    assert np.nanvar(wrong[late, 0]) > 1e-3  # (tau_d + 13) / tau_d keeps moving with tau_d


def test_isolator_fed_in_chunks_equals_one_pass():
    observers = {}
    data = {}
    for kind in ("bias", "proportional"):
        observer, K, t, f_hat, tau_d = _synthetic("bias", kind)
        observers[kind] = (observer, K)
        data[kind] = f_hat
    labels = ("X", "Y", "N")
    whole = Isolator(observers, labels).update(t, data, tau_d)
    chunked = Isolator(observers, labels)
    for start in range(0, len(t), 37):
        sl = slice(start, start + 37)
        result = chunked.update(t[sl], {k: v[sl] for k, v in data.items()}, tau_d[sl])
    for kind in observers:
        np.testing.assert_allclose(result.f_bar[kind], whole.f_bar[kind], rtol=1e-9, atol=1e-12, equal_nan=True)
        np.testing.assert_allclose(result.variance[kind], whole.variance[kind], rtol=1e-6, atol=1e-15,
                                   equal_nan=True)
    assert result.decisions["X"].kind == whole.decisions["X"].kind == "bias"


@pytest.mark.parametrize("config", [
    fixed_thrusters([0.0, np.pi / 2, np.pi], [[-1.0, 0.3, 0.0], [0.0, 0.5, 0.0], [1.0, -0.3, 0.0]],
                    [[0.5, 0.0, 0.0], [-0.5, 0.2, 0.0]]),
    vectored_thrusters([0.3, -0.2], [1.2, 1.4], [[-1.0, 0.3, 0.1], [-1.0, -0.3, 0.1]], ["ex", "both"]),
    configuration_at(vehicle("docking_auv"), np.zeros(6), np.array([1.5, 0, 0, 0, 0, 0]), np.zeros(4)),
], ids=["fixed", "vectored", "fins"])
def test_identification_round_trips_u_tau_u(config):
    u = np.linspace(0.3, 1.7, config.B.shape[1])
    np.testing.assert_allclose(actuator_values(config, config.B @ u), u, rtol=1e-10)


def test_identification_refuses_a_configuration_it_cannot_invert():
    crowded = fixed_thrusters([0.0, 0.5, 1.0, 1.5], [[-1.0, 0.3, 0.0], [0.0, 0.5, 0.0], [1.0, -0.3, 0.0],
                                                     [0.5, 0.5, 0.0]], [])
    with pytest.raises(IdentifiabilityError, match="traded against"):
        actuator_values(crowded, np.ones(6))


@pytest.mark.parametrize("kind, value", [("proportional", 0.7), ("bias", 13.0), ("bias", -0.05),
                                         ("loss_of_effectiveness", 0.3)])
def test_correction_restores_the_desired_actuation(kind, value):
    model = vehicle("docking_auv")
    labels = model.input_labels
    u_d = np.array([20.0, 0.02, -0.05, -0.05])
    actuator = 0 if value == 13.0 else 2
    fault = ActuatorFault(actuator, kind, value)
    estimate = {labels[actuator]: ActuatorFaultEstimate(labels[actuator], kind, value, 0.0)}
    B = configuration_at(model, np.zeros(6), np.array([1.5, 0, 0, 0, 0, 0]), u_d).B
    u_star = corrected_commands(u_d, estimate, labels, B, model.u_min, model.u_max)
    delivered = np.asarray(apply_actuator_faults(ca.DM(u_star), 0.0, (fault,))).ravel()
    np.testing.assert_allclose(delivered, u_d, rtol=1e-12, atol=1e-12)


def test_a_stuck_actuator_is_stopped_and_its_share_redistributed():
    config = fixed_thrusters([0.0, 0.0, np.pi / 2], [[-1.0, 0.3, 0.0], [-1.0, -0.3, 0.0], [0.0, 0.0, 0.0]], [])
    labels = config.labels
    u_d = np.array([10.0, 10.0, 2.0])
    estimate = {labels[1]: ActuatorFaultEstimate(labels[1], "constant", 0.0, 0.0)}
    correction = linear_correction(estimate, labels, config.B)
    u_star = correction.S @ u_d + correction.o
    assert u_star[1] == 0.0
    # the others deliver the closest force they can: the residual is orthogonal to their columns
    residual = config.B @ u_star - config.B @ u_d
    np.testing.assert_allclose(config.B[:, [0, 2]].T @ residual, 0.0, atol=1e-9)
    assert np.linalg.norm(residual) < np.linalg.norm(config.B[:, 1] * u_d[1])  # better than doing nothing


def test_correction_refuses_an_unknown_kind_and_an_actuator_with_no_effect_left():
    labels = ("a", "b")
    with pytest.raises(FaultError, match="unknown actuator fault kind 'wobble'; known: proportional, bias"):
        linear_correction({"a": ActuatorFaultEstimate("a", "wobble", 1.0, 0.0)}, labels, np.eye(2))
    with pytest.raises(IdentifiabilityError, match="b: a proportional fault of 0.0"):
        linear_correction({"b": ActuatorFaultEstimate("b", "proportional", 0.0, 0.0)}, labels, np.eye(2))


def test_correction_keeps_commands_within_bounds():
    model = vehicle("docking_auv")
    labels = model.input_labels
    u_d = np.array([95.0, 0.0, 0.2, 0.2])
    estimate = {"delta_ru": ActuatorFaultEstimate("delta_ru", "proportional", 0.5, 0.0)}
    B = configuration_at(model, np.zeros(6), np.array([1.5, 0, 0, 0, 0, 0]), u_d).B
    u_star = corrected_commands(u_d, estimate, labels, B, model.u_min, model.u_max)
    assert np.all(u_star <= model.u_max + 1e-9) and np.all(u_star >= model.u_min - 1e-9)
    assert u_star[3] > u_d[3]  # the healthy lower rudder takes over what the upper cannot deliver


def test_diagnosis_in_the_loop_identifies_the_docking_faults():
    from dataclasses import replace

    from uvsym.sim.scenario import load_scenario
    from uvsym.sim.simulation import scenario_observers, simulate_scenario

    scenario = replace(load_scenario("docking_faults"), duration=6.0)
    diagnosis = FaultDiagnosis(scenario.model, scenario_observers(scenario.model, scenario.observers))
    simulate_scenario(scenario, supervisor=diagnosis)
    assert diagnosis.identified["X"].kind == "bias"
    assert abs(diagnosis.identified["X"].value - 13.0) < 0.01
    for rudder in ("delta_ru", "delta_rd"):
        assert diagnosis.identified[rudder].kind == "proportional"
        assert abs(diagnosis.identified[rudder].value - 0.8) < 0.001
    assert list(diagnosis.healthy) == ["delta_e"]
    assert diagnosis.isolation_time_s < 5.0


@pytest.mark.parametrize("builder", ["proportional_observer", "bias_observer", "constant_observer"])
def test_observer_functions_have_the_named_signature_and_an_init(builder):
    import uvsym.observers as observers

    model = vehicle(OTTER)
    function = getattr(observers, builder)(model)
    assert function.name_in() == ["x", "eta", "nu", "tau_d", "K"]
    assert function.name_out() == ["x_dot", "f_hat"]
    eta, nu, tau_d, K = np.array([1.0, 2.0, 0.3]), np.array([1.2, 0.1, 0.05]), np.array([40.0, 3.0, 8.0]), np.ones(3)
    x0 = observers.init_state(function, eta, nu, tau_d, K)
    np.testing.assert_allclose(np.asarray(function(x0, eta, nu, tau_d, K)[1]).ravel(), 0.0, atol=1e-12)


def test_a_model_name_or_other_object_is_refused_with_the_right_hint():
    with pytest.raises(ObserverError, match=r"got str 'otter3dof' \(build it with uvsym.vehicle\('otter3dof'\)\)$"):
        actuator_observer(OTTER, "bias")
    with pytest.raises(ObserverError, match=r"^model must be a uvsym Model, got int 42$"):  # no hint for a non-name
        actuator_observer(42, "bias")


def test_observer_symbols_and_entries_carry_fossens_names():
    # 6 DOF: the restoring forces g(eta) depend on roll and pitch (eta entries phi, theta), so x_dot reads eta_3, eta_4
    def symbols(function):  # names of the symbols its first output depends on
        raw = function.raw
        return {s.name() for s in ca.symvar(raw.call(raw.sx_in())[0])}

    observer = actuator_observer(vehicle("docking_auv"), "bias", "momentum")
    names = symbols(observer.function)
    assert {"eta_3", "eta_4"} <= names
    assert {name.rsplit("_", 1)[0] for name in names} == {"x", "eta", "nu", "tau_d", "K"}
    assert observer.L.name_in() == ["nu", "tau_d", "K"] and observer.R.name_in() == ["nu", "tau_d", "K"]
    assert observer.error_matrix.name_in() == ["tau_d", "K"]
    names = symbols(actuator_observer(vehicle("docking_auv"), "proportional", "momentum").error_dynamics)  # R(tau_d)
    assert {name.rsplit("_", 1)[0] for name in names} == {"e", "f", "eta", "nu", "tau_d", "tau_d_dot", "K"}
    # a bad entry is named by its force label (X, Y, Z, K, M, N)
    zeros, ones = np.zeros(6), np.ones(6)
    with pytest.raises(ArgumentError, match=r"bias_observer: argument x entry Z is nan"):
        observer.function(np.r_[0.0, 0.0, np.nan, 0.0, 0.0, 0.0], zeros, zeros, ones, ones)
    with pytest.raises(ArgumentError, match=r"bias_observer: argument K entry M is inf"):
        observer.function(zeros, zeros, zeros, ones, np.r_[1.0, 1.0, 1.0, 1.0, np.inf, 1.0])
    with pytest.raises(ArgumentError, match=r"bias_observer: argument tau_d entry N is nan"):
        observer.function(zeros, zeros, zeros, np.r_[1.0, 1.0, 1.0, 1.0, 1.0, np.nan], ones)
    with pytest.raises(ArgumentError, match=r"\.L: argument K entry Y is inf"):
        observer.L(zeros, ones, np.r_[1.0, np.inf, 1.0, 1.0, 1.0, 1.0])


def test_design_gains_messages_name_the_mistake():
    observer = actuator_observer(vehicle(OTTER), "proportional")
    tau_d = np.array([40.0, 3.0, 10.0])
    with pytest.raises(ObserverError, match=r"got CheckedFunction \(pass the observer, not its .function\)"):
        design_gains(observer.function, 0.5, tau_d)
    for bad in (-0.5, 0.0, np.inf, True, "0.5"):  # negative, zero (no finite gain), infinite, a bool, a string
        with pytest.raises(ObserverError, match=rf"^time_constant must be positive and finite \(s\), got {bad!r}$"):
            design_gains(observer, bad, tau_d)
    with pytest.raises(ObserverError, match=r"^tau_d must have 3 finite entries, got \[1.0, 2.0\]$"):
        design_gains(observer, 0.5, [1, 2])
    with pytest.raises(ObserverError, match=r"^tau_d must be 3 numbers \(N, N m\), got \['a', 'b', 'c'\]$"):
        design_gains(observer, 0.5, ["a", "b", "c"])
    with pytest.raises(ObserverError, match=r"^tau_d = \[0.0, 0.0, 0.0\] is zero in every channel: the proportional "
                                            r"observer sees no fault in any of them \(Remark 2: a fault scaling "
                                            r"tau_d,i is invisible where tau_d,i = 0\); give the nominal desired "
                                            r"action of the run$"):
        design_gains(observer, 0.5, np.zeros(3))


def test_unobservable_channels_check_tau_d():
    observer = actuator_observer(vehicle(OTTER), "proportional")
    assert unobservable_channels(observer, [40, 0, -1e-7]) == (1, 2)  # |tau_d,i| <= 1e-6 N
    assert unobservable_channels(observer, [1e-6, -1e-6, 1.5e-6]) == (0, 1)  # the threshold itself is unobservable
    with pytest.raises(ObserverError, match=r"^tau_d must be 3 numbers \(N, N m\), got 'abc'$"):
        unobservable_channels(observer, "abc")
    with pytest.raises(ObserverError, match=r"^tau_d must have 3 finite entries, got \[40.0, nan, 1.0\]$"):
        unobservable_channels(observer, [40.0, np.nan, 1.0])  # nan is not "observable"


def test_stopped_actuator_is_commanded_zero_while_the_others_saturate():
    # B = [[1, 1, 1], [0, 1, -1]]; a stuck at 0 is stopped and its 3 N of X go to b, c: pinv([[1, 1], [1, -1]]) [3, 0]
    # = [1.5, 1.5], so u_lin = [0, 5.5, 2.5]; b is capped at 5 and c stays at 2.5 (B_bc is square and invertible:
    # |B_bc (u - u_lin)| = |(-0.5 + dc, -0.5 - dc)| is least at dc = 0)
    B = np.array([[1.0, 1.0, 1.0], [0.0, 1.0, -1.0]])
    estimate = {"a": ActuatorFaultEstimate("a", "constant", 0.0, 0.0)}
    u_star = corrected_commands([3.0, 4.0, 1.0], estimate, ("a", "b", "c"), B, np.full(3, -5.0), np.full(3, 5.0))
    assert u_star[0] == 0.0  # stopped: no command at all, not the edge of its +-1e-12 band
    np.testing.assert_allclose(u_star[1:], [5.0, 2.5], atol=1e-9)
    exact_B = [[Fraction(1), Fraction(1), Fraction(1)], [Fraction(0), Fraction(1), Fraction(-1)]]  # B given exactly
    u_exact = corrected_commands([3.0, 4.0, 1.0], estimate, ("a", "b", "c"), exact_B, np.full(3, -5.0), np.full(3, 5.0))
    np.testing.assert_allclose(u_exact, [0.0, 5.0, 2.5], atol=1e-9)


def test_a_stopped_actuator_is_commanded_exactly_zero_however_the_solver_rounds():
    # B = [[0.1, 0.1, -0.1, 0.3], [0.1, 0.1, 0.2, -0.2]], a stuck at 0 with u_d,a = 4: a's column equals b's, and
    # pinv(B_bcd) (0.1, 0.1) is e_b less its part along the null direction n = (-4, 5, 3) of B_bcd (|n|^2 = 50):
    # (0.68, 0.4, 0.24), so u_lin = (1, 0, 5) + 4 (0.68, 0.4, 0.24) = (3.72, 1.6, 5.96) with d beyond 5. The forces
    # B_bcd u_lin are met exactly on the line u_lin + t n; d <= 5 needs t <= -0.32 and b <= 5 needs t >= -0.32, so
    # (b, c, d) = (5, 0, 5) is the one command in the bounds with no residual
    B = np.array([[0.1, 0.1, -0.1, 0.3], [0.1, 0.1, 0.2, -0.2]])
    estimate = {"a": ActuatorFaultEstimate("a", "constant", 0.0, 0.0)}
    u_star = corrected_commands([4.0, 1.0, 0.0, 5.0], estimate, ("a", "b", "c", "d"), B, np.full(4, -5.0),
                                np.full(4, 5.0))
    assert u_star[0] == 0.0  # not the solver's rounding (it gave -4.4e-16 when a was kept in the least squares)
    np.testing.assert_allclose(u_star[1:], [5.0, 0.0, 5.0], rtol=0.0, atol=1e-12)


def test_a_positive_bias_leaves_the_lower_bound_of_the_command_alone():
    # a bias of +3 delivers u + 3: the command must keep u in [-10, 10] and u + 3 in [-10, 10], so u in [-10, 7];
    # u_d = -6 gives u* = -9, inside that range, so it is returned unchanged and delivers -6
    estimate = {"a": ActuatorFaultEstimate("a", "bias", 3.0, 0.0)}
    # (a and b push the same force, so a command inside the bounds is kept as it is, not traded against b)
    B, bounds = np.array([[1.0, 1.0]]), (np.full(2, -10.0), np.full(2, 10.0))
    np.testing.assert_array_equal(corrected_commands([-6.0, 1.0], estimate, ("a", "b"), B, *bounds), [-9.0, 1.0])
    exact = corrected_commands([Fraction(-6), Fraction(1)], estimate, ("a", "b"), B, *bounds)  # exact u_d
    assert exact.dtype == np.float64 and exact.tolist() == [-9.0, 1.0]
    # the upper bound moves by the bias: u_d = 10 needs u* = 7, the edge, still inside
    np.testing.assert_array_equal(corrected_commands([10.0, 1.0], estimate, ("a", "b"), B, *bounds), [7.0, 1.0])
    # u_d = 11 needs u* = 8, beyond 7: with B = I the command stops at 7 (delivering u_max = 10) and b is untouched
    np.testing.assert_allclose(corrected_commands([11.0, 1.0], estimate, ("a", "b"), np.eye(2), *bounds), [7.0, 1.0],
                               atol=1e-12)
    # integer bounds are bounds in the input's unit, not an integer type: u_max = 10 leaves a bias of 0.5 the bound
    # 9.5, so u_d = 9.75 gives u* = 9.25, inside; u_min = -10 leaves a bias of -0.5 the bound -9.5, and -9.75 gives
    # -9.25
    halves = {"a": ActuatorFaultEstimate("a", "bias", 0.5, 0.0), "b": ActuatorFaultEstimate("b", "bias", -0.5, 0.0)}
    np.testing.assert_array_equal(corrected_commands([9.75, -9.75], halves, ("a", "b"), np.eye(2), [-10, -10],
                                                     [10, 10]), [9.25, -9.25])


def test_commands_on_their_bounds_are_kept_without_a_fault():
    # a and b push the same force: u_d = (-10, 4) is inside [-10, 10] (a on its bound) and needs no change
    np.testing.assert_array_equal(corrected_commands([-10.0, 4.0], {}, ("a", "b"), np.array([[1.0, 1.0]]),
                                                     np.full(2, -10.0), np.full(2, 10.0)), [-10.0, 4.0])


def test_stopping_every_actuator_is_refused_and_exact_B_is_accepted():
    stuck = {label: ActuatorFaultEstimate(label, "constant", 1.0, 0.0) for label in ("a", "b")}
    with pytest.raises(IdentifiabilityError, match=r"^every actuator is stopped: nothing can take over$"):
        linear_correction(stuck, ("a", "b"), np.eye(2))
    # a stopped: its column (1, 0) is pinv([[1, 1], [1, -1]]) (1, 0) = (1/2, 1/2) of b and c; B given exactly
    B = [[Fraction(1), Fraction(1), Fraction(1)], [Fraction(0), Fraction(1), Fraction(-1)]]
    correction = linear_correction({"a": ActuatorFaultEstimate("a", "constant", 0.0, 0.0)}, ("a", "b", "c"), B)
    np.testing.assert_allclose(correction.S, [[0.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, 0.0, 1.0]], atol=1e-15)
    np.testing.assert_array_equal(correction.o, 0.0)


def test_configuration_labels_and_exact_equilibrium_values():
    config = configuration_at(vehicle("docking_auv"), np.zeros(6), np.array([1.5, 0, 0, 0, 0, 0]), np.zeros(4))
    assert config.labels == ("X", "delta_e", "delta_ru", "delta_rd")  # the model's inputs: thrust, elevator, rudders
    assert config.groups == (("all", (0, 1, 2, 3)),)  # one group of every input (the 6-equation counting rule)
    u_e = [Fraction(1, 2), Fraction(-1, 8), Fraction(1, 16), Fraction(0)]
    tau = [Fraction(k, 3) for k in range(6)]
    u = actuator_values(config, tau, tau_e=tau, u_e=u_e)  # tau = tau_e: u = u_e exactly, as floats
    assert u.dtype == np.float64
    np.testing.assert_array_equal(u, [0.5, -0.125, 0.0625, 0.0])
    # 3 DOF (X, Y, N): rows Z, K, M of the 6-row B are zero
    otter = vehicle(OTTER)
    B3 = np.asarray(otter.B(np.zeros(3), np.zeros(3), np.zeros(2), 0.0, 0.0))
    B6 = configuration_at(otter, np.zeros(3), np.zeros(3), np.zeros(2)).B
    np.testing.assert_array_equal(B6[2:5], 0.0)
    np.testing.assert_array_equal(B6[[0, 1, 5]], B3)
    with pytest.raises(ConfigurationError, match=r"^docking_auv: B must be a finite k x m matrix with 1 <= k <= 6 "):
        actuator_values(config, np.zeros(6), rows=[])  # no force rows at all


def test_a_weakened_actuator_that_saturates_hands_the_rest_to_one_acting_on_the_same_force():
    """Two actuators on one force (B = [1, 1]), the first at half effectiveness: u_d = (1, 0) asks 1 N, the
    linear correction commands 2 on the first, beyond its bound 1. The bounded least squares must then deliver
    0.5 u_0 + u_1 = 1 exactly (e.g. u = (1, 0.5)); weighting by 1 / effectiveness would deliver 1.5."""

    faults = {"a": ActuatorFaultEstimate("a", "proportional", 0.5, 1.0)}
    u_star = corrected_commands([1.0, 0.0], faults, ("a", "b"), np.array([[1.0, 1.0]]), [-1.0, -1.0], [1.0, 1.0])
    assert np.all(np.abs(u_star) <= 1.0 + 1e-12)
    assert 0.5 * u_star[0] + u_star[1] == pytest.approx(1.0, abs=1e-9)


def test_actuator_values_lists_every_pair_that_trades_separated_by_semicolons():
    from uvsym.models.configurations import ActuatorConfiguration

    pair = ActuatorConfiguration("pair", np.array([[1.0, 1.0]]), ("a", "b"), (("all", (0, 1)),))  # 1 force, 2 inputs
    reason = "{} can be traded against {} without changing tau (rank 1 < 2 inputs)"
    expected = (f"pair: actuator values cannot be recovered from tau: "
                f"{reason.format('a', 'b')}; {reason.format('b', 'a')}")
    with pytest.raises(IdentifiabilityError) as info:
        actuator_values(pair, [1.0], rows=[0])
    assert str(info.value) == expected
