"""Scenarios as data: a TOML file names the vehicle, initial state, controller, faults, observers,
current, duration and step. Every field is checked; an error names it (``faults[2].kind``).

Units are SI (m, s, rad, N) as everywhere in uvsym; only keys ending in ``_deg`` take degrees.
The shipped examples (``uvsym simulate --list``) document every field.
"""

from __future__ import annotations

import difflib
import math
import re
import tomllib
from copy import deepcopy
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from uvsym.codegen.cache import memoized
from uvsym.diagnosis.settings import DiagnosisSettings
from uvsym.errors import (
    DiagnosisError,
    FaultError,
    KinematicsError,
    ModelError,
    ObserverError,
    ScenarioError,
    UnknownNameError,
)
from uvsym.faults import ACTUATOR_KINDS, PROFILES, SENSOR_KINDS, ActuatorFault, Profile, SensorFault, actuator_kind
from uvsym.kinematics import Tzyx
from uvsym.models.model import Model
from uvsym.models.registry import vehicle
from uvsym.observers import FORMS, KINDS, actuator_observer
from uvsym.observers.gains import design_gains
from uvsym.sim.controllers import Autopilot, LineOfSight, Loop
from uvsym.sim.fields import Fields as _Fields  # also imported under this name by derivations
from uvsym.sim.run import MAX_SAMPLES, check_memory
from uvsym.sim.shipped import shipped_scenarios

__all__ = ["Scenario", "ObserverSpec", "load_scenario", "parse_scenario", "read_scenario_file",
           "shipped_scenarios"]

_PROFILE_KEYS = ("profile", "onset", "end", "duration", "rate", "period", "duty")


@dataclass(frozen=True)
class ObserverSpec:
    """An actuator-fault observer to run: kind, form, convergence time constant (s), nominal tau_d."""

    kind: str
    form: str
    time_constant: float
    tau_d: tuple[float, ...] | None


@dataclass(frozen=True)
class Scenario:
    """A validated scenario (see the module docstring); ``model`` is built with the overrides.

    current: mean (V_c m/s, beta_c rad); current_variation: (standard deviation m/s, time
    constant s) of a first-order Gauss-Markov variation of the speed, drawn from ``seed``.
    """

    name: str
    description: str
    model: Model
    duration: float
    step: float
    seed: int
    eta0: np.ndarray
    nu0: np.ndarray
    actuators0: np.ndarray | None
    current: tuple[float, float]
    controller: Autopilot
    actuator_faults: tuple[ActuatorFault, ...]
    sensor_faults: tuple[SensorFault, ...]
    observers: tuple[ObserverSpec, ...]
    current_variation: tuple[float, float] = (0.0, 10.0)
    diagnosis: DiagnosisSettings | None = None


def read_scenario_file(path) -> dict:
    """The parsed TOML table of the scenario file ``path``; ScenarioError when it cannot be read or parsed."""
    path = Path(path)
    return _table(path, _content(path))


def _content(path: Path) -> bytes:
    """The bytes of a scenario file; ScenarioError naming ``path`` when it cannot be read."""
    try:
        return path.read_bytes()
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot be read: {exc}") from None


def _table(path: Path, content: bytes) -> dict:
    """The parsed TOML table of a scenario file's bytes (UTF-8, as TOML is); ScenarioError naming ``path``."""
    try:
        return tomllib.loads(content.decode())
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: not valid TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise ScenarioError(f"{path}: cannot be read: {exc}") from None


def load_scenario(source) -> Scenario:
    """Read and validate a scenario from a TOML file path or the name of a shipped example.

    The file is read on every call; its validation is memoized in-process by path and content (a
    changed file is validated again). Each call returns its own initial-state arrays and controller
    (the model is the library's, shared as :func:`~uvsym.models.registry.vehicle` shares it).
    """
    path = Path(source)
    if not path.exists():
        shipped = shipped_scenarios()
        if str(source) not in shipped:
            raise UnknownNameError(f"no scenario file {source!r} and no shipped scenario of that name; "
                                   f"shipped: {', '.join(shipped)}")
        path = shipped[str(source)]
    scenario = _validated(str(path), _content(path))
    return replace(scenario, eta0=scenario.eta0.copy(), nu0=scenario.nu0.copy(),
                   actuators0=None if scenario.actuators0 is None else scenario.actuators0.copy(),
                   controller=deepcopy(scenario.controller))


@memoized(32)
def _validated(path: str, content: bytes) -> Scenario:
    """The scenario of a file's bytes, validated (memoized: the same file loaded again is not re-validated)."""
    return parse_scenario(_table(Path(path), content), default_name=Path(path).stem)


def parse_scenario(data: dict, default_name: str = "scenario", schema: dict | None = None) -> Scenario:
    """Validate a scenario given as a dict (the parsed TOML); ``schema`` collects the fields read
    (:func:`scenario_schema`)."""
    top = _Fields(data, "", schema)
    top.describe("name", "string", "", "the file's name")
    name = top.label("name", default_name, spaces=True)
    description = top.text("description", "")
    if "vehicle" not in data:
        near = difflib.get_close_matches("plant", [str(k) for k in data], n=1, cutoff=0.7)
        raise ScenarioError("vehicle: missing; a vehicle scenario names its vehicle (vehicle = NAME), a scenario "
                            "over any other System its plant (plant = NAME or module:function; see uvsym models)"
                            + (f"; is {near[0]!r} a misspelt 'plant'?" if near else top._misspelt("vehicle")))
    vehicle_name = top.text("vehicle")
    overrides = top.raw("vehicle_parameters", {}, "table", "parameter = value overrides (uvsym models show VEHICLE)")
    if not isinstance(overrides, dict):
        raise ScenarioError("vehicle_parameters: expected a table of parameter = value")
    try:
        model = vehicle(vehicle_name, **overrides)
    except (ModelError, UnknownNameError) as exc:
        raise ScenarioError(f"vehicle: {exc}") from None
    dof, m = model.dof, model.n_inputs
    duration, step = top.number("duration", positive=True), top.number("step", positive=True)
    observer_items = data.get("observers", [])
    _check_size(duration, step, model, len(observer_items) if isinstance(observer_items, list) else 0)
    if abs(round(duration / step) * step - duration) > 1e-9 * duration:
        raise ScenarioError(f"step: {step} s does not divide duration {duration} s")
    seed = top.raw("seed", 0, "integer", ">= 0 (noise and current draws)")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise ScenarioError(f"seed: expected a non-negative integer, got {seed!r}")

    initial = top.table("initial") or top.empty("initial")
    eta0 = initial.vector("eta", dof, [0.0] * dof)
    if dof == 6:
        try:
            Tzyx(eta0[3], eta0[4])
        except KinematicsError as exc:
            raise ScenarioError(f"initial.eta: theta (entry 5): {exc}") from None
    nu0 = initial.vector("nu", dof, [0.0] * dof)
    actuators0 = initial.vector("actuators", m)
    initial.done()

    current = top.table("current") or top.empty("current")
    V_c = current.number("speed", 0.0, minimum=0.0)
    beta_c = math.radians(current.number("direction_deg", 0.0))
    variation = (current.number("speed_std", 0.0, minimum=0.0), current.number("time_constant", 10.0, positive=True))
    current.done()

    top.describe("controller", "table", "the loops and the path")
    controller = _controller(top.table("controller"), model)
    actuator_faults, sensor_faults = fault_tables(top.tables("faults"), model.input_labels, model.state_labels,
                                                  duration)
    observers = _observers(top.tables("observers"), model)
    diagnosis = _diagnosis(top.table("diagnosis"), model, observers, sensor_faults, duration, step)
    top.done()
    return Scenario(name=name, description=description, model=model, duration=duration, step=step, seed=seed,
                    eta0=eta0, nu0=nu0, actuators0=actuators0, current=(V_c, beta_c),
                    current_variation=variation, controller=controller,
                    actuator_faults=actuator_faults, sensor_faults=sensor_faults, observers=observers,
                    diagnosis=diagnosis)


def _loop(fields: _Fields | None) -> Loop | None:
    if fields is None:
        return None
    defaults = Loop(reference=0.0, kp=0.0)
    kwargs = {"reference": fields.number("reference"), "kp": fields.number("kp")}
    for key in ("ki", "kd", "feedforward", "kp_inner", "theta_max"):
        kwargs[key] = fields.number(key, getattr(defaults, key))
    kwargs["i_limit"] = fields.number("i_limit", 1e12, positive=True)
    fields.done()
    return Loop(**kwargs)


def _controller(fields: _Fields | None, model: Model) -> Autopilot:
    if fields is None:
        raise ScenarioError("controller: required table is missing")
    speed, heading, depth = _loop(fields.table("speed")), _loop(fields.table("heading")), _loop(fields.table("depth"))
    path = None
    path_fields = fields.table("path")
    if path_fields is not None:
        points = path_fields.raw("waypoints", None, "list of [north, east] pairs", "finite, m")
        if not isinstance(points, list) or not all(isinstance(p, list) and len(p) == 2 for p in points):
            raise ScenarioError("controller.path.waypoints: expected a list of [north, east] pairs (m)"
                                + ("" if points is not None else path_fields._misspelt("waypoints")))
        for i, point in enumerate(points):
            for j, v in enumerate(point):
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                    raise ScenarioError(f"controller.path.waypoints[{i}][{j}]: expected a finite number (m), "
                                        f"got {v!r}")
        path = LineOfSight(tuple(tuple(float(v) for v in p) for p in points),
                           lookahead=path_fields.number("lookahead", 10.0, positive=True),
                           acceptance=path_fields.number("acceptance", 2.0, minimum=0.0),
                           turn_radius=path_fields.number("turn_radius", 0.0, minimum=0.0))
        path_fields.done()
    fields.describe("outputs", "table", "which inputs each loop drives")
    outputs_fields = fields.table("outputs")
    if outputs_fields is None:
        raise ScenarioError("controller.outputs: required table is missing (which inputs each loop drives)")
    outputs_fields.describe("<loop>", "table", "speed, yaw or pitch = {input label = weight, ...}: the inputs "
                            "the loop drives")
    outputs = {}
    for channel in list(outputs_fields.data):
        mix = _Fields(outputs_fields.data[channel], f"controller.outputs.{channel}")  # its keys are data
        outputs_fields.used.add(channel)
        outputs[channel] = {label: mix.number(label) for label in list(mix.data)}
    model_based = fields.raw("model_based", False, "boolean")
    if not isinstance(model_based, bool):
        raise ScenarioError(f"controller.model_based: expected true or false, got {model_based!r}")
    fields.done()
    autopilot = Autopilot(speed=speed, heading=heading, depth=depth, path=path, outputs=outputs,
                          model_based=model_based)
    autopilot.check(model.input_labels, model.dof)
    return autopilot


def _profile(fields: _Fields) -> Profile:
    defaults = Profile()
    kwargs = {"kind": fields.text("profile", "step", choices=PROFILES)}
    fields.describe("end", "number", "> onset, s: the fault stops (faults that come and go)", "none")
    fields.describe("duty", "number", "in (0, 1]: the fraction of each period the fault is on", "0.5")
    for key in _PROFILE_KEYS[1:]:
        if key != "end" or fields.has(key):
            kwargs[key] = fields.number(key, getattr(defaults, key), positive=key in ("duration", "rate", "period"),
                                        minimum=0.0 if key == "onset" else None)
    return Profile(**kwargs)


def fault_tables(items: list[_Fields], inputs: tuple[str, ...], outputs: tuple[str, ...], duration: float,
                 owner: str = "the vehicle"):
    """(actuator faults, sensor faults) of ``[[faults]]`` tables: ``actuator`` names one of ``inputs``,
    ``sensor`` one of ``outputs``. ScenarioError naming the field of one that is malformed or can never
    act (onset outside [0, duration), a value that changes nothing, a negative factor)."""
    actuator, sensor = [], []
    for fields in items:
        fields.describe("actuator", "string", f"an input of {owner} (an actuator fault)", "one of the two")
        fields.describe("sensor", "string", f"a measured signal of {owner} (a sensor fault)", "one of the two")
        fields.describe("kind", "string", f"with actuator: {', '.join(ACTUATOR_KINDS)}; with sensor: "
                                          f"{', '.join(SENSOR_KINDS)}")
        try:
            if fields.has("actuator"):
                label = fields.text("actuator", choices=inputs)
                kind = fields.text("kind", choices=tuple(ACTUATOR_KINDS))
                fault = ActuatorFault(inputs.index(label), kind, fields.number("value"), _profile(fields))
                _check_actuator_value(fields, fault)
                actuator.append(fault)
            elif fields.has("sensor"):
                label = fields.text("sensor", choices=outputs)
                kind = fields.text("kind", choices=tuple(SENSOR_KINDS))
                value = fields.number("value", 0.0 if kind == "stuck" else None)
                sensor.append(SensorFault(outputs.index(label), kind, value, _profile(fields)))
                fault = sensor[-1]
            else:
                raise ScenarioError(f"{fields.path}: give either actuator = <input of {owner}> or sensor = "
                                    f"<measured signal of {owner}>")
        except FaultError as exc:
            raise ScenarioError(f"{fields.path}.{_fault_field(str(exc))}: {exc}") from None
        if not 0.0 <= fault.profile.onset < duration:
            raise ScenarioError(f"{fields.path}.onset: {fault.profile.onset:g} s is outside the run [0, {duration:g}) "
                                "s; the fault would never act")
        fields.done()
    return tuple(actuator), tuple(sensor)


def _fault_field(message: str) -> str:
    """The field of a fault table that a FaultError's message is about (its profile parameter, else value)."""
    if message.startswith("unknown fault profile"):
        return "profile"
    named = re.search(r"fault profile (\w+)", message)
    return named.group(1) if named else "value"


def _check_actuator_value(fields: _Fields, fault: ActuatorFault) -> None:
    kind = fault.kind_object
    if kind.name == "proportional" and fault.value < 0.0:
        raise ScenarioError(f"{fields.path}.value: a proportional factor scales what the actuator delivers (1 "
                            f"healthy, 0 dead); {fault.value:g} would reverse it")


def _observers(items: list[_Fields], model: Model) -> tuple[ObserverSpec, ...]:
    """The observers, one per kind; ScenarioError naming the field of a duplicate or of a nominal tau_d
    that is missing or leaves every channel unobservable."""
    specs: dict[str, tuple[str, ObserverSpec]] = {}
    for fields in items:
        kind = fields.text("kind", choices=KINDS)
        if kind in specs:
            raise ScenarioError(f"{fields.path}.kind: a {kind} observer is already listed ({specs[kind][0]}); "
                                "each kind runs once")
        spec = ObserverSpec(kind=kind, form=fields.text("form", "paper", choices=FORMS),
                            time_constant=fields.number("time_constant", positive=True),
                            tau_d=None if not fields.has("tau_d") else tuple(fields.vector("tau_d", model.dof)))
        fields.done()  # a misspelt key is named before the design reads a default in its place
        if actuator_kind(kind).scales and spec.tau_d is None:
            raise ScenarioError(f"{fields.path}.tau_d: the {kind} observer's gain design needs a nominal tau_d")
        try:
            design_gains(actuator_observer(model, kind, spec.form), spec.time_constant, spec.tau_d)
        except ObserverError as exc:
            raise ScenarioError(f"{fields.path}.tau_d: {exc}") from None
        specs[kind] = (fields.path, spec)
    return tuple(spec for _, spec in specs.values())


def _diagnosis(fields: _Fields | None, model: Model, observers: tuple[ObserverSpec, ...],
               sensor_faults: tuple[SensorFault, ...], duration: float, step: float) -> DiagnosisSettings | None:
    """The continuous actuator diagnosis (:class:`~uvsym.diagnosis.DiagnosisSettings`), or None
    without a [diagnosis] table. Sensor noise defaults to the scenario's own noise faults that act
    for the whole run (the sensors' specification)."""
    if fields is None:
        return None
    name = fields.text("observer", DiagnosisSettings().observer, choices=("bias",))
    if name not in [observer.kind for observer in observers]:
        raise ScenarioError("diagnosis.observer: the diagnosis reads the bias observer's estimate, and the scenario "
                            "runs none; add [[observers]] with kind = \"bias\"")
    return diagnosis_settings(fields, model, name, whole_run_noise(sensor_faults, model.state_labels), duration, step)


def whole_run_noise(sensor_faults, labels: tuple[str, ...]) -> dict[str, float]:
    """Measured channel -> standard deviation of the Gaussian noise faults acting for the whole run (the
    sensors' specification), from sensor faults indexing ``labels``."""
    return {labels[f.channel]: f.value for f in sensor_faults
            if f.kind == "noise" and f.profile.onset == 0.0 and math.isinf(f.profile.end)}


def diagnosis_settings(fields: _Fields, model: Model, observer: str, noise: dict[str, float], duration: float,
                       step: float) -> DiagnosisSettings:
    """The :class:`~uvsym.diagnosis.DiagnosisSettings` of a table (every field but ``observer``, given),
    for a run of ``duration`` s sampled every ``step`` s; noise: measured channel -> standard deviation
    the table's ``noise`` defaults to. ScenarioError naming the field."""
    defaults = DiagnosisSettings()
    lists = {}
    rules = {"kinds": "fault kinds: " + ", ".join(ACTUATOR_KINDS),
             "actuators": "the vehicle's input labels (none: all)"}
    for key, known in (("kinds", ACTUATOR_KINDS), ("actuators", model.input_labels)):
        value = fields.raw(key, list(getattr(defaults, key)), "list of strings", rules[key])
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise ScenarioError(f"{fields.path}.{key}: expected a list of names, got {value!r}")
        for item in value:
            if item not in known:
                near = difflib.get_close_matches(item, list(known), n=1)
                raise ScenarioError(f"{fields.path}.{key}: unknown name {item!r}" + (f" (did you mean {near[0]!r}?)"
                                    if near else "") + f"; known: {', '.join(known)}")
        lists[key] = tuple(value)
    numbers = {key: fields.number(key, getattr(defaults, key), positive=True)
               for key in ("window_s", "min_window_s", "isolation_window_s", "period_s", "resolution", "floor")}
    for key in ("false_alarm_rate", "isolation_error_rate"):  # probabilities, checked by DiagnosisSettings
        numbers[key] = fields.raw(key, getattr(defaults, key), "number", "in (0, 1), per test")
    confirm = fields.raw("confirm", defaults.confirm, "integer", ">= 1 (decisions)")
    correct = fields.raw("correct", defaults.correct, "boolean", "feed identified faults back as a correction")
    noise_fields = fields.table("noise")
    fields.describe("noise.<channel>", "number", "standard deviation of a measured channel's noise",
                    "the scenario's noise faults")
    if noise_fields is not None:
        noise = {channel: noise_fields.number(channel, minimum=0.0) for channel in list(noise_fields.data)}
        for channel in noise:
            if channel not in model.state_labels:
                raise ScenarioError(f"{fields.path}.noise.{channel}: unknown measured channel; known: "
                                    f"{', '.join(model.state_labels)}")
    fields.done()
    if numbers["window_s"] >= duration:
        raise ScenarioError(f"{fields.path}.window_s: {numbers['window_s']:g} s is not shorter than the run "
                            f"({duration:g} s): no window would ever be tested")
    if abs(numbers["period_s"] / step - round(numbers["period_s"] / step)) > 1e-9 or numbers["period_s"] < step:
        raise ScenarioError(f"{fields.path}.period_s: {numbers['period_s']:g} s is not a whole number of steps "
                            f"({step:g} s)")
    try:
        return DiagnosisSettings(observer=observer, confirm=confirm, correct=correct, noise=noise, **lists, **numbers)
    except DiagnosisError as exc:  # its message names the field as diagnosis.<field>
        raise ScenarioError(str(exc).replace("diagnosis.", f"{fields.path}.", 1)) from None


def _check_size(duration: float, step: float, model: Model, n_observers: int) -> None:
    """ScenarioError naming ``step`` or ``duration`` when the run's samples cannot be held: more than
    MAX_SAMPLES, or more bytes than the machine has (a lower bound: true and measured states, five
    input-sized command signals, the sensor faults, tau_d and each observer's estimates)."""
    samples = duration / step + 1
    field = "step" if step < 1e-6 else "duration"
    what = f"{field}: {duration:g} s at step {step:g} s ({samples:.3g} samples)"
    if not samples < MAX_SAMPLES:
        raise ScenarioError(f"{what} is more than {MAX_SAMPLES:.0e} samples; shorten the run or lengthen the step")
    per_sample = 3 * 2 * model.dof + 5 * model.n_inputs + model.dof * (1 + n_observers)
    check_memory(8 * int(samples) * per_sample, what, ScenarioError)
