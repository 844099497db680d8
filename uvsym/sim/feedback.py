"""Controllers as blocks of a loop wired by signal name: PID, state feedback (LQR), time tables.

Each constructor returns a :class:`~uvsym.sim.blocks.Block`. Signals may be given as names (the
unit is then the unit of the loop signal they are joined to) or as Signals with units (e.g.
``plant.u.select(["u_sq"])``).
"""

from __future__ import annotations

from collections.abc import Sequence

import casadi as ca
import numpy as np
from scipy.linalg import solve_continuous_are, solve_discrete_are

from uvsym.errors import ModelError
from uvsym.numbers import real
from uvsym.sim.blocks import Block, as_signals, block
from uvsym.systems.discretize import zoh_matrices
from uvsym.systems.signals import Signals, signals
from uvsym.systems.system import System

__all__ = ["pid", "state_feedback", "lqr", "lqr_gain", "open_loop", "table_value", "INTERPOLATIONS"]

INTERPOLATIONS = ("previous", "linear")


def _one(spec, what: str) -> Signals:
    group = as_signals(spec, what)
    if group.size != 1:
        raise ModelError(f"{what} must be one signal, got {list(group.names)}")
    return group


def pid(name: str, measured: str | Signals, reference: float | str = 0.0, *, output: str | Signals, kp: float,
        ki: float = 0.0, kd: float = 0.0, limits: tuple[float, float] | None = None, dt: float) -> Block:
    """Discrete PID on one measured signal, derivative on the measurement, anti-windup by clamping.

    With e_k = r_k - y_k (r a constant or the loop signal named ``reference``)::

        v_k = kp e_k + ki I_k - kd (y_k - y_{k-1}) / dt,     u_k = min(max(v_k, lo), hi)
        I_{k+1} = I_k + e_k dt, held while v_k is beyond a limit and ki e_k pushes further

    State ``[I (unit of y times s), y_{k-1}]``, starting at ``[0, y_0]`` (no derivative kick at the
    start). A measurement substitution switched on mid-run is not bumpless: the derivative term
    sees the step from the sensor to its substitute for one sample (use kd = 0, or read the raw
    sensor, where that matters). Publishes u under ``output``; limits (lo, hi) in u's unit.
    """
    y_sig, u_sig = _one(measured, "measured"), _one(output, "output")
    kp, ki, kd = (real(v, f"pid {name}: {k}", ModelError) for k, v in (("kp", kp), ("ki", ki), ("kd", kd)))
    dt = real(dt, f"pid {name}: dt (s)", ModelError, positive=True)
    if limits is not None and (not isinstance(limits, (list, tuple, np.ndarray)) or len(limits) != 2):
        raise ModelError(f"pid {name}: limits must be (lo, hi) with lo < hi, got {limits!r}")
    lo, hi = (-np.inf, np.inf) if limits is None else (real(limits[0], f"pid {name}: limits[0]", ModelError),
                                                       real(limits[1], f"pid {name}: limits[1]", ModelError))
    if not lo < hi:
        raise ModelError(f"pid {name}: limits must be (lo, hi) with lo < hi, got {limits}")
    unit = y_sig.units[0]
    reads = y_sig
    if isinstance(reference, str):
        reads = y_sig + Signals((reference,), (unit,), ("set-point",), "read")
    state = signals(("I", f"{unit} s" if unit else "", "integral of the error"),
                    ("y_prev", unit, "previous measurement"), group="state")

    def step(s, r):
        y = r[0]
        e = (r[1] if isinstance(reference, str) else float(reference)) - y
        v = kp * e + ki * s[0] - kd * (y - s[1]) / dt
        winding = ca.logic_or(ca.logic_and(v > hi, ki * e > 0), ca.logic_and(v < lo, ki * e < 0))
        integral = s[0] + ca.if_else(winding, 0.0, e * dt)
        return ca.vertcat(integral, y), ca.fmin(ca.fmax(v, lo), hi)

    return block(name, step=step, state=state, reads=reads, publishes=u_sig, dt=dt,
                 init=lambda r0: np.array([0.0, r0[0]]), description=f"PID on {y_sig.names[0]} -> {u_sig.names[0]}")


def state_feedback(name: str, K, reads: Sequence[str] | Signals, x_ref=None, u_ref=None,
                   publishes: Sequence[str] | Signals = (), dt: float | None = None) -> Block:
    """Static state feedback ``u = u_ref - K (x - x_ref)``: K (m, n), x read by the n names of
    ``reads``, u published under the m names of ``publishes``; x_ref (n,), u_ref (m,) default 0;
    dt: the sample period (s) K was designed for (a loop at another period refuses it), or None."""
    reads, publishes = as_signals(reads, "read"), as_signals(publishes, "published")
    K = np.atleast_2d(np.asarray(K, dtype=float))
    if K.shape != (publishes.size, reads.size) or not np.all(np.isfinite(K)):
        raise ModelError(f"state feedback {name}: K must be finite ({publishes.size}, {reads.size}) for "
                         f"{list(publishes.names)} from {list(reads.names)}, got shape {K.shape}")
    x_ref = np.zeros(reads.size) if x_ref is None else reads.vector(x_ref, f"{name}: x_ref")
    u_ref = np.zeros(publishes.size) if u_ref is None else publishes.vector(u_ref, f"{name}: u_ref")
    return block(name, step=lambda s, r: (s, ca.DM(u_ref) - ca.mtimes(ca.DM(K), r - ca.DM(x_ref))),
                 reads=reads, publishes=publishes, dt=dt, description="u = u_ref - K (x - x_ref)")


def lqr_gain(A, B, Q, R, dt: float | None = None) -> np.ndarray:
    """The LQR gain K (m, n) of ``u = -K x``.

    Continuous (dt None): ``x' = A x + B u``, min int x'Qx + u'Ru, ``K = R^-1 B' P`` with P of
    ``A'P + PA - PBR^-1B'P + Q = 0``. Discrete (A, B of ``x_{k+1} = A x_k + B u_k``, dt set):
    ``K = (R + B'PB)^-1 B'PA`` with P of the discrete Riccati equation. ModelError for wrong
    shapes or when no stabilising solution exists.
    """
    A, B = np.atleast_2d(np.asarray(A, dtype=float)), np.asarray(B, dtype=float)
    B = B.reshape(A.shape[0], -1)
    Q, R = np.atleast_2d(np.asarray(Q, dtype=float)), np.atleast_2d(np.asarray(R, dtype=float))
    n, m = B.shape
    if Q.shape != (n, n) or R.shape != (m, m):
        raise ModelError(f"LQR: Q must be ({n}, {n}) and R ({m}, {m}), got {Q.shape} and {R.shape}")
    for what, M, least in (("Q", Q, "positive semi-definite"), ("R", R, "positive definite")):
        if not np.all(np.isfinite(M)) or np.max(np.abs(M - M.T)) > 1e-12 * max(1.0, float(np.max(np.abs(M)))):
            raise ModelError(f"LQR: {what} must be a finite symmetric matrix, got {M.tolist()}")
        smallest = float(np.min(np.linalg.eigvalsh(0.5 * (M + M.T))))
        if smallest < -1e-12 * max(1.0, float(np.max(np.abs(M)))) or (what == "R" and not smallest > 0):
            raise ModelError(f"LQR: {what} must be {least} (a weight), its smallest eigenvalue is {smallest:.6g}")
    try:
        if dt is None:
            return np.linalg.solve(R, B.T @ solve_continuous_are(A, B, Q, R))
        P = solve_discrete_are(A, B, Q, R)
        return np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ModelError(f"LQR: no stabilising Riccati solution ((A, B) stabilisable? Q >= 0, R > 0?): {exc}") from None


def lqr(system: System, Q, R, *, name: str = "lqr", dt: float | None = None, x_op=None, u_op=None,
        reads: Sequence[str] | Signals | None = None, publishes: Sequence[str] | Signals | None = None) -> Block:
    """State feedback ``u = u_op - K (x - x_op)`` with K the LQR gain of the system linearised at
    (x_op, u_op) (default its operating point).

    A discrete system uses its own sample period; a continuous one is designed in continuous time,
    or, with ``dt`` (s), on its exact zero-order-hold sampling (the loop's period). Reads the
    states by their names (a plant with ``y = x``) unless ``reads`` names the estimates to use;
    publishes the system's inputs (with units) unless ``publishes`` names others.
    """
    lin = system.linearize(x0=x_op, u0=u_op)
    A, B, period = lin.A, lin.B, system.dt
    if period is None and dt is not None:
        (A, B), period = zoh_matrices(A, B, dt), dt
    K = lqr_gain(A, B, Q, R, period)
    return state_feedback(name, K, system.x if reads is None else reads, lin.x0, lin.u0,
                          system.u if publishes is None else publishes, dt=period)


def open_loop(name: str, t_table, u_table, publishes: Sequence[str] | Signals,
              interpolation: str = "previous") -> Block:
    """A time table: reads the loop time ``t`` (s), publishes u(t).

    t_table (k,) strictly increasing (s), u_table (k, m) (or (k,) for m = 1). ``previous``: u_i
    from the first sample at or after t_i (within 1e-9 s) on; ``linear``: straight lines between
    the points. Before t_0 u_0 is held, after the last point the last value.
    """
    if interpolation not in INTERPOLATIONS:
        raise ModelError(f"open loop {name}: unknown interpolation {interpolation!r}; known: "
                         f"{', '.join(INTERPOLATIONS)}")
    publishes = as_signals(publishes, "published")
    try:
        times = np.asarray(t_table, dtype=float).reshape(-1)
        values = np.asarray(u_table, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"open loop {name}: times and values must be numbers, got {t_table!r} and {u_table!r}") \
            from None
    if times.size == 0 or values.size != times.size * publishes.size:
        raise ModelError(f"open loop {name}: needs one row of {publishes.size} value(s) per time; got {times.size} "
                         f"times and a table of shape {values.shape}")
    values = values.reshape(times.size, publishes.size)
    if not np.all(np.isfinite(values)) or not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
        raise ModelError(f"open loop {name}: needs finite, strictly increasing times and a (k, {publishes.size}) "
                         f"table for {list(publishes.names)}; got {times.size} times and shape {np.shape(u_table)}")

    def step(s, r):
        return s, table_value(r[0], times, values, interpolation)

    return block(name, step=step, reads=signals(("t", "s", "loop time"), group="read"), publishes=publishes,
                 description=f"time table ({interpolation})")


def table_value(t, times: np.ndarray, values: np.ndarray, interpolation: str):
    """u(t) of a time table (:func:`open_loop`'s rule): t a CasADi scalar -> (m,) CasADi column, or t a
    numpy (N,) array of times (s) -> (N, m) array, by the same operations in the same order (so the
    two agree to the last bit). times (k,) strictly increasing (s), values (k, m)."""
    numeric = isinstance(t, np.ndarray)
    if numeric:
        t = t[:, None]
        u, constant = np.broadcast_to(values[0], (t.shape[0], values.shape[1])), np.asarray
        where, low, high = (lambda c: np.where(c, 1.0, 0.0)), np.fmax, np.fmin
    else:
        u, constant = ca.DM(values[0]), ca.DM
        where, low, high = (lambda c: ca.if_else(c, 1.0, 0.0)), ca.fmax, ca.fmin
    for i in range(1, times.size):
        if interpolation == "previous":
            u = u + where(t >= times[i] - 1e-9) * constant(values[i] - values[i - 1])
        else:
            slope = (values[i] - values[i - 1]) / (times[i] - times[i - 1])
            u = u + (high(low(t, times[i - 1]), times[i]) - times[i - 1]) * constant(slope)
    return u
