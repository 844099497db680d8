"""``simulate(model, controller, ...)``: the public entry point of the simulation package."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from uvsym.codegen.cache import memoized
from uvsym.conventions import FORCE_LABELS
from uvsym.errors import KinematicsError, SimulationError
from uvsym.faults import ActuatorFault, SensorFault
from uvsym.kinematics import Tzyx
from uvsym.models.model import Model
from uvsym.observers import ActuatorObserver, actuator_observer
from uvsym.observers.base import Observer
from uvsym.observers.discrete import actuator_fault_observer
from uvsym.observers.gains import design_gains
from uvsym.sim.closed_loop import ClosedLoop, actuator_fault_table, build_closed_loop
from uvsym.sim.controllers import Autopilot
from uvsym.sim.inputs import CompactInputs, input_rows
from uvsym.sim.loop import fault_summary, per_sample, varying_rows
from uvsym.sim.result import SimResult
from uvsym.sim.run import Supervisor, check_memory, grid, memory_needed, run_closed_loop
from uvsym.sim.scenario import ObserverSpec, Scenario
from uvsym.sim.step_error import TOLERANCE

__all__ = ["simulate", "simulate_scenario", "observer_blocks", "scenario_observers", "current_profile", "PreparedRun",
           "prepare_run", "scenario_arguments"]


@dataclass(frozen=True)
class PreparedRun:
    """A run of :func:`simulate` ready for the runner: its loop, initial state z0 (n_z,), per-sample
    inputs W (N + 1, n_w; dense, or compact for the lanes), the attitude guard (None below 6 DOF), the
    result's meta (no timings), the fast path's step-error tolerance (None: not checked) and the run's
    actuator faults where its loop is shared (which W carries; None: the loop's own)."""

    loop: ClosedLoop
    z0: np.ndarray
    W: np.ndarray | CompactInputs
    guard: Callable | None
    meta: dict
    rk4_tolerance: float | None = TOLERANCE
    actuator_faults: tuple | None = None


def simulate(model: Model, controller: Autopilot, *, duration: float, dt: float, eta0, nu0,
             actuators0=None, current=(0.0, 0.0),
             actuator_faults: tuple[ActuatorFault, ...] = (), sensor_faults: tuple[SensorFault, ...] = (),
             observers: tuple[Observer, ...] = (), supervisor: Supervisor | None = None,
             method: str = "fast", substeps: int = 1, seed: int = 0, options: dict | None = None,
             compiled: bool = True, progress=None, rk4_tolerance: float | None = TOLERANCE) -> SimResult:
    """Simulate ``model`` under ``controller`` for ``duration`` s, sampled every ``dt`` s.

    Parameters
    ----------
    model : Model
        The vehicle (:mod:`uvsym.models.model`).
    controller : Autopilot
        Guidance and control (:mod:`uvsym.sim.autopilot`).
    duration : float
        Length of the run (s).
    dt : float
        Sample time (s).
    eta0 : (dof,) array
        Initial position/attitude (m, rad).
    nu0 : (dof,) array
        Initial velocity (m/s, rad/s).
    actuators0 : (m,) array or None
        Initial actuator values; default: the first command (no start-up transient).
    current : (2,) or (N + 1, 2) array
        Current (V_c m/s, beta_c rad), constant or one row per sample.
    actuator_faults : tuple of ActuatorFault
        Faults on the actuators (:mod:`uvsym.faults`).
    sensor_faults : tuple of SensorFault
        Faults on the measured states.
    observers : tuple of Observer
        Estimators (:class:`~uvsym.observers.base.Observer`, sampled every dt) run in the loop; each
        reads measured states and ``tau_d.<force>`` by name and starts from ``init``.
    supervisor : Supervisor or None
        Discrete logic run every ``supervisor.period`` s that may correct the commands.
    method : str
        ``fast`` (compiled fixed-step RK4, ``substeps`` per sample) or a CasADi integrator plugin
        (``cvodes``, ``idas``, ``rk``, ``collocation``) over each sample.
    substeps : int
        RK4 steps per sample on the fast path.
    seed : int
        Seed of the standard normal draws behind sensor noise faults.
    options : dict or None
        Integrator options, over the defaults of ``uvsym.sim.run.DEFAULT_OPTIONS``.
    compiled : bool
        Fast path compiled to C when a compiler is found (else interpreted by CasADi).
    progress : callable or None
        Called with the fraction of the run done (0 to 1) as it advances.
    rk4_tolerance : float or None
        The fast path's local error per sample, relative to each state's scale over the run, checked by
        step doubling (:mod:`uvsym.sim.step_error`: an IntegrationAccuracyWarning naming the substeps
        that would meet it); None: no check.

    Returns
    -------
    SimResult
        Signals x (true state), y (measured), u_desired (controller), u_command (sent, corrected and
        saturated), u_expected (what healthy actuators deliver), u_actual (delivered), fault_actuator
        (u_actual - healthy), fault_sensor (y - x), tau_desired, reference and f_hat/<observer>, one
        row per grid time ``0, dt, ..., duration``.
    """
    run = prepare_run(model, controller, duration=duration, dt=dt, eta0=eta0, nu0=nu0, actuators0=actuators0,
                      current=current, actuator_faults=actuator_faults, sensor_faults=sensor_faults,
                      observers=observers, method=method, substeps=substeps, seed=seed)
    result, timing = run_closed_loop(run.loop, run.z0, run.W, method=method, supervisor=supervisor, options=options,
                                     compiled=compiled, progress=progress, guard=run.guard,
                                     rk4_tolerance=rk4_tolerance)
    return SimResult(result.t, result.signals, {**run.meta, **timing})


def prepare_run(model: Model, controller: Autopilot, *, duration: float, dt: float, eta0, nu0, actuators0=None,
                current=(0.0, 0.0), actuator_faults: tuple[ActuatorFault, ...] = (),
                sensor_faults: tuple[SensorFault, ...] = (), observers: tuple[Observer, ...] = (),
                method: str = "fast", substeps: int = 1, seed: int = 0, current_in_w: bool = False,
                loop: ClosedLoop | None = None, compact: bool = False) -> PreparedRun:
    """The loop, z0, W, guard and meta of :func:`simulate` (same arguments), checked, before anything runs.

    current_in_w: read a constant current from W rather than build it into the step (so runs with
    different currents share one compiled step, as the lanes of a batch do). loop: one already built
    for this model, controller, dt, sensor faults, observers and substeps with ``current=None``, to
    share (its fixed-step ``step`` takes the actuator faults from W, its step check the run's
    ``actuator_faults``; its ``plant_ode``, the integrators', holds none: method ``fast`` only).
    compact: W as :class:`~uvsym.sim.inputs.CompactInputs` (what the lanes read), else dense.
    """
    N = grid(duration, dt)
    env = np.asarray(current, dtype=float)
    per_sample(env, 2, N, "current (V_c m/s, beta_c rad)")
    dof, m, n = model.dof, model.n_inputs, 2 * model.dof
    x0 = np.concatenate([_vector(eta0, dof, "eta0"), _vector(nu0, dof, "nu0")])
    if dof == 6:
        try:
            Tzyx(x0[3], x0[4])
        except KinematicsError as exc:
            raise KinematicsError(f"eta0: {exc}") from None
    shared = loop is not None
    if shared and method != "fast" and loop.actuator_faults != tuple(actuator_faults):
        raise SimulationError(f"method {method!r} integrates the shared loop's plant_ode, which holds other actuator "
                              "faults than this run's; share a loop with method 'fast' only")
    if not shared:
        loop = build_closed_loop(model, controller, dt, actuator_faults=tuple(actuator_faults),
                                 sensor_faults=tuple(sensor_faults), observers=tuple(observers), substeps=substeps,
                                 current=tuple(env) if env.shape == (2,) and not current_in_w else None)
    check_memory(memory_needed(N + 1, loop), f"{duration:g} s at step {dt:g} s ({N + 1} samples)")
    inputs = _run_inputs(loop, N, dt, env, tuple(actuator_faults), n if sensor_faults else 0, seed)
    W = inputs if compact else inputs.dense()

    lay = loop.layout
    z0 = np.zeros(loop.n_z)
    z0[lay["x"]], z0[lay["held"]] = x0, x0
    _, u_cmd0, _ = loop.discrete(z0, input_rows(W, 0))
    a0 = np.asarray(u_cmd0).ravel() if actuators0 is None else _vector(actuators0, m, "actuators0")
    z0[lay["a"]], z0[lay["a_expected"]] = a0, a0
    tau_d0 = np.asarray(model.tau(x0[:dof], x0[dof:], a0, 0.0, 0.0)).ravel()
    measured = dict(zip(model.state_labels, x0))
    desired = {f"tau_d.{force}": value for force, value in zip(FORCE_LABELS[dof], tau_d0)}
    for obs in observers:
        sl = loop.observer_slices[obs.name]
        z0[lay["xo"].start + sl.start:lay["xo"].start + sl.stop] = obs.initial_state(
            [measured[n] for n in obs.reads_y.names], [desired[n] for n in obs.reads_u.names])

    meta = {"vehicle": model.name, "method": method, "dt_s": dt, "duration_s": duration, "substeps": substeps,
            "seed": seed, "observers": [obs.name for obs in observers],
            "actuator_faults": [fault_summary(f, model.input_labels[f.actuator]) for f in actuator_faults],
            "sensor_faults": [fault_summary(f, model.state_labels[f.channel]) for f in sensor_faults]}
    return PreparedRun(loop, z0, W, _attitude_guard(loop) if dof == 6 else None, meta,
                       actuator_faults=tuple(actuator_faults) if shared else None)


def _run_inputs(loop: ClosedLoop, N: int, dt: float, env: np.ndarray, faults: tuple[ActuatorFault, ...], n_noise: int,
                seed: int) -> CompactInputs:
    """The run's W (N + 1, n_w) at samples k dt, ``[t, noise, V_c, beta_c, vec(S), o, D, B]``, as its varying
    columns: the times, ``n_noise`` seeded draws behind sensor faults, the current where it varies and the
    fault columns the faults touch; the rest constant (the current where it holds, the correction S = I,
    o = 0, no fault)."""
    m = loop.model.n_inputs
    constant = np.zeros(loop.n_w)
    constant[loop.correction_columns] = np.concatenate([np.eye(m).reshape(-1), np.zeros(m)])
    columns, blocks = [np.arange(1 + n_noise)], []  # t, noise: columns 0..n_noise
    env_columns = np.arange(loop.n_w)[loop.env_columns]
    if env.shape == (2,):
        constant[env_columns] = env
    else:
        blocks.append(env)
        columns.append(env_columns)
    touched, values = actuator_fault_table(loop, faults, N)
    blocks.append(values)
    columns.append(loop.fault_columns.start + touched)
    return CompactInputs(constant, np.concatenate(columns).astype(np.int_), varying_rows(N, dt, n_noise, seed, blocks))


def _attitude_guard(loop):
    """guard(t, out) for :func:`run_closed_loop`: SimulationError at the first sample where the true
    pitch reaches or crosses +-90 deg (cos theta below 1e-9 or changing sign), where the Euler-angle
    kinematics eta' = J(eta) nu are singular and the attitude that follows is meaningless."""
    rows, labels, _ = loop.signals["x"]
    column = rows.start + labels.index("theta")
    previous = [None]

    def guard(t: np.ndarray, out: np.ndarray) -> None:
        if not len(out):
            return  # no sample to judge (a run stopped before its first one is reported by the runner)
        cos_theta = np.cos(out[:, column])
        before = np.concatenate([[cos_theta[0] if previous[0] is None else previous[0]], cos_theta[:-1]])
        hit = np.flatnonzero((np.abs(cos_theta) < 1e-9) | (np.sign(cos_theta) != np.sign(before)))
        if hit.size:
            k = hit[0]
            raise SimulationError(f"kinematic singularity at t = {t[k]:.6g} s: the state x.theta = "
                                  f"{np.degrees(out[k, column]):.6g} deg reached pitch +-90 deg, where "
                                  "eta' = J(eta) nu is undefined (Euler angles); the run is stopped there")
        if cos_theta.size:
            previous[0] = cos_theta[-1]

    return guard


def _vector(values, size: int, name: str) -> np.ndarray:
    array = np.asarray(values, dtype=float).reshape(-1)
    if array.size != size:
        raise SimulationError(f"{name} must have {size} entries, got {array.size}")
    if not np.all(np.isfinite(array)):
        raise SimulationError(f"{name} has non-finite entries: {array.tolist()}")
    return array


def scenario_observers(model: Model, specs: tuple[ObserverSpec, ...]) -> dict[str, tuple[ActuatorObserver, np.ndarray]]:
    """kind -> (observer, K): the scenario's observers, with gains designed for their time constants."""
    observers = {}
    for spec in specs:
        observer = actuator_observer(model, spec.kind, spec.form)
        observers[spec.kind] = (observer, design_gains(observer, spec.time_constant, spec.tau_d).K)
    return observers


def current_profile(scenario: Scenario):
    """(V_c, beta_c), or with a speed variation one row per sample (N + 1, 2): a first-order
    Gauss-Markov process ``V' = -(V - V_mean) / T + w`` of the given standard deviation, seeded
    with ``scenario.seed + 1`` (independent of the sensor-noise draws), speed kept >= 0."""
    std, T = scenario.current_variation
    if std == 0.0:
        return scenario.current
    N = grid(scenario.duration, scenario.step)
    a = np.exp(-scenario.step / T)
    rng = np.random.default_rng(scenario.seed + 1)
    deviation = np.empty(N + 1)
    deviation[0] = std * rng.standard_normal()
    kicks = std * np.sqrt(1 - a * a) * rng.standard_normal(N)
    for k in range(N):
        deviation[k + 1] = a * deviation[k] + kicks[k]
    speed = np.maximum(scenario.current[0] + deviation, 0.0)
    return np.column_stack([speed, np.full(N + 1, scenario.current[1])])


@memoized(16)
def observer_blocks(model: Model, specs: tuple[ObserverSpec, ...], dt: float) -> tuple[Observer, ...]:
    """The scenario's observers as :class:`~uvsym.observers.base.Observer` sampled every ``dt`` s,
    named by their kind (f_hat in the kind's unit); memoized in-process (gain design and symbolic build
    are done once per model object, specs and dt)."""
    return tuple(actuator_fault_observer(model, kind, dt, K, form=observer.form, name=kind)
                 for kind, (observer, K) in scenario_observers(model, specs).items())


def simulate_scenario(scenario: Scenario, *, method: str = "fast", supervisor: Supervisor | None = None,
                      progress=None, **options) -> SimResult:
    """Run a validated :class:`Scenario`; keyword options go to :func:`simulate` (e.g. substeps).

    A scenario with a [diagnosis] table runs its :class:`~uvsym.diagnosis.ActuatorDiagnosis`: in the
    loop when it corrects the commands, else on the finished record (the same decisions, faster);
    the result's ``events`` hold its decision log (unless ``supervisor`` replaces it).
    """
    diagnosis = None
    if scenario.diagnosis is not None and supervisor is None:
        from uvsym.diagnosis.run import diagnosis_for  # the diagnosis package builds on this module

        diagnosis = diagnosis_for(scenario)
        supervisor = diagnosis if scenario.diagnosis.correct else None
    result = simulate(scenario.model, scenario.controller, **scenario_arguments(scenario), supervisor=supervisor,
                      method=method, progress=progress, **options)
    meta = {"scenario": scenario.name, **result.meta}
    if diagnosis is not None:
        if supervisor is None:
            diagnosis.update(result.t, {name: result[name].values for name in diagnosis.reads})
        meta["events"] = [event.as_dict() for event in diagnosis.events]
    return SimResult(result.t, result.signals, meta)


def scenario_arguments(scenario: Scenario, observers: tuple[Observer, ...] | None = None) -> dict:
    """The keyword arguments of :func:`simulate` (and :func:`prepare_run`) a scenario sets, past model and
    controller; ``observers``: its :func:`observer_blocks` when the caller has them already."""
    return {"duration": scenario.duration, "dt": scenario.step, "eta0": scenario.eta0, "nu0": scenario.nu0,
            "actuators0": scenario.actuators0, "current": current_profile(scenario),
            "actuator_faults": scenario.actuator_faults, "sensor_faults": scenario.sensor_faults,
            "observers": observer_blocks(scenario.model, scenario.observers, scenario.step) if observers is None
            else observers, "seed": scenario.seed}
