"""``uvsym simulate FILE.toml`` for this study: one seeded run with one actuator fault.

A scenario file::

    study = "uio-zonotope"
    samples = 300          # samples of 0.01 s (default 300)
    seed = 0               # noise, disturbance and initial-state draws

    [fault]                # optional: without it the run is healthy
    actuator = "Vf"        # Vf, Vb, Vr or Vl
    kind = "abrupt"        # abrupt (size in V) or drift (size in V/s)
    size = 10.0
    onset = 50             # sample

The result holds the true states ``x``, measurements ``y``, commanded voltages ``u``, the fault
``f`` (V), and per bank observer its residual ``r/<observer>``, its band ``lower/<observer>``,
``upper/<observer>`` and ``alarm/<observer>`` (1 where the residual is outside its band).
"""

from __future__ import annotations

import numbers
import time

import numpy as np

from derivations.uio_zonotope.design import DT, bands, design
from derivations.uio_zonotope.experiment import Fault, detection, simulate_runs
from uvsym.errors import ScenarioError
from uvsym.sim.result import Signal, SimResult
from uvsym.sim.scenario import _Fields

__all__ = ["MAX_SAMPLES", "parse", "simulate"]

MAX_SAMPLES = 3000
KINDS = ("abrupt", "drift")


def _integer(fields: _Fields, key: str, default: int, low: int, high: int) -> int:
    value = fields.raw(key, default)
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not low <= value <= high:
        raise ScenarioError(f"{fields._name(key)}: expected an integer in [{low}, {high}], got {value!r}")
    return int(value)


def parse(table: dict) -> tuple[int, int, Fault | None]:
    """(samples, seed, fault or None) from the scenario table; ScenarioError naming the field."""
    fields = _Fields(table, "")
    samples = _integer(fields, "samples", 300, 2, MAX_SAMPLES)
    seed = _integer(fields, "seed", 0, 0, 2**32 - 1)
    fault = None
    spec = fields.table("fault")
    if spec is not None:
        names = design().plant.u.names
        actuator = spec.text("actuator", choices=names)
        kind = spec.text("kind", choices=KINDS)
        size = spec.number("size")
        onset = _integer(spec, "onset", 50, 0, samples - 1)
        spec.done()
        fault = Fault(names.index(actuator), kind, size, onset)
    fields.done()
    return samples, seed, fault


def simulate(table: dict, *, name: str = "scenario", progress=None, method=None) -> SimResult:
    """One run of the scenario ``table`` (module docstring) as a SimResult."""
    if method is not None:
        raise ScenarioError(f"method: this study runs its sampled linear loop only; got {method!r}")
    samples, seed, fault = parse(table)
    if progress is not None:
        progress(f"{name}: {samples} samples, seed {seed}")
    d = design()
    started = time.perf_counter()
    runs = simulate_runs(seed, 1, fault, samples)
    outside = detection(runs, 0)["outside"][:, :, 0]
    x, u = d.plant.x, d.plant.u
    signals = {"x": Signal(runs.x[..., 0], x.names, x.units), "y": Signal(runs.y[..., 0], x.names, x.units),
               "u": Signal(runs.u[..., 0], u.names, u.units),
               "f": Signal(runs.fault[:, None], ("f",), ("V",))}
    for i, (obs, band) in enumerate(zip(d.bank.observers, bands(samples))):
        labels = tuple(f"r_{n}" for n in x.names)
        signals[f"r/{obs.name}"] = Signal(runs.residuals[i][..., 0], labels, x.units)
        signals[f"lower/{obs.name}"] = Signal(band.lower, labels, x.units)
        signals[f"upper/{obs.name}"] = Signal(band.upper, labels, x.units)
        signals[f"alarm/{obs.name}"] = Signal(outside[:, i:i + 1].astype(float), ("alarm",), ("-",))
    meta = {"study": "uio-zonotope", "scenario": name, "samples": samples, "seed": seed, "dt_s": DT,
            "fault": None if fault is None else {"actuator": u.names[fault.actuator], "kind": fault.kind,
                                                 "size": fault.size, "onset_sample": fault.onset},
            "wall_s": time.perf_counter() - started}
    return SimResult(np.arange(samples) * DT, signals, meta)
