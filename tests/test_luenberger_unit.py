"""Unit tests of :func:`uvsym.observers.luenberger.luenberger_observer` on a linear oscillator.

Every expected value is computed here by hand from the plant's matrices (A, B, C, G), never by
the observer's own code: the continuous injection, one RK4 step as the matrix polynomial it is on a
linear plant, the error dynamics (A - L C) e + G d, and the signal groups the observer declares.
"""

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import ObserverError
from uvsym.observers.luenberger import luenberger_observer
from uvsym.systems import signals, system

GAIN = np.array([[3.0], [-1.5]])  # (n_x, n_y) = (2, 1)
K0 = 2.0  # the plant's nominal stiffness p0 (N/m)
X_OP = [0.5, -0.25]


def _oscillator(x_group: str = "signal", y_group: str = "signal"):
    """pos' = vel, vel' = -k pos - 0.5 vel + force + push, y = pos: every group the default "signal"
    unless given, a parameter k (p0 = 2 N/m), a disturbance push and a non-zero x_op."""
    return system("osc", "damped oscillator",
                  x=signals(("pos", "m"), ("vel", "m/s"), group=x_group), u=signals(("force", "N")),
                  d=signals(("push", "N")), p=signals(("k", "N/m")), y=signals(("pos_meas", "m"), group=y_group),
                  rhs=lambda x, u, d, p: ca.vertcat(x[1], -p[0] * x[0] - 0.5 * x[1] + u[0] + d[0]),
                  output=lambda x, u, p: x[0], p0=[K0], x_op=X_OP)


def _matrices(k: float):
    """(A, B, C, G) of the oscillator with stiffness k, written out by hand."""
    return (np.array([[0.0, 1.0], [-k, -0.5]]), np.array([[0.0], [1.0]]), np.array([[1.0, 0.0]]),
            np.array([[0.0], [1.0]]))


def _column(value) -> np.ndarray:
    return np.asarray(value, dtype=float).reshape(-1)


def test_continuous_form_adds_the_gain_times_the_output_error():
    obs = luenberger_observer(_oscillator(), GAIN, 0.1)
    continuous = obs.equations["continuous"]
    assert list(obs.equations) == ["continuous"]
    assert isinstance(continuous, ca.Function)
    assert continuous.name_in() == ["xhat", "y", "u", "p"] and continuous.name_out() == ["xhat_dot"]
    xhat, y, u, k = np.array([0.3, -0.7]), np.array([1.1]), np.array([0.4]), 3.0
    A, B, C, _ = _matrices(k)
    expected = A @ xhat + B @ u + GAIN @ (y - C @ xhat)  # y - C xhat = 0.8: injection (+2.4, -1.2)
    np.testing.assert_allclose(_column(continuous(xhat, y, u, [k])), expected, rtol=1e-14, atol=1e-14)


def test_error_dynamics_are_a_minus_lc_plus_the_disturbance():
    obs = luenberger_observer(_oscillator(), GAIN, 0.1)
    f = obs.error_dynamics
    assert f.name_in() == ["e", "x", "u", "d", "p"] and f.name_out() == ["e_dot"]
    e, x, u, d, k = np.array([0.2, -0.1]), np.array([0.6, 0.9]), np.array([-0.3]), np.array([0.25]), 3.0
    A, _, C, G = _matrices(k)
    np.testing.assert_allclose(_column(f(e, x, u, d, [k])), (A - GAIN @ C) @ e + G @ d, rtol=1e-14, atol=1e-14)


def test_symbols_inside_the_equations_are_named_after_their_inputs():
    """Printing an equation (``f.sx_out()``) reads in the inputs' own names: xhat_0, y, e_1, d, ..."""
    obs = luenberger_observer(_oscillator(), GAIN, 0.1)
    for f in (obs.equations["continuous"], obs.error_dynamics):
        for i in range(f.n_in()):
            assert str(f.sx_in(i)) == str(ca.SX.sym(f.name_in(i), f.numel_in(i))), (f.name(), f.name_in(i))


def test_default_step_is_one_rk4_step_plus_the_sampled_injection():
    """Linear plant: one RK4 step over dt is x+ = R(A dt) x + dt S(A dt) B u, with R(Z) = I + Z + Z^2/2 +
    Z^3/6 + Z^4/24 and S(Z) = I + Z/2 + Z^2/6 + Z^3/24; the observer adds dt L (y - C x)."""
    dt = 0.5  # large, so that one step and two half steps differ by far more than rounding
    obs = luenberger_observer(_oscillator(), GAIN, dt)
    s, y, u = np.array([0.3, -0.7]), np.array([1.1]), np.array([0.4])
    A, B, C, _ = _matrices(K0)

    def one_step(h):
        Z, eye = A * h, np.eye(2)
        R = eye + Z + Z @ Z / 2 + Z @ Z @ Z / 6 + Z @ Z @ Z @ Z / 24
        S = eye + Z / 2 + Z @ Z / 6 + Z @ Z @ Z / 24
        return R, h * S @ B

    R, Bd = one_step(dt)
    s_next, out = obs.step(s, y, u, obs.p0)
    np.testing.assert_allclose(_column(s_next), R @ s + Bd @ u + dt * GAIN @ (y - C @ s), rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(_column(out), np.concatenate([s, y - C @ s]), rtol=1e-14, atol=1e-14)
    R2, Bd2 = one_step(dt / 2)
    two, _ = luenberger_observer(_oscillator(), GAIN, dt, steps=2).step(s, y, u, obs.p0)
    np.testing.assert_allclose(_column(two), R2 @ (R2 @ s + Bd2 @ u) + Bd2 @ u + dt * GAIN @ (y - C @ s),
                               rtol=1e-13, atol=1e-14)
    assert np.abs(_column(two) - _column(s_next)).max() > 1e-4  # the two tests above are not the same test


def test_signals_parameters_and_initial_state_come_from_the_plant():
    obs = luenberger_observer(_oscillator(), GAIN, 0.1)
    assert obs.name == "luenberger"
    assert (obs.state.names, obs.state.units, obs.state.group) == (("pos_hat", "vel_hat"), ("m", "m/s"), "state")
    assert (obs.reads_y.names, obs.reads_y.group) == (("pos_meas",), "measurement")
    assert (obs.reads_u.names, obs.reads_u.group) == (("force",), "input")
    assert (obs.params.names, obs.params.units, obs.params.group) == (("k",), ("N/m",), "parameter")
    np.testing.assert_array_equal(obs.p0, [K0])
    assert obs.publishes.names == ("pos_hat", "vel_hat", "r_pos_meas")
    assert obs.publishes.units == ("m", "m/s", "m")
    np.testing.assert_array_equal(obs.initial_state([9.0], [1.0]), X_OP)  # x_op, not the measurement
    assert obs.description == ("Luenberger observer of osc: xhat' = f(xhat, u) + L (y - h(xhat, u)), "
                               "sampled every 0.1 s (1 RK4 step(s) of the model)")


def test_published_group_is_generic_because_it_mixes_estimates_and_residuals():
    """Whatever the plant calls its states and outputs, the published estimates and residuals are two
    different groups, so the group of the whole is "signal" (Signals.__add__)."""
    obs = luenberger_observer(_oscillator(x_group="residual", y_group="estimate"), GAIN, 0.1)
    assert obs.publishes.group == "signal"
    assert obs.state.group == "state" and obs.reads_y.group == "measurement"


def test_bad_arguments_raise_observer_errors_naming_the_field():
    plant = _oscillator()
    with pytest.raises(ObserverError, match=r"^observer name '2fast' must start with a letter"):
        luenberger_observer(plant, GAIN, 0.1, name="2fast")
    with pytest.raises(ObserverError, match=r"gain L must be a finite \(2, 1\) matrix"):
        luenberger_observer(plant, [[None], [1.0]], 0.1)  # a missing entry is not finite, not a TypeError
    for steps in (0, 2.0):
        with pytest.raises(ObserverError, match=rf"^luenberger: steps must be a positive integer, got {steps!r}$"):
            luenberger_observer(plant, GAIN, 0.1, steps=steps)
