"""The estimator contract: every observer, filter or adaptive estimator is an :class:`Observer`.

An estimator is a discrete step, sampled every ``dt`` seconds::

    s_{k+1}, out_k = step(s_k, y_k, u_k, p)

as one named ``casadi.Function`` with inputs ``(s, y, u, p)`` and outputs ``(s_next, out)``:
``s`` its own state, ``y`` the measurements it reads, ``u`` the known inputs it reads (commands,
desired forces), ``p`` its parameters (gains, tuning), ``out`` what it publishes (estimates,
residuals, fault estimates). ``out_k`` belongs to sample k (it may use ``y_k``).

What a new estimator implements (like ``scipy.integrate.OdeSolver``'s ``_step_impl``):

- the step expression, built from CasADi symbols (``observer(..., step=...)`` takes a Python
  callable ``(s, y, u, p) -> (s_next, out)`` and makes the named Function);
- the names and units of what it reads (``reads_y``, ``reads_u``: the names of loop signals),
  of its state, parameters (with default values ``p0``) and of what it publishes;
- its initial state from the first sample (``init(y0, u0, p) -> s0``, default zeros);
- where the method has one, its symbolic error dynamics (``error_dynamics``, a Function with
  named inputs, for ``uvsym verify``).

What it gets for free: it runs in any closed loop wired by signal name (:mod:`uvsym.sim.wiring`),
scalar or compiled; it exports to C (:mod:`uvsym.codegen`); a report renders its equations
(:mod:`uvsym.report.equations`); its size errors are caught here, before anything runs.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from uvsym.checked import checked
from uvsym.codegen.cache import memoized
from uvsym.errors import ObserverError, UnknownNameError
from uvsym.symbolic import as_column, has_nan_constant
from uvsym.systems.signals import Signals

__all__ = ["Observer", "check_name", "observer", "STEP_INPUTS", "STEP_OUTPUTS"]

STEP_INPUTS = ("s", "y", "u", "p")
STEP_OUTPUTS = ("s_next", "out")


@dataclass(frozen=True)
class Observer:
    """A discrete-time estimator (module docstring).

    step(s, y, u, p) -> (s_next, out) (numeric calls checked: :mod:`uvsym.checked`; ``step.raw``
    unchecked); state, reads_y, reads_u, params, publishes: the Signals of
    s, y, u, p and out; p0: (n_p,) default parameters; dt: sample period (s); init(y0, u0, p) ->
    s0 (None: zeros); error_dynamics: symbolic error dynamics for verify, or None; equations:
    further named Functions a report may render (e.g. the continuous right-hand side; a Gaussian
    filter keeps its GaussianFilter under "filter").
    """

    name: str
    step: ca.Function
    state: Signals
    reads_y: Signals
    reads_u: Signals
    params: Signals
    publishes: Signals
    p0: np.ndarray
    dt: float
    init: Callable | None = None
    error_dynamics: ca.Function | None = None
    equations: dict = field(default_factory=dict)
    description: str = ""

    def __post_init__(self):
        check_name(self.name, "observer")
        groups = (self.state, self.reads_y, self.reads_u, self.params)
        names = [n for g in groups for n in g.names]
        shared = sorted({n for n in names if names.count(n) > 1})
        if shared:
            raise ObserverError(f"{self.name}: names {shared} stand in more than one of state, reads_y, reads_u, "
                                "params; each signal needs its own name")
        f = self.step
        if not isinstance(f, ca.Function):
            raise ObserverError(f"{self.name}: step must be a casadi.Function, got {type(f).__name__}")
        if tuple(f.name_in()) != STEP_INPUTS or tuple(f.name_out()) != STEP_OUTPUTS:
            raise ObserverError(f"{self.name}: step must map (s, y, u, p) -> (s_next, out), got "
                                f"({', '.join(f.name_in())}) -> ({', '.join(f.name_out())})")
        for i, group in enumerate((self.state, self.reads_y, self.reads_u, self.params)):
            if f.numel_in(i) != group.size:
                raise ObserverError(f"{self.name}: step input {STEP_INPUTS[i]} has {f.numel_in(i)} entries but "
                                    f"{group.size} {group.group} signals are named ({', '.join(group.names)})")
        for i, group in enumerate((self.state, self.publishes)):
            if f.numel_out(i) != group.size:
                raise ObserverError(f"{self.name}: step output {STEP_OUTPUTS[i]} has {f.numel_out(i)} entries but "
                                    f"{group.size} signals are named ({', '.join(group.names)})")
        if not (np.isfinite(self.dt) and self.dt > 0):
            raise ObserverError(f"{self.name}: sample period dt must be positive and finite (s), got {self.dt}")
        try:
            p0 = self.params.vector(self.p0, f"{self.name}: parameters p0")
        except Exception as exc:
            raise ObserverError(str(exc)) from None
        object.__setattr__(self, "p0", p0)
        labels = {"s": self.state.names, "y": self.reads_y.names, "u": self.reads_u.names, "p": self.params.names,
                  "s_next": self.state.names, "out": self.publishes.names}
        object.__setattr__(self, "step", checked(f, self.name, labels))  # numeric calls checked; .raw unchecked

    def parameters(self, p=None) -> np.ndarray:
        """The parameter vector: ``p0``, or p (array or ``{name: value}``) checked against ``params``."""
        if p is None:
            return self.p0
        try:
            return self.params.vector(p, f"{self.name}: parameters")
        except Exception as exc:
            raise ObserverError(str(exc)) from None

    def initial_state(self, y0, u0, p=None) -> np.ndarray:
        """The state before the first sample, from the first measurement y0 and input u0."""
        p = self.parameters(p)
        try:
            y0 = self.reads_y.vector(y0, f"{self.name}: y0")
            u0 = self.reads_u.vector(u0, f"{self.name}: u0")
        except Exception as exc:
            raise ObserverError(str(exc)) from None
        if self.init is None:
            return np.zeros(self.state.size)
        s0 = np.asarray(self.init(y0, u0, p), dtype=float).reshape(-1)
        if s0.size != self.state.size or not np.all(np.isfinite(s0)):
            raise ObserverError(f"{self.name}: init gave {s0.size} entries (finite: {bool(np.all(np.isfinite(s0)))}),"
                                f" expected {self.state.size} finite")
        return s0

    def run(self, Y, U, p=None, s0=None, *, missing_y: bool = False, compiled: bool | None = None,
            states="all") -> tuple[np.ndarray, np.ndarray]:
        """Run on recorded data (open loop): Y (N, n_y), U (N, n_u) -> (S (N + 1, n_s), OUT (N, n_out)).

        states: ``"all"`` returns every state S (N + 1, n_s), from s0; ``"final"`` only the last one, S (1, n_s),
        which spares the history's memory where the outputs are what is wanted (the LMS monitor's state holds
        its weights and regressor window, 235 numbers a sample); a sequence of state names (or a
        :class:`Signals` of them) the history of those entries only, S (N + 1, k) in the order given (the LMS
        monitor's weights ``C_1 .. C_M``: what an adaptive-filter library returns beside its outputs).
        missing_y: Y may hold NaN (an estimator that skips the update of such a sample, e.g. a
        Kalman filter); the initial state is then taken from the first complete measurement.
        compiled: the steps in a compiled C loop (:func:`uvsym.codegen.compile.compile_roll`, IEEE flags:
        the numbers of CasADi's evaluation to rounding) rather than CasADi's virtual machine; None: from
        ``COMPILE_FROM`` samples on when a C compiler is found and Y has no NaN to skip (a first call
        compiles, about a second, kept in the compile cache).
        """
        Y, U = np.atleast_2d(np.asarray(Y, dtype=float)), np.atleast_2d(np.asarray(U, dtype=float))
        if Y.shape[1] != self.reads_y.size or U.shape[1] != self.reads_u.size or len(Y) != len(U) or len(Y) == 0:
            raise ObserverError(f"{self.name}: measurements Y must be (N, {self.reads_y.size}) "
                                f"({', '.join(self.reads_y.names)}) and inputs U (N, {self.reads_u.size}), "
                                f"at least one sample; got {Y.shape} and {U.shape}")
        bad_y = np.any(np.isinf(Y)) if missing_y else not np.all(np.isfinite(Y))
        if bad_y or not np.all(np.isfinite(U)):
            raise ObserverError(f"{self.name}: inputs U must be finite and measurements Y finite"
                                + (" or NaN" if missing_y else ""))
        kept_entries = self._kept_entries(states)
        every, final = kept_entries is None, kept_entries == ()
        picked = list(range(self.state.size) if every else kept_entries)
        p = self.parameters(p)
        first = next((k for k in range(len(Y)) if np.all(np.isfinite(Y[k]))), 0)
        s = self.initial_state(np.nan_to_num(Y[first]), U[0], p) if s0 is None else \
            np.asarray(s0, dtype=float).reshape(-1)
        if s.size != self.state.size or not np.all(np.isfinite(s)):
            raise ObserverError(f"{self.name}: s0 must be {self.state.size} finite values, got {s.size}")
        roll = None
        if compiled or (compiled is None and len(Y) >= COMPILE_FROM and not missing_y):
            roll = _compiled_roll(self.step, bool(compiled), kept_entries)
        if roll is not None:
            W = np.ascontiguousarray(np.column_stack([Y, U, np.broadcast_to(p, (len(Y), p.size))]))
            n_out = self.publishes.size
            if final:
                outputs = np.empty((len(Y), n_out))
                return np.asarray(roll(s, W, outputs)).reshape(1, -1), outputs
            rows = np.empty((len(Y) + 1, n_out + len(picked)))  # rows [out; kept s]: S and OUT views, no copy
            rows[0, :n_out], rows[0, n_out:] = np.nan, s[picked]
            roll(s, W, rows[1:])
            return rows[:, n_out:], rows[1:, :n_out]
        kept, outputs, last = [s[None, :] if every or final else s[None, picked]], [], s
        for start in range(0, len(Y), RUN_CHUNK):  # fixed chunks: the cost is linear in N (one mapaccum(N) is not)
            k = min(RUN_CHUNK, len(Y) - start)
            S, OUT = _rolled(self.step, k)(last, Y[start:start + k].T, U[start:start + k].T, p)
            S = np.asarray(S).T.reshape(k, -1)
            last = S[-1]
            kept.append(S[-1:] if final else S if every else S[:, picked])
            outputs.append(np.asarray(OUT).T.reshape(k, -1))
        return kept[-1] if final else np.vstack(kept), np.vstack(outputs)

    def _kept_entries(self, states) -> tuple[int, ...] | None:
        """The state entries ``run`` keeps the history of: None (every one) for ``"all"``, none for ``"final"``,
        else the positions of the names given (ObserverError for anything else, an unknown name listing the
        known)."""
        if isinstance(states, str):
            if states == "all":
                return None
            if states == "final":
                return ()
            raise ObserverError(f"{self.name}: states must be 'all', 'final' or a sequence of state names, "
                                f"got {states!r}")
        try:
            names = list(states)
        except TypeError:
            raise ObserverError(f"{self.name}: states must be 'all', 'final' or a sequence of state names, "
                                f"got {states!r}") from None
        if not names:
            raise ObserverError(f"{self.name}: states as a selection must name at least one state entry, got "
                                f"{states!r}")
        if not all(isinstance(name, str) for name in names):
            raise ObserverError(f"{self.name}: states as a selection holds state names (strings), got {states!r}")
        try:
            return tuple(self.state.indices(names))
        except UnknownNameError as error:
            raise ObserverError(f"{self.name}: states: {error}") from None


RUN_CHUNK = 2048  # samples per mapaccum call of Observer.run
COMPILE_FROM = 5000  # samples from which Observer.run compiles its steps by default


@memoized(32, key=lambda step, required, history: (step, required, None if history is None
                                                   else np.asarray(history, dtype=np.int64)))
def _compiled_roll(step: ca.Function, required: bool, history: tuple[int, ...] | None):
    """``roll(s0, W, rows) -> s_end`` of ``step`` in C (W's rows [y; u; p], each row of ``rows`` [out; the
    ``history`` entries of s_next]: every entry for None, just [out] for none); None without a compiler unless
    ``required`` (then CodegenError). Memoized with the positions as one array (a key of 235 numbers frozen one
    by one would cost 0.1 ms a call)."""
    from uvsym.codegen.compile import DEFAULT_FLAGS, compile_roll
    from uvsym.errors import CodegenError

    s, y, u, p = (ca.SX.sym(name, step.size1_in(i)) for i, name in enumerate(STEP_INPUTS))
    s_next, out = step(s, y, u, p)
    every = history is None or history == tuple(range(step.size1_in(0)))
    rows = ca.vertcat(out, s_next) if every else ca.vertcat(out, s_next[list(history)]) if history else out
    suffix = "" if every else "_kept" if history else "_out"  # the compile cache keys by the Function, not its name
    rolled = ca.Function(f"{step.name()}_run{suffix}", [s, ca.vertcat(y, u, p)], [s_next, rows])
    try:
        return compile_roll(rolled, DEFAULT_FLAGS)
    except CodegenError:
        if required:
            raise
        return None


@memoized(32)
def _rolled(step: ca.Function, k: int) -> ca.Function:
    """``k`` steps of ``step`` accumulated on the state (its first input and output), built once per size."""
    return step.mapaccum("run", k, [0], [0])


def check_name(name: str, what: str, error=ObserverError) -> None:
    """``error`` unless ``name`` can name a CasADi and C function: a letter, then letters, digits
    and single underscores."""
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z](_?[A-Za-z0-9])*", name):
        raise error(f"{what} name {name!r} must start with a letter and hold only letters, digits and single "
                    "underscores (it names C functions)")


def observer(name: str, *, step: Callable, state: Signals, reads_y: Signals, reads_u: Signals,
             publishes: Signals, dt: float, params: Signals | None = None, p0=None, **options) -> Observer:
    """Build an :class:`Observer` from a Python callable ``step(s, y, u, p) -> (s_next, out)`` on SX.

    ``options`` go to :class:`Observer` (init, error_dynamics, equations, description).
    """
    check_name(name, "observer")
    params = params if params is not None else Signals(group="parameter")
    s, y, u, p = (ca.SX.sym(a, g.size) for a, g in zip(STEP_INPUTS, (state, reads_y, reads_u, params)))
    result = step(s, y, u, p)
    if not isinstance(result, tuple) or len(result) != 2:
        raise ObserverError(f"{name}: step must return (s_next, out)")
    try:
        s_next, out = (ca.densify(as_column(v)) for v in result)
    except TypeError as exc:
        raise ObserverError(f"{name}: step: {exc}") from None
    for what, expr, group in (("s_next", s_next, state), ("out", out, publishes)):
        if expr.numel() != group.size:
            raise ObserverError(f"{name}: step gives {what} with {expr.numel()} entries, expected {group.size}")
    stray = sorted({v.name() for v in ca.symvar(ca.vertcat(s_next, out))} -
                   {v.name() for v in ca.symvar(ca.vertcat(s, y, u, p))})
    if stray:
        raise ObserverError(f"{name}: step uses symbols other than s, y, u, p: {stray}")
    function = ca.Function(f"{name}_step", [s, y, u, p], [s_next, out], list(STEP_INPUTS), list(STEP_OUTPUTS))
    if has_nan_constant(function):
        raise ObserverError(f"{name}: the step holds a NaN constant: a math or numpy function applied to a CasADi "
                            "symbol gives NaN; use casadi's own (ca.sin, ca.exp, ...)")
    return Observer(name=name, step=function, state=state, reads_y=reads_y, reads_u=reads_u, params=params,
                    publishes=publishes, p0=np.zeros(params.size) if p0 is None else p0, dt=dt, **options)
