"""The local error of the fast method's fixed-step RK4, estimated by step doubling on sampled steps.

The fast path integrates the plant over each sample with ``substeps`` classical RK4 steps and no
error control. After a run, at ``CHECKS`` of its samples -- the first ``EARLY``, the ``JUMPS``
samples where the held plant input changes most (a set-point step, a saturating command, a fault
switching on), and samples spread evenly -- the step ``s_k -> s_{k+1}`` is taken again from the
run's own state (read back from its log, :meth:`~uvsym.sim.loop.SampledLoop.integrated`) with
``substeps`` and with ``2 substeps`` RK4 steps; Richardson's estimate of the first one's error is
``e = (s_n - s_2n) 16 / 15``. A step during which an actuator fault switches on or off is not
checked: RK4's last stage there already sees the next sample's fault (the smear of
:mod:`uvsym.sim.wiring`, at most one sample), which no number of substeps removes; such steps are
found from the run's fault profiles (:meth:`~uvsym.faults.Profile.jumps`) where the loop carries its
actuator faults in w (the vehicle loop, whose redone steps then take the faults at every stage time
of both), else where the logged ``fault_actuator`` turns zero or non-zero. Each entry's
error is measured against the entry's scale over the run, ``tolerance (max_k |s_k,i|) + ATOL``, and
the largest ratio is reported with the substeps that would meet the tolerance (the error over a
sample falls as ``substeps^-4``). Sampled steps: numerical evidence, never a bound on every sample.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.codegen.cache import memoized
from uvsym.codegen.compile import DEFAULT_FLAGS, compile_function
from uvsym.errors import CodegenError, IntegrationAccuracyWarning, SimulationError
from uvsym.evaluation import InPlace
from uvsym.faults import actuator_fault_affine
from uvsym.sim.inputs import input_column, input_rows
from uvsym.symbolic import rk4, rk4_stage_times

__all__ = ["CHECKS", "TOLERANCE", "StepError", "check_indices", "check_tolerance",
           "checked_runs", "checked_steps", "state_name", "step_error", "step_errors"]

CHECKS, EARLY, JUMPS = 32, 4, 12
_ROWS = 1024  # logged rows read back at a time by a run's check
TOLERANCE = 1e-4  # default: local error per sample, relative to each state entry's scale over the run
ATOL = 1e-12  # absolute floor of every entry's scale (its unit)


@dataclass(frozen=True)
class StepError:
    """The largest error ratio found (error over what the tolerance allows: > 1 fails), the sample time
    t_s (s) and the integrated state entry (its index) where, and the substeps that would meet the
    tolerance there; checked: how many steps were checked."""

    ratio: float
    t_s: float
    entry: int
    substeps_needed: int
    checked: int

    def as_dict(self) -> dict:
        return {"largest_error_ratio": self.ratio, "at_s": self.t_s, "entry": self.entry,
                "substeps_needed": self.substeps_needed, "steps_checked": self.checked}


def check_tolerance(tolerance) -> float | None:
    """The tolerance, checked: None (no check) or a positive finite number; SimulationError otherwise."""
    if tolerance is None:
        return None
    if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not (
            math.isfinite(tolerance) and tolerance > 0):
        raise SimulationError(f"rk4_tolerance must be a positive number (relative error per sample) or None, "
                              f"got {tolerance!r}")
    return float(tolerance)


def check_indices(U: np.ndarray, switching: np.ndarray | None = None) -> list[int]:
    """The samples k (< N, U (N + 1, m) the held inputs) whose step is checked (module docstring);
    switching: (N,) True where an actuator fault switches on or off during step k (never checked)."""
    N = len(U) - 1
    if N < 1:
        return []
    by_input = np.ascontiguousarray(U.T)  # (m, N + 1): the reductions below run along contiguous rows
    scale = np.abs(by_input).max(axis=1) + 1e-300
    change = (np.abs(np.diff(by_input[:, :N], axis=1, prepend=by_input[:, :1])) / scale[:, None]).max(axis=0) \
        if len(by_input) else np.zeros(N)
    spread = np.linspace(0, N - 1, max(1, CHECKS - EARLY - JUMPS)).round().astype(int)
    chosen = {*range(min(EARLY, N)), *(int(k) for k in _largest(change, JUMPS)), *(int(k) for k in spread)}
    return sorted(k for k in chosen if switching is None or not switching[k])


def _column_max(A: np.ndarray) -> np.ndarray:
    """(n,) the largest |entry| of each column of A (k, n), one contiguous pass per column (numpy's reduction
    over the rows of a narrow table steps row by row)."""
    return np.abs(np.ascontiguousarray(A.T)).max(axis=1)


def _largest(change: np.ndarray, count: int) -> np.ndarray:
    """The samples of the ``count`` largest positive changes, ties to the earlier sample (those a stable sort
    of -change puts first), in O(N): a partition, not a sort."""
    positive = np.where(change > 0, change, 0.0)  # NaN and no change are never chosen
    if positive.size > count:
        kth = np.partition(positive, positive.size - count)[positive.size - count]  # the count-th largest
        above = np.flatnonzero(positive > kth)
        chosen = np.concatenate([above, np.flatnonzero(positive == kth)[:count - above.size]])
    else:
        chosen = np.arange(positive.size)
    return chosen[positive[chosen] > 0]


@memoized(16)
def _doubled(plant_ode: ca.Function, dt: float, substeps: int) -> ca.Function:
    """(s, u, env, t) -> [s after substeps RK4 steps; s after 2 substeps] over one sample of dt s."""
    s, u = ca.SX.sym("s", plant_ode.size1_in(0)), ca.SX.sym("u", plant_ode.size1_in(1))
    env, t = ca.SX.sym("env", plant_ode.size1_in(2)), ca.SX.sym("t")
    coarse, fine = (rk4(plant_ode, s, dt, n, u, env, t=t) for n in (substeps, 2 * substeps))
    return ca.Function("doubled", [s, u, env, t], [coarse, fine])


@memoized(16)
def _doubled_by_faults(fault_ode: ca.Function, dt: float, substeps: int) -> ca.Function:
    """(s, u, env, D, B) -> [s after substeps RK4 steps; s after 2 substeps] over one sample of dt s, the
    actuators delivering ``a + D_i a + B_i`` at node i of the fine steps' stage times (D, B (m nodes,),
    actuator a at ``i m + a``, node i at ``i dt / (4 substeps)``; the coarse steps' stages at the even nodes)."""
    m = fault_ode.size1_in(3)
    nodes = 4 * substeps + 1
    s, u = ca.SX.sym("s", fault_ode.size1_in(0)), ca.SX.sym("u", fault_ode.size1_in(1))
    env, D, B = ca.SX.sym("env", fault_ode.size1_in(2)), ca.SX.sym("D", m * nodes), ca.SX.sym("B", m * nodes)
    quarter = dt / (4 * substeps)

    def ode(s, u, env, offset):
        i = round(offset / quarter)
        return fault_ode(s, u, env, D[i * m:(i + 1) * m], B[i * m:(i + 1) * m])

    coarse, fine = (rk4(ode, s, dt, n, u, env) for n in (substeps, 2 * substeps))
    return ca.Function("doubled_by_faults", [s, u, env, D, B], [coarse, fine])


@memoized(16)
def _mapped(doubled: ca.Function, runs: int, compiled: bool) -> InPlace:
    """``doubled`` over the ``CHECKS`` steps of each of ``runs`` runs at once, one per column, evaluated in place
    (:class:`~uvsym.evaluation.InPlace`); compiled: its C (from the compile cache; CasADi's virtual machine where
    there is no compiler)."""
    return InPlace((_compiled(doubled) if compiled else doubled).map(CHECKS * runs))


@memoized(16)
def _compiled(doubled: ca.Function) -> ca.Function:
    """``doubled`` compiled (about 6x faster than CasADi's virtual machine on the docking vehicle; no fused
    multiply-adds, so that it rounds as the virtual machine does), or itself where it cannot be."""
    try:
        return compile_function(doubled, (*DEFAULT_FLAGS, "-ffp-contract=off"))
    except CodegenError:
        return doubled


def step_error(loop, outputs: np.ndarray, W: np.ndarray, tolerance: float) -> StepError | None:
    """The largest error of the checked steps of a finished run (module docstring): outputs (N + 1, n_out)
    its logged rows, W (N + 1, n_w) its inputs (dense or compact). None for a discrete-time plant, a loop
    that cannot read its integrated state back, or a run of no step."""
    return step_errors(loop, [(outputs, W, tolerance, None)])[0]


def step_errors(loop, runs, compiled: bool = False, state_max=None) -> list[StepError | None]:
    """:func:`step_error` of each run ``(outputs, W, tolerance, faults)`` of one loop, every checked step of every
    run in one call of the doubled step mapped over them all (compiled: its C, as compiled loops want). faults:
    the run's actuator faults where they are not the loop's own (``loop.actuator_faults``: a loop shared by
    runs of other faults, which its w carries), else None. state_max: one (n_s,) per run, the largest ``abs(s_i)`` of
    its states z_0 .. z_N (s = z[:n_s]) as the runner kept them, or None to read them back from the logged rows."""
    if loop.plant_ode is None:
        return [None] * len(runs)
    faults = [loop.actuator_faults if run_faults is None else run_faults for *_, run_faults in runs]
    state_max = [None] * len(runs) if state_max is None else state_max
    plans = [_plan(loop, outputs, W, tolerance, run_faults, largest)
             for (outputs, W, tolerance, _), run_faults, largest in zip(runs, faults, state_max)]
    checked = [i for i, plan in enumerate(plans) if plan is not None and plan[-1]]
    if checked:
        coarse, fine = _redone(loop, [plans[i] for i in checked], [faults[i] for i in checked], compiled)
    errors, i = [], 0
    for plan in plans:
        if plan is None:
            errors.append(None)
            continue
        scale, _, W, ks = plan
        worst = (0.0, 0.0, 0)
        if ks:
            block = slice(i * CHECKS, i * CHECKS + len(ks))
            i += 1
            ratio = np.abs(coarse[block] - fine[block]) * (16.0 / 15.0) / scale  # (checked, entries)
            entries = np.argmax(ratio, axis=1)
            largest = ratio[np.arange(len(ks)), entries]
            valid = np.flatnonzero(np.isfinite(largest) & (largest > 0))  # a step with a non-finite entry says nothing
            if valid.size:
                j = int(valid[np.argmax(largest[valid])])
                worst = (float(largest[j]), float(input_rows(W, ks[j])[0]), int(entries[j]))
        ratio, t_s, entry = worst
        needed = loop.substeps if ratio <= 1.0 else math.ceil(loop.substeps * ratio ** 0.25)
        errors.append(StepError(ratio, t_s, entry, needed, len(ks)))
    return errors


def _redone(loop, plans, faults, compiled: bool) -> tuple[np.ndarray, np.ndarray]:
    """(coarse, fine), each (CHECKS len(plans), n_s): the checked steps of each plan redone from the run's logged
    state with ``substeps`` and ``2 substeps`` RK4 steps (its last one repeated to fill CHECKS rows); a loop
    with a ``fault_ode`` takes each run's actuator faults at the fine steps' stage times."""
    arguments = []
    for (_, outputs, W, ks), run_faults in zip(plans, faults):
        rows = ks + ks[-1:] * (CHECKS - len(ks))
        (S_r, U_r), W_r = loop.integrated(outputs[rows]), input_rows(W, rows)
        last = _stage_faults(loop, run_faults, W_r[:, 0]) if loop.fault_ode is not None else (W_r[:, 0][None, :],)
        arguments.append((S_r.T, U_r.T, W_r[:, loop.env_columns].T, *last))
    arguments = [np.concatenate(parts, axis=1) for parts in zip(*arguments)]
    doubled = _doubled_by_faults(loop.fault_ode, loop.dt, loop.substeps) if loop.fault_ode is not None \
        else _doubled(loop.plant_ode, loop.dt, loop.substeps)
    coarse, fine = (v.T for v in _mapped(doubled, len(plans), compiled)(*arguments))
    return coarse, fine


def _stage_faults(loop, faults, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(D, B), each (m nodes, len(t)): the actuator faults' ``applied = a + D a + B`` at the stage times of
    ``2 substeps`` RK4 steps over the sample from each t (node i, actuator a at ``i m + a``)."""
    m = loop.fault_ode.size1_in(3)
    times = rk4_stage_times(t, loop.dt, 2 * loop.substeps)  # (len(t), nodes)
    phis = [np.asarray(fault.profile.phi(ca.DM(times.reshape(-1)))).reshape(times.shape) for fault in faults]
    parts, folded = actuator_fault_affine(faults, m, phis, times.shape)
    dense = np.zeros((2, len(t), times.shape[1], m))
    for (part, actuator), values in zip(parts, folded):
        dense[part, :, :, actuator] = values
    return dense[0].reshape(len(t), -1).T, dense[1].reshape(len(t), -1).T


def _plan(loop, outputs: np.ndarray, W, tolerance: float, faults, state_max=None):
    """(scale, outputs, W, checked samples) of a run's step check, or None where nothing can be checked. The
    logged rows are read back ``_ROWS`` at a time (each piece's temporaries stay small): the held inputs, and
    each state entry's largest absolute value unless ``state_max`` (n_s,) gives it (then in one piece: its
    temporaries are the inputs' size, (N + 1, m)). The steps where an actuator fault
    switches: from ``faults`` (its profiles' jumps) where given, else where the logged ``fault_actuator`` turns
    zero or non-zero."""
    if len(W) < 2 or loop.integrated(outputs[:1]) is None:
        return None
    largest, inputs, faulty = [], [], []
    piece = _ROWS if state_max is None else len(outputs)
    for start in range(0, len(outputs), piece):
        rows = outputs[start:start + piece]
        if state_max is None:
            S, U = loop.integrated(rows)
            largest.append(_column_max(S))
        else:
            U = loop.held_inputs(rows)
        inputs.append(U.T)
        if faults is None:
            faulty.append(loop.logged(rows, "fault_actuator").T != 0)
    U = np.concatenate(inputs, axis=1).T  # (N + 1, m), a view of its contiguous transpose
    if faults is None:
        faulty = np.concatenate(faulty, axis=1)  # (m, N + 1)
        switching = np.any(faulty[:, 1:] != faulty[:, :-1], axis=0) if len(faulty) else None
    else:
        t = input_column(W, 0)[:-1]
        switching = np.zeros(len(t), dtype=bool)
        for fault in faults:
            switching |= fault.profile.jumps(t, loop.dt)
    scale = np.max(largest, axis=0) if state_max is None else np.asarray(state_max, dtype=float)
    return tolerance * scale + ATOL, outputs, W, check_indices(U, switching)


def state_name(loop, entry: int) -> str:
    """The name of entry ``entry`` of a loop's integrated state s: a logged state's ``x.<label>``, else
    the actuator state it is (the vehicle format's s = [x; a])."""
    labels = loop.signals["x"][1] if "x" in loop.signals else ()
    return f"x.{labels[entry]}" if entry < len(labels) else f"the integrated state s[{entry}] (an actuator)"


def checked_steps(loop, outputs: np.ndarray, W: np.ndarray, tolerance: float, faults=None) -> dict | None:
    """The step error of a finished run (:func:`step_error`; faults as :func:`step_errors` has them) as the
    result's ``rk4_error`` meta, with an IntegrationAccuracyWarning (naming the state, the time and the
    substeps that would do) when it misses the tolerance; None where nothing was checked."""
    return checked_runs(loop, [(outputs, W, tolerance, faults)], stacklevel=5)[0]


def checked_runs(loop, runs, stacklevel: int = 4, compiled: bool = False, state_max=None) -> list[dict | None]:
    """:func:`checked_steps` of each run ``(outputs, W, tolerance, faults)`` of one loop (:func:`step_errors`, compiled
    and state_max as it says); stacklevel: the warnings', counted from this function."""
    metas = []
    for (_, _, tolerance, _), error in zip(runs, step_errors(loop, runs, compiled, state_max)):
        if error is None:
            metas.append(None)
            continue
        if error.ratio > 1.0:
            warnings.warn(f"fast method: RK4 with {loop.substeps} substep(s) per {loop.dt:g} s sample misses the "
                          f"tolerance {tolerance:g} by a factor {error.ratio:.3g} at t = {error.t_s:g} s in "
                          f"{state_name(loop, error.entry)} (step doubling on {error.checked} sampled steps, the "
                          "error against the entry's largest value in the run); substeps = "
                          f"{error.substeps_needed} would meet it (or a CasADi integrator method)",
                          IntegrationAccuracyWarning, stacklevel=stacklevel)
        metas.append(error.as_dict() | {"tolerance": tolerance, "state": state_name(loop, error.entry)})
    return metas
