"""``simulate_batch``: many runs of one closed loop at once, in lanes of one compiled step.

Runs that share the compiled step -- the same vehicle, controller, observers, sensor faults, step,
duration and substeps -- differ freely in initial state, current, actuator faults (they are
per-sample inputs of the step, :mod:`uvsym.sim.closed_loop`; a constant current all of them share is
built into the step instead, as the scalar path builds it) and noise seed. They run ``lanes`` at
a time through :func:`uvsym.codegen.compile_lanes`: one C loop over the steps whose body runs every
lane side by side, vectorised by the compiler. Each run's result equals :func:`simulate_scenario`'s
for it up to rounding (the vector math library's sin, cos, ... differ from the scalar ones in the
last bits; tests/test_batch.py). A run needing a supervisor (Python logic between chunks) cannot
run in lanes: :func:`simulate_batch` refuses one, and a scenario whose [diagnosis] corrects the
commands, while it runs a diagnosis that only watches on the finished record, as
:func:`simulate_scenario` does; :func:`simulate_scenario` runs the others.
Scenarios over any System (:class:`~uvsym.sim.system_scenario.SystemScenario`) share a step when
their plant, blocks, fault shapes (target, kind, profile kind), substitutions, step and substeps
are the same (fault sizes, onsets, durations, noise levels, seeds, initial states and
disturbances are per-run inputs, :mod:`uvsym.sim.wiring`); their detectors decide on each lane's
finished record, as :func:`~uvsym.sim.system_scenario.simulate_system_scenario` does. One whose
substitutions switch on a flag (a supervisor) is refused.
Without a C compiler, or for a step the lanes cannot run, every run falls back to the scalar path
(with a warning).
"""

from __future__ import annotations

import time
import warnings
from typing import Sequence

import numpy as np

from uvsym.codegen.cache import frozen, memoized
from uvsym.codegen.compile import compile_lanes
from uvsym.codegen.lane_width import measured_lanes
from uvsym.errors import CodegenError, SimulationError
from uvsym.sim.closed_loop import build_closed_loop
from uvsym.sim.inputs import CompactInputs, input_column, input_rows
from uvsym.sim.result import Signal, SimResult
from uvsym.sim.run import CHUNK, check_chunk, run_closed_loop
from uvsym.sim.scenario import Scenario
from uvsym.sim.simulation import PreparedRun, observer_blocks, prepare_run, scenario_arguments
from uvsym.sim.step_error import checked_runs

__all__ = ["LANES", "default_lanes", "simulate_batch", "run_lanes"]

LANES = 4  # trajectories per compiled step where the processor's vectors hold 4 doubles or more (see default_lanes)


def default_lanes() -> int:
    """Trajectories per compiled step on this processor (:func:`~uvsym.codegen.lane_width.measured_lanes`):
    one vector of doubles, at most ``LANES``, on processors of 2 or 4 doubles per vector; on AVX-512 (8
    doubles) 8 where a calibration loop measured them clearly faster than 4, else 4 (some processors run
    512-bit arithmetic at half the rate of 256-bit, and the docking loop's 8 lanes measured 256 against 220 ns
    per trajectory-step there), measured once per machine and cached.
    """
    return measured_lanes()


def simulate_batch(scenarios: Sequence, *, lanes: int | None = None, substeps: int = 1, compiled: bool = True,
                   supervisor=None, current_in_step: bool = True) -> list[SimResult]:
    """Each scenario run as :func:`simulate_scenario` (method ``fast``; for a SystemScenario
    :func:`~uvsym.sim.system_scenario.simulate_system_scenario`, whose own substeps hold) would, in
    lanes of shared compiled steps.

    Scenarios share a loop when they share the model object (as loads of one file, or ``dataclasses.replace``
    of one scenario, do), have equal controllers, observers, sensor faults, step and duration;
    each such group runs in lanes (``lanes`` per compiled step; None: :func:`default_lanes`). Results are
    in the order of ``scenarios``; meta as :func:`simulate_scenario`'s plus ``lanes``, ``wall_s`` being the
    group's. current_in_step: build a constant current the group shares into its step (fewer operations);
    False reads it from each run's inputs, so that calls with other currents share the step and its compiled
    library (a campaign's chunks).

    Raises
    ------
    SimulationError
        For ``lanes`` not a positive integer, a supervisor or a [diagnosis] that corrects the commands
        (lanes run without Python in the loop), and as :func:`simulate_scenario` does for a run that
        diverges (naming the scenario).
    """
    _check_lanes(lanes)
    if supervisor is not None:
        raise SimulationError("simulate_batch runs without a supervisor (no Python between the steps of the lanes); "
                              "run supervised scenarios with simulate_scenario")
    from uvsym.sim.system_scenario import SystemScenario

    groups: dict[tuple, list[int]] = {}
    systems: dict[tuple, list[int]] = {}
    for i, scenario in enumerate(scenarios):
        if isinstance(scenario, SystemScenario):
            if scenario.supervisor is not None:
                raise SimulationError(f"scenarios[{i}] ({scenario.name}): its substitutions switch on a flag, a "
                                      "supervisor the lanes cannot run; run it with simulate_system_scenario")
            systems.setdefault((id(scenario.loop.step), scenario.duration), []).append(i)
            continue
        if not isinstance(scenario, Scenario):
            raise SimulationError(f"scenarios[{i}] must be a Scenario or a SystemScenario, got "
                                  f"{type(scenario).__name__}")
        if scenario.diagnosis is not None and scenario.diagnosis.correct:
            raise SimulationError(f"scenarios[{i}] ({scenario.name}): its [diagnosis] corrects the commands, a "
                                  "supervisor the lanes cannot run; run it with simulate_scenario")
        shape = (id(scenario.model), frozen(scenario.controller), scenario.observers, scenario.sensor_faults,
                 scenario.step, scenario.duration)
        groups.setdefault(shape, []).append(i)
    results: list[SimResult | None] = [None] * len(scenarios)
    for members in groups.values():
        first = scenarios[members[0]]
        observers = observer_blocks(first.model, first.observers, first.step)
        loop = build_closed_loop(first.model, first.controller, first.step, sensor_faults=first.sensor_faults,
                                 observers=observers, substeps=substeps,
                                 current=_shared_current([scenarios[i] for i in members]) if current_in_step
                                 else None)
        runs = [prepare_run(scenarios[i].model, scenarios[i].controller, **scenario_arguments(scenarios[i], observers),
                            substeps=substeps, loop=loop, compact=True) for i in members]
        names = [scenarios[i].name for i in members]
        for i, result in zip(members, run_lanes(runs, lanes=lanes, compiled=compiled, names=names)):
            meta = {"scenario": scenarios[i].name, **result.meta}
            if scenarios[i].diagnosis is not None:
                meta["events"] = _diagnosed(scenarios[i], result)
            results[i] = SimResult(result.t, result.signals, meta)
    for members in systems.values():
        for i, result in zip(members, _system_lanes([scenarios[i] for i in members], lanes, compiled)):
            results[i] = result
    return results


def _shared_current(scenarios: list[Scenario]) -> tuple[float, float] | None:
    """The constant current (V_c, beta_c) every scenario of a group holds, built into the lanes' step as the
    scalar path builds it into its own (fewer operations: no current, no trigonometry of it); None when
    they differ or vary in time (each run's current then read from its W)."""
    currents = {tuple(float(c) for c in s.current) for s in scenarios}
    if len(currents) == 1 and all(s.current_variation[0] == 0.0 for s in scenarios):
        return currents.pop()
    return None


def _system_lanes(scenarios: list, lanes: int | None, compiled: bool) -> list[SimResult]:
    """Scenarios over one shared wired step, in lanes; each result as simulate_system_scenario gives it."""
    from uvsym.sim.system_scenario import decided, scenario_inputs, scenario_meta_arguments
    from uvsym.sim.system_simulation import wired_meta

    runs = [PreparedRun(scenario.loop, scenario.z0, scenario_inputs(scenario, compact=True), None,
                        wired_meta(scenario.loop, method="fast", **scenario_meta_arguments(scenario)),
                        scenario.rk4_tolerance) for scenario in scenarios]
    results = run_lanes(runs, lanes=lanes, compiled=compiled, names=[s.name for s in scenarios])
    return [decided(scenario, result) for scenario, result in zip(scenarios, results)]


def _diagnosed(scenario: Scenario, result: SimResult) -> list[dict]:
    """The decision log of the scenario's [diagnosis] run on the finished record, as :func:`simulate_scenario`
    gives it for a diagnosis that does not correct."""
    from uvsym.diagnosis.run import diagnosis_for  # the diagnosis package builds on uvsym.sim

    diagnosis = diagnosis_for(scenario)
    diagnosis.update(result.t, {name: result[name].values for name in diagnosis.reads})
    return [event.as_dict() for event in diagnosis.events]


def run_lanes(runs: Sequence[PreparedRun], *, lanes: int | None = None, compiled: bool = True,
              names: Sequence[str] | None = None) -> list[SimResult]:
    """Runs prepared on ONE shared loop step (:func:`prepare_run` with ``loop=``, or wired loops of one
    shape) and the same grid, ``lanes`` at a time (None: :func:`default_lanes`).

    Returns one SimResult per run (meta: the run's, ``lanes``, ``wall_s`` and ``build_s`` of the
    batch). ``names`` label the runs in errors (default: their index). Falls back to one scalar run
    after another (with a warning) when the lanes cannot be compiled.
    """
    _check_lanes(lanes)
    if not runs:
        return []
    lanes = default_lanes() if lanes is None else lanes
    loop, N = runs[0].loop, runs[0].W.shape[0] - 1
    for i, run in enumerate(runs):
        if run.loop.step is not loop.step or run.W.shape != runs[0].W.shape:
            raise SimulationError(f"run {i} does not share the first run's loop and grid; prepare them with one loop")
    names = [str(i) for i in range(len(runs))] if names is None else list(names)
    started = time.perf_counter()
    try:
        if not compiled:
            raise CodegenError("compiled=False")
        roll = compile_lanes(loop.step, lanes)
    except CodegenError as exc:
        if compiled:
            warnings.warn(f"running the batch one run after another: {exc}", stacklevel=2)
        return [_scalar(run, compiled) for run in runs]
    build_s = time.perf_counter() - started
    n_out = loop.discrete.size1_out("out")
    results = []
    for first in range(0, len(runs), lanes):
        group = list(runs[first:first + lanes])
        started = time.perf_counter()
        # each run's own W and logged rows, as the scalar path has them: the roll gathers and scatters the lanes
        Ws = [run.W if isinstance(run.W, CompactInputs) else np.ascontiguousarray(run.W, dtype=float)
              for run in group]
        outputs = [np.empty((N + 1, n_out)) for _ in group]
        padding = lanes - len(group)  # padding lanes repeat the last run, into its own rows (the same values)
        lane_W, lane_out = Ws + Ws[-1:] * padding, outputs + outputs[-1:] * padding
        z = np.stack([run.z0 for run in group] + [group[-1].z0] * padding, axis=-1)
        # the roll keeps each lane's largest |z| (the step check's scale) and finds its non-finite output rows
        z_max, first_bad = np.zeros((loop.n_s, lanes)), np.full(lanes, -1, dtype=np.int_)  # s = z[:n_s]
        for start in range(0, N, CHUNK["fast"]):
            k = min(CHUNK["fast"], N - start)
            z = roll.runs(z, [W[start:start + k] for W in lane_W], [out[start:start + k] for out in lane_out],
                          z_max, first_bad)
            for lane, (W, out, run) in enumerate(zip(Ws, outputs, group)):
                W_rows, rows = W[start:start + k], out[start:start + k]
                try:
                    if first_bad[lane] >= 0 or not np.isfinite(z[:, lane]).all():
                        check_chunk(loop, "fast", start, input_rows(W_rows, slice(None)), rows, z[:, lane], run.guard)
                    elif run.guard is not None:
                        run.guard(input_column(W_rows, 0), rows)
                except SimulationError as exc:
                    raise SimulationError(f"run {names[first + lane]}: {exc}") from None
        last = np.asarray(_final(loop.discrete, lanes)(z, np.stack([input_rows(W, N) for W in lane_W], axis=-1))[2])
        for lane, out in enumerate(outputs):
            out[N] = last[:, lane]
        wall = time.perf_counter() - started
        checked = [(lane, (out, W, run.rk4_tolerance, run.actuator_faults))  # as the scalar path checks them,
                   for lane, (out, W, run) in enumerate(zip(outputs, Ws, group))  # all in one call
                   if run.rk4_tolerance is not None]
        state_max = [z_max[:, lane] for lane, _ in checked]  # over z_0 .. z_N
        errors = dict(zip([lane for lane, _ in checked], checked_runs(loop, [c for _, c in checked], compiled=True,
                                                                      state_max=state_max)))
        for lane, (run, W, out) in enumerate(zip(group, Ws, outputs)):  # views of the run's rows: no copy
            signals = {name: Signal(out[:, sl], labels, units) for name, (sl, labels, units) in loop.signals.items()}
            meta = {**run.meta, "lanes": lanes, "wall_s": wall, "build_s": build_s}
            if errors.get(lane) is not None:
                meta["rk4_error"] = errors[lane]
            results.append(SimResult(input_column(W, 0).copy(), signals, meta))
    return results


def _check_lanes(lanes) -> None:
    """SimulationError unless ``lanes`` is None or a positive integer."""
    if lanes is not None and (isinstance(lanes, bool) or not isinstance(lanes, int) or lanes < 1):
        raise SimulationError(f"lanes must be a positive integer (trajectories per compiled step) or None (this "
                              f"processor's measured count), got {lanes!r}")


@memoized(16)
def _final(discrete, lanes: int):
    """The loop's discrete part over ``lanes`` columns (the logged row after the last step of each lane)."""
    return discrete.map(lanes)


def _scalar(run: PreparedRun, compiled: bool) -> SimResult:
    """One run on the scalar fast path (the fallback of :func:`run_lanes`)."""
    # the runner writes a supervisor's decisions into its W: the run's own copy
    W = run.W.dense() if isinstance(run.W, CompactInputs) else run.W.copy()
    result, timing = run_closed_loop(run.loop, run.z0, W, compiled=compiled, guard=run.guard,
                                     rk4_tolerance=run.rk4_tolerance, actuator_faults=run.actuator_faults)
    return SimResult(result.t, result.signals, {**run.meta, **timing})
