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
``s = [f_hat (n); P's non-zeros; q (n); L's non-zeros; nu (n)]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.conventions import FORCE_LABELS
from uvsym.errors import ObserverError
from uvsym.faults import actuator_kind
from uvsym.models.model import Model
from uvsym.observers.actuator import actuator_observer
from uvsym.observers.base import Observer, check_name
from uvsym.systems.signals import Signals

__all__ = ["SampledObserver", "actuator_fault_observer", "gain_units", "sampled_observer"]


def _drop_residue(matrix: ca.SX, inputs: list, samples: int = 8, rtol: float = 1e-12) -> ca.SX:
    """``matrix`` without the entries that are rounding residue at every sampled input.

    Products such as ``M M^-1`` leave entries like ``1e-17 k tau`` that are zero in exact
    arithmetic; an entry whose value never exceeds ``rtol`` times the matrix's largest at
    ``samples`` random inputs (every input drawn uniformly from [0.5, 2]) is dropped (made
    structurally zero), so that a diagonal matrix is seen as one.
    """
    probe = ca.Function("probe", inputs, [matrix])
    rng = np.random.default_rng(0)
    largest = np.zeros(matrix.shape)
    for _ in range(samples):
        value = np.abs(np.asarray(probe(*[rng.uniform(0.5, 2.0, v.shape) for v in inputs])))
        largest = np.maximum(largest, value / max(value.max(), 1e-300))
    cleaned = ca.SX(*matrix.shape)
    for i, j in zip(*np.nonzero(largest > rtol)):
        cleaned[int(i), int(j)] = matrix[int(i), int(j)]
    return cleaned


def _pieces(function: ca.Function) -> ca.Function:
    """(eta, nu, tau_d, K) -> (P, q, L) of the module docstring, derived from the observer Function."""
    n = function.size1_in("x")
    f_hat, eta, nu = ca.SX.sym("f_hat", n), ca.SX.sym("eta", n), ca.SX.sym("nu", n)
    tau_d, K = ca.SX.sym("tau_d", n), ca.SX.sym("K", n)
    R = -function(ca.SX.zeros(n), eta, nu, tau_d, K)[1]
    phi = function(f_hat + R, eta, nu, tau_d, K)[0]
    inputs = [eta, nu, tau_d, K]
    jac = ca.jacobian(phi, f_hat)
    if ca.depends_on(jac, f_hat):
        raise ObserverError(f"observer {function.name()}: x_dot must be affine in x (x_dot = P (x - R) + q), "
                            "the sampled-data form needs it")
    P = _drop_residue(jac, inputs)
    q = ca.substitute(phi, f_hat, ca.DM.zeros(n))
    L = _drop_residue(ca.jacobian(R, nu), inputs)
    return ca.Function("pieces", inputs, [P, q, L], ["eta", "nu", "tau_d", "K"], ["P", "q", "L"])


@dataclass(frozen=True)
class SampledObserver:
    """The sampled-data observer: ``step(s, eta, nu, tau_d, K) -> (s_next, f_hat)``.

    s holds sample k-1 (module docstring; P and L by their non-zeros only); eta, nu, tau_d are
    sample k's and f_hat is the estimate at sample k.
    """

    step: ca.Function
    pieces: ca.Function
    n: int
    nnz_P: int
    nnz_L: int

    @property
    def state_size(self) -> int:
        return 3 * self.n + self.nnz_P + self.nnz_L

    def initial_state(self, eta, nu, tau_d, K) -> np.ndarray:
        """The state before the first sample: f_hat = 0 and sample k-1 equal to the first sample."""
        P, q, L = self.pieces(eta, nu, tau_d, K)
        return np.concatenate([np.zeros(self.n), np.asarray(P.nonzeros()), np.asarray(q).ravel(),
                               np.asarray(L.nonzeros()), np.asarray(nu, dtype=float).ravel()])


def sampled_observer(function: ca.Function, dt: float) -> SampledObserver:
    """The sampled-data form (module docstring) of ``function`` for the sample period dt (s)."""
    n = function.size1_in("x")
    pieces = _pieces(function)
    sp_P, sp_L = pieces.sparsity_out("P"), pieces.sparsity_out("L")
    nnz_P, nnz_L = sp_P.nnz(), sp_L.nnz()
    s, eta, nu = ca.SX.sym("s", 3 * n + nnz_P + nnz_L), ca.SX.sym("eta", n), ca.SX.sym("nu", n)
    tau_d, K = ca.SX.sym("tau_d", n), ca.SX.sym("K", n)
    f_prev, P_prev = s[:n], ca.SX(sp_P, s[n:n + nnz_P])
    q_prev = s[n + nnz_P:2 * n + nnz_P]
    L_prev, nu_prev = ca.SX(sp_L, s[2 * n + nnz_P:2 * n + nnz_P + nnz_L]), s[2 * n + nnz_P + nnz_L:]
    P, q, L = pieces(eta, nu, tau_d, K)
    rhs = f_prev + dt / 2 * (ca.mtimes(P_prev, f_prev) + q_prev + q) - ca.mtimes((L_prev + L) / 2, nu - nu_prev)
    lhs = ca.SX.eye(n) - dt / 2 * P
    f_hat = ca.solve(lhs, rhs)  # on SX, a structurally diagonal lhs back-substitutes to rhs_i / lhs_ii
    s_next = ca.densify(ca.vertcat(f_hat, *P.nonzeros(), q, *L.nonzeros(), nu))
    step = ca.Function("observer_step", [s, eta, nu, tau_d, K], [s_next, f_hat],
                       ["s", "eta", "nu", "tau_d", "K"], ["s_next", "f_hat"])
    return SampledObserver(step=step, pieces=pieces, n=n, nnz_P=nnz_P, nnz_L=nnz_L)


def gain_units(kind: str, form: str, force_units: tuple[str, ...]) -> tuple[str, ...]:
    """Units of the gain entries K per channel: the rate is ``k_i`` (times ``tau_d,i^2`` when the
    fault scales the command) in the momentum form, and that over ``m_i^2`` in the paper's form,
    with ``m_i`` in kg for a force channel (N) and kg m^2 for a moment channel (N m)."""
    scales = actuator_kind(kind).scales
    units = []
    for force in force_units:
        per_force = f" {force}^2" if " " not in force else f" ({force})^2"
        mass = "kg^2" if force == "N" else "kg^2 m^4"
        if form == "momentum":
            units.append(f"1/(s{per_force})" if scales else "1/s")
        else:
            units.append(f"{mass}/(s{per_force})" if scales else f"{mass}/s")
    return tuple(units)


def actuator_fault_observer(model: Model, kind: str, dt: float, K, form: str = "paper",
                            name: str | None = None) -> Observer:
    """Liu et al. 2014's ``kind`` observer (Theorems 1-3) on ``model`` as an :class:`Observer`.

    step(s, y = [eta; nu], u = tau_d, p = K) -> (s_next, f_hat): the sampled-data form of this
    module. Reads the model's states by name and ``tau_d.<force>`` (the desired generalised force,
    N and N m); publishes ``f_hat.<force>`` (the fault estimate: factors for proportional, forces
    otherwise). The continuous observer is kept in ``equations["continuous"]``.
    """
    check_name(name or kind, "observer")
    continuous = actuator_observer(model, kind, form)
    sampled = sampled_observer(continuous.function, dt)
    n = model.dof
    try:
        gains = np.asarray(K, dtype=float).ravel()
    except (TypeError, ValueError):
        gains = np.empty(0)
    if gains.size != n or not np.all(np.isfinite(gains)) or np.any(gains <= 0):
        raise ObserverError(f"{name or kind} observer: the gains K must be {n} positive finite numbers (one per "
                            f"force channel; a gain <= 0 makes the error grow), got {K!r}")
    forces = Signals(FORCE_LABELS[n], model.force_units, group="force")
    f_units = tuple(map(actuator_kind(kind).unit, model.force_units))
    states = Signals(model.state_labels, model.state_units, group="measurement")
    name = name or kind
    s_names = tuple(f"{name}.s{i}" for i in range(sampled.state_size))
    y, u = ca.SX.sym("y", 2 * n), ca.SX.sym("u", n)
    s, K_sym = ca.SX.sym("s", sampled.state_size), ca.SX.sym("p", n)
    s_next, f_hat = sampled.step(s, y[:n], y[n:], u, K_sym)
    step = ca.Function(f"{name}_step", [s, y, u, K_sym], [s_next, f_hat], ["s", "y", "u", "p"], ["s_next", "out"])
    return Observer(
        name=name, step=step, dt=dt, p0=K,
        state=Signals(s_names, ("-",) * len(s_names), group="state"),
        reads_y=states, reads_u=forces.renamed(prefix="tau_d.", group="desired force"),
        params=Signals(tuple(f"K.{f}" for f in forces), gain_units(kind, form, model.force_units), group="gain"),
        publishes=Signals(tuple(f"f_hat.{f}" for f in forces), f_units, group="fault estimate"),
        init=lambda y0, u0, p: sampled.initial_state(y0[:n], y0[n:], u0, p),
        error_dynamics=continuous.error_dynamics, equations={"continuous": continuous.function},
        description=f"{kind} actuator-fault observer of {model.name} ({form} form), sampled every {dt:g} s")
