"""Parts of the hybrid observer (uvsym.observers.hybrid): rank tolerance, input conversion, the split's
fields, the messages that name a field, and the plant with sensor-fault states. Expected values by hand."""

from fractions import Fraction

import casadi as ca
import numpy as np
import pytest
import sympy

from uvsym.errors import ObserverError
from uvsym.observers.hybrid import (
    FaultEstimator,
    decouple,
    hybrid_observer,
    linear_error_model,
    observer_state,
    with_sensor_fault_states,
)
from uvsym.systems import signals, system

A3 = np.array([[-1.0, 1.0, 0.0], [1.0, -2.0, 0.0], [1.0, 0.0, -1.0]])
F = np.array([[0.0], [2.0]])
DT = 1e-3


def plant(A=A3, b=(1.0,)):
    """x' = A x + (d, d + b1 u1, b2 u2), y = (x1, x3); b gives one gain per input."""
    u = signals(*((f"u{k + 1}", "m/s") for k in range(len(b))), group="input")
    inputs = (lambda v: ca.vertcat(0, b[0] * v[0], 0)) if len(b) == 1 else \
        (lambda v: ca.vertcat(0, b[0] * v[0], b[1] * v[1]))
    return system("three", "test plant", x=signals(("x1", "m"), ("x2", "m"), ("x3", "m"), group="state"),
                  u=u, d=signals(("d", "m/s"), group="disturbance"),
                  y=signals(("y1", "m"), ("y3", "m"), group="output"),
                  rhs=lambda x, v, d, p: ca.mtimes(ca.DM(A), x) + ca.vertcat(d, d, 0) + inputs(v),
                  output=lambda x, v, p: ca.vertcat(x[0], x[2]))


def split(sys3, **kw):
    return decouple(sys3, sys3.linearize(), z1=["x1", "x2"], w1=["y1"], **kw)


# --- ranks (Assumption 1) at the relative tolerance 1e-9 ---


def test_a_singular_value_at_the_tolerance_does_not_count():
    # B = [[0, 0], [1, 0], [0, 1e-9]] and C [B E] = [[0, 0, 1], [0, 1e-9, 0]]: singular values exactly 1 and
    # 1e-9 = 1e-9 x the largest, which is not above the tolerance
    dec = split(plant(b=(1.0, 1e-9)))
    for M in (np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1e-9]]), np.array([[0.0, 0.0, 1.0], [0.0, 1e-9, 0.0]])):
        assert np.linalg.svd(M, compute_uv=False).tolist() == [1.0, 1e-9]  # the premise: exact singular values
    assert dec.ranks == {"B": 1, "E": 1, "C[B E]": 1, "m + r": 2}


def test_the_tolerance_is_relative_to_the_largest_singular_value():
    # B = diag-like (1e-3, 1e-8): the ratio 1e-5 is far above 1e-9, so both columns count although tiny
    dec = split(plant(b=(1e-3, 1e-8)))
    assert dec.ranks["B"] == 2 and dec.ranks["m + r"] == 3


# --- conversion of user matrices: None entries are NaN, hence typed errors ---


def test_none_entries_in_E_F_and_gains_are_typed_errors_not_type_errors():
    sys3 = plant()
    lin = sys3.linearize()
    with pytest.raises(ObserverError, match=r"^decoupling: E must be a finite \(3, r\) matrix and F \(2, q\); got "
                                            r"\(3, 1\), \(2, 1\)$"):
        decouple(sys3, lin, z1=["x1", "x2"], w1=["y1"], F=[[0.0], [None]])
    with pytest.raises(ObserverError, match=r"^decoupling: E must be a finite \(3, r\) matrix and F \(2, q\); got "
                                            r"\(3, 1\), \(2, 1\)$"):
        decouple(sys3, lin, z1=["x1", "x2"], w1=["y1"], E=[[1.0], [None], [0.0]], F=F)
    with pytest.raises(ObserverError, match=r"^three: F must be a finite \(2, 1\) matrix, got \(2, 1\)$"):
        with_sensor_fault_states(sys3, [[0.0], [None]], signals(("f_s", "m"), group="fault"))
    dec = split(sys3, F=F)
    with pytest.raises(ObserverError, match=r"^hybrid: K1 must be a finite \(2, 1\) matrix, got shape \(2, 1\)$"):
        hybrid_observer(sys3, dec, [[None], [0.0]], [[1.0]], DT)


def test_a_gain_that_is_no_number_is_a_typed_error():
    sys3 = plant()
    with pytest.raises(ObserverError, match=r"^hybrid: L must be a finite \(1, 1\) matrix, got shape \(\)$"):
        hybrid_observer(sys3, split(sys3, F=F), [[1.0], [0.0]], "five", DT)


def test_a_finite_E_does_not_excuse_an_infinite_F():
    sys3 = plant()
    with pytest.raises(ObserverError, match=r"^decoupling: E must be a finite \(3, r\) matrix and F \(2, q\)"):
        split(sys3, F=[[0.0], [np.inf]])  # the infinite entry is on subsystem 2's output y3


# --- the split's fields ---


def test_the_split_names_its_parts_and_keeps_the_exact_matrices():
    dec = split(plant(), F=F)
    assert (dec.z1, dec.z2, dec.w1, dec.w2) == (("x1", "x2"), ("x3",), ("y1",), ("y3",))
    # by hand: E1 = (1, 1), C1 = (1, 0): H = E1 / (C1 E1) = (1, 1), Tu = I - H C1 = [[0, 0], [-1, 1]]
    assert dec.exact["H"] == sympy.Matrix([[1], [1]])
    assert dec.exact["Tu"] == sympy.Matrix([[0, 0], [-1, 1]])
    assert dec.F2.dtype == np.float64 and dec.F2.tolist() == [[2.0]]


def test_omega2_is_tu_times_a12():
    # x1' = -x1 + x2 + x3 + d: A12 = (1, 0), and Tu = [[0, 0], [-1, 1]] (as above) makes Omega2 = (0, -1)
    A = A3 + np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    dec = split(plant(A))
    np.testing.assert_array_equal(dec.omega["Omega2"], [[0.0], [-1.0]])
    assert dec.exact["Omega2"] == sympy.Matrix([[0], [-1]])
    np.testing.assert_array_equal(dec.omega["Omega3"], [[1.0, 0.0]])  # A21, untransformed


def test_no_fault_directions_give_no_fault_columns_and_no_estimator():
    sys3 = plant()
    dec = split(sys3)
    assert dec.F2.shape == (1, 0)
    est = FaultEstimator(Gamma=[[1.0]], M1=[[1.0]], M2=[[0.0]])
    with pytest.raises(ObserverError, match="^hybrid: a fault estimator needs fault directions F$"):
        hybrid_observer(sys3, dec, [[1.0], [0.0]], [[1.0]], DT, estimator=est)
    with pytest.raises(ObserverError, match="^error model: a fault estimator needs fault directions F$"):
        linear_error_model(dec, [[1.0], [0.0]], [[1.0]], est)


def test_a_full_order_split_has_empty_blocks_of_the_right_shapes():
    # z1 = every state, w1 = every output: subsystem 2 is empty (the full-order unknown-input observer)
    sys3 = plant()
    dec = decouple(sys3, sys3.linearize(), z1=["x1", "x2", "x3"], w1=["y1", "y3"])
    assert dec.z2 == () and dec.w2 == ()
    assert dec.omega["Omega2"].shape == (3, 0)
    assert dec.omega["Omega3"].shape == (0, 3)
    assert dec.omega["Omega4"].shape == (0, 0)
    # by hand: H = [[1, 0], [1, 0], [0, 0]], Tu = [[0, 0, 0], [-1, 1, 0], [0, 0, 1]], Tu A below
    np.testing.assert_array_equal(dec.omega["Omega1"], [[0.0, 0.0, 0.0], [2.0, -3.0, 0.0], [1.0, 0.0, -1.0]])


# --- messages naming the field ---


def test_unknown_names_are_listed_with_the_known_ones():
    sys3 = plant()
    lin = sys3.linearize()
    with pytest.raises(ObserverError, match=r"^decoupling: z1 \['x1', 'x9'\] must be distinct names of states "
                                            r"\(x1, x2, x3\); unknown: \['x9'\]$"):
        decouple(sys3, lin, z1=["x1", "x9"], w1=["y1"])
    with pytest.raises(ObserverError, match=r"^decoupling: w1 \['y2'\] must be distinct names of outputs "
                                            r"\(y1, y3\); unknown: \['y2'\]$"):
        decouple(sys3, lin, z1=["x1", "x2"], w1=["y2"])


def test_outputs_of_subsystem_2_reading_subsystem_1_are_named():
    sys3 = plant()
    # z1 = every state, so y3 (left in subsystem 2) reads x3 of subsystem 1
    with pytest.raises(ObserverError, match="^decoupling: outputs w2 read subsystem-1 states; the split must follow "
                                            "C's blocks$"):
        decouple(sys3, sys3.linearize(), z1=["x1", "x2", "x3"], w1=["y1"])


@pytest.mark.parametrize("bad", ["M1", "M2"])
def test_estimator_gain_messages_name_the_gain_and_the_caller(bad):
    sys3 = plant()
    dec = split(sys3, F=F)
    gains = {"Gamma": [[1.0]], "M1": [[1.0]], "M2": [[0.0]], bad: [[1.0, 2.0]]}
    with pytest.raises(ObserverError, match=rf"^est: {bad} must be a finite \(1, 1\) matrix, got shape \(1, 2\)$"):
        hybrid_observer(sys3, dec, [[1.0], [0.0]], [[1.0]], DT, name="est", estimator=FaultEstimator(**gains))
    with pytest.raises(ObserverError, match=rf"^error model: {bad} must be a finite \(1, 1\) matrix"):
        linear_error_model(dec, [[1.0], [0.0]], [[1.0]], FaultEstimator(**gains))


def test_the_error_model_names_itself_when_i_plus_f2_gamma_m2_is_singular():
    dec = split(plant(), F=F)
    # by hand: 1 + F2 Gamma M2 = 1 + 2 (-0.5) = 0
    with pytest.raises(ObserverError, match="^error model: I \\+ F2 Gamma M2 is singular; the residual is not "
                                            "defined$"):
        linear_error_model(dec, [[1.0], [0.0]], [[1.0]], FaultEstimator(Gamma=[[1.0]], M1=[[1.0]], M2=[[-0.5]]))


# --- observer_state ---


def test_observer_state_of_exact_numbers_is_a_float_vector_without_integral_states_by_default():
    sys3 = plant()
    dec = split(sys3, F=F)
    xhat = [Fraction(1, 3), Fraction(2, 3), Fraction(1, 2)]
    C = [[Fraction(1), Fraction(0), Fraction(0)], [Fraction(0), Fraction(0), Fraction(1)]]
    s = observer_state(dec, xhat, C)
    # by hand: w1 = y1 = 1/3, v = zhat1 - H w1 = (1/3 - 1/3, 2/3 - 1/3), zhat2 = x3 = 1/2; no integral state
    assert s.dtype == np.float64 and s.shape == (3,)
    np.testing.assert_allclose(s, [0.0, 1 / 3, 0.5], rtol=0, atol=1e-15)


# --- with_sensor_fault_states ---


def scaled():
    return system("scaled", "x' = -a x + u, y = x", x=signals(("x", "m"), group="state"),
                  u=signals(("u", "m/s"), group="input"), p=signals(("a", "1/s"), group="parameter"),
                  rhs=lambda x, u, d, p: -p[0] * x + u, p0=[2.5], x_op=[0.4], u_op=[1.0], source="a test plant")


def test_sensor_fault_states_keep_the_operating_point_source_and_name_the_system():
    aug = with_sensor_fault_states(scaled(), [[1.0]], signals(("f_s", "m"), group="fault"))
    assert aug.name == "scaled_with_faults"
    assert aug.description == "x' = -a x + u, y = x; sensor faults as constant states"
    np.testing.assert_array_equal(aug.x_op, [0.4, 0.0])  # the fault starts at 0
    np.testing.assert_array_equal(aug.u_op, [1.0])
    assert aug.source == "a test plant"
    assert aug.x.group == "state" and aug.x.names == ("x", "f_s")


def test_sensor_fault_states_read_a_flat_F_row_by_row():
    aug = with_sensor_fault_states(plant(), [0.0, 2.0], signals(("f_s", "m"), group="fault"))
    # F = [[0], [2]]: y = (x1, x3 + 2 f) at x = (0.1, 0.2, 0.3), f = 0.7
    np.testing.assert_allclose(np.asarray(aug.h([0.1, 0.2, 0.3, 0.7], [0.0], [])).ravel(), [0.1, 1.7],
                               rtol=0, atol=1e-15)
