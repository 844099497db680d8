"""The blocks a scenario file can name: ``[[blocks]]`` tables turned into loop blocks.

Each table has ``type`` (a key of :data:`BLOCKS`) and ``name`` (the block's name: the result group
of what it publishes, and the prefix of its qualified signal names ``<name>.<signal>``), plus the
design parameters of its type. Gains are designed from them here (an LQR from its weights, a
Luenberger gain by LMI from a decay rate), never typed in the file, unless the file gives the
gain itself. Units are SI, as everywhere in uvsym.

=================  ==============================================================================
type               fields (besides type and name)
=================  ==============================================================================
pid                measured, output (signal names), reference (number or signal name), kp, ki, kd,
                   limits = [lo, hi]
state_feedback     gain (m x n), reads (n names), publishes (m names), x_ref, u_ref
lqr                q, r (weights: a list of the diagonal or a full matrix), reads (default: the
                   plant's states), publishes (default: the plant's inputs)
open_loop          times (s), values (one row per time), publishes, interpolation
luenberger         decay (1/s, LMI design certified in exact arithmetic) or gain (n x n_y)
ukf, ekf           q, r, p0 (covariances: a number, the diagonal or a full matrix)
lms                measured, regressor, reference (signal names), order, mu, eps0, r0, window,
                   hold, confirm (samples)
sensor_step        measured (one signal), noise_std (its white noise, default the [noise] entry of
                   the measured output), false_alarms_per_hour, before, after, glitch (samples),
                   alarm_z: the calibrated sensor-step monitor (:mod:`uvsym.observers.step_monitor`)
uio_bank           poles (F's n eigenvalues), measured (outputs), decouple (disturbances): one UIO
                   per input, publishing r_<input>_<output> (:mod:`uvsym.sim.uio_block`)
hybrid             z1, w1 (subsystem 1), sensor, sensor_gain, k1 or decay, l, gamma, m1, m2 (fault
                   estimator), model, x0 (:mod:`uvsym.sim.hybrid_block`)
select             flag, on, off, output (signal names; on, off, output one name or n each): a
                   switch of the same sample, ``output = flag ? on : off`` (substitution from the
                   sample the flag rises; ``[substitutions]`` switch from the next sample)
autopilot          waypoints, lookahead, turn_radius, acceptance, speed, speed_loop, heading_loop,
                   mix, reads, limits, saturate (LOS guidance with PID loops, :mod:`uvsym.sim.autopilot`)
actuator_observer  kind, form, time_constant, tau_d, commands: Liu et al.'s actuator-fault observer on
                   a vehicle plant, publishing tau_d.<force> and f_hat.<force>
                   (:mod:`uvsym.sim.actuator_block`)
mmae               filter (ukf, ekf), models (hypothesis = inputs with an efficiency state), q, r,
                   p0, x0, efficiency_p0, walk_std, floor, prior, reset, steps, alpha, beta, kappa
                   (:mod:`uvsym.observers.mmae_design`)
=================  ==============================================================================
"""

from __future__ import annotations

import numpy as np

from uvsym.codegen.cache import memoized
from uvsym.errors import ScenarioError, UvsymError
from uvsym.sim.blocks import Block, observer_block
from uvsym.sim.fields import Fields
from uvsym.sim.hybrid_block import hybrid_block
from uvsym.systems.signals import Signals
from uvsym.systems.system import System

__all__ = ["BLOCKS", "build_block", "schedule"]


def _matrix(fields: Fields, key: str, shape: tuple[int, int], dims: str, default=None, *,
            diagonal: bool = True) -> np.ndarray:
    """A (rows, cols) matrix: a full list of rows, or (square, ``diagonal``) a number or the diagonal;
    ``dims`` names its shape for the schema (``n_x x n_x``)."""
    fields._record(key, "number, list or matrix", default, dims + (", or a number, or its diagonal" if diagonal
                                                                    else ""))
    fields.used.add(key)
    value = fields.data.get(key, default)
    if value is None:
        raise ScenarioError(f"{fields._name(key)}: required matrix is missing{fields._misspelt(key)}")
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError(f"{fields._name(key)}: expected numbers, got {value!r}") from None
    if diagonal and shape[0] == shape[1] and array.ndim == 0:
        array = np.full(shape[0], float(array))
    if diagonal and shape[0] == shape[1] and array.shape == (shape[0],):
        array = np.diag(array)
    if array.shape != shape or not np.all(np.isfinite(array)):
        raise ScenarioError(f"{fields._name(key)}: expected a finite {shape[0]} x {shape[1]} matrix"
                            + (" (or a number, or its diagonal)" if diagonal and shape[0] == shape[1] else "")
                            + f", got {value!r}")
    return array


def _names(fields: Fields, key: str, default=None, size: int | None = None) -> tuple[str, ...]:
    """Signal names: one string or a list of them (``size`` of them when given)."""
    value = fields.raw(key, default, "string or list of strings", "loop signal names")
    if isinstance(value, str):
        value = [value]
    if value is None:
        raise ScenarioError(f"{fields._name(key)}: required signal name(s) missing{fields._misspelt(key)}")
    if not isinstance(value, (list, tuple)) or not value or not all(isinstance(v, str) for v in value):
        raise ScenarioError(f"{fields._name(key)}: expected a signal name or a list of them, got {value!r}")
    if size is not None and len(value) != size:
        raise ScenarioError(f"{fields._name(key)}: expected {size} signal names, got {list(value)}")
    return tuple(value)


def _group(plant: System, names: tuple[str, ...], where: str, group: str) -> Signals:
    """Signals named ``names`` with the units the plant gives them (its states, inputs or outputs), else ''."""
    units = {}
    for g in (plant.x, plant.u, plant.y):
        units.update(zip(g.names, g.units))
    return Signals(names, tuple(units.get(n, "") for n in names), group=group)


def _pid(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.sim.feedback import pid

    measured, output = _names(fields, "measured", size=1), _names(fields, "output", size=1)
    reference = fields.raw("reference", 0.0, "number or signal name", "set-point (measured's unit)")
    if not isinstance(reference, str):
        reference = Fields({"reference": reference}, fields.path).number("reference")
    limits = fields.raw("limits", None, "[lo, hi]", "output bounds (output's unit)", "none")
    if limits is not None:
        limits = tuple(Fields({"limits": limits}, fields.path).vector("limits", 2))
    gains = {key: fields.number(key, 0.0 if key != "kp" else None) for key in ("kp", "ki", "kd")}
    return pid(name, _group(plant, measured, fields.path, "read"), reference,
               output=_group(plant, output, fields.path, "published"), limits=limits, dt=dt, **gains)


def _state_feedback(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.sim.feedback import state_feedback

    _plant_defaults(fields)
    reads = _names(fields, "reads", plant.x.names)
    publishes = _names(fields, "publishes", plant.u.names)
    K = _matrix(fields, "gain", (len(publishes), len(reads)), "publishes x reads", diagonal=False)
    return state_feedback(name, K, _group(plant, reads, fields.path, "read"),
                          fields.vector("x_ref", len(reads)), fields.vector("u_ref", len(publishes)),
                          _group(plant, publishes, fields.path, "published"))


def _plant_defaults(fields: Fields) -> None:
    """Describe, for the schema, the reads and publishes that default to the plant's states and inputs."""
    fields.describe("reads", "string or list of strings", "loop signal names", "the plant's states")
    fields.describe("publishes", "string or list of strings", "loop signal names", "the plant's inputs")


def _lqr(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.sim.feedback import lqr

    _plant_defaults(fields)
    reads = _names(fields, "reads", plant.x.names, size=plant.x.size)
    publishes = _names(fields, "publishes", plant.u.names, size=plant.u.size)
    Q = _matrix(fields, "q", (plant.x.size,) * 2, "n_x x n_x")
    R = _matrix(fields, "r", (plant.u.size,) * 2, "n_u x n_u")
    return lqr(plant, Q, R, name=name, dt=dt, reads=_group(plant, reads, fields.path, "read"),
               publishes=_group(plant, publishes, fields.path, "published"))


def _open_loop(fields: Fields, plant: System, dt: float, name: str) -> Block:
    return schedule(fields, plant, name, _names(fields, "publishes"))


def schedule(fields: Fields, plant: System, name: str, publishes: tuple[str, ...]) -> Block:
    """A time table (``times``, ``values``, ``interpolation``) publishing ``publishes``: an open_loop
    block, or a scenario's set-point schedule."""
    from uvsym.sim.feedback import INTERPOLATIONS, open_loop

    times = fields.raw("times", None, "list of numbers", "strictly increasing, s")
    values = fields.raw("values", None, "list of rows", "one row (or number) per time")
    if times is None or values is None:
        raise ScenarioError(f"{fields.path}: a time table needs times and values")
    for key, table in (("times", times), ("values", values)):
        try:
            finite = np.all(np.isfinite(np.asarray(table, dtype=float)))
        except (TypeError, ValueError):
            finite = False
        if not finite:
            raise ScenarioError(f"{fields._name(key)}: expected finite numbers, got {table!r}")
    return open_loop(name, times, values, _group(plant, publishes, fields.path, "published"),
                     fields.text("interpolation", "previous", choices=INTERPOLATIONS))


def _luenberger(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.observers.luenberger import luenberger_observer

    if fields.has("gain"):
        L = _matrix(fields, "gain", (plant.x.size, plant.y.size), "n_x x n_y", diagonal=False)
    else:
        import cvxpy

        from uvsym.verify import synthesize_observer_gain

        decay = fields.number("decay", positive=True)
        if decay * dt >= 1.0:
            raise ScenarioError(f"{fields.path}.decay: {decay:g} 1/s is not below 1/step = {1 / dt:g} 1/s; an "
                                "observer sampled every step cannot decay faster")
        lin = plant.linearize()
        try:
            L = synthesize_observer_gain(lin.A, lin.C, decay=decay).L
        except cvxpy.error.SolverError as exc:
            raise ScenarioError(f"{fields.path}.decay: the LMI solver failed at {decay:g} 1/s ({exc}); try a "
                                "smaller rate") from None
    return observer_block(luenberger_observer(plant, L, dt, name=name))


def _gaussian(kind: str):
    def build(fields: Fields, plant: System, dt: float, name: str) -> Block:
        from uvsym.observers import ekf, ukf

        n, n_y = plant.x.size, plant.y.size
        options = {"Q": _matrix(fields, "q", (n, n), "n_x x n_x"), "R": _matrix(fields, "r", (n_y, n_y), "n_y x n_y"),
                   "P0": _matrix(fields, "p0", (n, n), "n_x x n_x")}
        factory = ukf if kind == "ukf" else ekf
        return observer_block(factory(plant, dt=dt, name=name, **options))

    return build


def _lms(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.observers.lms import lms_monitor

    measured = _group(plant, _names(fields, "measured", size=1), fields.path, "measurement")
    regressor = _group(plant, _names(fields, "regressor", size=1), fields.path, "input")
    reference = fields.raw("reference", None, "string", "signal subtracted before regression")
    if reference is not None and not isinstance(reference, str):
        raise ScenarioError(f"{fields.path}.reference: expected a signal name, got {reference!r}")
    options = {key: fields.integer(key, default, minimum=1, unit="samples") for key, default in
               (("order", 10), ("window", 20), ("hold", 3), ("confirm", 10))}
    options |= {key: fields.number(key, positive=True) for key in ("mu", "eps0", "r0")}
    return observer_block(lms_monitor(measured, regressor, dt=dt, name=name,
                                      reference=None if reference is None else _group(plant, (reference,), "",
                                                                                      "input"), **options))


def _sensor_step(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.observers.step_monitor import AFTER, BEFORE, GLITCH, sensor_step_monitor

    measured = _group(plant, _names(fields, "measured", size=1), fields.path, "measurement")
    fields.describe("noise_std", "number", "> 0 (the measured output's unit)", "the [noise] entry of measured")
    if fields.schema is None and not fields.has("noise_std"):
        raise ScenarioError(f"{fields._name('noise_std')}: not given, and [noise] has no Gaussian entry for "
                            f"{measured.names[0]!r} (the plant's outputs: {', '.join(plant.y.names)}) to default to")
    options = {key: fields.integer(key, default, minimum=0, unit="samples") for key, default in
               (("before", BEFORE), ("after", AFTER), ("glitch", GLITCH))}
    options |= {"false_alarms_per_hour": fields.number("false_alarms_per_hour", 0.1, positive=True),
                "alarm_z": fields.number("alarm_z", 3.5, positive=True),
                "noise_std": fields.number("noise_std", positive=True)}
    return observer_block(sensor_step_monitor(measured, dt=dt, name=name, **options))


def _uio_bank(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.sim.uio_block import uio_bank_block  # here: the zonotope sets load only for a UIO bank

    return uio_bank_block(fields, plant, dt, name)


def _select(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.sim.blocks import select

    flag = _names(fields, "flag", size=1)[0]
    output = _names(fields, "output")
    on, off = (_names(fields, key, size=len(output)) for key in ("on", "off"))
    units = set(_group(plant, on + off, fields.path, "read").units) - {""}  # the plant's units of on and off
    return select(name, flag=flag, on=on, off=off, output=output, unit=units.pop() if len(units) == 1 else "")


def _autopilot(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.sim.autopilot import autopilot_block

    return autopilot_block(fields, plant, dt, name)


def _actuator_observer(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.sim.actuator_block import actuator_observer_block

    return actuator_observer_block(fields, plant, dt, name)


def _mmae(fields: Fields, plant: System, dt: float, name: str) -> Block:
    from uvsym.observers.mmae_design import designed_bank

    return observer_block(designed_bank(fields, plant, dt, name))


BLOCKS = {"pid": _pid, "state_feedback": _state_feedback, "lqr": _lqr, "open_loop": _open_loop,
          "luenberger": _luenberger, "ukf": _gaussian("ukf"), "ekf": _gaussian("ekf"), "lms": _lms,
          "sensor_step": _sensor_step, "uio_bank": _uio_bank, "hybrid": hybrid_block,
          "select": _select, "autopilot": _autopilot, "mmae": _mmae,
          "actuator_observer": _actuator_observer}


def build_block(fields: Fields, plant: System, dt: float) -> Block:
    """The block a ``[[blocks]]`` table describes (module docstring), sampled every ``dt`` s.

    Memoized in-process by the table's content, its path, the plant object and dt (gain designs are
    made once: the runs of a campaign differ in faults, not in their blocks).

    Raises ScenarioError naming the field: an unknown type or field (with the close match), a
    missing or malformed parameter, or a design that fails for the plant (the design's own message).
    """
    if fields.schema is not None:  # recording the schema: each type's fields under blocks[<type>]
        kind = fields.text("type", choices=tuple(BLOCKS))
        typed = Fields(fields.data, f"blocks[{kind}]", fields.schema)
        typed.used.add("type")
        return _build(typed, plant, dt, kind)
    return _built(fields.data, fields.path, plant, dt)


@memoized(64)
def _built(data: dict, path: str, plant: System, dt: float) -> Block:
    return _build(Fields(data, path), plant, dt)


def _build(fields: Fields, plant: System, dt: float, kind: str | None = None) -> Block:
    kind = kind or fields.text("type", choices=tuple(BLOCKS))
    name = fields.text("name", kind)
    try:
        built = BLOCKS[kind](fields, plant, dt, name)
    except ScenarioError as exc:
        raise ScenarioError(f"{exc}{fields.unread_hint()}") from None
    except UvsymError as exc:
        raise ScenarioError(f"{fields.path} ({kind} {name!r}): {exc}{fields.unread_hint()}") from None
    fields.done()
    return built
