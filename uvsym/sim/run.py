"""``simulate``: run a closed loop on a grid with a chosen method, in supervisor-sized chunks.

Methods: ``fast`` rolls the symbolic fixed-step RK4 closed-loop step in a C loop compiled with
the system C compiler when there is one (otherwise interpreted, with ``mapaccum``). ``cvodes``,
``idas``, ``rk`` and ``collocation`` integrate the plant over each sample with CasADi's integrators
(``integrator(name, plugin, dae, t0, grid)``) while the same discrete part runs in between.

A supervisor (isolation, identification, correction) runs every ``supervisor.period`` seconds on
the samples of the chunk just simulated and may return a decision that acts from the next chunk
on: a new command correction ``(S, o)`` (the marine loop), or a :class:`Substitution` switching
measurement substitution channels (a loop wired by :func:`uvsym.sim.wiring.interconnect`). A loop
says where its per-sample input w holds them: ``correction_columns``, ``substitution_columns``
(channel -> column), and the plant's environment ``env_columns``.
"""

from __future__ import annotations

import math
import os
import time
import warnings
from dataclasses import dataclass
from typing import Protocol

import casadi as ca
import numpy as np

from uvsym.codegen import compile_roll, find_compiler
from uvsym.errors import CodegenError, SimulationError, UvsymError
from uvsym.observers.ftc import Correction
from uvsym.sim.integrator_options import METHODS, checked_options
from uvsym.sim.loop import SampledLoop
from uvsym.sim.result import Signal, SimResult
from uvsym.sim.step_error import TOLERANCE, check_tolerance, checked_steps

__all__ = ["METHODS", "Correction", "Substitution", "Supervisor", "run_closed_loop", "check_chunk", "check_memory",
           "memory_needed"]

MAX_SAMPLES = 1e12  # beyond any machine's memory at 8 bytes a sample and signal
# samples per call between progress reports (no supervisor): the fast path pays per call, the
# integrators step in Python anyway
CHUNK = {"fast": 10000, "integrator": 100}
# each integrator's default options (a run's own options override them): tight tolerances for the variable-step
# ones; one collocation element per sample (CasADi's 20 give a 20 times larger Newton system each sample: 12 times
# slower on the docking run, for the same 2e-10 m from cvodes at 1e-12)
DEFAULT_OPTIONS = {"cvodes": {"abstol": 1e-12, "reltol": 1e-12}, "idas": {"abstol": 1e-12, "reltol": 1e-12},
                   "collocation": {"number_of_finite_elements": 1}}


@dataclass(frozen=True)
class Substitution:
    """Measurement substitution: the channels switched on (every other channel off), by name."""

    channels: frozenset[str] = frozenset()

    def __post_init__(self):
        channels = (self.channels,) if isinstance(self.channels, str) else self.channels
        object.__setattr__(self, "channels", frozenset(channels))


class Supervisor(Protocol):
    """Discrete logic run every ``period`` seconds on the latest chunk of samples."""

    period: float

    def update(self, t: np.ndarray, signals: dict[str, np.ndarray]) -> Correction | Substitution | None:
        """t: (k,) sample times (s); signals: name -> (k, n) values. Returns a new decision or None."""


def run_closed_loop(loop: SampledLoop, z0: np.ndarray, W: np.ndarray, *, method: str = "fast",
                    supervisor: Supervisor | None = None, options: dict | None = None,
                    compiled: bool = True, progress=None, guard=None,
                    rk4_tolerance: float | None = TOLERANCE,
                    actuator_faults: tuple | None = None) -> tuple[SimResult, dict]:
    """Simulate ``len(W) - 1`` samples from z0; W: (N + 1, n_w) per-sample inputs, one row a sample.

    The decision columns of W are overwritten by the supervisor's decisions. ``guard(t, out)``
    (t: (k,) s, out: (k, n_out) logged rows) raises a typed error for samples outside the model's
    domain (e.g. a kinematic singularity); it sees every chunk, before the finiteness check, so the
    cause is named rather than its NaN. Returns the result (samples at every grid time, meta
    without the caller's part) and timing information, with the fast path's ``rk4_error`` on
    sampled steps (:mod:`uvsym.sim.step_error`; an IntegrationAccuracyWarning past
    ``rk4_tolerance``, None: not checked). actuator_faults: the run's, for that check, where they are not the
    loop's own (a loop shared by runs of other faults, which W carries); None: the loop's.

    Raises
    ------
    SimulationError
        For an unknown method or supervisor period, options refused by
        :func:`~uvsym.sim.integrator_options.checked_options`, or a loop whose signals become
        non-finite (names the first signal entry and the time).
    """
    if method not in METHODS:
        raise SimulationError(f"unknown method {method!r}; known: {', '.join(METHODS)}")
    options = checked_options(method, options)
    N = W.shape[0] - 1
    if supervisor is not None:
        period = getattr(supervisor, "period", None)
        if not isinstance(period, (int, float)) or not (math.isfinite(period) and period > 0):
            raise SimulationError(f"a supervisor needs a positive, finite period (s), got {period!r}")
        chunk = max(1, round(period / loop.dt))
    else:
        chunk = CHUNK["fast" if method == "fast" else "integrator"]
    W = np.ascontiguousarray(W, dtype=float)
    outputs = np.empty((N + 1, loop.discrete.size1_out("out")))
    advance, build_s = _stepper(loop, method, min(chunk, N), options, compiled)
    z = np.asarray(z0, dtype=float)
    tolerance = check_tolerance(rk4_tolerance) if method == "fast" and loop.plant_ode is not None else None
    started = time.perf_counter()
    for start in range(0, N, chunk):
        k = min(chunk, N - start)
        z = advance(z, W[start:start + k], outputs[start:start + k])
        check_chunk(loop, method, start, W[start:start + k], outputs[start:start + k], z, guard)
        if supervisor is not None:
            signals = {name: outputs[start:start + k, sl] for name, (sl, _, _) in loop.signals.items()}
            decision = supervisor.update(W[start:start + k, 0], signals)
            if decision is not None:
                columns, values = _decision_columns(loop, decision)
                W[start + k:, columns] = values
        if progress is not None:
            progress((start + k) / N)
    outputs[N] = np.asarray(loop.discrete(z, W[N])[2]).ravel()
    wall = time.perf_counter() - started
    checked = checked_steps(loop, outputs, W, tolerance, actuator_faults) if tolerance is not None else None
    # views of the one logged table (their columns are disjoint): no copy, half the memory
    signals = {name: Signal(outputs[:, sl], labels, units) for name, (sl, labels, units) in loop.signals.items()}
    timing = {"wall_s": wall, "build_s": build_s}
    if checked is not None:
        timing["rk4_error"] = checked
    return SimResult(W[:, 0].copy(), signals, {}), timing


def check_chunk(loop: SampledLoop, method: str, start: int, W_rows: np.ndarray, rows: np.ndarray, z: np.ndarray,
                guard=None) -> None:
    """The guard, then SimulationError naming the first non-finite logged entry (or the state z at
    the chunk's end) of the k samples from sample ``start``: W_rows (k, n_w), rows (k, n_out) logged."""
    bad = np.flatnonzero(~np.all(np.isfinite(rows), axis=1))
    k = bad[0] if bad.size else len(rows)
    if guard is not None:
        guard(W_rows[:k, 0], rows[:k])
    if bad.size or not np.all(np.isfinite(z)):
        what = _first_non_finite(loop, rows[k]) if bad.size else "its state"
        raise SimulationError(f"the loop diverged: {what} is non-finite from t = {(start + k) * loop.dt:.6g} s "
                              f"({method}); look for an unstable loop (gains, signs), a model that gives NaN "
                              "there, or too large a step")


def _first_non_finite(loop: SampledLoop, row: np.ndarray) -> str:
    """``signal.label (value)`` of the first non-finite entry of one logged row."""
    column = int(np.flatnonzero(~np.isfinite(row))[0])
    for name, (sl, labels, _) in loop.signals.items():
        if sl.start <= column < sl.stop:
            return f"{name}.{labels[column - sl.start]} ({row[column]})"
    return f"logged entry {column} ({row[column]})"


def _decision_columns(loop: SampledLoop, decision) -> tuple[slice | list[int], np.ndarray]:
    """Where in w a supervisor's decision goes and its values; SimulationError for one the loop cannot take."""
    if isinstance(decision, Correction) and loop.correction_columns is not None:
        width = loop.correction_columns.stop - loop.correction_columns.start  # m (m + 1): vec(S), then o
        try:
            S, o = np.asarray(decision.S), np.asarray(decision.o)
        except ValueError as exc:  # ragged nesting
            raise SimulationError(f"supervisor returned a Correction that is not two arrays: {exc}") from None
        if not all(np.can_cast(a.dtype, float, "same_kind") for a in (S, o)):  # not complex: no imaginary part lost
            raise SimulationError(f"supervisor returned a Correction of {S.dtype} S and {o.dtype} o; it takes real "
                                  "numbers")
        if S.shape != (o.size, o.size) or o.shape != (o.size,) or S.size + o.size != width:
            raise SimulationError(f"supervisor returned a Correction with S {S.shape} and o {o.shape}; this loop takes "
                                  f"S (m, m) and o (m,) with m (m + 1) = {width}")
        return loop.correction_columns, np.concatenate([S.reshape(-1, order="F"), o])
    if isinstance(decision, Substitution):
        channels = loop.substitution_columns
        unknown = sorted(decision.channels - set(channels))
        if unknown:
            raise SimulationError(f"supervisor switched on substitution channels {unknown} the loop does not have; "
                                  f"channels: {', '.join(channels) or 'none'}")
        return list(channels.values()), np.array([float(c in decision.channels) for c in channels])
    raise SimulationError(f"supervisor returned {type(decision).__name__}, which this loop cannot apply; "
                          f"expected {'Correction' if loop.correction_columns is not None else 'Substitution'} or None")


def _stepper(loop: SampledLoop, method: str, chunk: int, options: dict, compiled: bool):
    """(advance(z, W_rows, out_rows) -> z_end, seconds spent building); advance fills out_rows (k, n_out)."""
    started = time.perf_counter()
    if method != "fast" and loop.plant_ode is None:
        raise SimulationError(f"a discrete-time plant has nothing to integrate: use method 'fast', not {method!r}")
    if method == "fast":
        if compiled and find_compiler() is not None:
            try:
                return compile_roll(loop.step), time.perf_counter() - started
            except CodegenError as exc:
                warnings.warn(f"running the fast path interpreted: {exc}", stacklevel=3)
        rollers = {chunk: loop.step.mapaccum("closed_loop_roll", chunk)}  # built before the clock starts
        states = np.empty((chunk, loop.n_z))

        def advance(z, W_rows, out_rows):
            k = W_rows.shape[0]
            if k not in rollers:
                rollers[k] = loop.step.mapaccum("closed_loop_roll", k)
            # buffer() evaluates in place, without converting arguments; CasADi is column-major,
            # so a C-ordered (k, n) array is the (n, k) matrix it expects.
            buffer, trigger = rollers[k].buffer()
            z_in = np.ascontiguousarray(z, dtype=float)
            buffer.set_arg(0, memoryview(z_in))
            buffer.set_arg(1, memoryview(W_rows))
            buffer.set_res(0, memoryview(states[:k]))
            buffer.set_res(1, memoryview(out_rows))
            trigger()
            return states[k - 1].copy()

        return advance, time.perf_counter() - started

    n_s, m, env_columns = loop.n_s, loop.discrete.size1_out("u_cmd"), loop.env_columns
    n_env = env_columns.stop - env_columns.start
    s, p, tau = ca.SX.sym("s", n_s), ca.SX.sym("p", m + n_env + 1), ca.SX.sym("tau")
    dae = {"x": s, "p": p, "t": tau, "ode": loop.plant_ode(s, p[:m], p[m:m + n_env], p[m + n_env] + tau)}
    opts = {**DEFAULT_OPTIONS.get(method, {}), **options}
    try:
        integrator = ca.integrator("plant", method, dae, 0.0, loop.dt, opts)
    except RuntimeError as exc:
        raise SimulationError(f"cannot build the {method} integrator with options {opts}: "
                              f"{str(exc).splitlines()[-1]}") from None
    discrete = loop.discrete

    def advance(z, W_rows, out_rows):
        for i, w in enumerate(W_rows):
            z_disc, u_cmd, out_i = discrete(z, w)
            p_i = np.concatenate([np.asarray(u_cmd).ravel(), w[env_columns], w[:1]])
            try:
                s_next = integrator(x0=z[:n_s], p=p_i)["xf"]
            except RuntimeError as exc:
                raise SimulationError(f"{method} failed at t = {w[0]:.6g} s: {str(exc).splitlines()[-1]}") from None
            z = np.concatenate([np.asarray(s_next).ravel(), np.asarray(z_disc).ravel()])
            out_rows[i] = np.asarray(out_i).ravel()
        return z

    return advance, time.perf_counter() - started


def grid(duration: float, dt: float) -> int:
    """Number of samples N with N dt = duration; SimulationError unless dt divides duration."""
    if not (duration > 0.0 and dt > 0.0 and math.isfinite(duration)):
        raise SimulationError(f"duration and step must be positive and finite, got {duration} s and {dt} s")
    if not duration / dt < MAX_SAMPLES:
        raise SimulationError(f"duration {duration:g} s at step {dt:g} s is {duration / dt:.3g} samples, more than "
                              f"{MAX_SAMPLES:.0e} (no machine holds them); shorten the run or lengthen the step")
    N = round(duration / dt)
    if abs(N * dt - duration) > 1e-9 * duration:
        raise SimulationError(f"step {dt} s does not divide duration {duration} s")
    return N


def memory_needed(samples: int, loop: SampledLoop) -> int:
    """Bytes a run of ``samples`` samples may hold at once, at most: its per-sample inputs W dense (a batch's
    lanes hold only W's varying columns), its logged outputs and one copy of them (float64)."""
    return 8 * samples * (loop.n_w + 2 * loop.discrete.size1_out("out"))


def available_memory() -> int | None:
    """Bytes the system can still give (MemAvailable of /proc/meminfo, else physical memory); None if unknown."""
    try:
        with open("/proc/meminfo") as handle:
            for line in handle:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None


def check_memory(needed: int, what: str, error: type[UvsymError] = SimulationError) -> None:
    """``error`` with both figures when ``needed`` bytes exceed what the machine has available."""
    available = available_memory()
    if available is not None and needed > available:
        raise error(f"{what} needs at least {_bytes(needed)} of memory, {_bytes(available)} are available; shorten the "
                    "run or lengthen the step")


def _bytes(count: float) -> str:
    if count < 1024:
        return f"{count:.0f} B"
    for unit in ("KiB", "MiB", "GiB", "TiB", "PiB", "EiB"):
        count /= 1024
        if count < 1024 or unit == "EiB":
            return f"{count:.3g} {unit}"
