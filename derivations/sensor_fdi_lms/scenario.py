"""``uvsym simulate FILE.toml`` with ``study = "sensor-fdi-lms"``: any fault, onset, size, sensor and profile.

Tables and fields (all optional; without a ``[fault]`` table the run has no fault; a ``[fault]``
table's fields default to the paper's 30 deg compass bias at sample 70)::

    [fault]    sensor = "psi", kind = "bias" | "drift" | "stuck" | "noise", size_deg = 30.0 (none: no fault),
               onset_sample = 70, profile = "step" | "pulse" | "ramp" | "incipient" | "intermittent",
               length_samples = 1
    [run]      ftc = true, seed = 0, warm_up_samples = 500, record_samples = 400
    [monitor]  order = 70, mu = 0.01, eps0_deg2 = 9.0, r0 = 9.0

Every field is checked; a bad one is a ScenarioError naming it (``fault.sensor: ...``). A mu at
or beyond the mean-square stability bound of the run's input power warns with the bound.
"""

from __future__ import annotations

import numbers
from dataclasses import fields

import numpy as np

from derivations.sensor_fdi_lms.experiment import PROFILES, Run, run
from uvsym.errors import ScenarioError
from uvsym.faults import SENSOR_KINDS
from uvsym.observers.lms import check_mu

__all__ = ["simulate", "run_from_table"]

FIELDS = {"fault": {"sensor": "sensor", "kind": "kind", "size_deg": "size_deg", "onset_sample": "onset",
                    "profile": "profile", "length_samples": "length"},
          "run": {"ftc": "ftc", "seed": "seed", "warm_up_samples": "warm_up", "record_samples": "record"},
          "monitor": {"order": "order", "mu": "mu", "eps0_deg2": "eps0_deg2", "r0": "r0"}}
SENSORS = ("psi",)  # the outputs of rov_yaw


def _number(value, where: str, integer: bool = False):
    kind = numbers.Integral if integer else numbers.Real
    if isinstance(value, bool) or not isinstance(value, kind) or not np.isfinite(value):
        raise ScenarioError(f"{where}: expected {'an integer' if integer else 'a finite number'}, got {value!r}")
    return int(value) if integer else float(value)


def run_from_table(table: dict) -> Run:
    """The :class:`Run` a parsed scenario describes (ScenarioError naming the first bad field)."""
    unknown = sorted(set(table) - set(FIELDS))
    if unknown:
        raise ScenarioError(f"{unknown[0]}: unknown table; known: {', '.join(FIELDS)}")
    values = {}
    for section, known in FIELDS.items():
        part = table.get(section, {})
        if not isinstance(part, dict):
            raise ScenarioError(f"{section}: expected a table, got {part!r}")
        for key, value in part.items():
            if key not in known:
                raise ScenarioError(f"{section}.{key}: unknown field; known: {', '.join(known)}")
            values[(section, key)] = value
    spec = {}
    defaults = {f.name: f.default for f in fields(Run)}
    for (section, key), value in values.items():
        where, name = f"{section}.{key}", FIELDS[section][key]
        if name in ("sensor", "kind", "profile"):
            choices = {"sensor": SENSORS, "kind": tuple(SENSOR_KINDS), "profile": PROFILES}[name]
            if value not in choices:
                raise ScenarioError(f"{where}: unknown {name} {value!r}; known: {', '.join(choices)}")
        elif name == "ftc":
            if not isinstance(value, bool):
                raise ScenarioError(f"{where}: expected true or false, got {value!r}")
        elif name == "size_deg" and value == "none":
            value = None
        else:
            value = _number(value, where, integer=isinstance(defaults[name], int) and name != "size_deg")
        spec[name] = value
    if "fault" not in table:
        spec["size_deg"] = None  # no [fault] table: a healthy run
    result = Run(**spec)
    for where, name, low in (("run.seed", "seed", 0), ("run.warm_up_samples", "warm_up", 0),
                             ("run.record_samples", "record", 1),
                             ("fault.onset_sample", "onset", 0), ("fault.length_samples", "length", 1)):
        if getattr(result, name) < low:
            raise ScenarioError(f"{where}: must be at least {low}, got {getattr(result, name)}")
    for where, name in (("monitor.order", "order"), ("monitor.mu", "mu"), ("monitor.eps0_deg2", "eps0_deg2"),
                        ("monitor.r0", "r0")):
        if not getattr(result, name) > 0:
            raise ScenarioError(f"{where}: must be positive, got {getattr(result, name)}")
    if result.onset >= result.record:
        raise ScenarioError(f"fault.onset_sample: {result.onset} is beyond the run's record of {result.record} "
                            "samples (run.record_samples)")
    return result


def simulate(table: dict, *, name: str = "scenario", progress=None, method: str | None = None):
    """Run a scenario table (module docstring); returns the SimResult (method: only ``fast``)."""
    if method not in (None, "fast"):
        raise ScenarioError(f"method: this study runs on the compiled fixed-step path only ('fast'), got {method!r}")
    spec = run_from_table(table)
    outcome = run(spec)
    u = outcome.result["u"]["u"][spec.warm_up:]
    check_mu(spec.mu, spec.order, float(np.mean(u ** 2)), what="monitor.mu")
    if progress is not None:
        progress(1.0)
    return outcome.result
