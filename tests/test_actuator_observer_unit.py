"""The observer builders pass their form on: with ``x = 0`` the estimate is ``f_hat = -R``, and R is, by the module's
definitions, ``-K M^-1 T_d nu`` (paper) or ``-K T_d M nu`` (momentum) for the proportional observer and
``-K M^-1 nu`` or ``-K M nu`` for the bias and constant ones; the expected values are those products, by hand."""

from __future__ import annotations

import numpy as np
import pytest

from uvsym import vehicle
from uvsym.observers import bias_observer, constant_observer, proportional_observer

NU = np.array([1.2, 0.1, 0.05])  # m/s, m/s, rad/s
TAU_D = np.array([40.0, 3.0, 8.0])  # N, N, N m
K = np.array([2.0, 3.0, 0.5])


@pytest.mark.parametrize("builder, scales", [(proportional_observer, True), (bias_observer, False),
                                             (constant_observer, False)])
def test_each_builder_passes_its_form_on(builder, scales):
    model = vehicle("otter3dof")  # diagonal M
    M = model.M
    T_d = np.diag(TAU_D) if scales else np.eye(3)
    expected = {"paper": np.diag(K) @ np.linalg.inv(M) @ T_d @ NU, "momentum": np.diag(K) @ T_d @ M @ NU}
    assert not np.allclose(expected["paper"], expected["momentum"])  # the forms differ on this vehicle
    for form, f_hat in expected.items():
        function = builder(model, form)
        np.testing.assert_allclose(np.asarray(function(np.zeros(3), np.zeros(3), NU, TAU_D, K)[1]).ravel(), f_hat,
                                   rtol=1e-12)


# the exact error dynamics, the fault action, the names and the messages


def _hand_A(M, kind, form, tau_d, K):
    """e' = A e for constant tau_d: A = L M^-1 G with L = dR/dnu; G = T_d (proportional) or I (bias, constant);
    paper R = -K M^-1 G nu so A = -K M^-1 G M^-1 G; momentum R = -K G M nu so A = -K G^2."""
    G = np.diag(tau_d) if kind == "proportional" else np.eye(len(tau_d))
    Minv = np.linalg.inv(M)
    return -np.diag(K) @ Minv @ G @ Minv @ G if form == "paper" else -np.diag(K) @ G @ G


def _hand_tau_d_term(M, kind, form, nu, tau_d_dot, K):
    """(dR/dtau_d) tau_d': R_i = -K_i (M^-1 (tau_d o nu))_i (paper) or -K_i tau_i (M nu)_i (momentum) for the
    proportional observer; R does not depend on tau_d for the bias and constant ones."""
    if kind != "proportional":
        return np.zeros(len(nu))
    return -K * (np.linalg.inv(M) @ (nu * tau_d_dot)) if form == "paper" else -K * (M @ nu) * tau_d_dot


@pytest.mark.parametrize("vehicle_name, forms", [("otter3dof", ("paper", "momentum")),
                                                 ("docking_auv", ("momentum",))])
@pytest.mark.parametrize("kind", ["proportional", "bias", "constant"])
def test_exact_error_dynamics_are_the_hand_derived_A_e_plus_the_tau_d_rate_term(vehicle_name, forms, kind):
    """With the plant M nu' = G f + b - h (b = tau_d for bias: v + f), the observer's e' is A e plus
    (dR/dtau_d) tau_d', whatever f, eta and nu are: the fault's offset b and the known forces h cancel."""
    from uvsym.observers.actuator import actuator_observer

    model = vehicle(vehicle_name)
    n = model.dof
    rng = np.random.default_rng(7)
    for form in forms:
        obs = actuator_observer(model, kind, form)
        for _ in range(3):
            e, f, eta, nu = (rng.uniform(-1, 1, n) for _ in range(4))
            tau_d, tau_d_dot, K = rng.uniform(5, 50, n), rng.uniform(-3, 3, n), rng.uniform(0.5, 3, n)
            A = _hand_A(model.M, kind, form, tau_d, K)
            np.testing.assert_allclose(np.asarray(obs.error_matrix(tau_d, K)), A, rtol=1e-10,
                                       atol=1e-12 * np.abs(A).max())
            e_dot = np.asarray(obs.error_dynamics(e, f, eta, nu, tau_d, np.zeros(n), K)).ravel()
            np.testing.assert_allclose(e_dot, A @ e, rtol=1e-9, atol=1e-12)
            e_dot = np.asarray(obs.error_dynamics(e, f, eta, nu, tau_d, tau_d_dot, K)).ravel()
            np.testing.assert_allclose(e_dot, A @ e + _hand_tau_d_term(model.M, kind, form, nu, tau_d_dot, K),
                                       rtol=1e-9, atol=1e-12)


def _numbers(expression, symbols, values):
    import casadi as ca

    return np.asarray(ca.Function("f", symbols, [expression])(*values))


def test_fault_action_is_g1_T_d_plus_s1_I_and_g0_tau_d_plus_s0_with_the_identity_flag():
    """deliver(tau_d, f) = (g0 + g1 f) tau_d + s0 + s1 f gives G = g1 T_d + s1 I and b = g0 tau_d + s0, by hand,
    for every registered kind and one with four non-unit coefficients; the flag says whether G is I."""
    import casadi as ca

    from uvsym.faults import ActuatorKind, actuator_kind
    from uvsym.observers.actuator import _fault_action

    tau = np.array([2.0, -3.0, 5.0])
    tau_d = ca.SX.sym("tau_d", 3)
    I3, T = np.eye(3), np.diag(tau)
    expected = {  # kind: (G, b, G is I)
        "proportional": (T, np.zeros(3), False),
        "bias": (I3, tau, True),
        "constant": (I3, np.zeros(3), True),
        "loss_of_effectiveness": (-T, tau, False),  # (1 - f) v
    }
    kinds = {name: actuator_kind(name) for name in expected}
    kinds["general"] = ActuatorKind("general", (-np.inf, np.inf), gain=(2.0, 3.0), shift=(5.0, 7.0), healthy=0.0)
    expected["general"] = (3.0 * T + 7.0 * I3, 2.0 * tau + 5.0, False)
    kinds["doubled"] = ActuatorKind("doubled", (-np.inf, np.inf), gain=(0.0, 0.0), shift=(0.0, 2.0), healthy=0.0)
    expected["doubled"] = (2.0 * I3, np.zeros(3), False)
    for name, kind in kinds.items():
        G, b, identity = _fault_action(kind, ca.diag(tau_d), tau_d)
        G_expected, b_expected, identity_expected = expected[name]
        np.testing.assert_allclose(_numbers(G, [tau_d], [tau]), G_expected, rtol=0, atol=0, err_msg=name)
        np.testing.assert_allclose(_numbers(b, [tau_d], [tau]).ravel(), b_expected, rtol=0, atol=0, err_msg=name)
        assert identity is identity_expected, name


def test_the_functions_and_their_outputs_carry_the_names_of_the_paper():
    from uvsym.observers.actuator import actuator_observer

    obs = actuator_observer(vehicle("otter3dof"), "bias")
    named = {obs.function: ("bias_observer", ["x", "eta", "nu", "tau_d", "K"], ["x_dot", "f_hat"]),
             obs.R: ("R", ["nu", "tau_d", "K"], ["R"]), obs.L: ("L", ["nu", "tau_d", "K"], ["L"]),
             obs.error_matrix: ("A", ["tau_d", "K"], ["A"]),
             obs.error_dynamics: ("e_dot", ["e", "f", "eta", "nu", "tau_d", "tau_d_dot", "K"], ["e_dot"])}
    for function, (name, inputs, outputs) in named.items():
        assert (function.name(), function.name_in(), function.name_out()) == (name, inputs, outputs)


ENTRY = {"x": "N", "eta": "psi", "nu": "r", "tau_d": "N", "K": "N", "e": "N", "f": "N", "tau_d_dot": "N"}


@pytest.mark.parametrize("function_name", ["function", "R", "L", "error_matrix", "error_dynamics"])
def test_a_non_finite_argument_is_named_by_the_model_function_argument_and_entry_label(function_name):
    """The third entry of a 3-DOF vector is psi (eta), r (nu) or N (the forces x, tau_d, K, e, f, tau_d_dot)."""
    from uvsym.errors import ArgumentError
    from uvsym.observers.actuator import actuator_observer

    function = getattr(actuator_observer(vehicle("otter3dof"), "bias"), function_name)
    for index, argument in enumerate(function.name_in()):
        values = [np.ones(3) for _ in function.name_in()]
        values[index] = np.array([1.0, 1.0, np.nan])
        with pytest.raises(ArgumentError) as error:
            function(*values)
        assert str(error.value).startswith(f"otter3dof.{function.name()}: argument {argument} "
                                           f"entry {ENTRY[argument]} is nan"), str(error.value)


def test_a_non_finite_output_is_named_by_its_entry_label():
    """Finite arguments so large that the products overflow: the first non-finite entry is named (X, the surge
    force, for these arguments). Called by position the outputs are checked in order (x_dot first); called by
    name CasADi returns them by name (f_hat first), so f_hat's own overflow is named too."""
    from uvsym.errors import ArgumentError
    from uvsym.observers.actuator import actuator_observer

    obs = actuator_observer(vehicle("otter3dof"), "bias")
    big, ones = np.full(3, 1e200), np.ones(3)
    with pytest.raises(ArgumentError, match=r"^otter3dof\.bias_observer: output x_dot entry X is -?inf at finite"):
        obs.function(big, ones, ones, ones, big)
    x = np.array([1.79e308, 1.0, 1.0])  # x - R overflows in the first entry, where R = -K M^-1 nu
    with pytest.raises(ArgumentError, match=r"^otter3dof\.bias_observer: output f_hat entry X is inf at finite"):
        obs.function(x=x, eta=ones, nu=ones, tau_d=ones, K=np.array([1e308, 1.0, 1.0]))
    with pytest.raises(ArgumentError, match=r"^otter3dof\.e_dot: output e_dot entry X is -?inf at finite"):
        obs.error_dynamics(big, ones, ones, ones, ones, ones, big)


def test_unknown_kinds_and_forms_list_the_known_ones_and_assumption_1_is_named():
    from uvsym.errors import ObserverError
    from uvsym.observers.actuator import actuator_observer

    model = vehicle("otter3dof")
    with pytest.raises(ObserverError) as error:
        actuator_observer(model, "stuck")
    assert str(error.value) == "unknown observer kind 'stuck'; known: proportional, bias, constant"
    with pytest.raises(ObserverError) as error:
        actuator_observer(model, "bias", "Paper")
    assert str(error.value) == "unknown observer form 'Paper'; known: paper, momentum"
    with pytest.raises(ObserverError) as error:
        actuator_observer(vehicle("docking_auv"), "proportional", "paper")
    assert str(error.value) == ("docking_auv: the paper's proportional observer needs a diagonal mass matrix "
                                "(Assumption 1: CG = CB, symmetric vehicle); use form='momentum'")


def test_assumption_1_is_refused_from_an_off_diagonal_mass_of_1e_12_on():
    """M is diagonal to 1e-12 (absolute, kg or kg m): an off-diagonal entry of 1e-10 is coupling, 1e-13 is not."""
    from dataclasses import replace

    from uvsym.errors import ObserverError
    from uvsym.observers.actuator import actuator_observer

    model = vehicle("otter3dof")
    for offset, refused in ((1e-10, True), (1e-13, False)):
        M = model.M.copy()
        M[0, 1] = M[1, 0] = offset
        coupled = replace(model, M=M)
        if refused:
            with pytest.raises(ObserverError, match="diagonal mass matrix"):
                actuator_observer(coupled, "proportional", "paper")
        else:
            assert actuator_observer(coupled, "proportional", "paper").form == "paper"
