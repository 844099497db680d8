"""Hybrid unknown-input / adaptive observer for sensor faults (Yu, Jiang & Zhang 2018, eqs. 2-6, 17-18).

The plant ``x' = f(x, u, d, p)``, ``y = C x + F f_s`` (linear outputs) with ``f = A x + f_a(x) + B u
+ E d`` near an operating point is split by a permutation of states and outputs (the paper's
``z = T x``, ``omega = S y`` with T, S permutations) into

    subsystem 1:  z1' = f_z1(z, u) + E1 d,   omega1 = C1 z1          (disturbance, no fault)
    subsystem 2:  z2' = f_z2(z, u),          omega2 = C4 z2 + F2 f_s  (fault, no disturbance)

(:func:`decouple` checks that split). Observers (continuous time, sampled by RK4 with y, u held):

    v' = Tu f_z1(zhat, u) + K1 (omega1 - C1 zhat1),  zhat1 = v + H omega1,  Tu = I - H C1   (eq. 5/17)
    zhat2' = f_z2(zhat, u) + L r,  r = omega2 - C4 zhat2 - F2 f_hat                      (eq. 6/18)

with ``H = E1 (C1 E1)^+`` so that ``Tu E1 = 0`` (d leaves the error). Without a fault estimator
``f_hat = 0`` and r is the detection residual (eq. 6); with one, the adaptive law
``f_hat' = Gamma (M1 r + M2 r')`` (eq. 18, on the residual r rather than the unmeasured e2) is
run as its integral (the paper's remark 5): ``f_hat = Gamma (M2 r + M1 q)``, ``q' = r``, so
``r = (I + F2 Gamma M2)^-1 (omega2 - C4 zhat2 - F2 Gamma M1 q)``. A split with no subsystem 2
is the full-order unknown-input observer (Chen & Patton 1999, the paper's baseline [11]).

Linearised, the errors ``e1 = Tu z1 - v``, ``e2 = z2 - zhat2`` and ``e_q = f_s - Gamma M1 q`` obey
``e' = A_e e + B_e f_s'`` (:func:`linear_error_model`); Omega1 = Tu A11, Omega2 = Tu A12,
Omega3 = A21, Omega4 = A22 are the blocks of the paper's LMIs (11) and (22).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np
import sympy

from uvsym.errors import ObserverError, UIOConditionError
from uvsym.observers.base import Observer, check_name, observer
from uvsym.observers.uio import uio_conditions
from uvsym.symbolic import rk4
from uvsym.systems.signals import Signals, signals
from uvsym.systems.system import Linearization, System, system

__all__ = ["Decoupling", "FaultEstimator", "LinearErrorModel", "decouple", "hybrid_observer", "linear_error_model",
           "observer_state", "with_sensor_fault_states"]

RANK_TOLERANCE = 1e-9  # relative to the largest singular value


def _rank(M: np.ndarray) -> int:
    s = np.linalg.svd(np.atleast_2d(M), compute_uv=False) if np.size(M) else np.zeros(0)
    return int(np.sum(s > RANK_TOLERANCE * s[0])) if s.size and s[0] > 0 else 0


def _rational(M: np.ndarray) -> sympy.Matrix:
    return sympy.Matrix(M.shape[0], M.shape[1], [sympy.Rational(float(v)) for v in M.ravel()])


def _with_rows(M, rows: int) -> np.ndarray:
    """``M`` as a float matrix of ``rows`` rows (its entries in row order) when its size allows, else as given
    (the caller's shape check then names it)."""
    M = np.atleast_2d(np.asarray(M, dtype=float))
    return M.reshape(rows, -1) if rows and M.size % rows == 0 else M


def _floats(M: sympy.Matrix) -> np.ndarray:
    return np.array(M.tolist(), dtype=float).reshape(M.shape)


@dataclass(frozen=True)
class Decoupling:
    """The split of the module docstring. z1, z2, w1, w2: state and output names; C1 (p1, n1),
    C4 (p2, n2), F2 (p2, q), E1 (n1, r), H (n1, p1), Tu (n1, n1); omega: Omega1..4 (floats);
    exact: the same as sympy Rational matrices (Tu, H, Omega_i computed in exact arithmetic from
    the linearisation's doubles); ranks: rank B, rank E, rank C [B E], m + r (Assumption 1);
    undetectable: eigenvalues of Tu A11 with Re >= 0 that C1 does not see (no K1 moves them)."""

    plant: str
    z1: tuple[str, ...]
    z2: tuple[str, ...]
    w1: tuple[str, ...]
    w2: tuple[str, ...]
    iz1: tuple[int, ...]
    iz2: tuple[int, ...]
    iw1: tuple[int, ...]
    iw2: tuple[int, ...]
    C1: np.ndarray
    C4: np.ndarray
    F2: np.ndarray
    E1: np.ndarray
    H: np.ndarray
    Tu: np.ndarray
    omega: dict
    exact: dict
    ranks: dict
    undetectable: tuple[complex, ...] = ()


def _names(group: Signals, names, what: str) -> tuple[int, ...]:
    unknown = [n for n in names if n not in group.names]
    if unknown or len(set(names)) != len(names):
        raise ObserverError(f"decoupling: {what} {list(names)} must be distinct names of {group.group}s "
                            f"({', '.join(group.names)}); unknown: {unknown}")
    return tuple(group.index(n) for n in names)


def decouple(plant: System, lin: Linearization, *, z1, w1, E=None, F=None) -> Decoupling:
    """Split ``plant`` linearised as ``lin`` into subsystem 1 (states z1, outputs w1: disturbance E)
    and subsystem 2 (the other states and outputs: sensor faults F (n_y, q)); E (n_x, r) default lin.E.

    Raises
    ------
    ObserverError
        Unknown names; outputs of one subsystem that read the other's states; a disturbance acting on
        subsystem 2 or a fault on subsystem 1's outputs; ``rank(C1 E1) != rank(E1)`` (no UIO exists;
        checked by :func:`uvsym.observers.uio.uio_conditions`, whose detectability verdict is kept
        in ``undetectable`` rather than raised, for the LMI claims to refute).
    """
    E = lin.E if E is None else np.atleast_2d(np.asarray(E, dtype=float))
    n, p = lin.A.shape[0], lin.C.shape[0]
    F = np.zeros((p, 0)) if F is None else _with_rows(F, p)
    if E.shape[0] != n or F.shape[0] != p or not (np.all(np.isfinite(E)) and np.all(np.isfinite(F))):
        raise ObserverError(f"decoupling: E must be a finite ({n}, r) matrix and F ({p}, q); got {E.shape}, "
                            f"{F.shape}")
    iz1, iw1 = _names(plant.x, z1, "z1"), _names(plant.y, w1, "w1")
    iz2 = tuple(i for i in range(n) if i not in iz1)
    iw2 = tuple(i for i in range(p) if i not in iw1)
    C, A = lin.C, lin.A
    for rows, cols, what in ((iw1, iz2, "w1 read subsystem-2 states"), (iw2, iz1, "w2 read subsystem-1 states")):
        if np.any(C[np.ix_(rows, cols)]):
            raise ObserverError(f"decoupling: outputs {what}; the split must follow C's blocks")
    if np.any(E[list(iz2)]) or np.any(F[list(iw1)]):
        raise ObserverError("decoupling: the disturbance E must act on subsystem 1 only and the faults F on "
                            "outputs of subsystem 2 only")
    C1, E1 = C[np.ix_(iw1, iz1)], E[list(iz1)]
    try:  # the unknown-input observer's two existence conditions (Chen & Patton), for subsystem 1
        uio_conditions(A[np.ix_(iz1, iz1)], C1, E1, time="continuous")
        undetectable = ()
    except UIOConditionError as exc:
        if exc.ranks is None or exc.ranks[0] != exc.ranks[1]:
            raise ObserverError(f"decoupling: {exc}") from None
        undetectable = exc.eigenvalues  # T A11 has modes C1 cannot see: no K1 stabilises them
    exact = {"C1": _rational(C1), "E1": _rational(E1)}
    CE = exact["C1"] * exact["E1"]
    exact["H"] = exact["E1"] * CE.pinv() if CE.rank() else sympy.zeros(len(iz1), len(iw1))
    exact["Tu"] = sympy.eye(len(iz1)) - exact["H"] * exact["C1"]
    blocks = {"Omega1": (iz1, iz1, True), "Omega2": (iz1, iz2, True), "Omega3": (iz2, iz1, False),
              "Omega4": (iz2, iz2, False)}
    for name, (rows, cols, transformed) in blocks.items():
        block = _rational(A[np.ix_(rows, cols)].reshape(len(rows), len(cols)))
        exact[name] = exact["Tu"] * block if transformed else block
    B = lin.B
    ranks = {"B": _rank(B), "E": _rank(E), "C[B E]": _rank(C @ np.hstack([B, E])), "m + r": _rank(B) + _rank(E)}
    return Decoupling(plant.name, tuple(z1), tuple(plant.x.names[i] for i in iz2), tuple(w1),
                      tuple(plant.y.names[i] for i in iw2), iz1, iz2, iw1, iw2, C1, C[np.ix_(iw2, iz2)],
                      F[list(iw2)], E1, _floats(exact["H"]), _floats(exact["Tu"]),
                      {k: _floats(exact[k]) for k in blocks}, exact, ranks, tuple(undetectable))


@dataclass(frozen=True)
class FaultEstimator:
    """Adaptive PI law ``f_hat' = Gamma (M1 r + M2 r')`` (eq. 18): Gamma (q, q), M1 and M2 (q, p2)."""

    Gamma: np.ndarray
    M1: np.ndarray
    M2: np.ndarray


def _gain(value, shape: tuple[int, int], what: str, name: str) -> np.ndarray:
    try:
        M = np.atleast_2d(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        M = None
    if M is None or M.shape != shape or not np.all(np.isfinite(M)):
        raise ObserverError(f"{name}: {what} must be a finite {shape} matrix, got shape {np.shape(value)}")
    return M


def _estimator(est: FaultEstimator | None, dec: Decoupling, name: str) -> tuple[np.ndarray, ...]:
    """(Gamma M1, Gamma M2, N = (I + F2 Gamma M2)^-1), zeros without an estimator."""
    q, p2 = dec.F2.shape[1], len(dec.iw2)
    if est is None:
        return np.zeros((q, p2)), np.zeros((q, p2)), np.eye(p2)
    if q == 0:
        raise ObserverError(f"{name}: a fault estimator needs fault directions F")
    Gamma = _gain(est.Gamma, (q, q), "Gamma", name)
    GM1, GM2 = Gamma @ _gain(est.M1, (q, p2), "M1", name), Gamma @ _gain(est.M2, (q, p2), "M2", name)
    S = np.eye(p2) + dec.F2 @ GM2
    if abs(np.linalg.det(S)) < 1e-12:
        raise ObserverError(f"{name}: I + F2 Gamma M2 is singular; the residual is not defined")
    return GM1, GM2, np.linalg.inv(S)


def hybrid_observer(plant: System, dec: Decoupling, K1, L, dt: float, *, estimator: FaultEstimator | None = None,
                    faults: Signals | None = None, name: str = "hybrid", steps: int = 1) -> Observer:
    """The observer of the module docstring for gains K1 (n1, p1) and L (n2, p2), sampled every dt (s).

    State (v, zhat2, and the integral of r with an estimator); publishes ``<x>_hat`` for every state,
    ``r_<y>`` for every output (subsystem 1's ``omega1 - C1 zhat1``, subsystem 2's r) and, with an
    estimator, ``<fault>_hat`` (``faults`` names the q faults, default ``f_1 ...``). Starts at the
    operating point."""
    check_name(name, "observer")
    n1, n2, p1, p2 = len(dec.iz1), len(dec.iz2), len(dec.iw1), len(dec.iw2)
    K1, L = _gain(K1, (n1, p1), "K1", name), _gain(L, (n2, p2), "L", name)
    GM1, GM2, N = _estimator(estimator, dec, name)
    q = dec.F2.shape[1] if estimator is not None else 0
    n_int = p2 if q else 0  # the estimator integrates r (p2 entries)
    if faults is None:
        faults = signals(*((f"f_{j + 1}", "", f"sensor fault {j + 1}") for j in range(q)), group="fault")
    if faults.size != q:
        raise ObserverError(f"{name}: {q} faults are estimated but {faults.size} are named")
    zero_d = ca.DM.zeros(plant.d.size)
    x_op = plant.x_op

    def parts(s, y, u, p):
        v, zhat2, qint = s[:n1], s[n1:n1 + n2], s[n1 + n2:]
        w1, w2 = y[list(dec.iw1)], y[list(dec.iw2)]
        zhat1 = v + ca.mtimes(ca.DM(dec.H), w1)
        r2 = w2 - ca.mtimes(ca.DM(dec.C4), zhat2)
        if q:
            r2 = ca.mtimes(ca.DM(N), r2 - ca.mtimes(ca.DM(dec.F2 @ GM1), qint))
        xhat = ca.SX.zeros(plant.x.size)
        xhat[list(dec.iz1)] = zhat1
        if n2:
            xhat[list(dec.iz2)] = zhat2
        return xhat, zhat1, r2, w1 - ca.mtimes(ca.DM(dec.C1), zhat1), qint

    def rhs(s, y, u, p):
        xhat, _, r2, r1, _ = parts(s, y, u, p)
        fx = plant.f(xhat, u, zero_d, p)
        v_dot = ca.mtimes(ca.DM(dec.Tu), fx[list(dec.iz1)]) + ca.mtimes(ca.DM(K1), r1)
        z2_dot = fx[list(dec.iz2)] + ca.mtimes(ca.DM(L), r2) if n2 else ca.SX.zeros(0)
        return ca.vertcat(v_dot, z2_dot, r2 if q else ca.SX.zeros(0))

    def step(s, y, u, p):
        xhat, _, r2, r1, qint = parts(s, y, u, p)
        r = ca.SX.zeros(plant.y.size)
        r[list(dec.iw1)] = r1
        if p2:
            r[list(dec.iw2)] = r2
        f_hat = ca.mtimes(ca.DM(GM2), r2) + ca.mtimes(ca.DM(GM1), qint) if q else ca.SX.zeros(0)
        return rk4(lambda s_, _t: rhs(s_, y, u, p), s, dt, steps), ca.vertcat(xhat, r, f_hat)

    def init(y0, u0, _p):
        v0 = x_op[list(dec.iz1)] - dec.H @ np.asarray(y0)[list(dec.iw1)]
        return np.concatenate([v0, x_op[list(dec.iz2)], np.zeros(n_int)])

    state = Signals(tuple(f"v_{n}" for n in dec.z1) + tuple(f"{n}_hat" for n in dec.z2) +
                    tuple(f"int_r_{dec.w2[j]}" for j in range(n_int)), tuple(plant.x.units[i] for i in dec.iz1) +
                    tuple(plant.x.units[i] for i in dec.iz2) + tuple(f"{plant.y.units[i]} s" for i in dec.iw2[:n_int]),
                    group="state")
    kind = "fault estimator (eq. 18)" if q else ("detection observer (eq. 6)" if n2 else "unknown-input observer")
    symbols = [ca.SX.sym(k, size) for k, size in zip("syup", (state.size, plant.y.size, plant.u.size, plant.p.size))]
    continuous = ca.Function(f"{name}_continuous", symbols, [rhs(*symbols)], list("syup"), ["s_dot"])
    return observer(name, step=step, dt=dt, p0=plant.p0, params=plant.p.renamed(group="parameter"), state=state,
                    equations={"continuous": continuous},
                    reads_y=plant.y.renamed(group="measurement"), reads_u=plant.u.renamed(group="input"),
                    publishes=plant.x.renamed(suffix="_hat", group="estimate") +
                    plant.y.renamed(prefix="r_", group="residual") + faults.renamed(suffix="_hat", group="estimate"),
                    init=init, description=f"hybrid unknown-input observer of {plant.name}, {kind}, sampled every "
                                           f"{dt:g} s ({steps} RK4 step(s))")


def observer_state(dec: Decoupling, xhat, C, q: int = 0) -> np.ndarray:
    """The state (v, zhat2, 0) of :func:`hybrid_observer` whose estimate is ``xhat`` (n,) when the
    outputs read ``C xhat`` (C the plant's (p, n) output matrix); q integral states (p2 for an
    estimator, else 0), started at 0."""
    xhat = np.asarray(xhat, dtype=float).ravel()
    w1 = (np.asarray(C, dtype=float) @ xhat)[list(dec.iw1)]
    return np.concatenate([xhat[list(dec.iz1)] - dec.H @ w1, xhat[list(dec.iz2)], np.zeros(q)])


@dataclass(frozen=True)
class LinearErrorModel:
    """``e' = A e + B f_s'``, ``f_s - f_hat = G e`` for e = (e1, e2, e_q) (module docstring)."""

    A: np.ndarray
    B: np.ndarray
    G: np.ndarray


def linear_error_model(dec: Decoupling, K1, L, estimator: FaultEstimator | None = None) -> LinearErrorModel:
    """The linearised error of :func:`hybrid_observer` with these gains (module docstring)."""
    n1, n2, p1, p2 = len(dec.iz1), len(dec.iz2), len(dec.iw1), len(dec.iw2)
    K1, L = _gain(K1, (n1, p1), "K1", "error model"), _gain(L, (n2, p2), "L", "error model")
    GM1, GM2, N = _estimator(estimator, dec, "error model")
    q = GM1.shape[0] if estimator is not None else 0
    GM1, GM2 = GM1[:q], GM2[:q]  # no estimator: no fault rows
    O1, O2, O3, O4 = (dec.omega[k] for k in ("Omega1", "Omega2", "Omega3", "Omega4"))
    r_e2, r_eq = N @ dec.C4, N @ dec.F2[:, :q]  # r = N (C4 e2 + F2 e_q)
    A = np.block([[O1 - K1 @ dec.C1, O2, np.zeros((n1, q))],
                  [O3, O4 - L @ r_e2, -L @ r_eq],
                  [np.zeros((q, n1)), -GM1 @ r_e2, -GM1 @ r_eq]])
    B = np.vstack([np.zeros((n1 + n2, q)), np.eye(q)])
    G = np.hstack([np.zeros((q, n1)), -GM2 @ r_e2, np.eye(q) - GM2 @ r_eq])  # f - f_hat = e_q - Gamma M2 r
    return LinearErrorModel(A, B, G)


def with_sensor_fault_states(plant: System, F, faults: Signals) -> System:
    """``plant`` with constant sensor faults as extra states: ``f' = 0``, ``y = h(x, u, p) + F f``
    (F (n_y, q)); a Luenberger observer of it is the integral adaptive fault estimator."""
    F = _with_rows(F, plant.y.size)
    if F.shape != (plant.y.size, faults.size) or not np.all(np.isfinite(F)):
        raise ObserverError(f"{plant.name}: F must be a finite ({plant.y.size}, {faults.size}) matrix, got {F.shape}")
    n = plant.x.size
    return system(f"{plant.name}_with_faults", f"{plant.description}; sensor faults as constant states",
                  x=plant.x + faults.renamed(group="state"), u=plant.u, d=plant.d, p=plant.p, y=plant.y,
                  rhs=lambda x, u, d, p: ca.vertcat(plant.f(x[:n], u, d, p), ca.SX.zeros(faults.size)),
                  output=lambda x, u, p: plant.h(x[:n], u, p) + ca.mtimes(ca.DM(F), x[n:]), p0=plant.p0,
                  x_op=np.concatenate([plant.x_op, np.zeros(faults.size)]), u_op=plant.u_op, source=plant.source)
