"""Actuator-fault observers of Liu et al. 2014 (Theorems 1-3, eqs. 2-17).

For a vehicle ``M nu' + h(eta, nu) = tau`` with desired action ``tau_d`` the three fault types
(Definition 1) deliver

    proportional  tau = T_d f      (T_d = diag(tau_d), f = 1 when healthy)
    bias          tau = tau_d + f
    constant      tau = f

Each observer keeps a state ``x`` and estimates ``f_hat = x - R(nu)``. ``R`` is written once per
type; ``L = dR/dnu`` is taken by ``casadi.jacobian``. With

    x' = L M^-1 (G x - G R - h + b),      (G, b) = (T_d, 0), (I, tau_d), (I, 0)

the unknown ``nu'`` cancels and the error ``e = f - f_hat`` obeys ``e' = L M^-1 G e`` while
``tau_d`` is constant (eqs. 5-11).

``R`` per form: ``paper`` -- ``R_p = -K M^-1 T_d nu`` and ``R_a = R_c = -K M^-1 nu`` exactly as
printed, so ``A = -K (M^-1 T_d)^2`` or ``-K M^-2``; ``momentum`` -- ``R_p = -K T_d M nu`` and
``R_a = R_c = -K M nu``, so ``A = -K T_d^2`` or ``-K`` for *any* symmetric positive definite M.
With M diagonal the two forms are the same observer with ``K_momentum = K_paper / m_i^2``; with
a coupled M (a CG offset) the paper's proportional observer need not converge and its bias
observer converges with coupled, badly spread rates, while the momentum form keeps one
decoupled rate per channel (``k_i tau_d,i^2`` or ``k_i``).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.checked import checked
from uvsym.codegen.cache import memoized
from uvsym.conventions import FORCE_LABELS, POSITION_LABELS, VELOCITY_LABELS
from uvsym.errors import ObserverError
from uvsym.faults import ActuatorKind, actuator_kind
from uvsym.models.model import Model

__all__ = ["KINDS", "FORMS", "ActuatorObserver", "actuator_observer", "any_plant_error_dynamics",
           "proportional_observer", "bias_observer", "constant_observer", "init_state"]

KINDS = ("proportional", "bias", "constant")
FORMS = ("paper", "momentum")


@dataclass(frozen=True)
class ActuatorObserver:
    """One observer and the symbolic pieces it was derived from.

    function(x, eta, nu, tau_d, K) -> (x_dot, f_hat); R(nu, tau_d, K) -> R; L(nu, tau_d, K) -> dR/dnu;
    error_matrix(tau_d, K) -> A with ``e' = A e`` for constant ``tau_d``;
    error_dynamics(e, f, eta, nu, tau_d, tau_d_dot, K) -> e' exactly for a constant fault f on the plant
    ``M nu' = G f + b - h``, including the term ``+(dR/dtau_d) tau_d'`` that the paper's proof drops when
    ``tau_d`` varies.
    """

    kind: str
    form: str
    model_name: str
    function: ca.Function
    R: ca.Function
    L: ca.Function
    error_matrix: ca.Function
    error_dynamics: ca.Function


def actuator_observer(model: Model, kind: str, form: str = "paper",
                      require_assumption_1: bool = True) -> ActuatorObserver:
    """Build the observer of ``kind`` (proportional, bias, constant) for ``model``; memoized in-process by
    what it reads of the model (its name, M's values and its h), so that every scenario of a campaign over
    one vehicle shares its observers.

    ``require_assumption_1=False`` builds the paper's proportional observer on a coupled M anyway
    (to show by machine that it can diverge there; never for use).

    Raises
    ------
    ObserverError
        For a model that is not a :class:`Model` (e.g. its name), an unknown kind or form, or the
        paper's proportional observer on a model whose M is not diagonal (Assumption 1; its error
        dynamics need not converge there: use ``form="momentum"``).
    """
    if not isinstance(model, Model):
        hint = f" (build it with uvsym.vehicle({model!r}))" if isinstance(model, str) else ""
        raise ObserverError(f"model must be a uvsym Model, got {type(model).__name__} {model!r:.40}{hint}")
    if kind not in KINDS:
        raise ObserverError(f"unknown observer kind {kind!r}; known: {', '.join(KINDS)}")
    if form not in FORMS:
        raise ObserverError(f"unknown observer form {form!r}; known: {', '.join(FORMS)}")
    return _build(model, kind, form, bool(require_assumption_1))


@memoized(64, key=lambda model, kind, form, require: (model.name, model.M, model.h, kind, form, require))
def _build(model: Model, kind: str, form: str, require_assumption_1: bool) -> ActuatorObserver:
    """:func:`actuator_observer`, built (its arguments checked); memoized by what it reads of the model."""
    M = model.M
    coupled = not np.allclose(M, np.diag(np.diag(M)), rtol=0, atol=1e-12)
    if require_assumption_1 and actuator_kind(kind).scales and form == "paper" and coupled:
        raise ObserverError(f"{model.name}: the paper's proportional observer needs a diagonal mass matrix "
                            "(Assumption 1: CG = CB, symmetric vehicle); use form='momentum'")
    n = model.dof
    M_inv = ca.DM(np.linalg.inv(M))
    d = _derivation(kind, form, M_inv, M_inv if form == "paper" else ca.DM(M), model.h)
    x, eta, nu, tau_d, K, e, f, tau_d_dot = (d[v] for v in ("x", "eta", "nu", "tau_d", "K", "e", "f", "tau_d_dot"))
    x_dot, f_hat, R, L, e_dot, A = (d[v] for v in ("x_dot", "f_hat", "R", "L", "e_dot", "A"))
    names = ["x", "eta", "nu", "tau_d", "K"]
    function = ca.Function(f"{kind}_observer", [x, eta, nu, tau_d, K], [x_dot, f_hat], names, ["x_dot", "f_hat"])
    forces = FORCE_LABELS[n]
    labels = {"x": forces, "eta": POSITION_LABELS[n], "nu": VELOCITY_LABELS[n], "tau_d": forces, "K": forces,
              "x_dot": forces, "f_hat": forces, "e": forces, "f": forces, "tau_d_dot": forces, "e_dot": forces}

    def check(fn: ca.Function) -> ca.Function:  # numeric calls checked (uvsym.checked); .raw unchecked
        return checked(fn, model.name, labels)

    return ActuatorObserver(
        kind=kind, form=form, model_name=model.name, function=check(function),
        R=check(ca.Function("R", [nu, tau_d, K], [R], ["nu", "tau_d", "K"], ["R"])),
        L=check(ca.Function("L", [nu, tau_d, K], [L], ["nu", "tau_d", "K"], ["L"])),
        error_matrix=check(ca.Function("A", [tau_d, K], [A], ["tau_d", "K"], ["A"])),
        error_dynamics=check(ca.Function("e_dot", [e, f, eta, nu, tau_d, tau_d_dot, K], [e_dot],
                                         ["e", "f", "eta", "nu", "tau_d", "tau_d_dot", "K"], ["e_dot"])),
    )


def _derivation(kind: str, form: str, M_inv, P, h) -> dict[str, ca.SX]:
    """The observer's symbols and expressions (module docstring): ``M_inv`` (n x n) and ``P`` (the
    form's gain matrix, ``M^-1`` or ``M``) constant or symbolic, ``h(eta, nu)`` (n) the plant's
    forces. Exact error dynamics: with f constant, ``x = f - e + R(nu, tau_d)`` and the faulty plant
    ``M nu' = G f + b - h``, ``e' = -x' + L nu' + (dR/dtau_d) tau_d'``; ``A = L M^-1 G`` when tau_d' = 0."""
    n = M_inv.size1()
    x, eta, nu = ca.SX.sym("x", n), ca.SX.sym("eta", n), ca.SX.sym("nu", n)
    tau_d, K = ca.SX.sym("tau_d", n), ca.SX.sym("K", n)
    T_d, K_mat = ca.diag(tau_d), ca.diag(K)
    G, b, identity = _fault_action(actuator_kind(kind), T_d, tau_d)
    gain = P if identity else (ca.mtimes(P, G) if form == "paper" else ca.mtimes(G, P))
    R = -ca.mtimes(K_mat, ca.mtimes(gain, nu))
    L = ca.jacobian(R, nu)
    forces = h(eta, nu)
    LM = ca.mtimes(L, M_inv)
    x_dot = ca.mtimes(LM, ca.mtimes(G, x) - ca.mtimes(G, R) - forces + b)
    e, f, tau_d_dot = ca.SX.sym("e", n), ca.SX.sym("f", n), ca.SX.sym("tau_d_dot", n)
    plant_nu_dot = ca.mtimes(M_inv, ca.mtimes(G, f) + b - forces)
    e_dot = (-ca.substitute(x_dot, x, f - e + R) + ca.mtimes(L, plant_nu_dot)
             + ca.mtimes(ca.jacobian(R, tau_d), tau_d_dot))
    return {"x": x, "eta": eta, "nu": nu, "tau_d": tau_d, "K": K, "e": e, "f": f, "tau_d_dot": tau_d_dot,
            "x_dot": x_dot, "f_hat": x - R, "R": R, "L": L, "e_dot": e_dot, "A": ca.mtimes(LM, G)}


def any_plant_error_dynamics(kind: str, form: str, n: int) -> dict[str, ca.SX]:
    """:func:`actuator_observer`'s derivation for every plant of n degrees of freedom at once:
    ``M^-1`` (symbols ``M_inv``, n x n), the momentum form's ``M`` (symbols ``M``) and
    ``h(eta, nu)`` (symbols ``h``, n) are free symbols, so an identity of its ``e_dot`` holds for
    any mass matrix and any forces, in exact arithmetic (no double constant is folded). Keys as
    :func:`_derivation`'s, plus ``M_inv``, ``M`` and ``h``."""
    if kind not in KINDS or form not in FORMS:
        raise ObserverError(f"unknown observer kind {kind!r} or form {form!r}; known: {KINDS}, {FORMS}")
    M_inv, M, h = ca.SX.sym("M_inv", n, n), ca.SX.sym("M", n, n), ca.SX.sym("h", n)
    d = _derivation(kind, form, M_inv, M_inv if form == "paper" else M, lambda eta, nu: h)
    return {**d, "M_inv": M_inv, "M": M, "h": h}


def _fault_action(fault: ActuatorKind, T_d, tau_d) -> tuple:
    """(G, b, G is I) with ``tau = G f + b`` for the kind's ``deliver(tau_d, f) = (g0 + g1 f) tau_d + s0 + s1 f``:
    ``G = g1 T_d + s1 I``, ``b = g0 tau_d + s0``; zero terms are left out and unit factors add no operation. G is
    never empty: in every kind of KINDS the fault acts on tau (g1 or s1 is not 0)."""
    (g0, g1), (s0, s1) = fault.gain, fault.shift
    n = tau_d.numel()

    def total(*terms):
        present = [matrix if c == 1.0 else c * matrix for c, matrix in terms if c != 0.0]
        return sum(present[1:], present[0]) if present else None

    G = total((g1, T_d), (s1, ca.SX.eye(n)))
    b = total((g0, tau_d), (s0, ca.SX.ones(n)))
    return G, (ca.SX.zeros(n) if b is None else b), (g1, s1) == (0.0, 1.0)


def proportional_observer(model: Model, form: str = "paper") -> ca.Function:
    """Theorem 1 (eqs. 2, 12-13): ``(x, eta, nu, tau_d, K) -> (x_dot, f_hat)``, f the proportional factors.

    The CasADi Function alone: ``actuator_observer(model, "proportional", form).function`` (that object also
    carries the error dynamics and what design_gains needs).
    """
    return actuator_observer(model, "proportional", form).function


def bias_observer(model: Model, form: str = "paper") -> ca.Function:
    """Theorem 2 (eqs. 3, 14-15): ``(x, eta, nu, tau_d, K) -> (x_dot, f_hat)``, f the biases (N, N m).

    The CasADi Function alone: ``actuator_observer(model, "bias", form).function`` (that object also
    carries the error dynamics and what design_gains needs).
    """
    return actuator_observer(model, "bias", form).function


def constant_observer(model: Model, form: str = "paper") -> ca.Function:
    """Theorem 3 (eqs. 4, 16-17): ``(x, eta, nu, tau_d, K) -> (x_dot, f_hat)``, f the delivered forces.

    The CasADi Function alone: ``actuator_observer(model, "constant", form).function`` (that object also
    carries the error dynamics and what design_gains needs).
    """
    return actuator_observer(model, "constant", form).function


def init_state(observer: ca.Function, eta, nu, tau_d, K) -> np.ndarray:
    """The observer state x with f_hat = 0 at (eta, nu, tau_d): since f_hat = x - R, x = R = -f_hat(x=0)."""
    n = observer.size1_in("x")
    return -np.asarray(observer(np.zeros(n), eta, nu, tau_d, K)[1]).ravel()
