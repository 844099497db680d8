"""``simulate_system(plant, blocks, ...)``: run a loop wired by signal name on a time grid."""

from __future__ import annotations

import numpy as np

from uvsym.errors import SimulationError
from uvsym.faults import ActuatorFault, SensorFault, fault_parameters
from uvsym.sim.inputs import CompactInputs
from uvsym.sim.loop import fault_summary, per_sample, varying_rows
from uvsym.sim.result import SimResult
from uvsym.sim.run import Supervisor, check_memory, grid, memory_needed, run_closed_loop
from uvsym.sim.step_error import TOLERANCE
from uvsym.sim.wiring import WiredLoop, interconnect
from uvsym.systems.system import System

__all__ = ["simulate_system", "initial_state", "loop_inputs", "run_wired", "wired_meta"]


def initial_state(loop: WiredLoop, x0, w0: np.ndarray) -> np.ndarray:
    """z0: plant state x0, the stuck-sensor latch at the healthy outputs, and each block's initial
    state: ``init`` of its reads at t = 0. The inits are repeated once per block, so that a block
    reading another block's output sees that block already initialised (a chain of any order)."""
    plant = loop.plant
    z0 = np.zeros(loop.n_z)
    z0[loop.layout["x"]] = plant.x.vector(x0, f"{plant.name}: x0")
    for b in loop.blocks:
        z0[loop.layout[b.name]] = b.s0
    out = np.asarray(loop.discrete(z0, w0)[2]).ravel()
    z0[loop.layout["held"]] = out[loop.signals["y"][0]] - out[loop.signals["fault_sensor"][0]]
    for _ in loop.blocks:
        for b, r0 in zip(loop.blocks, loop.reads.call([z0, w0])):  # call: a list even for one block
            z0[loop.layout[b.name]] = b.initial_state(np.asarray(r0).ravel())
    return z0


def simulate_system(plant: System, blocks, *, duration: float, dt: float, x0, method: str = "fast",
                    actuator_faults: tuple[ActuatorFault, ...] = (), sensor_faults: tuple[SensorFault, ...] = (),
                    substitutions: dict[str, str] | None = None, supervisor: Supervisor | None = None, d=None,
                    p=None, seed: int = 0, substeps: int = 1, options: dict | None = None, compiled: bool = True,
                    progress=None, rk4_tolerance: float | None = TOLERANCE) -> SimResult:
    """Simulate ``plant`` in the loop with ``blocks`` (wired by :func:`uvsym.sim.wiring.interconnect`)
    for ``duration`` s, sampled every ``dt`` s.

    Parameters
    ----------
    plant : System
        The plant, continuous or discrete (:mod:`uvsym.systems.system`).
    blocks : sequence of Block
        Controllers, estimators and logic (:mod:`uvsym.sim.blocks`), wired to the plant by signal name.
    duration : float
        Length of the run (s).
    dt : float
        Sample time (s).
    x0 : (n_x,) array or dict
        Initial plant state (or ``{name: value}``), in the states' units.
    method : str
        ``fast`` (compiled fixed-step RK4, ``substeps`` per sample) or a CasADi integrator plugin
        (``cvodes``, ``idas``, ``rk``, ``collocation``) over each sample.
    actuator_faults : tuple of ActuatorFault
        Faults on the plant's inputs (:mod:`uvsym.faults`).
    sensor_faults : tuple of SensorFault
        Faults on its measured outputs.
    substitutions : dict or None
        Channel -> substitute signal, switched by the supervisor's ``Substitution`` decisions (all off
        at the start).
    supervisor : Supervisor or None
        Discrete logic run every ``supervisor.period`` s.
    d : (n_d,) or (N + 1, n_d) array or None
        Plant disturbances, constant or one row per sample; default 0.
    p : (n_p,) array or None
        Plant parameters; default ``plant.p0``.
    seed : int
        Seed of the standard normal draws behind sensor noise faults.
    substeps : int
        RK4 steps per sample on the fast path.
    options : dict or None
        Integrator options, over the defaults of ``uvsym.sim.run.DEFAULT_OPTIONS``.
    compiled : bool
        Fast path compiled to C when a compiler is found (else interpreted by CasADi).
    progress : callable or None
        Called with the fraction of the run done (0 to 1) as it advances.
    rk4_tolerance : float or None
        The fast path's step-error tolerance (as in :func:`uvsym.sim.simulate`); None: no check.

    Returns
    -------
    SimResult
        One row per grid time ``0, dt, ..., duration``: x (true states), y (measured outputs), u (plant
        inputs applied, after actuator faults), one group per block (what it publishes, named by the
        block), fault_sensor (y - h(x, u)), fault_actuator (u - commanded) and, with substitutions,
        substitution (each channel's switch, 0 or 1).
    """
    N = grid(duration, dt)
    for what, faults in (("actuator_faults", actuator_faults), ("sensor_faults", sensor_faults)):
        late = [i for i, f in enumerate(faults) if not f.profile.onset < duration]
        if late:
            raise SimulationError(f"{what}[{late[0]}]: onset {faults[late[0]].profile.onset:g} s is not before the "
                                  f"end of the run ({duration:g} s): the fault would never act")
    loop = interconnect(plant, blocks, dt=dt, actuator_faults=tuple(actuator_faults),
                        sensor_faults=tuple(sensor_faults), substitutions=substitutions, substeps=substeps, p=p)
    W = loop_inputs(loop, N, d, seed)
    z0 = initial_state(loop, x0, W[0])
    return run_wired(loop, z0, W, method=method, supervisor=supervisor, options=options, compiled=compiled,
                     progress=progress, duration=duration, seed=seed, actuator_faults=actuator_faults,
                     sensor_faults=sensor_faults, substitutions=substitutions, rk4_tolerance=rk4_tolerance)


def loop_inputs(loop: WiredLoop, N: int, d=None, seed: int = 0, compact: bool = False):
    """W (N + 1, n_w) of a wired loop: times, seeded noise draws, disturbances d (constant (n_d,) or one
    row per sample; default 0), the numbers of the loop's faults, substitution switches off. compact: as
    :class:`~uvsym.sim.inputs.CompactInputs` (the times, the draws and a varying d its columns), else dense.
    SimulationError when it cannot be held."""
    plant = loop.plant
    check_memory(memory_needed(N + 1, loop), f"{N * loop.dt:g} s at step {loop.dt:g} s ({N + 1} samples)")
    n_noise, start = plant.y.size, loop.env_columns.start  # one row per sample: [t, noise, d, theta, switches]
    d = np.zeros(plant.d.size) if d is None else np.asarray(d, dtype=float)
    per_sample(d, plant.d.size, N, "d")
    constant = np.zeros(loop.n_w)
    constant[loop.fault_columns] = [value for fault in loop.faults for value in fault_parameters(fault)]
    columns, blocks = [np.arange(1 + n_noise)], []
    if d.ndim == 1:
        constant[start:start + plant.d.size] = d
    else:
        blocks.append(d)
        columns.append(np.arange(start, start + plant.d.size))
    inputs = CompactInputs(constant, np.concatenate(columns).astype(np.int_),
                           varying_rows(N, loop.dt, n_noise, seed, blocks))
    return inputs if compact else inputs.dense()


def run_wired(loop: WiredLoop, z0: np.ndarray, W: np.ndarray, *, method: str = "fast",
              supervisor: Supervisor | None = None, options: dict | None = None, compiled: bool = True,
              progress=None, duration: float, seed: int = 0, actuator_faults=(), sensor_faults=(),
              substitutions=None, rk4_tolerance: float | None = TOLERANCE) -> SimResult:
    """Run a wired loop from z0 over the rows of W (:func:`loop_inputs`); the result of :func:`simulate_system`
    (the faults and substitutions given only describe the loop's own in the result's meta)."""
    result, timing = run_closed_loop(loop, z0, W, method=method, supervisor=supervisor, options=options,
                                     compiled=compiled, progress=progress, rk4_tolerance=rk4_tolerance)
    meta = wired_meta(loop, method=method, duration=duration, seed=seed, actuator_faults=actuator_faults,
                      sensor_faults=sensor_faults, substitutions=substitutions)
    return SimResult(result.t, result.signals, meta | timing)


def wired_meta(loop: WiredLoop, *, method: str, duration: float, seed: int, actuator_faults=(), sensor_faults=(),
               substitutions=None) -> dict:
    """The meta of a wired loop's result (no timings): plant, method, dt_s, duration_s, substeps, seed,
    blocks, order, substitutions and the faults (target by name, kind, value, profile, onset_s, end_s)."""
    plant = loop.plant
    return {"plant": plant.name, "method": method, "dt_s": loop.dt, "duration_s": duration,
            "substeps": loop.substeps, "seed": seed, "blocks": [b.name for b in loop.blocks],
            "order": list(loop.order), "substitutions": dict(substitutions or {}),
            "actuator_faults": [fault_summary(f, plant.u.names[f.actuator]) for f in actuator_faults],
            "sensor_faults": [fault_summary(f, plant.y.names[f.channel]) for f in sensor_faults]}
