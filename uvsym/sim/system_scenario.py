"""Scenarios over any System: a TOML file names the plant, the blocks wired by signal name, the
faults, noise, set-points and detectors. Every field is checked before anything runs; an error
names it (``blocks[1].decay``), with the close match of a misspelt key or name.

Top-level fields: ``plant`` (a registered plant or vehicle, ``uvsym models``; or
``module:function`` returning a System, the module imported from ``plant_path``, default the
scenario file's folder), ``[plant_parameters]`` (keyword arguments of the plant's builder),
``duration`` and ``step`` (s), ``substeps`` (RK4 steps per sample), ``rk4_tolerance`` (the fast
path's local error per sample, relative to each state's scale, checked by step doubling on sampled
steps, :mod:`uvsym.sim.step_error`; default 1e-4, false: not checked), ``seed`` (noise draws),
``[initial]`` (``x``: a list or a table of state = value; default the plant's operating point;
``d``: constant disturbances), ``[[disturbances]]`` (``signal`` = a disturbance name, ``times`` s,
``values``, ``interpolation`` "previous" or "linear": its schedule, sampled at every step and held
over it, instead of its constant), ``[noise]`` (output = standard deviation of Gaussian noise, or
output = ``{ uniform = bound }`` for noise uniform in ``[-bound, bound]``: the sensors'
specification, acting the whole run; the threshold calibration linearises the noise at its draw 0,
so it takes uniform noise for Gaussian noise of standard deviation ``bound sqrt(2 / pi)``, above
its true ``bound / sqrt 3``; disturbance = the same, a random disturbance drawn every sample,
held over it and added to ``d``: :class:`DisturbanceNoise`, seeded by ``disturbance_seed``,
default the stream ``(seed, 1)``, independent of the sensor noise), ``[[setpoints]]``
(``signal``, ``times`` s, ``values``, ``interpolation``: a schedule published as ``signal``),
``[[blocks]]`` (controllers and estimators, :mod:`uvsym.sim.catalogue`), ``[[faults]]`` (``actuator`` = an input name or
``sensor`` = an output name, ``kind``, ``value`` and the profile fields of vehicle scenarios),
``[substitutions]`` (``channel = { by = "signal", when = "flag signal" }``: while the flag is set
every block reading channel reads the substitute, from the next sample; a ``select`` block
switches in the same sample) and ``[[detectors]]``:

- ``type = "threshold"``: ``residuals`` (signal names ``<block>.<signal>``), ``targets`` (the
  input or output each points to), ``isolate`` (the residuals are structured, so the largest one
  isolates its target; default false: detection only, :mod:`uvsym.diagnosis.detectors`),
  ``false_alarms_per_hour`` (designed rate, default 1),
  ``thresholds`` (given, in the residuals' units, instead of designed: a calibration of one's own),
  ``std`` (the residuals' standard deviations; default computed from ``[noise]`` through the loop
  linearised at the plant's operating point, :mod:`uvsym.diagnosis.calibration`), ``confirm`` and
  ``release`` (samples), ``latch`` (a detection stands to the end: ``cleared`` only says the
  residuals are back inside, which an observer absorbing a constant bias gives while the fault
  persists), ``ignore_before`` (s);
- ``type = "lms"``: ``monitor`` (an lms block's name): its double criterion's decisions, and a
  StepSizeWarning when the block's mu is at or beyond the mean-square bound of the run's input power;
- ``type = "sensor_step"``: ``monitor`` (a sensor_step block's name): its confirmed steps as
  ``detected``, ``isolated`` and ``identified`` (the offset), ``cleared`` when the offset is back
  to zero (:class:`~uvsym.diagnosis.detectors.StepDecision`);
- ``type = "zonotope_bands"``: ``bank`` (a uio_bank block's name), ``noise_bound`` and
  ``initial_error`` (the stated bounds), ``generators``, ``reduction``, ``horizon``,
  ``isolation_window``, ``release``: band exits of the bank, isolation by their pattern
  (:mod:`uvsym.diagnosis.zonotope_bands`).
- ``type = "hybrid"``: the fields of ``threshold`` (``targets`` required; ``thresholds``, in the
  residuals' units, replace the designed ones when given) and ``estimate`` (a fault estimate,
  ``<block>.f_<sensor>_hat`` of a hybrid block), ``estimate_gain`` (the sensor's fault direction:
  the identified offset is gain x estimate), ``identify_after`` and ``average`` (s): ``identified``
  with the mean estimate ``identify_after`` s after each detection.
- ``type = "mmae"``: ``bank`` (an mmae block's name), ``threshold`` (probability, default 0.9),
  ``dwell`` (samples, default 1), ``settle`` (samples, default 20) and ``resolution`` (default
  0.02: an efficiency estimate is published where it stays within it over settle samples),
  ``ignore_before`` (s), ``kind`` (default proportional): the
  bank's hypothesis switches (:mod:`uvsym.diagnosis.hypotheses`); ``rule = "evidence"`` instead
  (the default ``"posterior"`` is the paper's): CUSUM detection, windowed release and an NIS test
  (``unexplained``) with thresholds from ``false_alarms_per_hour`` (default 1), ``clear_window``
  and ``nis_window`` (samples, default 60 and 20).
- ``type = "fault_diagnosis"``: ``observer`` (an actuator_observer block of kind bias, on a
  vehicle plant) and the fields of a vehicle scenario's [diagnosis] table but ``correct``: the
  continuous actuator diagnosis on the finished record (:mod:`uvsym.diagnosis.wired`).

Units are SI (m, s, rad, N, A, V) as everywhere in uvsym.
"""

from __future__ import annotations

import difflib
import importlib
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from uvsym.codegen.cache import memoized
from uvsym.diagnosis.detectors import DoubleCriterion, EstimatedFault, ResidualThreshold, StepDecision
from uvsym.errors import ScenarioError, UvsymError
from uvsym.errors import did_you_mean as _close
from uvsym.faults import ActuatorFault, SensorFault
from uvsym.sim.blocks import Block
from uvsym.sim.catalogue import _names, build_block, schedule
from uvsym.sim.fields import Fields
from uvsym.sim.result import SimResult
from uvsym.sim.run import Substitution
from uvsym.sim.scenario import fault_tables
from uvsym.sim.step_error import TOLERANCE
from uvsym.sim.system_simulation import initial_state, loop_inputs
from uvsym.sim.wiring import WiredLoop, interconnect
from uvsym.systems.system import System

__all__ = ["SystemScenario", "FlagSubstitution", "DisturbanceNoise", "parse_system_scenario", "is_system_scenario",
           "simulate_system_scenario", "parse_any_scenario", "simulate_any_scenario", "DETECTORS"]

def is_system_scenario(table: dict) -> bool:
    """True for a scenario table over a System (it names ``plant``), False for a vehicle scenario."""
    return "plant" in table


@dataclass(frozen=True)
class FlagSubstitution:
    """Supervisor (:class:`uvsym.sim.run.Supervisor`): every sample, the channels whose flag signal
    (``<block>.<label>``) is set (> 0.5) are substituted from the next sample on."""

    flags: tuple[tuple[str, str, int], ...]  # (channel, block, column of the block's published row)
    period: float

    def update(self, t: np.ndarray, signals: dict[str, np.ndarray]) -> Substitution:
        return Substitution({channel for channel, group, column in self.flags if signals[group][-1, column] > 0.5})


@dataclass(frozen=True)
class SystemScenario:
    """A validated scenario over a System (module docstring): the wired ``loop``, its initial state
    z0 (n_z,), disturbances d (constant (n_d,) or one row per sample (N + 1, n_d)), faults (their
    indices into the plant's inputs and outputs), the substitution supervisor (None without
    substitutions) and the detectors."""

    name: str
    description: str
    plant: System
    duration: float
    step: float
    seed: int
    loop: WiredLoop
    z0: np.ndarray
    d: np.ndarray
    actuator_faults: tuple[ActuatorFault, ...]
    sensor_faults: tuple[SensorFault, ...]
    supervisor: FlagSubstitution | None
    detectors: tuple
    substitutions: dict
    disturbance_noise: DisturbanceNoise | None = None
    rk4_tolerance: float | None = TOLERANCE

    @property
    def input_labels(self) -> tuple[str, ...]:
        return self.plant.u.names

    @property
    def output_labels(self) -> tuple[str, ...]:
        return self.plant.y.names


@dataclass(frozen=True)
class DisturbanceNoise:
    """Random disturbances drawn every sample and held over it, added to ``d``: ``bound U(-1, 1)`` where
    a bound is given, then ``std N(0, 1)`` where a standard deviation is, (n_d,) each, all columns
    drawn at once from ``numpy.random.default_rng(seed)`` (uniform draws first); the default seed is
    the stream ``(noise seed, 1)``, independent of the sensor noise's."""

    std: np.ndarray
    bound: np.ndarray
    seed: int | tuple[int, int]

    def draws(self, N: int) -> np.ndarray:
        """(N + 1, n_d) draws, one row per sample."""
        rng, shape = np.random.default_rng(self.seed), (N + 1, self.std.size)
        out = np.zeros(shape)
        if self.bound.any():
            out += self.bound * rng.uniform(-1.0, 1.0, size=shape)
        if self.std.any():
            out += self.std * rng.standard_normal(shape)
        return out


def _plant(top: Fields, root: Path) -> System:
    """The plant a scenario names (module docstring); ScenarioError naming ``plant`` or its parameters."""
    from uvsym.systems.registry import plant, plant_names

    source = top.text("plant")
    overrides = top.raw("plant_parameters", {}, "table", "keyword arguments of the plant's builder")
    if not isinstance(overrides, dict):
        raise ScenarioError("plant_parameters: expected a table of name = value")
    folder = top.text("plant_path", str(root))
    if ":" not in source:
        if source not in plant_names():
            raise ScenarioError(f"plant: unknown plant {source!r}{_close(source, plant_names())}; known: "
                                f"{', '.join(plant_names())}; or give module:function returning a System")
        try:
            return plant(source, **overrides)
        except UvsymError as exc:
            raise ScenarioError(f"plant_parameters: {exc}") from None
    return _user_plant(source, folder, overrides)


@memoized(16)
def _user_plant(source: str, folder: str, overrides: dict) -> System:
    """The System ``module:function`` returns for ``overrides``, the module imported from ``folder``;
    memoized in-process (as registered plants are), so that the scenarios of a campaign share one
    plant object and with it their blocks' designs."""
    module_name, _, function = source.partition(":")
    path = Path(folder)
    if not path.is_dir():
        raise ScenarioError(f"plant_path: folder {folder} does not exist")
    if str(path.resolve()) not in sys.path:
        sys.path.insert(0, str(path.resolve()))
    try:
        factory = getattr(importlib.import_module(module_name), function)
    except ImportError as exc:
        raise ScenarioError(f"plant: cannot import module {module_name!r} (searched {path.resolve()} and the "
                            f"installed packages): {exc}") from None
    except AttributeError:
        raise ScenarioError(f"plant: module {module_name!r} has no function {function!r}") from None
    if not callable(factory):
        raise ScenarioError(f"plant: {source} is a {type(factory).__name__}, not a function returning a System")
    try:
        built = factory(**overrides)
    except UvsymError as exc:
        raise ScenarioError(f"plant: {source}: {exc}") from None
    except TypeError as exc:
        raise ScenarioError(f"plant_parameters: {source} refuses them: {exc}") from None
    if not isinstance(built, System):
        raise ScenarioError(f"plant: {source} returned {type(built).__name__}, not a uvsym System")
    return built


def _rk4_tolerance(top: Fields) -> float | None:
    """``rk4_tolerance``: the fast path's step-error tolerance (:mod:`uvsym.sim.step_error`), or false."""
    value = top.raw("rk4_tolerance", TOLERANCE, "number or false",
                    "> 0: local error per sample checked by step doubling (relative to each state's scale); "
                    "false: not checked")
    if value is False:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (np.isfinite(value) and value > 0):
        raise ScenarioError(f"rk4_tolerance: expected a positive number or false, got {value!r}")
    return float(value)


def _point(fields: Fields, key: str, group, default: np.ndarray) -> np.ndarray:
    """A vector of the group's signals: a list in order, or a table name = value (others default)."""
    value = fields.raw(key, None, "list or table", f"one value per {group.group} ({', '.join(group.names)})")
    if value is None:
        return np.array(default, dtype=float)
    if isinstance(value, dict):
        vector = np.array(default, dtype=float)
        for name in value:
            if name not in group.names:
                raise ScenarioError(f"{fields._name(key)}.{name}: unknown {group.group}{_close(name, group.names)}; "
                                    f"known: {', '.join(group.names)}")
            vector[group.index(name)] = Fields(value, fields._name(key)).number(name)
        return vector
    return Fields({key: value}, fields.path).vector(key, group.size)


def _noise(fields: Fields, channel: str) -> tuple[str, float]:
    """(sensor fault kind, value) of one [noise] entry: a standard deviation, or ``{ uniform = bound }``."""
    if not isinstance(fields.data[channel], dict):
        return "noise", fields.number(channel, positive=True)
    entry = fields.table(channel)
    if not entry.has("uniform"):
        entry.done()  # an unknown key is named first, with its close match
    bound = entry.number("uniform", positive=True)
    entry.done()
    return "uniform_noise", bound


def _faults(items: list[Fields], plant: System, duration: float, noise: dict[str, tuple[str, float]]):
    """The [[faults]] (:func:`uvsym.sim.scenario.fault_tables` over the plant's inputs and outputs),
    the [noise] channels first as whole-run noise faults."""
    schema = items and items[0].schema is not None
    actuator, sensor = fault_tables(items, plant.u.names, plant.y.names, duration,
                                    "the plant" if schema else plant.name)
    return actuator, tuple(SensorFault(plant.y.index(name), *spec) for name, spec in noise.items()) + sensor


def _disturbances(items: list[Fields], plant: System, d: np.ndarray, N: int, step: float) -> np.ndarray:
    """The [[disturbances]] schedules (module docstring) over the samples ``k step``, k = 0..N: (N + 1,
    n_d) with the other disturbances at their constants d (n_d,); d itself without schedules."""
    from uvsym.sim.feedback import INTERPOLATIONS, open_loop

    if not items:
        return d
    schedules = []
    for fields in items:
        fields.describe("signal", "string", "one of the plant's disturbances")
        signal = fields.text("signal", choices=plant.d.names)
        given = fields.data.get("times")
        times = fields.vector("times", len(given)) if isinstance(given, list) and given else None
        if times is None or np.any(np.diff(times) <= 0):
            raise ScenarioError(f"{fields.path}.times: expected strictly increasing times (s), one per value, "
                                f"got {given!r}")
        values = fields.vector("values", times.size)
        how = fields.text("interpolation", "previous", choices=INTERPOLATIONS)
        fields.done()
        open_loop(f"disturbance_{signal}", times, values, (signal,), how)  # its checks: a set-point's table
        schedules.append((plant.d.index(signal), times, values.reshape(-1, 1), how))
    return _scheduled(d, tuple(schedules), N, step)


@memoized(8)
def _scheduled(d: np.ndarray, schedules: tuple, N: int, step: float) -> np.ndarray:
    """(N + 1, n_d) read-only: the constants d with each schedule (column, times, values (k, 1), interpolation)
    at the samples k step; shared by the runs of a campaign that schedule alike."""
    from uvsym.sim.feedback import table_value

    table, t = np.tile(d, (N + 1, 1)), step * np.arange(N + 1)
    for column, times, values, how in schedules:
        table[:, column] = table_value(t, times, values, how)[:, 0]
    table.flags.writeable = False
    return table


def _setpoint(fields: Fields, plant: System) -> Block:
    """A [[setpoints]] table: the schedule of one signal, as the block ``setpoint_<signal>``; memoized by
    the table's content (as catalogue blocks are), so that the runs of a campaign share their loop."""
    if fields.schema is not None:
        return _schedule_block(fields, plant)
    return _setpoint_block(fields.data, fields.path, plant)


@memoized(64)
def _setpoint_block(data: dict, path: str, plant: System) -> Block:
    return _schedule_block(Fields(data, path), plant)


def _told_noise(fields: Fields, noise: dict[str, tuple[str, float]]) -> Fields:
    """A sensor_step block's table with ``noise_std`` defaulting to its measured output's [noise]
    standard deviation (Gaussian entries only; the user's table is not changed)."""
    data = fields.data
    if (data.get("type") != "sensor_step" or "noise_std" in data
            or not isinstance(data.get("measured"), str) or noise.get(data["measured"], ("", 0))[0] != "noise"):
        return fields
    return Fields({**data, "noise_std": noise[data["measured"]][1]}, fields.path, fields.schema)


def _schedule_block(fields: Fields, plant: System) -> Block:
    signal = fields.text("signal")
    block = schedule(fields, plant, f"setpoint_{signal}", (signal,))
    fields.done()
    return block


def _substitutions(fields: Fields | None) -> tuple[dict[str, str], dict[str, str]]:
    """(channel -> substitute, channel -> flag signal) of a [substitutions] table."""
    if fields is None:
        return {}, {}
    fields.describe("<channel>", "table", "{ by = substitute signal, when = flag signal (0/1) }")
    by, when = {}, {}
    for channel in list(fields.data):
        entry = Fields(fields.data[channel], fields._name(channel))
        fields.used.add(channel)
        by[channel], when[channel] = entry.text("by"), entry.text("when")
        entry.done()
    return by, when


def _check_monitor(fields: Fields, monitor: str, blocks: dict, flag: str, what: str, listed: str) -> None:
    """ScenarioError naming ``monitor`` unless it is a block publishing ``<flag><its measured signal>``."""
    if monitor in blocks and f"{flag}{blocks[monitor].reads.names[0]}" in blocks[monitor].publishes.names:
        return
    known = [b for b in blocks if any(n.startswith(flag) for n in blocks[b].publishes.names)]
    raise ScenarioError(f"{fields.path}.monitor: {monitor!r} is not {what} of the scenario{_close(monitor, known)}; "
                        f"{listed}: {', '.join(known) or 'none'}")


def _lms_detector(fields: Fields, name: str, scenario_loop: WiredLoop, z0: np.ndarray, w0: np.ndarray,
                  step: float) -> DoubleCriterion:
    """``type = "lms"``: the double criterion of the lms block named ``monitor``."""
    monitor = fields.text("monitor")
    blocks = {b.name: b for b in scenario_loop.blocks}
    _check_monitor(fields, monitor, blocks, "R_", "an lms block", "lms blocks")
    block, regressor = blocks[monitor], logged_input(blocks[monitor].reads.names[1], scenario_loop)
    order = sum(n.startswith("C_") for n in block.state.names)  # the filter's weights C_1 .. C_M
    return DoubleCriterion(name, monitor, block.reads.names[0], block.description, block.parameters, regressor,
                           order)


def _step_detector(fields: Fields, name: str, scenario_loop: WiredLoop, z0: np.ndarray, w0: np.ndarray,
                   step: float) -> StepDecision:
    """``type = "sensor_step"``: the decisions of the sensor_step block named ``monitor``."""
    monitor = fields.text("monitor")
    blocks = {b.name: b for b in scenario_loop.blocks}
    _check_monitor(fields, monitor, blocks, "confirmed_", "a sensor_step block", "sensor_step blocks")
    return StepDecision(name, monitor, blocks[monitor].reads.names[0], blocks[monitor].description)


def logged_input(name: str, scenario_loop: WiredLoop) -> str:
    """The logged signal a block's read ``name`` of an input is: as given when qualified, else
    ``<block>.<name>`` of the block that publishes it, else the plant input ``u.<name>``."""
    if "." in name:
        return name
    return next((f"{b.name}.{name}" for b in scenario_loop.blocks if name in b.publishes.names), f"u.{name}")


def _logged(name: str, scenario_loop: WiredLoop, where: str) -> str:
    """The logged signal ``<group>.<label>`` a detector's ``name`` reads: qualified as given, or a bare
    label that one group logs (ScenarioError naming the qualified choices when several do, and the
    close matches when none does)."""
    logged = [f"{g}.{label}" for g, entry in scenario_loop.signals.items()
              if g not in ("fault_sensor", "fault_actuator") for label in entry[1]]
    if name in logged:
        return name
    choices = [q for q in logged if q.split(".", 1)[1] == name] if "." not in name else []
    if len(choices) == 1:
        return choices[0]
    if choices:
        raise ScenarioError(f"{where}: {name!r} is logged by several groups: name one of {', '.join(choices)}")
    near = difflib.get_close_matches(name, logged, n=3)
    raise ScenarioError(f"{where}: no logged signal {name!r}" + (f"; did you mean {' or '.join(map(repr, near))}?"
                                                                 if near else f"; logged: {', '.join(logged)}"))


def _threshold_detector(fields: Fields, name: str, scenario_loop: WiredLoop, z0: np.ndarray, w0: np.ndarray,
                        step: float) -> ResidualThreshold:
    """``type = "threshold"``: residual thresholds designed for a false-alarm rate (module docstring)."""
    from uvsym.diagnosis.calibration import residual_covariance

    residuals = tuple(_logged(name, scenario_loop, f"{fields.path}.residuals") for name in _names(fields, "residuals"))
    targets = fields.raw("targets", None, "list of strings", "the plant input or output each residual points to",
                         "none")
    known = scenario_loop.plant.u.names + scenario_loop.plant.y.names
    if targets is not None:
        targets = [targets] if isinstance(targets, str) else targets
        if not isinstance(targets, list) or len(targets) != len(residuals) or any(t not in known for t in targets):
            raise ScenarioError(f"{fields.path}.targets: expected {len(residuals)} names of the plant's inputs or "
                                f"outputs ({', '.join(known)}), got {targets!r}")
    std = fields.vector("std", len(residuals))
    given = fields.vector("thresholds", len(residuals))
    options = {"false_alarms_per_hour": fields.number("false_alarms_per_hour", 1.0, positive=True),
               "ignore_before": fields.number("ignore_before", 0.0, minimum=0.0)}
    options["isolate"] = fields.raw("isolate", False, "boolean", "the residuals are structured")
    if not isinstance(options["isolate"], bool) or (options["isolate"] and targets is None):
        raise ScenarioError(f"{fields.path}.isolate: expected true (with targets) or false, got "
                            f"{options['isolate']!r}")
    for key, default in (("confirm", 3), ("release", 20)):
        options[key] = fields.integer(key, default, minimum=1, unit="samples")
    options["latch"] = fields.raw("latch", False, "boolean", "a detection stands to the end of the run (no cleared)")
    if not isinstance(options["latch"], bool):
        raise ScenarioError(f"{fields.path}.latch: expected true or false, got {options['latch']!r}")
    fields.done()
    if std is None:
        std = np.sqrt(np.diag(residual_covariance(scenario_loop, z0, w0, residuals)))
        silent = [r for r, s in zip(residuals, std) if not s > 0]
        if silent:
            raise ScenarioError(f"{fields.path}.std: no sensor noise reaches {', '.join(silent)} ([noise] is "
                                "empty for what it depends on): state the residuals' standard deviations")
    return ResidualThreshold(name, residuals, std, step, targets=tuple(targets or ()),
                             given=() if given is None else tuple(given), **options)


def _zonotope_bands(fields: Fields, name: str, scenario_loop: WiredLoop, z0: np.ndarray, w0: np.ndarray,
                    step: float):
    """``type = "zonotope_bands"`` (:mod:`uvsym.diagnosis.zonotope_bands`, imported only for one)."""
    from uvsym.diagnosis.zonotope_bands import zonotope_bands_detector

    return zonotope_bands_detector(fields, name, scenario_loop, z0, w0, step)


def _hybrid_detector(fields: Fields, name: str, scenario_loop: WiredLoop, z0: np.ndarray, w0: np.ndarray,
                     step: float) -> EstimatedFault:
    """``type = "hybrid"``: a threshold test (the fields of ``threshold``) that detects, and the hybrid
    observer's fault estimate that identifies (:class:`~uvsym.diagnosis.detectors.EstimatedFault`)."""
    estimate = _logged(_names(fields, "estimate", size=1)[0], scenario_loop, f"{fields.path}.estimate")
    if estimate.partition(".")[0] in ("x", "u", "y"):
        raise ScenarioError(f"{fields.path}.estimate: {estimate!r} is not a block's published signal "
                            "(<block>.<signal>)")
    options = {"gain": fields.number("estimate_gain", 1.0),
               "identify_after": fields.number("identify_after", 0.5, minimum=0.0),
               "average": fields.number("average", 0.1, minimum=0.0)}
    if not fields.has("targets"):
        raise ScenarioError(f"{fields.path}.targets: required: the sensor each residual points to")
    return EstimatedFault(name, _threshold_detector(fields, name, scenario_loop, z0, w0, step), estimate, **options)


def _fault_diagnosis(fields: Fields, name: str, scenario_loop: WiredLoop, z0: np.ndarray, w0: np.ndarray,
                     step: float):
    """``type = "fault_diagnosis"`` (:mod:`uvsym.diagnosis.wired`, imported only for one)."""
    from uvsym.diagnosis.wired import fault_diagnosis_detector

    return fault_diagnosis_detector(fields, name, scenario_loop, z0, w0, step)


def _mmae(fields: Fields, name: str, scenario_loop: WiredLoop, z0: np.ndarray, w0: np.ndarray, step: float):
    """``type = "mmae"`` (:mod:`uvsym.diagnosis.hypotheses`, imported only for one)."""
    from uvsym.diagnosis.hypotheses import mmae_detector

    return mmae_detector(fields, name, scenario_loop, z0, w0, step)


DETECTORS = {"threshold": _threshold_detector, "lms": _lms_detector, "sensor_step": _step_detector,
             "zonotope_bands": _zonotope_bands,
             "hybrid": _hybrid_detector, "mmae": _mmae, "fault_diagnosis": _fault_diagnosis}


def _detector(fields: Fields, scenario_loop: WiredLoop, z0: np.ndarray, w0: np.ndarray, step: float):
    """The detector a ``[[detectors]]`` table describes: ``DETECTORS[type](fields, name, loop, z0, w0,
    step)``, each builder reading its own fields; ScenarioError naming the field. z0, w0: the point
    detectors calibrate at: the loop at the plant's operating point (its blocks initialised from
    their reads there), the first sample's inputs with the noise draws at 0."""
    kind = fields.text("type", choices=tuple(DETECTORS))
    if fields.schema is not None:  # recording the schema: each type's fields under detectors[<type>]
        fields = Fields(fields.data, f"detectors[{kind}]", fields.schema)
        fields.used.add("type")
    name = fields.label("name", kind)
    try:
        detector = DETECTORS[kind](fields, name, scenario_loop, z0, w0, step)
    except ScenarioError as exc:
        raise ScenarioError(f"{exc}{fields.unread_hint()}") from None
    except UvsymError as exc:
        raise ScenarioError(f"{fields.path} ({name}): {exc}{fields.unread_hint()}") from None
    fields.done()
    return detector


def parse_system_scenario(data: dict, default_name: str = "scenario", root=".",
                          schema: dict | None = None) -> SystemScenario:
    """Validate a scenario over a System given as a dict (the parsed TOML; module docstring) and
    wire its loop; ``root``: the scenario file's folder; ``schema`` collects the fields read."""
    top = Fields(data, "", schema)
    top.describe("name", "string", "the run's name in results and logs", "the file's name")
    top.describe("plant_path", "string", "folder a module:function plant is imported from",
                 "the scenario file's folder")
    name, description = top.label("name", default_name, spaces=True), top.text("description", "")
    plant = _plant(top, Path(root))
    duration, step = top.number("duration", positive=True), top.number("step", positive=True)
    if abs(round(duration / step) * step - duration) > 1e-9 * duration:
        raise ScenarioError(f"step: {step} s does not divide duration {duration} s")
    if duration / step > 1e9:
        raise ScenarioError(f"duration: {duration:g} s at step {step:g} s is more than 1e9 samples")
    substeps = top.integer("substeps", 1, minimum=1, unit="RK4 steps per sample")
    rk4_tolerance = _rk4_tolerance(top)
    seed = top.integer("seed", 0, unit="noise draws")
    initial = top.table("initial") or top.empty("initial")
    initial.describe("x", "list or table", "the plant's states: a list in order, or a table state = value",
                     "the plant's operating point")
    initial.describe("d", "list or table", "constant disturbances: a list in order, or a table name = value",
                     "zeros")
    x0 = _point(initial, "x", plant.x, plant.x_op)
    d = _point(initial, "d", plant.d, np.zeros(plant.d.size))
    initial.done()
    d = _disturbances(top.tables("disturbances"), plant, d, round(duration / step), step)
    disturbance_seed = top.raw("disturbance_seed", None, "integer", ">= 0: the draws of [noise]'s disturbances",
                               "the stream (seed, 1)")
    if disturbance_seed is not None:
        disturbance_seed = top.integer("disturbance_seed", unit="disturbance draws")
    noise_fields = top.table("noise")
    top.describe("noise.<output>", "number or table", "standard deviation of the output's Gaussian sensor noise, "
                 "or { uniform = bound } (its unit)", "none")
    top.describe("noise.<disturbance>", "number or table", "standard deviation of a white Gaussian disturbance, "
                 "or { uniform = bound }, drawn every sample and held over it (its unit)", "none")
    noise, spread = {}, {"noise": np.zeros(plant.d.size), "uniform_noise": np.zeros(plant.d.size)}
    if noise_fields is not None:
        for channel in list(noise_fields.data):
            if channel in plant.d.names:
                kind, value = _noise(Fields(noise_fields.data, noise_fields.path), channel)
                spread[kind][plant.d.index(channel)] = value
                noise_fields.used.add(channel)
                continue
            if channel not in plant.y.names:
                known = plant.y.names + plant.d.names
                raise ScenarioError(f"noise.{channel}: unknown output or disturbance of {plant.name}"
                                    f"{_close(channel, known)}; outputs: {', '.join(plant.y.names)}; disturbances: "
                                    f"{', '.join(plant.d.names) or 'none'}")
            noise[channel] = _noise(Fields(noise_fields.data, noise_fields.path), channel)  # no per-plant rows
            noise_fields.used.add(channel)
    blocks = [_setpoint(f, plant) for f in top.tables("setpoints")]
    blocks += [build_block(_told_noise(f, noise), plant, step) for f in top.tables("blocks")]
    actuator_faults, sensor_faults = _faults(top.tables("faults"), plant, duration, noise)
    by, when = _substitutions(top.table("substitutions"))
    detector_tables = top.tables("detectors")
    top.done()
    try:
        loop = interconnect(plant, blocks, dt=step, actuator_faults=actuator_faults, sensor_faults=sensor_faults,
                            substitutions=by, substeps=substeps)
    except UvsymError as exc:
        raise ScenarioError(f"blocks: {exc}") from None
    flags = []
    for channel, flag in when.items():
        group, _, label = flag.partition(".")
        entry = loop.signals.get(group)
        if entry is None or label not in entry[1] or group in ("x", "y", "u"):
            raise ScenarioError(f"substitutions.{channel}.when: {flag!r} is not a block's published signal "
                                "(<block>.<signal>)")
        flags.append((channel, group, list(entry[1]).index(label)))
    W0 = loop_inputs(loop, 0, d[0] if d.ndim == 2 else d, seed)
    W0[0, 1:1 + plant.y.size] = 0.0
    try:
        z0 = initial_state(loop, x0, W0[0])
    except UvsymError as exc:
        raise ScenarioError(f"initial: {exc}") from None
    names = {b.name for b in blocks}
    detectors = []
    z_op = initial_state(loop, plant.x_op, W0[0]) if detector_tables else None
    for fields in detector_tables:
        detector = _detector(fields, loop, z_op, W0[0], step)
        if detector.name in names:
            raise ScenarioError(f"{fields.path}.name: {detector.name!r} names a block or detector already")
        names.add(detector.name)
        detectors.append(detector)
    return SystemScenario(name=name, description=description, plant=plant, duration=duration, step=step, seed=seed,
                          loop=loop, z0=z0, d=d, actuator_faults=actuator_faults, sensor_faults=sensor_faults,
                          supervisor=FlagSubstitution(tuple(flags), step) if flags else None,
                          detectors=tuple(detectors), substitutions=by, disturbance_noise=DisturbanceNoise(
                              spread["noise"], spread["uniform_noise"],
                              (seed, 1) if disturbance_seed is None else disturbance_seed)
                          if any(v.any() for v in spread.values()) else None, rk4_tolerance=rk4_tolerance)



def simulate_system_scenario(scenario: SystemScenario, *, method: str = "fast", progress=None,
                             compiled: bool = True, options: dict | None = None) -> SimResult:
    """Run a validated :class:`SystemScenario`; every detector then decides on the finished record.

    The result's ``events`` hold every detector's decisions in time order (each names its
    ``detector``), its meta ``detectors`` each detector's design (rule, thresholds, designed rates).
    """
    from uvsym.sim.system_simulation import run_wired

    result = run_wired(scenario.loop, scenario.z0, scenario_inputs(scenario), method=method,
                       supervisor=scenario.supervisor, options=options, compiled=compiled, progress=progress,
                       rk4_tolerance=scenario.rk4_tolerance, **scenario_meta_arguments(scenario))
    return decided(scenario, result)


def scenario_inputs(scenario: SystemScenario, compact: bool = False):
    """W (N + 1, n_w) of the scenario's run (:func:`~uvsym.sim.system_simulation.loop_inputs`; compact as
    it says): its disturbances (constant or scheduled) plus its white disturbance noise, its seeded
    sensor-noise draws and its faults' numbers."""
    N = round(scenario.duration / scenario.step)
    d = scenario.d if scenario.disturbance_noise is None else scenario.d + scenario.disturbance_noise.draws(N)
    return loop_inputs(scenario.loop, N, d, scenario.seed, compact)


def scenario_meta_arguments(scenario: SystemScenario) -> dict:
    """The keyword arguments of :func:`~uvsym.sim.system_simulation.wired_meta` (and ``run_wired``) a
    scenario's run describes itself with: duration, seed, faults, substitutions."""
    return {"duration": scenario.duration, "seed": scenario.seed, "actuator_faults": scenario.actuator_faults,
            "sensor_faults": scenario.sensor_faults, "substitutions": scenario.substitutions}


def decided(scenario: SystemScenario, result: SimResult) -> SimResult:
    """``result`` with every detector's decisions on the finished record in its meta: ``events`` in time
    order (each names its ``detector``), ``detectors`` each detector's design, ``detector_cpu_s`` the
    processor time (s) each took to decide; ``scenario`` its name."""
    decisions, cpu = [], {}
    for detector in scenario.detectors:
        started = time.process_time()
        decisions += detector.decide(result)
        cpu[detector.name] = time.process_time() - started
    events = sorted(decisions, key=lambda e: e.t)
    meta = {"scenario": scenario.name, **result.meta, "events": [e.as_dict() for e in events],
            "detectors": [detector.design() for detector in scenario.detectors], "detector_cpu_s": cpu}
    return SimResult(result.t, result.signals, meta)


def parse_any_scenario(table: dict, default_name: str = "scenario", root="."):
    """The validated scenario of a parsed table: a :class:`SystemScenario` when it names a ``plant``,
    else a vehicle :class:`~uvsym.sim.scenario.Scenario`; root: the file's folder."""
    from uvsym.sim.scenario import parse_scenario

    if is_system_scenario(table):
        return parse_system_scenario(table, default_name=default_name, root=root)
    return parse_scenario(table, default_name=default_name)


def simulate_any_scenario(scenario, **options) -> SimResult:
    """Run either kind of scenario (:func:`simulate_system_scenario` or
    :func:`uvsym.sim.simulation.simulate_scenario`, whose options it passes on)."""
    if isinstance(scenario, SystemScenario):
        return simulate_system_scenario(scenario, **options)
    from uvsym.sim.simulation import simulate_scenario

    return simulate_scenario(scenario, **options)
