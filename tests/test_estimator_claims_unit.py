"""Unit tests of the estimator claims: the texts a certificate carries (claim, set), the point it is taken at,
the refusals and their messages, and the polynomial expansion's degree test. Expected values by hand."""

import re

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import ModelError, VerificationError
from uvsym.observers.base import observer
from uvsym.observers.luenberger import luenberger_observer
from uvsym.systems import signals, system
from uvsym.testing import assert_proved, assert_refuted
from uvsym.verify.estimators import _quadratic_form, linear_decay_claim, linearisation_claim, sampled_decay_claim

GAIN = np.array([[3.0], [0.0]])
# the equilibrium used below (not the operating point, which is 0): a' = -0.5 + 0.5 = 0, b' = -2 (0.25) + 0.5 = 0
X0, U0 = [0.5, 0.25], [0.5, 0.5]
WHERE = "true state at the equilibrium a = 0.5, b = 0.25; u1 = 0.5, u2 = 0.5; d = 0, p = p0"


def _twin():
    """a' = -a + u1, b' = -2 b + u2, y = a: two states, two inputs (so every list in a text has a separator)."""
    return system("twin", "two decoupled lags", x=signals(("a", "m"), ("b", "m"), group="state"),
                  u=signals(("u1", "m/s"), ("u2", "m/s"), group="input"), y=signals(("a_meas", "m"), group="output"),
                  rhs=lambda x, u, d, p: ca.vertcat(-x[0] + u[0], -2 * x[1] + u[1]), output=lambda x, u, p: x[0])


def _damped_pendulum():
    """angle' = rate, rate' = -9.81 sin(angle) - damping rate + torque, y = angle; damping a parameter."""
    return system("pendulum", "damped pendulum", x=signals(("angle", "rad"), ("rate", "rad/s"), group="state"),
                  u=signals(("torque", "rad/s^2"), group="input"), p=signals(("damping", "1/s"), group="parameter"),
                  p0=[0.5], y=signals(("angle_meas", "rad"), group="output"),
                  rhs=lambda x, u, d, p: ca.vertcat(x[1], -9.81 * ca.sin(x[0]) - p[0] * x[1] + u[0]),
                  output=lambda x, u, p: x[0])


def test_linear_decay_is_claimed_at_the_given_equilibrium_and_says_so():
    """A - L C = diag(-1 - 3, -2) at any point: decay 1.5 < 2 holds, and P satisfies the LMI."""
    plant = _twin()
    certificate = linear_decay_claim(luenberger_observer(plant, GAIN, 0.1), plant, 1.5, x0=X0, u0=U0)
    assert_proved(certificate)
    assert certificate.claim == "luenberger on twin: linearised error decays at rate 1.5 1/s"
    assert certificate.set == f"e near 0, {WHERE}"
    P, A_cl = np.array(certificate.details["P"]), np.diag([-4.0, -2.0])
    assert np.linalg.eigvalsh(P).min() > 0
    assert np.linalg.eigvalsh(A_cl.T @ P + P @ A_cl + 2 * 1.5 * P).max() < 0


def test_sampled_decay_is_claimed_at_the_given_equilibrium_and_says_so():
    """Ad = diag(R(-0.1) - 0.1 * 3, R(-0.2)), R the RK4 polynomial 1 + z + z^2/2 + z^3/6 + z^4/24: radius < 1."""
    plant = _twin()
    certificate = sampled_decay_claim(luenberger_observer(plant, GAIN, 0.1), plant, x0=X0, u0=U0)
    assert_proved(certificate)
    assert certificate.claim == "luenberger on twin, sampled every 0.1 s: the error map contracts (spectral radius < 1)"
    assert certificate.set == WHERE
    rk4 = np.polynomial.Polynomial([1, 1, 1 / 2, 1 / 6, 1 / 24])
    radius = max(abs(rk4(-0.1) - 0.3), abs(rk4(-0.2)))  # 0.6048375, 0.8187333...
    assert certificate.details["spectral_radius"] == pytest.approx(radius, rel=1e-12)


def test_sampled_decay_default_radius_is_one():
    """x' = x / 2, no injection, dt = 1 s: one RK4 step multiplies by 1 + 1/2 + 1/8 + 1/48 + 1/384 = 633/384, which
    is >= 1 (the default rho) but < 2."""
    plant = system("growth", "x' = x / 2", x=signals(("a", "-"), group="state"), u=signals(("u", "-"), group="input"),
                   rhs=lambda x, u, d, p: 0.5 * x + u)
    certificate = sampled_decay_claim(luenberger_observer(plant, [[0.0]], 1.0), plant, expected="refuted")
    assert_refuted(certificate)
    assert certificate.counterexample["rho"] == 1.0
    assert certificate.counterexample["eigenvalue_modulus"] == pytest.approx(633 / 384, rel=1e-12)


def test_claims_refuse_a_point_that_is_not_an_equilibrium_naming_what_moves():
    plant = _twin()
    obs = luenberger_observer(plant, GAIN, 0.1)
    message = "twin: the point is not an equilibrium (a, b move): the true state would not stay there"
    with pytest.raises(VerificationError, match=f"^{re.escape(message)}$"):
        linear_decay_claim(obs, plant, 1.0, x0=X0)  # u defaults to the operating point 0
    # the given u0 is what balances the given x0: neither may fall back to the operating point
    with pytest.raises(VerificationError, match="not an equilibrium"):
        sampled_decay_claim(obs, plant, x0=X0)
    with pytest.raises(VerificationError, match="not an equilibrium"):
        sampled_decay_claim(obs, plant, u0=U0)
    with pytest.raises(VerificationError, match="not an equilibrium"):
        linear_decay_claim(obs, plant, 1.0, u0=U0)


def test_claims_name_the_point_argument_of_the_wrong_size():
    plant = _twin()
    obs = luenberger_observer(plant, GAIN, 0.1)
    with pytest.raises(ModelError, match=re.escape("x0 must have 2 entries (a, b), got 3")):
        linear_decay_claim(obs, plant, 1.0, x0=[0.0, 0.0, 0.0])
    with pytest.raises(ModelError, match=re.escape("u0 must have 2 entries (u1, u2), got 1")):
        linear_decay_claim(obs, plant, 1.0, u0=[0.0])


def test_sampled_claim_refuses_an_observer_whose_state_is_not_the_plants():
    plant = _twin()
    one = signals(("a_hat", "m"), group="state")
    stub = observer("stub", step=lambda s, y, u, p: (s, s), state=one, reads_y=plant.y, reads_u=plant.u,
                    publishes=one, dt=0.1)
    message = "stub: its state (1) is not an estimate of twin's 2 states"
    with pytest.raises(VerificationError, match=f"^{re.escape(message)}$"):
        sampled_decay_claim(stub, plant)


def test_claims_name_the_inputs_of_error_dynamics_with_the_wrong_signature():
    plant = _twin()
    a, b = ca.SX.sym("a", 2), ca.SX.sym("b", 2)
    wrong = ca.Function("g", [a, b], [a - b], ["a", "b"], ["a_dot"])
    obs = observer("odd", step=lambda s, y, u, p: (s, s), state=plant.x, reads_y=plant.y, reads_u=plant.u,
                   publishes=plant.x.renamed(suffix="_hat"), dt=0.1, error_dynamics=wrong)
    with pytest.raises(VerificationError, match=re.escape("got ['a', 'b']")):
        linear_decay_claim(obs, plant, 1.0)


def test_linearisation_claim_texts_and_its_refutation_point():
    """The claim holds for the observer's own gain; for another gain it is refuted at a point over x, u, p (the
    symbols of the identity), in the entry where the gains differ: vec index 1 = row 1 (rate), column 0 (angle)."""
    plant = _damped_pendulum()
    gain = np.array([[4.0], [5.0]])
    obs = luenberger_observer(plant, gain, 0.01)
    proved = linearisation_claim(obs, plant, gain)
    assert_proved(proved)
    assert proved.claim == "luenberger on pendulum: linearised error dynamics are A(x, u) - L C(x, u)"
    assert proved.set == "all x, u, p; e = 0, d = 0"
    refuted = linearisation_claim(obs, plant, [[4.0], [6.0]], expected="refuted")
    assert_refuted(refuted)
    assert refuted.expected == "refuted"
    assert refuted.set == "all x, u, p; e = 0, d = 0"
    # casadi names a symbol of one entry without an index
    assert list(refuted.counterexample["point"]) == ["x_0", "x_1", "u", "p"]
    assert refuted.counterexample["entry"] == 1


def test_quadratic_expansion_refuses_a_cubic():
    """e' = -e + e^3 (products only): the third derivative is the single constant 6, so the degree is 3 and the
    expansion -e would drop the term that makes the error grow beyond |e| = 1."""
    e = ca.SX.sym("e")
    assert _quadratic_form(-e + e * e * e, e) is None


def test_quadratic_expansion_needs_e_as_the_only_symbol():
    """CasADi refuses the graph of an expression with a symbol other than e, and names it."""
    e, x = ca.SX.sym("e"), ca.SX.sym("x")
    with pytest.raises(RuntimeError, match="(?s)'graph'.*variables \\[x\\] are free"):
        _quadratic_form(-e * x, e)
