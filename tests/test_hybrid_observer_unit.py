"""Unit checks of uvsym.observers.hybrid.hybrid_observer: signal names, units, groups, messages, the
full-order unknown-input observer (no subsystem 2) and the initial state; expected values by hand."""

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import ModelError, ObserverError
from uvsym.observers.hybrid import FaultEstimator, decouple, hybrid_observer
from uvsym.systems import signals, system

A3 = np.array([[-1.0, 1.0, 0.0], [1.0, -2.0, 0.0], [1.0, 0.0, -1.0]])


def three():
    """x1' = -x1 + x2 + d, x2' = x1 - 2 x2 + d + u, x3' = x1 - x3; y = (x1, x3) (m, m/s)."""
    return system("three", "test plant", x=signals(("x1", "m"), ("x2", "m"), ("x3", "m"), group="state"),
                  u=signals(("u", "m/s"), group="input"), d=signals(("d", "m/s"), group="disturbance"),
                  y=signals(("y1", "m"), ("y3", "m"), group="output"),
                  rhs=lambda x, u, d, p: ca.mtimes(ca.DM(A3), x) + ca.vertcat(d, d + u, 0),
                  output=lambda x, u, p: ca.vertcat(x[0], x[2]))


def lag(y_group: str = "output", u_group: str = "input", p_group: str = "parameter"):
    """x1' = -x1 + d, x2' = x1 - a x2 + u (a = 2.5 1/s by default); y = (x1, x2); groups as labelled."""
    return system("lag", "two first-order lags", x=signals(("x1", "m"), ("x2", "m"), group="state"),
                  u=signals(("u", "m/s"), group=u_group), d=signals(("d", "m/s"), group="disturbance"),
                  p=signals(("a", "1/s"), group=p_group), y=signals(("y1", "m"), ("y2", "m"), group=y_group),
                  rhs=lambda x, u, d, p: ca.vertcat(-x[0] + d, x[0] - p[0] * x[1] + u), output=lambda x, u, p: x,
                  p0=[2.5])


def rk4_of_linear(M, c, s0, h):
    """One classical RK4 step of s' = M s + c: the Taylor polynomial of s(h) to 4th order."""
    expected, term = np.array(s0, dtype=float), M @ s0 + c
    for k in range(1, 5):
        expected = expected + h ** k * term / np.prod(range(1, k + 1))
        term = M @ term
    return expected


def split3(sys3):
    return decouple(sys3, sys3.linearize(), z1=["x1", "x2"], w1=["y1"], F=[[0.0], [2.0]])


def test_gain_and_fault_name_messages_name_the_observer_and_the_gain():
    sys3 = three()
    dec = split3(sys3)
    with pytest.raises(ObserverError, match=r"^obs: K1 must be a finite \(2, 1\) matrix, got shape \(1, 2\)$"):
        hybrid_observer(sys3, dec, [[1.0, 2.0]], [[1.0]], 0.1, name="obs")
    with pytest.raises(ObserverError, match=r"^obs: L must be a finite \(1, 1\) matrix, got shape \(2,\)$"):
        hybrid_observer(sys3, dec, [[1.0], [0.0]], [1.0, 2.0], 0.1, name="obs")
    two = signals(("fa", "m"), ("fb", "m"), group="fault")
    with pytest.raises(ObserverError, match=r"^obs: 1 faults are estimated but 2 are named$"):
        hybrid_observer(sys3, dec, [[1.0], [0.0]], [[1.0]], 0.1, name="obs", faults=two,
                        estimator=FaultEstimator(Gamma=[[1.0]], M1=[[1.0]], M2=[[0.0]]))


def test_published_signals_read_signals_and_their_groups():
    sys3 = three()
    obs = hybrid_observer(sys3, split3(sys3), [[1.0], [0.0]], [[1.0]], 0.1,
                          estimator=FaultEstimator(Gamma=[[1.0]], M1=[[1.0]], M2=[[0.0]]))
    pub = obs.publishes
    assert pub.names == ("x1_hat", "x2_hat", "x3_hat", "r_y1", "r_y3", "f_1_hat")
    # the default fault has no unit (F carries it) and is described by its number, counted from 1
    assert pub.units == ("m", "m", "m", "m", "m", "")
    assert pub.descriptions[-1] == "sensor fault 1"
    assert (obs.reads_y.group, obs.reads_u.group, obs.params.group) == ("measurement", "input", "parameter")
    assert obs.reads_y.names == ("y1", "y3") and obs.reads_u.names == ("u",)


def test_the_observer_relabels_the_plant_groups_and_publishes_a_plain_signal_group():
    # the plant labels its outputs "estimate" (e.g. they come from an upstream filter), its inputs "command" and
    # its parameters "constant": the observer reads them as measurements, inputs and parameters, and the
    # residuals it publishes are still not estimates, so the published group is the generic "signal"
    plant = lag("estimate", "command", "constant")
    obs = hybrid_observer(plant, decouple(plant, plant.linearize(), z1=["x1"], w1=["y1"]), [[2.0]], [[4.0]], 0.1)
    assert obs.publishes.names == ("x1_hat", "x2_hat", "r_y1", "r_y2")
    assert obs.publishes.group == "signal"
    assert (obs.reads_y.group, obs.reads_u.group, obs.params.group) == ("measurement", "input", "parameter")


def test_the_plant_parameters_and_their_defaults_are_the_observer_parameters():
    plant = lag()
    obs = hybrid_observer(plant, decouple(plant, plant.linearize(), z1=["x1"], w1=["y1"]), [[2.0]], [[4.0]], 0.1)
    assert obs.params.names == ("a",) and obs.params.units == ("1/s",)
    np.testing.assert_array_equal(obs.p0, [2.5])
    # by hand: H = 1, Tu = 0; zhat1 = v + y1, r1 = -v, r2 = y2 - z2; v' = 2 r1 = -2 v,
    # z2' = zhat1 - a z2 + u + 4 r2 = v - (a + 4) z2 + y1 + u + 4 y2
    s0, y, u, h = np.array([0.5, -0.25]), np.array([1.0, 2.0]), np.array([0.5]), 0.1
    for a in (2.5, 0.5):
        M = np.array([[-2.0, 0.0], [1.0, -(a + 4.0)]])
        c = np.array([0.0, y[0] + u[0] + 4.0 * y[1]])
        s1, out = obs.step(s0, y, u, obs.p0 if a == 2.5 else [a])
        np.testing.assert_allclose(np.asarray(s1).ravel(), rk4_of_linear(M, c, s0, h), rtol=1e-13, atol=1e-13)
        np.testing.assert_allclose(np.asarray(out).ravel(), [1.5, -0.25, -0.5, 2.25], rtol=0, atol=1e-15)


def test_full_order_unknown_input_observer_without_subsystem_2():
    sys3 = three()
    dec = decouple(sys3, sys3.linearize(), z1=["x1", "x2", "x3"], w1=["y1", "y3"])
    obs = hybrid_observer(sys3, dec, [[3.0, 0.0], [0.0, 0.0], [0.0, 2.0]], np.zeros((0, 0)), 0.1, name="uio")
    assert obs.description == ("hybrid unknown-input observer of three, unknown-input observer, sampled every "
                               "0.1 s (1 RK4 step(s))")
    assert obs.state.names == ("v_x1", "v_x2", "v_x3")
    # by hand: C1 E1 = (1, 0), H = E1 (C1 E1)^+ = [[1, 0], [1, 0], [0, 0]], Tu = [[0, 0, 0], [-1, 1, 0], [0, 0, 1]],
    # Tu A = [[0, 0, 0], [2, -3, 0], [1, 0, -1]], Tu B = (0, 1, 0); zhat = (v1 + y1, v2 + y1, v3),
    # r = (-v1, y3 - v3); v' = Tu (A zhat + B u) + K1 r = M v + c
    s0, y, u = np.array([0.3, -0.2, 0.5]), np.array([1.0, 2.0]), np.array([1.0])
    M = np.array([[-3.0, 0.0, 0.0], [2.0, -3.0, 0.0], [1.0, 0.0, -3.0]])
    c = np.array([0.0, -y[0] + u[0], y[0] + 2.0 * y[1]])
    s1, out = obs.step(s0, y, u, obs.p0)
    np.testing.assert_allclose(np.asarray(s1).ravel(), rk4_of_linear(M, c, s0, 0.1), rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(np.asarray(out).ravel(), [1.3, 0.8, 0.5, -0.3, 1.5], rtol=0, atol=1e-15)


def test_detection_observer_with_fault_directions_but_no_estimator_publishes_no_fault_estimate():
    # x1 -> x2 -> x3 chain, y = x; one fault seen by both subsystem-2 sensors, no estimator
    A = np.array([[-1.0, 0.0, 0.0], [1.0, -2.0, 0.0], [0.0, 1.0, -1.0]])
    chain = system("chain", "x1 -> x2 -> x3", x=signals(("x1", "m"), ("x2", "m"), ("x3", "m"), group="state"),
                   u=signals(("u", "m/s"), group="input"), d=signals(("d", "m/s"), group="disturbance"),
                   y=signals(("y1", "m"), ("y2", "m"), ("y3", "m"), group="output"),
                   rhs=lambda x, u, d, p: ca.mtimes(ca.DM(A), x) + ca.vertcat(d + u, 0, 0), output=lambda x, u, p: x)
    dec = decouple(chain, chain.linearize(), z1=["x1"], w1=["y1"], F=[[0.0], [1.0], [1.0]])
    obs = hybrid_observer(chain, dec, [[5.0]], 3.0 * np.eye(2), 0.1, name="detect")
    assert obs.publishes.names == ("x1_hat", "x2_hat", "x3_hat", "r_y1", "r_y2", "r_y3")
    # by hand: H = 1, zhat1 = v + y1, r1 = -v, r2 = (y2, y3) - (z2, z3) (no fault estimate subtracted)
    _, out = obs.step([0.5, 0.25, -1.0], [1.0, 2.0, 3.0], [0.0], obs.p0)
    np.testing.assert_allclose(np.asarray(out).ravel(), [1.5, 0.25, -1.0, -0.5, 1.75, 4.0], rtol=0, atol=1e-15)


def test_the_initial_state_puts_the_estimate_at_the_operating_point():
    sys3 = three()
    obs = hybrid_observer(sys3, split3(sys3), [[1.0], [0.0]], [[1.0]], 0.1)
    # by hand: x_op = 0, H = (1, 1): zhat1 = v + H y1 = 0 needs v = -H y1; zhat2 starts at x_op3 = 0
    np.testing.assert_array_equal(obs.initial_state([2.0, 5.0], [0.0]), [-2.0, -2.0, 0.0])


def test_published_names_that_collide_are_a_typed_error_naming_them():
    # state r_y1 publishes r_y1_hat and output y1_hat publishes the residual r_y1_hat; the plant labels its
    # states "residual", yet the published estimates and residuals together are the generic "signal" group
    plant = system("clash", "x1' = -x1 + d, x2' = x1 - x2 + u, y = x",
                   x=signals(("r_y1", "m"), ("x2", "m"), group="residual"), u=signals(("u", "m/s"), group="input"),
                   d=signals(("d", "m/s"), group="disturbance"),
                   y=signals(("y1_hat", "m"), ("y2", "m"), group="output"),
                   rhs=lambda x, u, d, p: ca.vertcat(-x[0] + d, x[0] - x[1] + u), output=lambda x, u, p: x)
    dec = decouple(plant, plant.linearize(), z1=["r_y1"], w1=["y1_hat"])
    with pytest.raises(ModelError, match=r"^signal names must be unique; repeated: \['r_y1_hat'\]$"):
        hybrid_observer(plant, dec, [[2.0]], [[4.0]], 0.1)
