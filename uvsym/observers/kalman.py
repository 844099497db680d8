"""What the Gaussian filters (:mod:`~uvsym.observers.ukf`, :mod:`~uvsym.observers.ekf`) share.

A filter here is a :class:`GaussianFilter`: two symbolic halves on a discrete model
``x_{k+1} = F(x_k, u_k, p) + w_k``, ``y_k = h(x_k, u_k, p) + v_k`` (``w ~ N(0, Q)``,
``v ~ N(0, R)``; F is the System's own map when it is discrete, else ``steps`` RK4 steps over dt):

- ``update(x, P, y, u, p) -> (x_post, P_post, r, loglik, margin)``: the measurement update at
  sample k from the prior ``(xhat_{k|k-1}, P_{k|k-1})``, its innovation r (n_y,) and
  ``log f(y_k | Y_{k-1}) = -1/2 r^T S^-1 r - sum_j log L_jj - n_y/2 log(2 pi)`` with
  ``S = L L^T`` the innovation covariance (from the Cholesky factor, never ``det``);
- ``predict(x, P, u, p) -> (x_next, P_next, margin)``: the prior of sample k + 1.

``margin`` is the smallest relative pivot ``d_j / a_jj`` of the Cholesky factorisations the half
made (:func:`cholesky`): > 0 iff each matrix factorised was positive definite (to the jitter).

As an :class:`~uvsym.observers.base.Observer` (:func:`filter_observer`) the state is
``s = [xhat_{k|k-1} (n); tril(P_{k|k-1}) (n (n + 1) / 2)]`` (lower triangle, column by column)
and one step publishes ``<x>_hat`` (``xhat_{k|k}``), ``r_<y>``, ``loglik``, ``pd_margin`` and
``skipped``; it keeps the filter in ``equations["filter"]`` (a report renders its structured form,
:func:`uvsym.report.equations.filter_equations`). A measurement vector holding a NaN is not
used: the update is skipped (prior kept, loglik 0), the prediction made, and ``skipped`` is 1 at
that sample (documented behaviour, tested).
:func:`run_filter` runs any such observer on recorded data and raises
:class:`~uvsym.errors.CovarianceError` naming the first sample whose margin is not positive.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.errors import CovarianceError, ObserverError
from uvsym.observers.base import Observer, check_name, observer
from uvsym.symbolic import rk4
from uvsym.systems.signals import Signals
from uvsym.systems.system import System

__all__ = ["GaussianFilter", "check_covariance", "positive_definite", "checked_inputs", "cholesky", "cho_solve",
           "gaussian_loglik", "transition", "packed", "unpacked", "covariance_signals", "measurement_gate",
           "initial_filter_state", "filter_observer", "run_filter", "efficiency_augmented"]

JITTER = 1e-12  # relative: a_jj (1 + JITTER) on the diagonal before factorising
SEMIDEFINITE = 1e-12  # relative to the largest diagonal entry: a pivot this small is a zero of a semi-definite P
TINY = 1e-300
LOG_2PI = float(np.log(2.0 * np.pi))
BOUND = 1e100  # |entries| of a failed Cholesky pass are clipped here, so squares and sums stay finite
FINITE = 1e300  # a NaN measurement is clamped into [-FINITE, FINITE] before it is gated out


@dataclass(frozen=True)
class GaussianFilter:
    """A filter as two symbolic halves (module docstring). system: the model filtered (possibly
    augmented), dt (s), Q (n, n), R (n_y, n_y), P0 (n, n), x0 (n,): initial prior; method: 'ukf'
    or 'ekf'; settings: the method's tuning (e.g. alpha, beta, kappa), JSON-friendly."""

    name: str
    method: str
    system: System
    dt: float
    Q: np.ndarray
    R: np.ndarray
    P0: np.ndarray
    x0: np.ndarray
    update: Callable
    predict: Callable
    settings: dict


def check_covariance(value, size: int, what: str) -> np.ndarray:
    """A (size, size) symmetric positive semi-definite matrix from ``value`` (a matrix, a vector of
    variances or a scalar variance): its smallest eigenvalue at least ``-SEMIDEFINITE`` times its
    largest absolute entry; CovarianceError naming ``what`` otherwise (an indefinite matrix)."""
    try:
        M = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise CovarianceError(f"{what} must be numbers, got {value!r}") from None
    if M.ndim == 0 or M.ndim == 1:
        M = np.diag(np.broadcast_to(M, (size,)) if M.size in (1, size) else M)
    if M.shape != (size, size):
        raise CovarianceError(f"{what} must be ({size}, {size}) (or {size} variances), got shape {M.shape}")
    if not np.all(np.isfinite(M)):
        raise CovarianceError(f"{what} has non-finite entries")
    if np.max(np.abs(M - M.T)) > 1e-12 * max(1.0, float(np.max(np.abs(M)))):
        raise CovarianceError(f"{what} is not symmetric (max |M - M^T| = {np.max(np.abs(M - M.T)):.3g})")
    smallest = float(np.min(np.linalg.eigvalsh(M)))
    if smallest < -SEMIDEFINITE * max(float(np.max(np.abs(M))), TINY):
        raise CovarianceError(f"{what} is indefinite (smallest eigenvalue {smallest:.6g}); a covariance is positive "
                              "semi-definite")
    return M


def positive_definite(M: np.ndarray) -> bool:
    """Whether a symmetric matrix is positive definite (its Cholesky factorisation succeeds)."""
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        return False
    return True


def checked_inputs(system: System, name: str, dt: float, Q, R, P0, x0) -> tuple[np.ndarray, ...]:
    """(Q, R, P0, x0) of a filter of ``system`` checked (CovarianceError / ObserverError naming the
    argument); x0 None: the system's operating point."""
    check_name(name, "observer")
    if not (isinstance(dt, (int, float)) and np.isfinite(dt) and dt > 0):
        raise ObserverError(f"{name}: sample period dt must be positive and finite (s), got {dt!r}")
    n, n_y = system.x.size, system.y.size
    Q, R, P0 = (check_covariance(v, size, f"{name}: {what}") for v, size, what in
                ((Q, n, "Q"), (R, n_y, "R"), (P0, n, "P0")))
    try:
        x0 = system.x.vector(system.x_op if x0 is None else x0, f"{name}: x0")
    except Exception as exc:
        raise ObserverError(str(exc)) from None
    return Q, R, P0, x0


def cholesky(A, semidefinite: bool = False) -> tuple[ca.SX, ca.SX]:
    """Lower factor L of ``sym(A) + JITTER diag(A)`` (SX, n <= ~10) and the smallest relative pivot
    ``min_j d_j / a_jj``, > 0 iff that matrix is positive definite (clipped below at -1).

    Where it is not, L is ``diag(sqrt(|a_jj| + 1))`` instead, and the entries of the pass are
    clipped to ``+-BOUND``, so that every output of a step stays finite at any finite input while
    the margin reports the failure (:func:`run_filter` raises on it). A positive definite
    matrix's factor is bounded by ``sqrt(a_ii)`` and never clipped.

    semidefinite: a pivot within ``SEMIDEFINITE`` times the largest diagonal entry of 0 is a zero of
    a positive semi-definite matrix: its column of L is 0 (so ``L L^T = A`` still) and it counts as
    a pivot of 1 in the margin, which is then > 0 iff A is semi-definite (a zero pivot whose column
    is not zero, or a negative pivot, shows an indefinite A).
    """
    A = 0.5 * (A + A.T)
    n = A.shape[0]
    L = [[ca.SX(0.0)] * n for _ in range(n)]
    margin = None
    tolerance = SEMIDEFINITE * ca.fmax(ca.mmax(ca.diag(A)), TINY) if semidefinite else None
    for j in range(n):
        d = A[j, j] * (1.0 + JITTER) - sum((L[j][k] ** 2 for k in range(j)), ca.SX(0.0))
        rest = [A[i, j] - sum((L[i][k] * L[j][k] for k in range(j)), ca.SX(0.0)) for i in range(j + 1, n)]
        relative = d / ca.fmax(A[j, j], TINY)
        if semidefinite:  # a zero pivot: its column must vanish too (to the tolerance, scaled as a product)
            zero = ca.fabs(d) <= tolerance
            column = sum((ca.fabs(c) for c in rest), ca.SX(0.0))
            relative = ca.if_else(zero, ca.if_else(column <= ca.sqrt(tolerance * ca.fmax(ca.mmax(ca.diag(A)), TINY)),
                                                   1.0, -1.0), relative)
        margin = relative if margin is None else ca.fmin(margin, relative)
        L[j][j] = ca.sqrt(ca.fmax(d, TINY))
        for i, c in zip(range(j + 1, n), rest):
            L[i][j] = ca.fmin(ca.fmax(c / L[j][j], -BOUND), BOUND)
        if semidefinite:
            L[j][j] = ca.if_else(zero, 0.0, L[j][j])
            for i in range(j + 1, n):
                L[i][j] = ca.if_else(zero, 0.0, L[i][j])
    margin = ca.fmax(margin, -1.0)
    healthy = margin > 0.0
    factor = ca.SX(ca.Sparsity.lower(n))  # structural zeros above the diagonal: shifts along late columns
    for j in range(n):                      # leave the early states untouched (shared evaluations)
        factor[j, j] = ca.if_else(healthy, L[j][j], ca.sqrt(ca.fabs(A[j, j]) + 1.0))
        for i in range(j + 1, n):
            factor[i, j] = healthy * L[i][j]
    return factor, margin


def _forward(L, B):
    """L^-1 B for lower-triangular L (SX), by substitution."""
    n = L.shape[0]
    rows = []
    for i in range(n):
        acc = B[i, :]
        for k in range(i):
            acc = acc - L[i, k] * rows[k]
        rows.append(acc / L[i, i])
    return ca.vertcat(*rows)


def cho_solve(L, B):
    """S^-1 B with ``S = L L^T`` (L lower, SX), by forward and back substitution."""
    Z = _forward(L, B)
    n = L.shape[0]
    rows = [None] * n
    for i in reversed(range(n)):
        acc = Z[i, :]
        for k in range(i + 1, n):
            acc = acc - L[k, i] * rows[k]
        rows[i] = acc / L[i, i]
    return ca.vertcat(*rows)


def gaussian_loglik(r, L):
    """``log N(r; 0, L L^T)`` (SX scalar) from the lower Cholesky factor L of the covariance."""
    z = _forward(L, r)
    n = L.shape[0]
    return -0.5 * ca.sumsqr(z) - sum((ca.log(L[j, j]) for j in range(n)), ca.SX(0.0)) - 0.5 * n * LOG_2PI


def transition(system: System, dt: float, steps: int = 1) -> Callable:
    """``F(x, u, p) -> x_next`` (SX): the discrete system's own map (its dt must equal dt), else
    ``steps`` RK4 steps of the continuous one; disturbances d = 0 (their effect goes into Q)."""
    no_disturbance = ca.DM.zeros(system.d.size)
    if system.discrete:
        if abs(system.dt - dt) > 1e-9 * dt:
            raise ObserverError(f"{system.name} is sampled every {system.dt:g} s, the filter every {dt:g} s")
        return lambda x, u, p: system.f(x, u, no_disturbance, p)
    if not (isinstance(steps, int) and steps >= 1):
        raise ObserverError(f"steps must be a positive integer, got {steps!r}")
    return lambda x, u, p: rk4(lambda s, _t: system.f(s, u, no_disturbance, p), x, dt, steps)


def _tril(n: int) -> list[tuple[int, int]]:
    return [(i, j) for j in range(n) for i in range(j, n)]


def packed(P) -> ca.SX:
    """The lower triangle of a symmetric matrix, column by column (averaging P and P^T)."""
    return ca.vertcat(*[0.5 * (P[i, j] + P[j, i]) for i, j in _tril(P.shape[0])])


def unpacked(v, n: int):
    """The symmetric (n, n) matrix whose lower triangle :func:`packed` gave."""
    P = ca.SX.zeros(n, n) if isinstance(v, ca.SX) else np.zeros((n, n))
    for k, (i, j) in enumerate(_tril(n)):
        P[i, j] = v[k]
        P[j, i] = v[k]
    return P


def covariance_signals(x: Signals) -> Signals:
    """Names and units of tril(P) for states x: ``P.<a>.<b>`` in ``unit(a) unit(b)``."""
    def unit(a, b):
        parts = [u for u in (a, b) if u not in ("-", "")]
        return " ".join(parts) if parts else "-"
    return Signals(tuple(f"P.{x.names[i]}.{x.names[j]}" for i, j in _tril(x.size)),
                   tuple(unit(x.units[i], x.units[j]) for i, j in _tril(x.size)),
                   tuple(f"covariance of {x.names[i]} and {x.names[j]}" for i, j in _tril(x.size)), "state")


def measurement_gate(filt: GaussianFilter, x, P, y, u, p):
    """The update of ``filt`` with NaN measurements gated out (module docstring):
    (x_post, P_post, r, loglik, margin, skipped) as SX."""
    y_clean = ca.fmin(ca.fmax(y, -FINITE), FINITE)  # fmax/fmin drop NaN: the graph stays finite
    valid = ca.SX(1.0)
    for i in range(y.numel()):  # NaN == anything is false (y == y would be simplified away)
        valid = valid * (y_clean[i] == y[i])
    y_used = valid * y_clean + (1.0 - valid) * filt.system.h(x, u, p)
    x_post, P_post, r, loglik, margin = filt.update(x, P, y_used, u, p)
    return (ca.if_else(valid, x_post, x), ca.if_else(valid, P_post, P), valid * r, valid * loglik, margin,
            1.0 - valid)


def initial_filter_state(filt: GaussianFilter) -> np.ndarray:
    """``[x0; tril(P0)]``: the filter's state before the first sample."""
    return np.concatenate([filt.x0, [filt.P0[i, j] for i, j in _tril(filt.x0.size)]])


def filter_observer(filt: GaussianFilter, description: str) -> Observer:
    """``filt`` as an Observer (state, publications and NaN handling in the module docstring)."""
    system, n = filt.system, filt.system.x.size
    x_names = system.x.renamed(suffix="_hat", group="state")

    def step(s, y, u, p):
        x, P = s[:n], unpacked(s[n:], n)
        x_post, P_post, r, loglik, m_update, skipped = measurement_gate(filt, x, P, y, u, p)
        x_next, P_next, m_predict = filt.predict(x_post, P_post, u, p)
        out = ca.vertcat(x_post, r, loglik, ca.fmin(m_update, m_predict), skipped)
        return tuple(ca.cse([ca.vertcat(x_next, packed(P_next)), out]))  # shared subexpressions once

    s0 = initial_filter_state(filt)
    diagnostics = Signals(("loglik", "pd_margin", "skipped"), ("-", "-", "-"),
                          ("log-likelihood of y_k", "smallest relative Cholesky pivot of the step (> 0: P.D.)",
                           "1 where y_k had a NaN and the update was skipped"), "diagnostic")
    return observer(filt.name, step=step, dt=filt.dt, p0=system.p0, params=system.p.renamed(group="parameter"),
                    state=x_names + covariance_signals(system.x), reads_y=system.y.renamed(group="measurement"),
                    reads_u=system.u.renamed(group="input"),
                    publishes=system.x.renamed(suffix="_hat", group="estimate")
                    + system.y.renamed(prefix="r_", group="residual") + diagnostics,
                    init=lambda y0, u0, p: s0, equations={"filter": filt}, description=description)


def run_filter(obs: Observer, Y, U, p=None, s0=None) -> tuple[np.ndarray, np.ndarray]:
    """Run a filter observer (or bank) publishing ``pd_margin`` on data: Y (N, n_y) may hold NaN
    (the update of that sample is skipped), U (N, n_u) finite -> (S (N + 1, n_s), OUT (N, n_out)).

    ObserverError for wrong sizes or non-finite inputs; CovarianceError naming the first sample
    whose covariance was not positive definite.
    """
    S, OUT = obs.run(Y, U, p, s0, missing_y=True)
    margin = OUT[:, obs.publishes.index("pd_margin")]
    bad = np.flatnonzero(~(margin > 0.0))
    if bad.size:
        k = int(bad[0])
        raise CovarianceError(f"{obs.name}: a covariance is no longer positive definite at sample {k} "
                              f"(t = {k * obs.dt:g} s; smallest relative Cholesky pivot {margin[k]:.3g}); "
                              "Q, R or P0 are ill-scaled, or the model diverged")
    return S, OUT


def efficiency_augmented(system: System, inputs: tuple[str, ...]) -> System:
    """``system`` with one efficiency state ``alpha_<input>`` (-) per named input: the input
    reaching the model is ``alpha_i u_i`` (the fault paper's ``n_i = alpha_i n_bar_i``, eq. 22) and
    ``alpha_i`` is a random walk (``alpha' = 0``, or ``alpha_{k+1} = alpha_k``; its noise in Q).
    Outputs and everything else as in ``system``; operating point alpha = 1."""
    picked = system.u.indices(inputs)
    if not picked or len(set(picked)) != len(picked):
        raise ObserverError(f"efficiency states need distinct inputs of {system.name}; got {list(inputs)}")
    alphas = Signals(tuple(f"alpha_{name}" for name in inputs), ("-",) * len(inputs),
                     tuple(f"efficiency of {name} (1 healthy)" for name in inputs), "state")
    n = system.x.size
    xa, u, d, p = (ca.SX.sym(a, size) for a, size in (("x", n + len(picked)), ("u", system.u.size),
                                                       ("d", system.d.size), ("p", system.p.size)))
    scaled = ca.vertcat(*[u[i] * xa[n + picked.index(i)] if i in picked else u[i] for i in range(system.u.size)])
    rest = xa[n:] if system.discrete else ca.SX.zeros(len(picked))
    f = ca.Function("f", [xa, u, d, p], [ca.vertcat(system.f(xa[:n], scaled, d, p), rest)], ["x", "u", "d", "p"],
                    ["x_next" if system.discrete else "x_dot"])
    h = ca.Function("h", [xa, u, p], [system.h(xa[:n], scaled, p)], ["x", "u", "p"], ["y"])
    return System(name=f"{system.name}_efficiency", description=f"{system.description}; efficiencies of "
                  f"{', '.join(inputs)} as random-walk states", x=system.x + alphas, u=system.u, d=system.d,
                  p=system.p, y=system.y, f=f, h=h, p0=system.p0, dt=system.dt,
                  x_op=np.concatenate([system.x_op, np.ones(len(picked))]), u_op=system.u_op,
                  u_min=system.u_min, u_max=system.u_max, constants=system.constants, source=system.source)
