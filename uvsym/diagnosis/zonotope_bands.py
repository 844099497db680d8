"""The ``zonotope_bands`` detector: a UIO bank's residuals against set-valued thresholds (Yang, Hu &
Zhang, eqs. 30-32), the bank's pattern of band exits isolating the faulty actuator.

The bands are computed before the run from the stated bounds only: ``|v_j| <= noise_bound_j`` on
every measured output (bounded noise of any distribution), ``|e_0,i| <= initial_error_i`` on the
observers' initial error; the zonotope of each observer's healthy residual is propagated
(:func:`uvsym.observers.uio_bank.residual_bands`, order bound ``generators``, ``reduction``) over
``horizon`` samples and its interval hull held beyond (F stable: what the initial error and the
noise older than ``horizon`` samples add is bounded by ``||A^horizon||_2`` of the joint error-noise
map A, which must be below ``HELD_TOLERANCE``). A healthy run whose noise and initial error obey
the bounds never leaves the bands (no false-alarm rate to design: it is 0 by construction, for
the linear model the bank is designed on); noise beyond the bounds, or model mismatch, can.

Decisions, sample by sample on the finished record, each observer named by the actuator it
decouples (observer i is blind to a fault on actuator i, sensitive to the others):

- ``detected`` at the first sample k where some residual entry leaves its band;
- at the end of the isolation window ``[k, k + isolation_window)``: ``isolated`` on the one
  actuator whose observer stayed inside on every sample of the window, ``ambiguous`` (candidates
  joined by ``|``) when several did, ``unexplained`` when none did (no single-actuator fault fits);
  no decision when the record ends inside the window;
- ``cleared`` once every residual has been inside for ``release`` samples in a row after that
  decision; the next exit is a new detection.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from uvsym.codegen.cache import memoized
from uvsym.diagnosis.detectors import ends_of_runs, read_signal
from uvsym.diagnosis.events import Event
from uvsym.errors import DiagnosisError, ScenarioError, SetError
from uvsym.observers.uio_bank import isolate, outside_band, residual_bands
from uvsym.sets.reduction import METHODS

__all__ = ["HELD_TOLERANCE", "ZonotopeBands", "zonotope_bands_detector"]

HELD_TOLERANCE = 1e-12  # ||A^horizon||_2 below which the band at the horizon is held


@dataclass(frozen=True)
class ZonotopeBands:
    """Band test of a UIO bank block (module docstring). residuals: per observer (its actuator) the
    signal names of its residual entries; lower, upper: (horizon, n_obs, p) band limits; dt (s);
    isolation_window, release: samples; settings: the stated bounds and propagation options."""

    name: str
    actuators: tuple[str, ...]
    residuals: tuple[tuple[str, ...], ...]
    lower: np.ndarray
    upper: np.ndarray
    dt: float
    isolation_window: int = 50
    release: int = 50
    settings: dict = field(default_factory=dict)

    def outside(self, result) -> np.ndarray:
        """(N, n_obs) booleans: observer j's residual outside its band at sample k (bands held past the horizon)."""
        N, H = len(result.t), len(self.lower)
        held = np.minimum(np.arange(N), H - 1)
        columns = []
        for j, names in enumerate(self.residuals):
            r = np.column_stack([read_signal(result, n) for n in names])
            band = _Band(self.lower[held, j], self.upper[held, j])
            columns.append(outside_band(r, band))
        return np.column_stack(columns)

    def decide(self, result) -> list[Event]:
        """The detections, isolation decisions and clearances of the record (module docstring)."""
        t = np.asarray(result.t, dtype=float)
        outside = self.outside(result)
        alarm = outside.any(axis=1)
        quiet = ends_of_runs(~alarm, self.release)
        events, k = [], 0
        while (hits := np.flatnonzero(alarm[k:])).size:
            k += int(hits[0])
            events.append(Event(_time(t[k]), "detected", detector=self.name))
            end = k + self.isolation_window - 1
            if end >= t.size:
                break
            inside = isolate(outside, self.actuators, k, self.isolation_window)
            if len(inside) == 1:
                events.append(Event(_time(t[end]), "isolated", inside[0], detector=self.name))
            elif inside:
                events.append(Event(_time(t[end]), "ambiguous", "|".join(inside), detector=self.name))
            else:
                events.append(Event(_time(t[end]), "unexplained", detector=self.name))
            released = np.flatnonzero(quiet[end + self.release:])  # runs of quiet samples after the decision
            if not released.size:
                break
            k = end + self.release + int(released[0])
            events.append(Event(_time(t[k]), "cleared", detector=self.name))
            k += 1
        return events

    def design(self) -> dict:
        """The rule, the stated bounds and each observer's band half-widths at the horizon."""
        half = (self.upper[-1] - self.lower[-1]) / 2
        return {"detector": self.name, "rule": "a residual entry outside its zonotope band's interval hull",
                **self.settings, "horizon_samples": len(self.lower), "isolation_window_samples": self.isolation_window,
                "release_samples": self.release, "false_alarms_per_hour": 0.0,
                "band_half_width_at_horizon": {a: dict(zip(names, row.tolist()))
                                               for a, names, row in zip(self.actuators, self.residuals, half)}}


@dataclass(frozen=True)
class _Band:
    """The interval hulls :func:`outside_band` reads: lower, upper (N, p)."""

    lower: np.ndarray
    upper: np.ndarray


@memoized(16)
def _band(design, vbar: np.ndarray, ebar: np.ndarray, horizon: int, generators: int, reduction: str) -> _Band:
    """The interval hulls of one observer's healthy-residual zonotopes; memoized in-process (the runs of
    a campaign share their bands)."""
    band = residual_bands(design, vbar, ebar, horizon, generators, reduction, track=False)
    return _Band(band.lower, band.upper)


def _time(t: float) -> float:
    return round(float(t), 9)


def _bounds(fields, key: str, names: tuple[str, ...], what: str) -> np.ndarray:
    """One non-negative bound per name: a number for all, or a table name = bound (every name given)."""
    value = fields.raw(key, None, "number or table", f"{what}: one bound for all, or name = bound")
    if isinstance(value, dict):
        missing = [n for n in names if n not in value]
        unknown = [n for n in value if n not in names]
        if missing or unknown:
            raise ScenarioError(f"{fields._name(key)}: expected a bound for each of {', '.join(names)}"
                                + (f"; missing {', '.join(missing)}" if missing else "")
                                + (f"; unknown {', '.join(unknown)}" if unknown else ""))
        value = [value[n] for n in names]
    elif value is not None and not isinstance(value, list):
        value = [value] * len(names)
    if not isinstance(value, list) or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and
                                              0 <= v < np.inf for v in value) or len(value) != len(names):
        raise ScenarioError(f"{fields._name(key)}: expected {what} as a number >= 0 or a table of "
                            f"{', '.join(names)} = bound, got {value!r}")
    return np.asarray(value, dtype=float)


def zonotope_bands_detector(fields, name: str, loop, z0, w0, step: float) -> ZonotopeBands:
    """``type = "zonotope_bands"``: fields ``bank`` (a uio_bank block), ``noise_bound`` (per measured
    output, its unit), ``initial_error`` (per state), ``generators`` (order bound), ``reduction``,
    ``horizon``, ``isolation_window`` and ``release`` (samples). ScenarioError naming the field."""
    from uvsym.sim.uio_block import UIOBankBlock, residual_name

    bank_name = fields.text("bank")
    banks = {b.name: b for b in loop.blocks if isinstance(b, UIOBankBlock)}
    if bank_name not in banks:
        import difflib

        near = difflib.get_close_matches(bank_name, list(banks), n=1)
        raise ScenarioError(f"{fields.path}.bank: {bank_name!r} is not a uio_bank block of the scenario"
                            + (f" (did you mean {near[0]!r}?)" if near else "")
                            + f"; uio_bank blocks: {', '.join(banks) or 'none'}")
    blk = banks[bank_name]
    vbar = _bounds(fields, "noise_bound", blk.measured, "noise bounds of the measured outputs")
    ebar = _bounds(fields, "initial_error", loop.plant.x.names, "initial error bounds of the states")
    generators = fields.integer("generators", 64, minimum=1, unit="generators")
    reduction = fields.text("reduction", "girard", choices=METHODS)
    horizon = fields.integer("horizon", 300, minimum=2, unit="samples")
    window = fields.integer("isolation_window", 50, minimum=1, unit="samples")
    release = fields.integer("release", 50, minimum=1, unit="samples")
    bands = []
    for actuator, design in zip(blk.bank.decoupled, blk.bank.designs):
        p, n = design.C.shape
        A = np.block([[design.F, -design.K1], [np.zeros((p, n + p))]])
        reach = float(np.linalg.norm(np.linalg.matrix_power(A, horizon), 2))
        if not reach <= HELD_TOLERANCE:
            raise ScenarioError(f"{fields.path}.horizon: after {horizon} samples the observer decoupling {actuator} "
                                f"still carries ||A^horizon|| = {reach:.3g} of its initial error and noise (above "
                                f"{HELD_TOLERANCE:g}): its band cannot be held; give a longer horizon")
        try:
            bands.append(_band(design, vbar, ebar, horizon, generators, reduction))
        except SetError as exc:
            raise ScenarioError(f"{fields.path}.generators: the band of the observer decoupling {actuator} "
                                f"cannot be propagated: {exc}") from None
    if not np.isclose(step, blk.dt):
        raise DiagnosisError(f"detector {name}: the bank samples every {blk.dt:g} s, the loop every {step:g} s")
    return ZonotopeBands(name, blk.bank.decoupled,
                         tuple(tuple(f"{bank_name}.{residual_name(a, y)}" for y in blk.measured)
                               for a in blk.bank.decoupled),
                         np.stack([b.lower for b in bands], axis=1), np.stack([b.upper for b in bands], axis=1),
                         step, window, release,
                         {"bank": bank_name, "noise_bound": dict(zip(blk.measured, vbar.tolist())),
                          "initial_error": dict(zip(loop.plant.x.names, ebar.tolist())), "generators": generators,
                          "reduction": reduction})
