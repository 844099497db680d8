"""Unscented Kalman filter of any System (Julier & Uhlmann; the scaled transform of Wan & van der Merwe).

For n states, ``lambda = alpha^2 (n + kappa) - n`` and the 2n + 1 sigma points
``X_0 = xhat``, ``X_{i}, X_{n+i} = xhat +- sqrt(n + lambda) L_i`` (L_i the i-th column of a
Cholesky factor of P, fault paper eq. 10: lower in an order with the passive states last, see
:func:`passive_last`) carry the weights (its eq. 11, typo corrected)::

    w_m0 = lambda / (n + lambda),  w_c0 = w_m0 + 1 - alpha^2 + beta,  w_i = 1 / (2 (n + lambda))

(the paper prints ``w_i = lambda / (2 (n + lambda))``, whose weights do not sum to 1). Prediction
(eqs. 12-14): ``xhat^- = sum w_m F(X_i)``, ``P^- = sum w_c (F(X_i) - xhat^-)(...)^T + Q``.
Update (eqs. 15-20): sigma points redrawn from ``(xhat^-, P^-)`` (so Q enters P_zz and P_xz:
the filter is exactly the Kalman filter on a linear Gaussian system), ``Z_i = h(X_i)``
(for an output affine in x, ``h = H x + c``, the transform is exact and is evaluated in closed
form: ``zhat = h(xhat^-)``, ``P_zz = H P^- H^T + R``, ``P_xz = P^- H^T``),
``P_zz = sum w_c dZ dZ^T + R``, ``P_xz = sum w_c dX dZ^T`` (eq. 18 with its missing transpose),
``K = P_xz P_zz^-1`` by Cholesky solves, ``xhat = xhat^- + K r``, ``P = P^- - K P_zz K^T =
P^- - K P_xz^T`` (symmetrised, factorised with a relative jitter of 1e-12 at the next use).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from uvsym.errors import ObserverError
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

__all__ = ["unscented_filter", "ukf", "unscented_weights", "passive_last"]


def unscented_weights(n: int, alpha: float, beta: float, kappa: float) -> tuple[float, np.ndarray, np.ndarray]:
    """(sqrt(n + lambda), w_m (2n+1,), w_c (2n+1,)) of the scaled unscented transform; ObserverError
    for alpha outside (0, 1], non-finite beta or n + kappa <= 0."""
    if not (isinstance(alpha, (int, float)) and 0.0 < alpha <= 1.0):
        raise ObserverError(f"UKF alpha must be in (0, 1], got {alpha!r}")
    if not (isinstance(beta, (int, float)) and np.isfinite(beta)):
        raise ObserverError(f"UKF beta must be a finite number, got {beta!r}")
    if not (isinstance(kappa, (int, float)) and np.isfinite(kappa) and n + kappa > 0):
        raise ObserverError(f"UKF kappa must be finite with n + kappa > 0 (n = {n}), got {kappa!r}")
    lam = alpha**2 * (n + kappa) - n
    w_m = np.full(2 * n + 1, 1.0 / (2.0 * (n + lam)))
    w_c = w_m.copy()
    w_m[0] = lam / (n + lam)
    w_c[0] = w_m[0] + 1.0 - alpha**2 + beta
    return float(np.sqrt(n + lam)), w_m, w_c


def _weighted(points, weights):
    return sum((w * X for w, X in zip(weights, points)), ca.SX.zeros(points[0].shape))


def _spread(left, right, weights, symmetric: bool):
    """``sum_i w_i a_i b_i^T`` of deviation columns a_i, b_i (SX); only the lower triangle is
    computed and mirrored when ``symmetric`` (left is right)."""
    rows, cols = left[0].numel(), right[0].numel()
    M = ca.SX.zeros(rows, cols)
    for i in range(rows):
        for j in range(i + 1 if symmetric else cols):
            M[i, j] = sum((w * a[i] * b[j] for w, a, b in zip(weights, left, right)), ca.SX(0.0))
            if symmetric:
                M[j, i] = M[i, j]
    return M


def passive_last(system: System, F) -> list[int]:
    """A state order with the states no other state's update depends on (e.g. positions) last.

    Sigma points along those states' Cholesky columns (the last ones) then change only those
    states, so their model evaluations share everything else with the central point (CSE)."""
    n = system.x.size
    x, u, p = ca.SX.sym("x", n), ca.SX.sym("u", system.u.size), ca.SX.sym("p", system.p.size)
    pattern = np.array(ca.DM(ca.jacobian(F(x, u, p), x).sparsity(), 1)) != 0
    passive = [j for j in range(n) if not any(pattern[i, j] for i in range(n) if i != j)]
    return [j for j in range(n) if j not in passive] + passive


def unscented_filter(system: System, *, dt: float, Q, R, P0, x0=None, alpha: float = 1.0, beta: float = 2.0,
                     kappa: float = 0.0, steps: int = 1, affine_closed_form: bool = True,
                     name: str = "ukf") -> GaussianFilter:
    """The UKF of ``system`` (module docstring) as a :class:`~uvsym.observers.kalman.GaussianFilter`.

    dt: sample period (s); Q (n, n) process and R (n_y, n_y) measurement noise covariances per
    sample, P0 (n, n) and x0 (n,) the prior at the first sample (matrices, variance vectors or
    scalars); steps: RK4 steps per sample of a continuous system; affine_closed_form: the update's
    moments in closed form when h is affine in x (False: by sigma points all the same). Q, R and P0 may be
    positive semi-definite (a discretised white-noise acceleration, a state known exactly): P's square
    root is then a semi-definite factorisation (:func:`~uvsym.observers.kalman.cholesky`), and only the
    innovation covariance must stay definite (pd_margin). CovarianceError for Q, R or P0 not symmetric
    or indefinite; ObserverError for alpha outside (0, 1] and other bad input.
    """
    Q, R, P0, x0 = checked_inputs(system, name, dt, Q, R, P0, x0)
    semidefinite = not (positive_definite(Q) and positive_definite(P0))  # P may then lose rank: factor it so
    n = system.x.size
    scale, w_m, w_c = unscented_weights(n, alpha, beta, kappa)
    F = transition(system, dt, steps)

    order = passive_last(system, F)
    back = np.argsort(order)

    def sigma_points(x, P):
        L, margin = cholesky(P[order, order], semidefinite)
        L = L[back, :]  # a square root of P: L L^T = P
        shifts = [scale * L[:, i] for i in range(n)]
        return [x] + [x + d for d in shifts] + [x - d for d in shifts], margin

    def predict(x, P, u, p):
        X, margin = sigma_points(x, P)
        FX = [F(Xi, u, p) for Xi in X]
        mean = _weighted(FX, w_m)
        deviations = [v - mean for v in FX]
        return mean, _spread(deviations, deviations, w_c, True) + ca.DM(Q), margin

    xs, us, ps = ca.SX.sym("x", n), ca.SX.sym("u", system.u.size), ca.SX.sym("p", system.p.size)
    H = ca.jacobian(system.h(xs, us, ps), xs)
    output_matrix = None if ca.depends_on(H, xs) or not affine_closed_form else ca.Function("H", [us, ps], [H])

    def moments(x, P, u, p):
        """(z_mean, P_zz - R, P_xz, margin): by sigma points, or in closed form for h affine in x,
        where the unscented transform is exact (``h(x), H P H^T, P H^T``; no factorisation)."""
        if output_matrix is not None:
            Hk = output_matrix(u, p)
            return system.h(x, u, p), ca.mtimes(ca.mtimes(Hk, P), Hk.T), ca.mtimes(P, Hk.T), ca.SX(1.0)
        X, margin = sigma_points(x, P)
        Z = [system.h(Xi, u, p) for Xi in X]
        z_mean = _weighted(Z, w_m)
        dZ = [z - z_mean for z in Z]
        return z_mean, _spread(dZ, dZ, w_c, True), _spread([Xi - x for Xi in X], dZ, w_c, False), margin

    def update(x, P, y, u, p):
        z_mean, P_zz, P_xz, margin = moments(x, P, u, p)
        P_zz = P_zz + ca.DM(R)
        L_S, margin_S = cholesky(P_zz)
        K = cho_solve(L_S, P_xz.T).T
        r = y - z_mean
        return (x + ca.mtimes(K, r), P - ca.mtimes(K, P_xz.T), r, gaussian_loglik(r, L_S),
                ca.fmin(margin, margin_S))

    return GaussianFilter(name, "ukf", system, float(dt), Q, R, P0, x0, update, predict,
                          {"alpha": alpha, "beta": beta, "kappa": kappa, "steps": steps,
                           "affine_closed_form": output_matrix is not None})


def ukf(system: System, **options) -> Observer:
    """The UKF of ``system`` as an :class:`~uvsym.observers.base.Observer` (options of
    :func:`unscented_filter`; state, publications and NaN handling in :mod:`uvsym.observers.kalman`)."""
    filt = unscented_filter(system, **options)
    s = filt.settings
    return filter_observer(filt, f"UKF of {system.name} (alpha {s['alpha']:g}, beta {s['beta']:g}, "
                                 f"kappa {s['kappa']:g}), sampled every {filt.dt:g} s")
