"""Unit tests of ``region_decay_claim``: input conversion, what the certificate says (claim, set, labels,
method, expected), the e'(0) = 0 proof of the quadratic expansion, and the scale of V = e'Pe.

The plants are linear (or cubic), so every expected value is derived by hand: for ``x' = -x + u``,
``y = x`` and gain l, the error obeys ``e' = -(1 + l) e``, so ``V = p e^2`` has ``V' = -2 p (1 + l) e^2``.
"""

import re
from dataclasses import replace
from fractions import Fraction

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import VerificationError
from uvsym.observers.luenberger import luenberger_observer
from uvsym.systems import signals, system
from uvsym.testing import assert_proved, assert_refuted
from uvsym.verify.estimators import region_decay_claim
from uvsym.verify.region import _sqrt_above

EXPANSION = ("; e' as its exact quadratic expansion (polynomial of degree <= 2 in e, e'(0) = 0 proved in exact "
             "rationals)")


def _lag(cubic: bool = False):
    """x' = -x (- x^3) + u, y = x: one state a (m), one input u (m/s); equilibria x = u (linear case)."""
    return system("lag", "first-order lag", x=signals(("a", "m"), group="state"),
                  u=signals(("u", "m/s"), group="input"),
                  rhs=lambda x, u, d, p: -x - (x ** 3 if cubic else 0) + u)


def _pair():
    """x1' = -x1 + u, x2' = -x2, y = x1: two states a (m), b (m/s)."""
    return system("pair", "two decoupled lags", x=signals(("a", "m"), ("b", "m/s"), group="state"),
                  u=signals(("u", "m/s"), group="input"), y=signals(("a_meas", "m"), group="output"),
                  rhs=lambda x, u, d, p: ca.vertcat(-x[0] + u[0], -x[1]), output=lambda x, u, p: x[0])


def test_a_refuted_claim_names_its_point_by_state_and_unit_and_v_dot_uses_p_as_given():
    """No injection (l = 0): V = e^2 gives V' = -2 e^2, above -3 e^2 everywhere but 0: refuted. The
    counterexample is keyed "e_a (m)" and its V' is -2 e^2 at its point (a P scaled up by 3 would prove it)."""
    plant = _lag()
    obs = luenberger_observer(plant, [[0.0]], 0.01)
    certificate = region_decay_claim(obs, plant, [[1.0]], gamma=3.0, half_widths=[0.5], cube=0.05,
                                     expected="refuted")
    assert_refuted(certificate)
    assert certificate.expected == "refuted"
    example = certificate.counterexample
    assert list(example["x"]) == ["e_a (m)"]
    e = example["x"]["e_a (m)"]
    assert 0 < abs(e) <= 0.5
    assert example["V_dot"] == pytest.approx(-2 * e * e, rel=1e-12)
    assert example["bound"] == pytest.approx(-3 * e * e, rel=1e-12)


def test_a_proved_claim_states_claim_set_and_the_exact_expansion():
    """l = 1, P = I: e' = (-2 e_a, -e_b), V' = -4 e_a^2 - 2 e_b^2 <= -0.5 e'e on the box."""
    plant = _pair()
    obs = luenberger_observer(plant, [[1.0], [0.0]], 0.01)
    certificate = region_decay_claim(obs, plant, np.eye(2), gamma=0.5, half_widths=[0.5, 0.25], cube=0.05)
    assert_proved(certificate)
    assert certificate.claim == f"{obs.name} on pair: V = e'Pe, V' <= -0.5 e'e (nonlinear error dynamics)"
    assert certificate.set == ("|e_a| <= 0.5 m, |e_b| <= 0.25 m/s; true state at the equilibrium a = 0, b = 0; "
                               "u = 0; d = 0, p = p0")
    assert certificate.method.endswith(EXPANSION)
    assert certificate.method.count("exact quadratic expansion") == 1


def test_a_non_polynomial_claim_does_not_say_it_was_expanded():
    """x' = -x - x^3: e' = -e - e^3 (degree 3, not expanded); V' = -2 e^2 - 2 e^4 <= -e^2: proved."""
    plant = _lag(cubic=True)
    obs = luenberger_observer(plant, [[0.0]], 0.01)
    certificate = region_decay_claim(obs, plant, [[1.0]], gamma=1.0, half_widths=[0.5], cube=0.05)
    assert_proved(certificate)
    assert "expansion" not in certificate.method


def test_the_inputs_u0_set_the_equilibrium():
    """x' = -x + u is at rest at x = u = 2 (not at the default u = 0)."""
    plant = _lag()
    obs = luenberger_observer(plant, [[1.0]], 0.01)
    certificate = region_decay_claim(obs, plant, [[1.0]], gamma=1.0, half_widths=[0.5], cube=0.05, x0=[2.0],
                                     u0=[2.0])
    assert_proved(certificate)
    assert certificate.set == "|e_a| <= 0.5 m; true state at the equilibrium a = 2; u = 2; d = 0, p = p0"


def test_integer_and_unsigned_inputs_are_converted_to_float_before_arithmetic():
    """P = 100 as int8 (100 + 100 would wrap to -56) and a half-width 1 as uint8 (-1 would wrap to 255):
    the same claim as in floats, V' = -200 e^2 <= -100 e^2, proved on |e| <= 1."""
    plant = _lag()
    obs = luenberger_observer(plant, [[0.0]], 0.01)
    certificate = region_decay_claim(obs, plant, np.array([[100]], dtype=np.int8), gamma=100.0,
                                     half_widths=np.array([1], dtype=np.uint8), cube=0.05)
    assert_proved(certificate)
    assert certificate.set.startswith("|e_a| <= 1 m; ")


def test_a_p_that_is_not_positive_definite_is_refused_with_its_eigenvalues_to_6_decimals():
    plant = _lag()
    obs = luenberger_observer(plant, [[0.0]], 0.01)
    message = ("P must be positive definite for V = e'Pe to measure the error; it is not (eigenvalues "
               "[-0.123457])")
    with pytest.raises(VerificationError, match=f"^{re.escape(message)}$"):
        region_decay_claim(obs, plant, [[-0.1234567]], gamma=1.0, half_widths=[0.5], cube=0.05)


def test_error_dynamics_not_zero_at_e_0_for_every_state_are_refused():
    """e' = -e + (x_a - x_b, 0): at the equilibrium x = 0 this is -e (a polynomial), but e'(0) = x_a - x_b
    is not 0 for every x, so the exact expansion (which is 0 at e = 0) would not be the observer's."""
    plant = _pair()
    obs = luenberger_observer(plant, [[1.0], [0.0]], 0.01)
    e, x, u, d, p = (ca.SX.sym(n, k) for n, k in (("e", 2), ("x", 2), ("u", 1), ("d", 0), ("p", 0)))
    shifted = ca.Function("shifted", [e, x, u, d, p], [-e + ca.vertcat(x[0] - x[1], 0)], ["e", "x", "u", "d", "p"],
                          ["e_dot"])
    wrong = replace(obs, error_dynamics=shifted)
    message = f"{obs.name}: its error dynamics are not 0 at e = 0 (refuted)"
    with pytest.raises(VerificationError, match=f"^{re.escape(message)}$"):
        region_decay_claim(wrong, plant, np.eye(2), gamma=1.0, half_widths=[0.5, 0.5], cube=0.05)


def test_a_true_claim_with_a_small_hessian_of_w_is_proved():
    """l = 1, P = I, gamma = 1.5: W = V' + 1.5 e'e = -2.5 e_a^2 - 0.5 e_b^2 < 0 off 0, Hessian diag(-5, -1). An exact
    interval Hessian (radius 0) must not be widened by the square root's rounding (it was by 1, whatever the units)."""
    plant = _pair()
    obs = luenberger_observer(plant, [[1.0], [0.0]], 0.01)
    assert_proved(region_decay_claim(obs, plant, np.eye(2), gamma=1.5, half_widths=[0.5, 0.25], cube=0.05))



@pytest.mark.parametrize("value", [Fraction(0), Fraction(1), Fraction(4, 9), Fraction(2), Fraction(1, 3),
                                   Fraction(10**30, 7)])
def test_the_square_root_bound_is_above_and_within_2_to_the_minus_64_over_q(value):
    """r^2 >= value in rationals, r exact for a perfect square, and r - 2^-64 / q is below sqrt(value)."""
    r = _sqrt_above(value)
    lower = r - Fraction(1, value.denominator * 2**64)
    assert r * r >= value and (lower < 0 or lower * lower < value)
    if value in (Fraction(0), Fraction(1), Fraction(4, 9)):
        assert r * r == value
