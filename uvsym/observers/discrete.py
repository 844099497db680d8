"""Sampled-data form of an observer ``(x, eta, nu, tau_d, K) -> (x_dot, f_hat)`` with ``f_hat = x - R``.

Eliminating x gives the estimate's own dynamics ``f_hat' = phi(f_hat) - L nu' - (dR/dtau_d) tau_d'``
with ``phi(f_hat) = x_dot(x = f_hat + R) = P f_hat + q`` and ``L = dR/dnu``. Between samples the
measured change of nu is known, so no derivative is needed; with ``tau_d`` changing between
samples the ``tau_d'`` term is absorbed exactly (the continuous proof's dropped term, see
``ActuatorObserver.error_dynamics``). The step from sample k-1 to k is the trapezoidal
(Crank-Nicolson) rule

    (I - dt/2 P_k) f_hat_k = (I + dt/2 P_{k-1}) f_hat_{k-1} + dt/2 (q_{k-1} + q_k) - (L_{k-1} + L_k)/2 (nu_k - nu_{k-1})

which keeps a matched, constant fault a fixed point to third order in dt (forward Euler on x
leaves an offset of order ``dt M nu''``) and is stable for any gain: the proportional
observer's rate ``k_i tau_d,i^2`` grows without bound with the desired action, which an
explicit step would not survive. The state carries what sample k-1 contributed:
``s = [f_hat (n); vec(P) (n n); q (n); vec(L) (n n); nu (n)]``.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

__all__ = ["discrete_observer", "discrete_initial_state", "discrete_state_size"]


def discrete_state_size(n: int) -> int:
    """Entries of the sampled-data observer state for n channels."""
    return 3 * n + 2 * n * n


def _pieces(function: ca.Function) -> ca.Function:
    """(eta, nu, tau_d, K) -> (P, q, L) of the module docstring, derived from the observer Function."""
    n = function.size1_in("x")
    f_hat, eta, nu = ca.SX.sym("f_hat", n), ca.SX.sym("eta", n), ca.SX.sym("nu", n)
    tau_d, K = ca.SX.sym("tau_d", n), ca.SX.sym("K", n)
    R = -function(ca.SX.zeros(n), eta, nu, tau_d, K)[1]
    phi = function(f_hat + R, eta, nu, tau_d, K)[0]
    P = ca.jacobian(phi, f_hat)
    q = ca.substitute(phi, f_hat, ca.DM.zeros(n))
    return ca.Function("pieces", [eta, nu, tau_d, K], [P, q, ca.jacobian(R, nu)],
                       ["eta", "nu", "tau_d", "K"], ["P", "q", "L"])


def discrete_observer(function: ca.Function, dt: float) -> ca.Function:
    """``(s, eta, nu, tau_d, K) -> (s_next, f_hat)``: one sample of the observer (module docstring).

    s holds sample k-1; eta, nu, tau_d are sample k's; f_hat is the estimate at sample k.
    """
    n = function.size1_in("x")
    pieces = _pieces(function)
    s, eta, nu = ca.SX.sym("s", discrete_state_size(n)), ca.SX.sym("eta", n), ca.SX.sym("nu", n)
    tau_d, K = ca.SX.sym("tau_d", n), ca.SX.sym("K", n)
    f_prev, rest = s[:n], s[n:]
    P_prev, q_prev = ca.reshape(rest[:n * n], n, n), rest[n * n:n * n + n]
    L_prev, nu_prev = ca.reshape(rest[n * n + n:2 * n * n + n], n, n), rest[2 * n * n + n:]
    P, q, L = pieces(eta, nu, tau_d, K)
    rhs = f_prev + dt / 2 * (ca.mtimes(P_prev, f_prev) + q_prev + q) - ca.mtimes((L_prev + L) / 2, nu - nu_prev)
    f_hat = ca.solve(ca.SX.eye(n) - dt / 2 * P, rhs)
    s_next = ca.vertcat(f_hat, ca.vec(P), q, ca.vec(L), nu)
    return ca.Function("observer_step", [s, eta, nu, tau_d, K], [s_next, f_hat],
                       ["s", "eta", "nu", "tau_d", "K"], ["s_next", "f_hat"])


def discrete_initial_state(function: ca.Function, eta, nu, tau_d, K) -> np.ndarray:
    """The state before the first sample: f_hat = 0, and sample k-1 taken equal to the first sample."""
    n = function.size1_in("x")
    P, q, L = (np.asarray(v) for v in _pieces(function)(eta, nu, tau_d, K))
    return np.concatenate([np.zeros(n), P.ravel(order="F"), q.ravel(), L.ravel(order="F"),
                           np.asarray(nu, dtype=float).ravel()])
