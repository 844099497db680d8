"""Positive semi-definite Q, R and P0 in the UKF and the EKF: accepted, and the filter exact where it must be.

A constant-velocity target sampled every 0.1 s with a discretised white-noise acceleration
(``Q = q G G^T``, ``G = [dt^2 / 2, dt]``: rank 1) and its position measured: the model is linear,
so the Kalman filter is exact and both the UKF and the EKF must give its numbers.
"""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import CovarianceError
from uvsym.observers.ekf import ekf
from uvsym.observers.kalman import check_covariance, cholesky, run_filter
from uvsym.observers.ukf import ukf
from uvsym.systems import signals, system

DT = 0.1
F = np.array([[1.0, DT], [0.0, 1.0]])
H = np.array([[1.0, 0.0]])
G = np.array([[DT ** 2 / 2], [DT]])
Q = 0.5 * G @ G.T  # rank 1
R = np.array([[0.04]])


def _target():
    x = signals(("pos", "m"), ("vel", "m/s"), group="state")
    return system("target", "constant velocity", x=x, u=signals(group="input"),
                  rhs=lambda x, u, d, p: ca.mtimes(ca.DM(F), x), y=signals(("pos_meas", "m"), group="output"),
                  output=lambda x, u, p: x[0], dt=DT)


def _kalman(Y, P0, x0):
    """The textbook Kalman filter (numpy): posterior means, one row per sample."""
    x, P, out = np.array(x0, dtype=float), np.array(P0, dtype=float), []
    for y in Y:
        S = H @ P @ H.T + R
        K = P @ H.T @ np.linalg.inv(S)
        x = x + (K @ (y - H @ x)).ravel()
        P = (np.eye(2) - K @ H) @ P
        out.append(x.copy())
        x, P = F @ x, F @ P @ F.T + Q
    return np.array(out)


@pytest.fixture(scope="module")
def measured():
    rng = np.random.default_rng(3)
    truth, Y = np.array([0.0, 1.0]), []
    for _ in range(60):
        Y.append([truth[0] + 0.2 * rng.standard_normal()])
        truth = F @ truth + (G * np.sqrt(0.5) * rng.standard_normal()).ravel()
    return np.array(Y)


@pytest.mark.parametrize("make", [ukf, ekf], ids=["ukf", "ekf"])
@pytest.mark.parametrize("P0", [np.diag([1.0, 4.0]), np.diag([0.0, 4.0]), np.zeros((2, 2))],
                         ids=["definite", "position known", "state known"])
def test_a_singular_q_and_p0_give_the_kalman_filter(make, P0, measured):
    filt = make(_target(), dt=DT, Q=Q, R=R, P0=P0, x0=[0.0, 1.0])
    _, out = run_filter(filt, measured, np.zeros((len(measured), 0)))
    posterior = out[:, [filt.publishes.index("pos_hat"), filt.publishes.index("vel_hat")]]
    np.testing.assert_allclose(posterior, _kalman(measured, P0, [0.0, 1.0]), rtol=0, atol=1e-9)


def test_an_indefinite_covariance_is_refused_by_name():
    with pytest.raises(CovarianceError, match=r"ukf: Q is indefinite \(smallest eigenvalue -1\)"):
        ukf(_target(), dt=DT, Q=np.diag([1.0, -1.0]), R=R, P0=np.eye(2))
    assert np.array_equal(check_covariance([0.0, 2.0], 2, "P0"), np.diag([0.0, 2.0]))


def test_the_semidefinite_factor_squares_back_and_its_margin_tells_indefinite():
    A = ca.SX.sym("A", 3, 3)
    factor = ca.Function("f", [A], list(cholesky(A, semidefinite=True)))
    B = np.array([[1.0, 2.0, 0.0], [0.0, 0.0, 0.0], [3.0, 1.0, 1.0]])
    rank_two = B @ B.T  # a zero row and column in the middle
    L, margin = (np.array(v) for v in factor(rank_two))
    np.testing.assert_allclose(L @ L.T, rank_two, atol=1e-12)
    assert margin.item() > 0
    indefinite = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 1.0]])  # a zero pivot, column not zero
    assert float(factor(indefinite)[1]) < 0
    assert float(factor(-np.eye(3))[1]) < 0
    strict = ca.Function("g", [A], [cholesky(A)[1]])
    assert float(strict(rank_two)) <= 0  # the default stays strict: the innovation covariance must be definite
