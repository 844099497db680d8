"""Claims on an estimator's error dynamics: linearisation identity, LMI decay, nonlinear decay on a box."""

import casadi as ca
import numpy as np
import pytest
import scipy.linalg

from uvsym.errors import VerificationError
from uvsym.observers.base import observer
from uvsym.observers.luenberger import luenberger_observer
from uvsym.systems import signals, system
from uvsym.testing import assert_proved, assert_refuted
from uvsym.verify.estimators import linear_decay_claim, linearisation_claim, region_decay_claim, sampled_decay_claim

X = signals(("angle", "rad"), ("rate", "rad/s"), group="state")
L = np.array([[4.0], [5.0]])


def _pendulum():
    """A damped pendulum, angle measured: nonlinear in the state."""
    return system("pendulum", "damped pendulum", x=X, u=signals(("torque", "rad/s^2"), group="input"),
                  y=signals(("angle_meas", "rad"), group="output"),
                  rhs=lambda x, u, d, p: ca.vertcat(x[1], -9.81 * ca.sin(x[0]) - 0.5 * x[1] + u[0]),
                  output=lambda x, u, p: x[0])


def test_luenberger_claims_on_a_pendulum():
    plant = _pendulum()
    obs = luenberger_observer(plant, L, 0.01)
    assert_proved(linearisation_claim(obs, plant, L))
    lin = plant.linearize()
    slowest = -max(np.linalg.eigvals(lin.A - L @ lin.C).real)
    assert slowest > 1.0  # computed independently of the claim
    assert_proved(linear_decay_claim(obs, plant, decay=0.9 * slowest))
    assert_refuted(linear_decay_claim(obs, plant, decay=1.1 * slowest, expected="refuted"))
    # the claim is about the observer it names: without injection the pendulum's own rate (0.25) is too slow
    assert_refuted(linear_decay_claim(luenberger_observer(plant, 0 * L, 0.01), plant, decay=1.0, expected="refuted"))
    # sampled: exp(dt * eigenvalues) inside the unit circle at 0.01 s; far outside at 1 s
    assert_proved(sampled_decay_claim(obs, plant))
    assert_refuted(sampled_decay_claim(luenberger_observer(plant, L, 1.0), plant, expected="refuted"))
    A_cl = lin.A - L @ lin.C
    P = scipy.linalg.solve_continuous_lyapunov(A_cl.T, -np.eye(2))
    proved = region_decay_claim(obs, plant, P, gamma=0.1, half_widths=[0.3, 0.3], cube=0.05)
    assert_proved(proved)
    # a wrong gain sign makes the error grow: refuted, with a point where V' + gamma e'e > 0
    bad = luenberger_observer(plant, -L, 0.01)
    refuted = region_decay_claim(bad, plant, P, gamma=0.1, half_widths=[0.3, 0.3], cube=0.05, expected="refuted")
    assert_refuted(refuted)
    point = np.array(list(refuted.counterexample["x"].values()))
    e_dot = np.asarray(bad.error_dynamics(point, np.zeros(2), [0.0], np.zeros(0), np.zeros(0))).ravel()
    assert 2 * point @ P @ e_dot + 0.1 * point @ point > 0  # re-checked in plain floats


def test_claims_reject_observers_without_error_dynamics():
    plant = _pendulum()
    plain = observer("plain", step=lambda s, y, u, p: (s, s), state=X, reads_y=plant.y, reads_u=plant.u,
                     publishes=X.renamed(suffix="_hat"), dt=0.1)
    with pytest.raises(VerificationError, match="needs error_dynamics"):
        linearisation_claim(plain, plant, L)
    obs = luenberger_observer(plant, L, 0.01)
    with pytest.raises(VerificationError, match="P must be 2x2"):
        region_decay_claim(obs, plant, np.eye(3), 0.1, [0.1, 0.1], 0.01)


def _bilinear():
    """x1' = -x1 + x1 x2 + u, x2' = -2 x2 + x1^2, y = x1: polynomial of degree 2."""
    return system("bilinear", "quadratic plant", x=signals(("a", "-"), ("b", "-"), group="state"),
                  u=signals(("u", "-"), group="input"), y=signals(("a_meas", "-"), group="output"),
                  rhs=lambda x, u, d, p: ca.vertcat(-x[0] + x[0] * x[1] + u[0], -2 * x[1] + x[0] ** 2),
                  output=lambda x, u, p: x[0], x_op=[0.5, 0.125], u_op=[0.5 - 0.5 * 0.125])


def test_quadratic_error_dynamics_are_expanded_exactly_and_proved_on_a_box():
    from uvsym.verify.estimators import _quadratic_form

    plant = _bilinear()
    assert np.allclose(np.asarray(plant.f(plant.x_op, plant.u_op, [], [])).ravel(), 0.0, atol=1e-15)
    gain = np.array([[3.0], [0.0]])
    obs = luenberger_observer(plant, gain, 0.01)
    e = ca.SX.sym("e", 2)
    direct = obs.error_dynamics(e, plant.x_op, plant.u_op, np.zeros(0), np.zeros(0))
    expanded = _quadratic_form(direct, e)
    compare = ca.Function("compare", [e], [direct, expanded])
    for point in np.random.default_rng(3).uniform(-2, 2, size=(20, 2)):
        a, b = (np.asarray(v).ravel() for v in compare(point))
        np.testing.assert_allclose(b, a, rtol=1e-12, atol=1e-12)
    lin = plant.linearize()
    P = scipy.linalg.solve_continuous_lyapunov((lin.A - gain @ lin.C).T, -np.eye(2))
    assert_proved(region_decay_claim(obs, plant, P, gamma=0.1, half_widths=[0.2, 0.2], cube=0.02))
    # too large a box: the quadratic terms win somewhere, and the verifier says where
    far = region_decay_claim(obs, plant, P, gamma=0.1, half_widths=[5.0, 5.0], cube=0.02, expected="refuted")
    assert_refuted(far)


def test_region_claims_refuse_what_would_make_them_unsound():
    plant = _pendulum()
    obs = luenberger_observer(plant, L, 0.01)
    with pytest.raises(VerificationError, match="positive definite"):
        region_decay_claim(obs, plant, -np.eye(2), 0.1, [0.3, 0.3], 0.05)
    with pytest.raises(VerificationError, match="not an equilibrium"):
        region_decay_claim(obs, plant, np.eye(2), 0.1, [0.3, 0.3], 0.05, x0=[0.5, 0.0])


def test_a_graph_with_floor_is_not_expanded_as_a_polynomial():
    """floor has a structurally zero derivative: the expansion must not be used, and the claim
    must not come out proved where V' > -gamma e'e (here at e = 0.5)."""
    from uvsym.verify.estimators import _quadratic_form

    plant = system("stepped", "x' = -x - 4 x floor(x)", x=signals(("a", "-"), group="state"),
                   u=signals(("u", "-"), group="input"), rhs=lambda x, u, d, p: -x - 4 * x * ca.floor(x) + u)
    obs = luenberger_observer(plant, [[1.0]], 0.01)
    e = ca.SX.sym("e")
    assert _quadratic_form(obs.error_dynamics(e, [0.0], [0.0], [], []), e) is None
    e_dot = float(obs.error_dynamics(0.5, [0.0], [0.0], [], []))
    assert 2 * 0.5 * e_dot + 0.1 * 0.25 > 0  # so "proved" would be false
    certificate = region_decay_claim(obs, plant, np.eye(1), 0.1, [1.0], 0.05, expected="refuted")
    assert certificate.status != "proved"
