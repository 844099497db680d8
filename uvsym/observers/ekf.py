"""Extended Kalman filter of any System, Jacobians by ``casadi.jacobian``.

Prediction ``xhat^- = F(xhat, u, p)``, ``P^- = A P A^T + Q`` with ``A = dF/dx`` at the posterior
(F the discrete map: the System's own, or RK4 steps of a continuous one, differentiated through
the integrator). Update ``S = H P^- H^T + R`` with ``H = dh/dx`` at the prior,
``K = P^- H^T S^-1`` by Cholesky solves, ``xhat = xhat^- + K (y - h(xhat^-))`` and the Joseph
form ``P = (I - K H) P^- (I - K H)^T + K R K^T`` (symmetric positive semi-definite by
construction). The log-likelihood uses S's Cholesky factor.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from uvsym.observers.base import Observer
from uvsym.observers.kalman import (
    GaussianFilter,
    checked_inputs,
    cho_solve,
    cholesky,
    filter_observer,
    gaussian_loglik,
    positive_definite,
    transition,
)
from uvsym.systems.system import System

__all__ = ["extended_filter", "ekf"]


def extended_filter(system: System, *, dt: float, Q, R, P0, x0=None, steps: int = 1,
                    name: str = "ekf") -> GaussianFilter:
    """The EKF of ``system`` (module docstring) as a :class:`~uvsym.observers.kalman.GaussianFilter`;
    arguments and errors as :func:`uvsym.observers.ukf.unscented_filter` (no alpha, beta, kappa)."""
    Q, R, P0, x0 = checked_inputs(system, name, dt, Q, R, P0, x0)
    semidefinite = not (positive_definite(Q) and positive_definite(P0))  # P may then lose rank (its margin)
    n = system.x.size
    F = transition(system, dt, steps)
    xs, us, ps = ca.SX.sym("x", n), ca.SX.sym("u", system.u.size), ca.SX.sym("p", system.p.size)
    F_x = F(xs, us, ps)
    h_x = system.h(xs, us, ps)
    model = ca.Function("model", [xs, us, ps], [F_x, ca.jacobian(F_x, xs), h_x, ca.jacobian(h_x, xs)])
    eye = ca.DM.eye(n)

    def predict(x, P, u, p):
        x_next, A, _, _ = model(x, u, p)
        P_next = ca.mtimes(ca.mtimes(A, P), A.T) + ca.DM(Q)
        return x_next, P_next, cholesky(P_next, semidefinite)[1]

    def update(x, P, y, u, p):
        _, _, z, H = model(x, u, p)
        S = ca.mtimes(ca.mtimes(H, P), H.T) + ca.DM(R)
        L_S, margin = cholesky(S)
        K = cho_solve(L_S, ca.mtimes(H, P)).T  # P H^T S^-1, P and S symmetric
        r = y - z
        IKH = eye - ca.mtimes(K, H)
        P_post = ca.mtimes(ca.mtimes(IKH, P), IKH.T) + ca.mtimes(ca.mtimes(K, ca.DM(R)), K.T)
        return x + ca.mtimes(K, r), P_post, r, gaussian_loglik(r, L_S), margin

    return GaussianFilter(name, "ekf", system, float(dt), Q, R, P0, np.asarray(x0), update, predict, {"steps": steps})


def ekf(system: System, **options) -> Observer:
    """The EKF of ``system`` as an :class:`~uvsym.observers.base.Observer` (options of
    :func:`extended_filter`)."""
    filt = extended_filter(system, **options)
    return filter_observer(filt, f"EKF of {system.name}, sampled every {filt.dt:g} s")
