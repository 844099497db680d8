"""Claims about actuator-fault observers, checked by machine.

Error dynamics are derived, not typed: ``ActuatorObserver.error_dynamics`` differentiates
``e = f - f_hat`` along the faulty plant; :func:`error_dynamics_claim` compares it with the
closed form ``e' = A(tau_d) e``. Convergence over a set of desired actions
(:func:`convergence_claim`) is a Lyapunov/LMI certificate on the error matrix at the set's
vertices. Each claim is named ``<name> (<form> form, <vehicle>): ...``, ``name`` being the
caller's (e.g. the theorem it checks).
"""

from __future__ import annotations

import itertools

import casadi as ca
import numpy as np

from uvsym.observers.actuator import ActuatorObserver, any_plant_error_dynamics
from uvsym.verify.certificate import Certificate
from uvsym.verify.identity import prove_identity
from uvsym.verify.lyapunov import lyapunov_decrease

__all__ = ["error_dynamics_claim", "any_plant_error_dynamics_claim", "convergence_claim"]


def _label(name: str, observer: ActuatorObserver) -> str:
    return f"{name} ({observer.form} form, {observer.model_name})"


def error_dynamics_claim(name: str, observer: ActuatorObserver, constant_tau_d: bool = True,
                         expected: str = "proved") -> Certificate:
    """``e' = A(tau_d) e`` (A = L M^-1 T_d or L M^-1) for the derived error dynamics of ``observer``;
    with ``constant_tau_d=False``, also while tau_d varies (tau_d' free)."""
    n = observer.error_matrix.size1_in(0)
    e, f, eta, nu, tau_d, tau_d_dot, K = (ca.SX.sym(v, n) for v in ("e", "f", "eta", "nu", "tau_d", "tau_d_dot", "K"))
    rate = ca.DM.zeros(n) if constant_tau_d else tau_d_dot
    derived = observer.error_dynamics(e, f, eta, nu, tau_d, rate, K)
    claimed = ca.mtimes(observer.error_matrix(tau_d, K), e)
    where = "all e, f, eta, nu, K" + (", tau_d constant" if constant_tau_d else ", tau_d varying (tau_d' free)")
    closed_form = "L M^-1 T_d e" if observer.kind == "proportional" else "L M^-1 e"
    inputs = [e, f, eta, nu, tau_d, K] + ([] if constant_tau_d else [tau_d_dot])
    varying = "" if constant_tau_d else " also while tau_d varies"
    return prove_identity(f"{_label(name, observer)}: e' = {closed_form}{varying}", derived, claimed, inputs, where,
                          expected)


def any_plant_error_dynamics_claim(name: str, kind: str, form: str, n: int, expected: str = "proved") -> Certificate:
    """``e' = L M^-1 G e`` for every plant of n degrees of freedom: M^-1 (and the momentum form's M)
    and the forces h as free symbols (:func:`uvsym.observers.actuator.any_plant_error_dynamics`), tau_d
    constant. Proved in exact arithmetic, it covers what a vehicle's own graph cannot show where CasADi
    folds products of M^-1's double constants into rounded doubles."""
    d = any_plant_error_dynamics(kind, form, n)
    derived = ca.substitute(d["e_dot"], d["tau_d_dot"], ca.DM.zeros(n))
    claimed = ca.mtimes(d["A"], d["e"])
    inputs = [d[v] for v in ("e", "f", "eta", "nu", "tau_d", "K", "h")] + [ca.vec(d["M_inv"]), ca.vec(d["M"])]
    closed_form = "L M^-1 T_d e" if kind == "proportional" else "L M^-1 e"
    return prove_identity(f"{name} ({form} form, any plant of {n} DOF): e' = {closed_form}", derived, claimed,
                          [ca.vertcat(*inputs)], f"all e, f, eta, nu, K, every M^-1 and h(eta, nu) "
                          f"({n} x {n} and {n} free symbols), tau_d constant", expected)


def convergence_claim(name: str, observer: ActuatorObserver, K, tau_min: float, tau_max: float, gamma: float,
                      expected: str = "proved") -> Certificate:
    """``V = e^T P e`` decreases at rate 2 gamma for gains K and every tau_d with ``tau_min <= |tau_d,i| <= tau_max``
    (N, N m; only the proportional observer's A depends on tau_d)."""
    n = observer.error_matrix.size1_in(0)
    K = np.asarray(K, dtype=float)
    corners = [(tau_min, tau_max)] * n if observer.kind == "proportional" else [(1.0,)] * n
    # A depends on tau_d only through tau_d,i^2 (the sign cancels; the paper's proportional form
    # is refused on a coupled M, where it would not), so the box's corners span it
    vertices = [np.asarray(observer.error_matrix(np.array(c), K)) for c in itertools.product(*corners)]
    gains = f"K = {np.round(K, 6).tolist()}"
    where = f"{tau_min:g} <= |tau_d,i| <= {tau_max:g} (N, N m), {gains}" if observer.kind == "proportional" else gains
    claim = f"{_label(name, observer)}: V = e'Pe decreases at rate {2 * gamma:g}"
    return lyapunov_decrease(claim, vertices, gamma, where, expected)
