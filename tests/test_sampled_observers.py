"""Sampled (discrete-time) actuator-fault observers of uvsym.observers.discrete: the pieces of the step, the
residue dropped from the update, initial states and labels, with expected values worked out by hand."""

import casadi as ca
import numpy as np
import pytest

import uvsym
from uvsym.errors import ObserverError
from uvsym.observers.actuator import actuator_observer
from uvsym.observers.discrete import _drop_residue, actuator_fault_observer, sampled_observer

ARGS = ["x", "eta", "nu", "tau_d", "K"]


def _two_channel(x_dot=None):
    """x' = -K (x - nu) + tau_d, f_hat = x - nu (2 states): R = nu, so P = diag(-K), q = tau_d, L = I."""
    x, eta, nu, tau_d, K = (ca.SX.sym(a, 2) for a in ARGS)
    rhs = -K * (x - nu) + tau_d if x_dot is None else x_dot(x, nu, tau_d, K)
    return ca.Function("two", [x, eta, nu, tau_d, K], [rhs, x - nu], ARGS, ["x_dot", "f_hat"])


def _symbol_names(function: ca.Function, i: int) -> list[str]:
    return [str(v) for v in ca.symvar(function.sx_in(i))]


def test_pieces_and_step_are_named_and_their_symbols_read_as_their_inputs():
    sampled = sampled_observer(_two_channel(), 0.1)
    pieces, step = sampled.pieces, sampled.step
    assert pieces.name() == "pieces"
    assert pieces.name_in() == ["eta", "nu", "tau_d", "K"] and pieces.name_out() == ["P", "q", "L"]
    for i, name in enumerate(("eta", "nu", "tau_d", "K")):
        assert _symbol_names(pieces, i) == [f"{name}_0", f"{name}_1"]
    assert step.name() == "observer_step"
    assert step.name_in() == ["s", "eta", "nu", "tau_d", "K"] and step.name_out() == ["s_next", "f_hat"]
    # s = [f_hat (2); P's 2 non-zeros; q (2); L's 2 non-zeros; nu (2)] = 10 entries
    assert _symbol_names(step, 0) == [f"s_{i}" for i in range(10)]
    for i, name in enumerate(("eta", "nu", "tau_d", "K"), start=1):
        assert _symbol_names(step, i) == [f"{name}_0", f"{name}_1"]


def test_pieces_by_name_are_the_hand_derived_P_q_L():
    pieces = sampled_observer(_two_channel(), 0.1).pieces
    out = pieces(eta=[0.3, -0.2], nu=[1.0, 2.0], tau_d=[5.0, -7.0], K=[2.0, 3.0])
    np.testing.assert_array_equal(np.asarray(ca.densify(out["P"])), np.diag([-2.0, -3.0]))
    np.testing.assert_array_equal(np.asarray(out["q"]).ravel(), [5.0, -7.0])
    np.testing.assert_array_equal(np.asarray(ca.densify(out["L"])), np.eye(2))


def test_an_observer_not_affine_in_x_is_refused_by_name():
    with pytest.raises(ObserverError) as refused:
        sampled_observer(_two_channel(lambda x, nu, tau_d, K: -K * (x - nu) ** 2 + tau_d), 0.1)
    assert str(refused.value) == ("observer two: x_dot must be affine in x (x_dot = P (x - R) + q), the sampled-data "
                                  "form needs it")


def test_a_state_independent_rate_and_input_keep_empty_P_in_the_state():
    """x' = tau_d, f_hat = x - nu: P = 0 (no non-zeros), so s = [f_hat; q; L; nu] and one step is
    f_hat_1 = dt (tau_0 + tau_1) / 2 - (nu_1 - nu_0) (trapezoid, L = I)."""
    sampled = sampled_observer(_two_channel(lambda x, nu, tau_d, K: tau_d), 0.5)
    assert (sampled.nnz_P, sampled.nnz_L, sampled.state_size) == (0, 2, 8)
    s0 = sampled.initial_state([0, 0], [1.0, 2.0], [2.0, 4.0], [1.0, 1.0])
    np.testing.assert_array_equal(s0, [0, 0, 2, 4, 1, 1, 1, 2])
    s1, f_hat = sampled.step(s0, [0, 0], [1.5, 1.0], [6.0, 0.0], [1.0, 1.0])
    np.testing.assert_array_equal(np.asarray(f_hat).ravel(), [0.5 * 8 / 2 - 0.5, 0.5 * 4 / 2 + 1.0])
    np.testing.assert_array_equal(np.asarray(s1).ravel(), [1.5, 2.0, 6, 0, 1, 1, 1.5, 1.0])


def test_residue_is_relative_to_the_largest_entry_and_the_boundary_is_dropped():
    a = ca.SX.sym("a", 2)
    # a genuinely small matrix is kept whole: only the ratio to its own largest entry counts
    tiny = _drop_residue(ca.diag(1e-13 * a), [a])
    assert tiny.nnz() == 2
    # entries at exactly rtol of the largest (a power-of-two ratio, exact) are dropped, above it kept
    cleaned = _drop_residue(ca.horzcat(4 * a[0], a[0], 2 * a[0]), [a], rtol=0.25)
    assert set(zip(*cleaned.sparsity().get_triplet())) == {(0, 0), (0, 2)}
    # a large matrix: 1e-13 of a 1e6 entry is residue, 1e-11 of it is not
    big = _drop_residue(ca.horzcat(1e6 * a[0], 1e-7 * a[1], 1e-5 * a[1]), [a])
    assert set(zip(*big.sparsity().get_triplet())) == {(0, 0), (0, 2)}


def test_residue_probe_draws_inputs_from_half_to_two_reproducibly():
    a = ca.SX.sym("a", 64)
    # zero on [0.5, 2] (dropped) but not above 2; zero above 1.5 but not below it (kept)
    outside = ca.sum1(ca.fmax(a - 2, 0))
    inside = ca.sum1(ca.fmax(1.5 - a, 0))
    cleaned = _drop_residue(ca.horzcat(1 + 0 * a[0], outside, inside), [a])
    assert set(zip(*cleaned.sparsity().get_triplet())) == {(0, 0), (0, 2)}
    # entries alive on part of the box only: the same entries are kept at every call (fixed draws), and the
    # default is 8 samples
    partial = ca.if_else(a > 1.8, 1, 0)
    first = _drop_residue(partial, [a]).sparsity().get_triplet()
    assert _drop_residue(partial, [a]).sparsity().get_triplet() == first
    assert _drop_residue(partial, [a], samples=8).sparsity().get_triplet() == first


@pytest.fixture  # per test, not per module: a mutation tool links a function to the tests whose set-up called it
def otter_bias():
    return uvsym.vehicle("otter3dof"), actuator_fault_observer(uvsym.vehicle("otter3dof"), "bias", 0.05, [1, 2, 3])


def test_actuator_fault_observer_labels_groups_units_and_equations(otter_bias):
    model, obs = otter_bias
    assert obs.reads_y.group == "measurement" and obs.reads_y.names == model.state_labels
    assert obs.state.group == "state" and obs.state.units == ("-",) * obs.state.size
    assert obs.state.names[0] == "bias.s0"
    assert obs.publishes.group == "fault estimate"
    assert obs.publishes.names == ("f_hat.X", "f_hat.Y", "f_hat.N")
    assert list(obs.equations) == ["continuous"]
    continuous = actuator_observer(model, "bias", "paper").function
    args = ([1.0, 2.0, 0.1], [0.5, -0.2, 0.05], [0.3, 0.1, 0.2], [10.0, -4.0, 2.0], [1.0, 2.0, 3.0])
    for got, want in zip(obs.equations["continuous"](*args), continuous(*args)):
        np.testing.assert_array_equal(np.asarray(got), np.asarray(want))
    # y = [eta; nu] and u = tau_d read under their protocol names
    raw = obs.step.raw
    assert _symbol_names(raw, 0) == [f"s_{i}" for i in range(obs.state.size)]
    assert _symbol_names(raw, 1) == [f"y_{i}" for i in range(6)]
    assert _symbol_names(raw, 2) == ["u_0", "u_1", "u_2"]


def test_actuator_fault_observer_momentum_form_gain_units():
    # momentum form, bias fault (the command is not scaled): the rate is k_i itself, 1/s
    obs = actuator_fault_observer(uvsym.vehicle("otter3dof"), "bias", 0.05, [1, 2, 3], form="momentum")
    assert obs.params.units == ("1/s", "1/s", "1/s")
    assert obs.description.endswith("(momentum form), sampled every 0.05 s")


@pytest.mark.parametrize("gains", [[1.0, 0.0, 3.0], [1.0, -2.0, 3.0]])
def test_actuator_fault_observer_refuses_zero_and_negative_gains(gains):
    with pytest.raises(ObserverError, match=r"^bias observer: the gains K must be 3 positive finite numbers"):
        actuator_fault_observer(uvsym.vehicle("otter3dof"), "bias", 0.05, gains)


def test_actuator_fault_observer_refuses_a_bad_name_as_an_observer_name():
    with pytest.raises(ObserverError, match=r"^observer name 'two words' must start with a letter"):
        actuator_fault_observer(uvsym.vehicle("otter3dof"), "bias", 0.05, [1, 2, 3], name="two words")


def test_initial_state_is_a_float_vector_even_from_an_object_array():
    """s0 = [f_hat = 0; P's non-zeros -K; q = tau_d; L's non-zeros 1; nu]; nu taken from a mixed-type table
    arrives as an object array and must not make the state one."""
    sampled = sampled_observer(_two_channel(), 0.1)
    s0 = sampled.initial_state([0, 0], np.array([1.5, 2.0], dtype=object), [3.0, 4.0], [1.0, 2.0])
    assert s0.dtype == np.float64
    np.testing.assert_array_equal(s0, [0, 0, -1, -2, 3, 4, 1, 1, 1.5, 2])
