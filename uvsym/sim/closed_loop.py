"""The closed loop as CasADi Functions: a discrete part at the sample rate and a continuous plant.

State ``z = [x (2 dof); a (m); xc; xo; a_expected (m); held (2 dof)]``: plant state, actuator
state, controller state, observer states, the response a healthy actuator would give to the
commands (the actuator model run in the controller), and the sensor latch of stuck faults. Per-sample input
``w = [t; noise (2 dof); V_c; beta_c; vec(S) (m m); o (m); D (m J); B (m J)]``: time, standard normal
draws, the current, the command correction ``u_cmd = sat(S u_d + o)`` set by a supervisor, and the
actuator faults at the J = 2 substeps + 1 distinct RK4 stage times of the sample.

Every actuator fault kind is affine in the value v it acts on (``ActuatorKind.affine``), and so is
its blend ``v + phi (deliver(v) - v)`` with the profile phi(t), and a chain of them: the fixed-step
path applies ``a + D_j a + B_j`` (D_j = 0, B_j = 0 healthy), with (D_j, B_j) worked out in numpy
from the fault list (:func:`actuator_fault_table`). One compiled step thus serves every actuator
fault of a loop, and lanes of a batch can differ in them. The integrators' ``plant_ode`` keeps the
faults symbolic in continuous time.

At each sample the discrete part measures ``y`` (sensor faults), runs the controller and the
observers, and holds ``u_cmd`` over the sample; the plant ``[x; a]`` is then integrated over
the sample with actuator faults acting on ``a`` in continuous time. The observers' desired
action is ``tau_d = tau(y, a_expected)``: what healthy actuators deliver for the commands sent,
so that an actuator's own lag is not mistaken for a fault.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.codegen.cache import memoized
from uvsym.conventions import FORCE_LABELS
from uvsym.errors import SimulationError
from uvsym.faults import ActuatorFault, SensorFault, actuator_fault_affine, apply_actuator_faults, apply_sensor_faults
from uvsym.models.actuators import saturate
from uvsym.models.model import Model
from uvsym.observers.base import Observer
from uvsym.sim.controllers import Autopilot
from uvsym.sim.loop import SampledLoop, logged_signals
from uvsym.symbolic import rk4, rk4_stage_times

__all__ = ["ClosedLoop", "build_closed_loop", "actuator_fault_table"]


@dataclass(frozen=True, kw_only=True)
class ClosedLoop(SampledLoop):
    """The marine scenario loop (module docstring for z and w; the runner's fields in
    :class:`~uvsym.sim.loop.SampledLoop`). ``layout`` maps x, a, xc, xo, a_expected, held to
    their slices; ``observers`` the estimators by name, ``observer_slices`` their states within
    xo. ``env_columns``, ``correction_columns``, ``fault_columns``: where w holds (V_c, beta_c),
    (vec(S), o) and the actuator faults (D, B), filled by :func:`actuator_fault_table`.
    """

    model: Model
    observer_slices: dict
    observers: dict[str, Observer]
    fault_columns: slice

    def integrated(self, out: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """s = [x; a] (a: the actuators' own state, u_actual less its fault) and u_command, per logged row."""
        a = self.logged(out, "u_actual") - self.logged(out, "fault_actuator")
        return np.hstack([self.logged(out, "x"), a]), self.held_inputs(out)

    def held_inputs(self, out: np.ndarray) -> np.ndarray:
        """u_command per logged row: the plant inputs held over each sample."""
        return self.logged(out, "u_command")


def _by_name(names: tuple[str, ...], available: dict, observer: str):
    """The entries of ``available`` named ``names`` (SimulationError naming an unknown one)."""
    unknown = [n for n in names if n not in available]
    if unknown:
        raise SimulationError(f"observer {observer} reads {unknown}, which the loop does not have; "
                              f"it has: {', '.join(available)}")
    return [available[n] for n in names]


@memoized(16)
def build_closed_loop(model: Model, controller: Autopilot, dt: float, *,
                      actuator_faults: tuple[ActuatorFault, ...] = (),
                      sensor_faults: tuple[SensorFault, ...] = (),
                      observers: tuple[Observer, ...] = (),
                      substeps: int = 1, current: tuple[float, float] | None = None) -> ClosedLoop:
    """The closed loop of ``model`` under ``controller`` sampled every ``dt`` seconds.

    current: a constant (V_c m/s, beta_c rad) built into the fixed-step path (fewer operations),
    or None to read the current from each sample's input ``w``. Memoized in-process
    (:func:`~uvsym.codegen.cache.memoized`): a rerun with equal arguments shares the loop built first.
    """
    if not dt > 0.0:
        raise SimulationError(f"sample period dt must be positive (s), got {dt}")
    if substeps < 1:
        raise SimulationError(f"substeps must be >= 1, got {substeps}")
    controller.check(model.input_labels, model.dof)
    n, m = 2 * model.dof, model.n_inputs
    n_c = len(controller.state_labels)
    for obs in observers:
        if abs(obs.dt - dt) > 1e-9 * dt:
            raise SimulationError(f"observer {obs.name} is sampled every {obs.dt:g} s, the loop every {dt:g} s")
    n_o = sum(obs.state.size for obs in observers)
    layout, start = {}, 0
    for part, size in (("x", n), ("a", m), ("xc", n_c), ("xo", n_o), ("a_expected", m), ("held", n)):
        layout[part], start = slice(start, start + size), start + size
    stages = 2 * substeps + 1  # distinct RK4 stage times in a sample: t + j dt / (2 substeps)
    n_z, n_w, n_s = start, 1 + n + 2 + m * m + m + 2 * m * stages, n + m

    z, w = ca.SX.sym("z", n_z), ca.SX.sym("w", n_w)
    x, xc, xo, a_expected, held = (z[layout[p]] for p in ("x", "xc", "xo", "a_expected", "held"))
    t, noise, V_c, beta_c = w[0], w[1:1 + n], w[1 + n], w[2 + n]
    S = ca.reshape(w[3 + n:3 + n + m * m], m, m)
    o = w[3 + n + m * m:3 + n + m * m + m]
    faults = ca.reshape(w[3 + n + m * m + m:], m, 2 * stages)  # column j: D_j, column J + j: B_j

    y, held_next = apply_sensor_faults(x, t, sensor_faults, held, noise)
    xc_next, u_d, refs = controller.law(xc, y, dt, model)
    u_cmd = saturate(ca.mtimes(S, u_d) + o, ca.DM(model.u_min), ca.DM(model.u_max))
    eta_y, nu_y = y[:model.dof], y[model.dof:]
    tau_d = model.tau(eta_y, nu_y, a_expected, 0.0, 0.0)
    a_expected_next = rk4(lambda a, _t: model.actuator_rate(a, u_cmd), a_expected, dt, substeps)

    measured = dict(zip(model.state_labels, ca.vertsplit(y)))
    desired = {f"tau_d.{force}": tau_d[i] for i, force in enumerate(FORCE_LABELS[model.dof])}
    xo_next, estimates, observer_slices, start = [], [], {}, 0
    for obs in observers:
        size = obs.state.size
        s_next, f_hat = obs.step(xo[start:start + size], ca.vertcat(*_by_name(obs.reads_y.names, measured, obs.name)),
                                 ca.vertcat(*_by_name(obs.reads_u.names, desired, obs.name)), ca.DM(obs.p0))
        xo_next.append(s_next)
        estimates.append(f_hat)
        observer_slices[obs.name] = slice(start, start + size)
        start += size

    a_now = z[layout["a"]]
    u_actual = a_now + (faults[:, 0] * a_now + faults[:, stages])
    out_parts = {
        "x": (x, model.state_labels, model.state_units),
        "y": (y, model.state_labels, model.state_units),
        "u_desired": (u_d, model.input_labels, model.input_units),
        "u_command": (u_cmd, model.input_labels, model.input_units),
        "u_expected": (a_expected, model.input_labels, model.input_units),
        "u_actual": (u_actual, model.input_labels, model.input_units),
        "fault_actuator": (u_actual - a_now, model.input_labels, model.input_units),
        "fault_sensor": (y - x, model.state_labels, model.state_units),
        "tau_desired": (tau_d, FORCE_LABELS[model.dof], model.force_units),
        "reference": (refs, controller.reference_labels, controller.reference_units),
    }
    for obs, f_hat in zip(observers, estimates):
        labels = tuple(n.rsplit(".", 1)[-1] for n in obs.publishes.names)
        if len(set(labels)) != len(labels):
            raise SimulationError(f"observer {obs.name}: its published names {list(obs.publishes.names)} do not stay "
                                  "apart once their '<quantity>.' prefix is dropped (this loop logs labels only)")
        out_parts[f"f_hat/{obs.name}"] = (f_hat, labels, obs.publishes.units)
    out, signals = logged_signals(out_parts)

    z_disc = ca.vertcat(xc_next, *xo_next, a_expected_next, held_next)
    # dense outputs: buffers and mapaccum read them as plain arrays
    z_disc, u_cmd, out = ca.densify(z_disc), ca.densify(u_cmd), ca.densify(out)
    discrete = ca.Function("closed_loop_discrete", [z, w], [z_disc, u_cmd, out], ["z", "w"], ["z_disc", "u_cmd", "out"])

    def s_dot(s, applied, u_cmd, env):
        """[x; a]' with the actuators delivering ``applied`` while they follow ``u_cmd``."""
        return ca.vertcat(model.f(s[:n], applied, env), model.actuator_rate(s[n:], u_cmd))

    s, uc, env, ts = ca.SX.sym("s", n_s), ca.SX.sym("u_cmd", m), ca.SX.sym("env", 2), ca.SX.sym("t")
    plant_ode = ca.Function("plant_ode", [s, uc, env, ts], [s_dot(s, apply_actuator_faults(s[n:], ts, actuator_faults),
                                                                 uc, env)], ["s", "u_cmd", "env", "t"], ["s_dot"])
    d, b = ca.SX.sym("d", m), ca.SX.sym("b", m)
    fault_ode = ca.Function("plant_fault_ode", [s, uc, env, d, b], [s_dot(s, s[n:] + (d * s[n:] + b), uc, env)],
                            ["s", "u_cmd", "env", "d", "b"], ["s_dot"])
    half = dt / (2 * substeps)

    def stage_ode(s, u_cmd, env, offset):
        """s_dot at ``offset`` s into the sample (rk4 runs from 0 here), faults from w's stage column."""
        j, a = round(offset / half), s[n:]
        return s_dot(s, a + (faults[:, j] * a + faults[:, stages + j]), u_cmd, env)

    env_step = ca.vertcat(V_c, beta_c) if current is None else ca.DM(current)
    s_next = rk4(stage_ode, z[:n_s], dt, substeps, u_cmd, env_step)
    # named apart from libc's regex step(): a C caller of an exported "step" may reach that one
    step = ca.Function("closed_loop_step", [z, w], [ca.densify(ca.vertcat(s_next, z_disc)), out],
                       ["z", "w"], ["z_next", "out"], {"cse": True})
    return ClosedLoop(model=model, dt=dt, substeps=substeps, n_z=n_z, n_w=n_w, n_s=n_s, discrete=discrete,
                      plant_ode=plant_ode, actuator_faults=tuple(actuator_faults), fault_ode=fault_ode,
                      step=step, layout=layout, observer_slices=observer_slices,
                      observers={obs.name: obs for obs in observers}, signals=signals, env_columns=slice(1 + n, 3 + n),
                      correction_columns=slice(3 + n, 3 + n + m * m + m), fault_columns=slice(3 + n + m * m + m, n_w))


def actuator_fault_table(loop: ClosedLoop, faults: tuple[ActuatorFault, ...], N: int) -> tuple[np.ndarray, np.ndarray]:
    """(columns (n,), values (N + 1, n)): the fault columns (within w's fault block, ascending) that ``faults``
    can make non-zero and their values; the block is ``[D_0 .. D_J-1, B_0 .. B_J-1]``, each (m,), actuator a of
    stage j at ``j m + a``: per stage j the (D_j, B_j) with ``applied = a + D_j a + B_j`` at the stage time
    ``k dt + j dt / (2 substeps)`` of sample k = 0..N, faults composed in order
    (:func:`~uvsym.faults.actuator_fault_affine`; every other column 0).
    """
    m, stages = loop.model.n_inputs, 2 * loop.substeps + 1
    parts, folded = actuator_fault_affine(faults, m, [_stage_phi(f.profile, loop.dt, loop.substeps, N)
                                                      for f in faults], (N + 1, stages))  # (parts, N + 1, J)
    columns = [part * stages * m + j * m + actuator for part, actuator in parts for j in range(stages)]
    order = np.argsort(columns, kind="stable")
    table = np.ascontiguousarray(folded.transpose(1, 0, 2).reshape(N + 1, -1)[:, order])
    return np.asarray(columns, dtype=np.int_)[order], table


@functools.lru_cache(maxsize=32)
def _stage_phi(profile, dt: float, substeps: int, N: int) -> np.ndarray:
    """phi (N + 1, J) at the stage times of each sample (:func:`~uvsym.symbolic.rk4_stage_times`), evaluated by
    CasADi as the symbolic step would (kept: reruns reuse it)."""
    times = rk4_stage_times(dt * np.arange(N + 1), dt, substeps)  # sample times as sample_inputs writes them
    phi = np.asarray(profile.phi(ca.DM(times.reshape(-1)))).reshape(times.shape)
    phi.setflags(write=False)
    return phi
