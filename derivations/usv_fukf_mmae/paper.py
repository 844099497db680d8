"""What Li et al. 2025 (the FUKF-MMAE paper) prints, checked by machine: its eq. 4 against the model of its eqs. 1-3,
its eq. 11's weights, its eq. 18's shapes."""

from __future__ import annotations

import numpy as np

import uvsym
from derivations.papers import paper
from uvsym.observers.ukf import unscented_weights

__all__ = ["CITATION", "printed_eq4", "eq4_check", "eq11_check", "eq18_check"]

CITATION = paper("li2025").reference()
POINT = {"nu": (1.5, 0.3, 0.2), "u": (60.0, 40.0)}  # m/s, m/s, rad/s; N, N: where eq. 4 is compared


def printed_eq4(nu, tau, M, D) -> np.ndarray:
    """(u', v', r') as the paper's eq. 4 prints them (tau = (tau_u, tau_v, tau_r))."""
    (u, v, r), (m11, m22, m33), (d11, d22, d33) = nu, np.diag(M), np.diag(D)
    return np.array([m22 / m11 * v * r - d11 / m11 * u + tau[0] / m11,
                     m11 / m22 * u * r - d22 / m22 * v,
                     (m11 - m22) / m22 * u * v - d33 / m33 * r + tau[2] / m33])


def eq4_check() -> dict:
    """Eq. 4 as printed versus ``M^-1 (tau - C(nu) nu - D nu)`` of eqs. 1-3 (the uvsym model), at POINT."""
    model = uvsym.vehicle("otter3dof")
    nu, u = np.array(POINT["nu"]), np.array(POINT["u"])
    derived = np.asarray(model.nu_dot(np.zeros(3), nu, u, 0.0, 0.0)).ravel()
    tau = np.asarray(model.tau(np.zeros(3), nu, u, 0.0, 0.0)).ravel()
    D = np.diag([float(model.h(np.zeros(3), np.eye(3)[i])[i]) for i in range(3)])  # diagonal damping: h(e_i)_i
    printed = printed_eq4(nu, tau, model.M, D)
    return {"point": POINT, "rows": ["u_dot", "v_dot", "r_dot"], "printed": printed.tolist(),
            "derived": derived.tolist(), "difference": (printed - derived).tolist()}


def eq11_check(n: int, alpha: float, beta: float, kappa: float) -> dict:
    """Sum of the mean weights as printed (``w_i = lambda / (2 (n + lambda))``) and as corrected."""
    lam = alpha**2 * (n + kappa) - n
    printed = lam / (n + lam) + 2 * n * lam / (2 * (n + lam))
    _, w_m, _ = unscented_weights(n, alpha, beta, kappa)
    return {"n": n, "lambda": lam, "printed_sum": printed, "corrected_sum": float(np.sum(w_m))}


def eq18_check(n: int, m: int) -> str:
    """What numpy says of eq. 18's product ``(gamma - xhat)(z - zhat)`` without the transpose."""
    try:
        np.ones((n, 1)) @ np.ones((m, 1))
    except ValueError as exc:
        return str(exc)
    return "no error"
