"""Detectors: decision blocks that read a finished record and publish into the one event log.

A detector has a ``name`` and ``decide(result) -> list[Event]`` (:mod:`uvsym.diagnosis.events`);
it reads the signals it names from the :class:`~uvsym.sim.result.SimResult` (``<group>.<label>``,
e.g. ``obs.r_omega_m``) and decides on every sample, as it would in the loop.

:class:`ResidualThreshold` -- residuals r_i (m of them) against thresholds ``c_i = z sigma_i``
with ``z = Phi^-1(1 - alpha / (2 m))`` and ``alpha = F dt / 3600``: under the stated noise model
(r Gaussian, zero mean, standard deviations sigma, from the loop's sensor noise by
:func:`~uvsym.diagnosis.calibration.residual_covariance` or given) a healthy sample exceeds some
threshold with probability at most alpha (Bonferroni), so the expected number of samples that
exceed, and hence of alarms, is at most F per hour (F: the designed false alarms per hour), for
correlated residuals too. ``detected`` once ``confirm`` samples in a row exceed, naming the target
of the residual with the largest ``|r_i| / c_i`` there (a hint); ``isolated`` on that target too
only with ``isolate`` set, which claims that the residuals are structured (each one responds to
its target's fault alone): an observer's output residuals are not (an actuator fault moves them
as a sensor fault does), so by default the detector detects and does not isolate. ``cleared``
once ``release`` samples in a row do not (hysteresis: no alarm stays latched after its evidence is
gone). ``cleared`` says the residuals are back inside their thresholds, not that the fault is gone:
an estimator whose model follows a constant bias (an observer's state absorbs a sensor offset)
brings its residual back while the fault persists; ``latch`` keeps every detection to the end of
the run instead (no ``cleared``, at most one alarm per run). Samples before
``ignore_before`` s (the estimator's start-up) are not judged. ``given`` thresholds (the residuals'
units, e.g. a study's own calibration on fault-free runs) replace ``z sigma``; sigma is then
reported beside them.

:class:`EstimatedFault` -- a :class:`ResidualThreshold` that detects, and a fault estimate that
identifies (the hybrid observer's, Yu et al. 2018, eq. 18): ``identified`` on the detected target,
``identify_after`` s after each detection that has not cleared by then, with value
``gain x`` the estimate's mean over the last ``average`` s (gain: the sensor's fault direction, so
that the value is the sensor's offset in its unit, kind ``bias``).

:class:`DoubleCriterion` -- the LMS-FIR monitor's own decision (Zhu et al., Sec. 3.2; published
as ``fault_<y>``): ``detected`` and ``isolated`` on sensor y when its fault flag rises,
``cleared`` when it falls.

:class:`StepDecision` -- the calibrated sensor-step monitor's decisions
(:mod:`uvsym.observers.step_monitor`, its ``fault_<y>`` flag and offset): ``detected``,
``isolated`` and ``identified`` (kind ``bias``, the confirmed offset) when the flag rises, a new
``identified`` when a further step changes the offset, ``cleared`` when it falls.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from uvsym.diagnosis.events import Event
from uvsym.errors import DiagnosisError

__all__ = ["ResidualThreshold", "DoubleCriterion", "StepDecision", "EstimatedFault", "check_samples", "flag_events",
           "threshold_factor", "read_signal", "ends_of_runs"]


def read_signal(result, name: str) -> np.ndarray:
    """(N,) the logged signal ``<group>.<label>`` of a SimResult; DiagnosisError naming it when absent."""
    group, _, label = name.partition(".")
    if group not in result.signals or label not in result.signals[group].labels:
        known = [f"{g}.{lab}" for g, s in result.signals.items() for lab in s.labels]
        raise DiagnosisError(f"signal {name!r} is not in the result; logged: {', '.join(known)}")
    return np.asarray(result[group][label], dtype=float)


def ends_of_runs(flags: np.ndarray, length: int) -> np.ndarray:
    """(N,) True at each sample that ends ``length`` (>= 1) consecutive true ``flags`` (N,): a running count in
    integers, exactly what ``np.convolve(flags, np.ones(length))[:N] >= length`` gives in O(N length)."""
    counts = np.cumsum(np.asarray(flags, dtype=np.int64))
    window = counts.copy()
    window[length:] -= counts[:-length]
    return window >= length


def check_samples(detector, *fields: str) -> None:
    """DiagnosisError naming the first of the detector's ``fields`` that is not an integer >= 1 (samples)."""
    for what in fields:
        value = getattr(detector, what)
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise DiagnosisError(f"detector {detector.name}: {what} must be an integer >= 1 (samples), got {value!r}")


def flag_events(result, flag_name: str, target: str, detector: str) -> list[Event]:
    """``detected`` and ``isolated`` on ``target`` where the logged 0/1 flag ``flag_name`` rises,
    ``cleared`` where it falls."""
    t = np.asarray(result.t, dtype=float)
    flag = read_signal(result, flag_name) > 0.5
    events = []
    for k in np.flatnonzero(np.diff(np.concatenate([[False], flag]).astype(int))):
        time = round(float(t[k]), 9)
        if flag[k]:
            events += [Event(time, "detected", target, detector=detector),
                       Event(time, "isolated", target, detector=detector)]
        else:
            events.append(Event(time, "cleared", target, detector=detector))
    return events


def threshold_factor(false_alarms_per_hour: float, dt: float, channels: int) -> float:
    """z of ``c = z sigma`` (module docstring): the two-sided Gaussian quantile of ``alpha / (2 m)``,
    ``alpha = F dt / 3600``, the per-sample false-alarm probability that allows F alarms per hour."""
    alpha = false_alarms_per_hour * dt / 3600.0
    if not 0.0 < alpha < 1.0:
        raise DiagnosisError(f"false_alarms_per_hour = {false_alarms_per_hour:g} at dt = {dt:g} s gives a per-sample "
                             f"probability of {alpha:g}, outside (0, 1)")
    from scipy.special import ndtri  # here: scipy.stats would cost every CLI call its import

    return float(-ndtri(alpha / (2 * channels)))


@dataclass(frozen=True)
class ResidualThreshold:
    """Threshold test on residuals (module docstring). residuals: m signal names; sigma: (m,) their
    standard deviations (residuals' units); isolate: the residuals are structured (module
    docstring); targets: the signal each residual points to (an input
    or output of the plant) or None; dt: sample period (s); latch: a detection stands to the end
    of the run (no ``cleared``)."""

    name: str
    residuals: tuple[str, ...]
    sigma: np.ndarray
    dt: float
    false_alarms_per_hour: float = 1.0
    confirm: int = 3
    release: int = 20
    ignore_before: float = 0.0
    targets: tuple[str | None, ...] = ()
    isolate: bool = False
    given: tuple[float, ...] = ()
    latch: bool = False
    thresholds: np.ndarray = field(init=False)

    def __post_init__(self):
        sigma = np.asarray(self.sigma, dtype=float).reshape(-1)
        if sigma.shape != (len(self.residuals),) or not np.all(np.isfinite(sigma)) or np.any(sigma <= 0):
            raise DiagnosisError(f"detector {self.name}: sigma must be {len(self.residuals)} positive finite standard "
                                 f"deviations (one per residual), got {sigma.tolist()}")
        check_samples(self, "confirm", "release")
        targets = self.targets or (None,) * len(self.residuals)
        if len(targets) != len(self.residuals):
            raise DiagnosisError(f"detector {self.name}: {len(targets)} targets for {len(self.residuals)} residuals")
        object.__setattr__(self, "targets", tuple(targets))
        object.__setattr__(self, "sigma", sigma)
        z = threshold_factor(self.false_alarms_per_hour, self.dt, len(self.residuals))
        given = np.asarray(self.given, dtype=float).reshape(-1)
        if given.size and (given.shape != sigma.shape or not np.all(np.isfinite(given)) or np.any(given <= 0)):
            raise DiagnosisError(f"detector {self.name}: given thresholds must be {sigma.size} positive finite "
                                 f"numbers, got {given.tolist()}")
        object.__setattr__(self, "thresholds", given if given.size else z * sigma)

    def decide(self, result) -> list[Event]:
        """The detections and clearances of the record (module docstring)."""
        t = np.asarray(result.t, dtype=float)
        ratio = np.column_stack([np.abs(read_signal(result, r)) / c for r, c in zip(self.residuals, self.thresholds)])
        ratio[t < self.ignore_before - 1e-9 * max(1.0, abs(self.ignore_before))] = 0.0
        outside = (ratio.max(axis=1) > 1.0).astype(int)
        # samples ending a run of `confirm` samples outside, and of `release` samples inside
        confirmed = np.flatnonzero(ends_of_runs(outside, self.confirm))
        released = np.flatnonzero(ends_of_runs(1 - outside, self.release))
        events, k = [], -1
        while (i := np.searchsorted(confirmed, k, side="right")) < confirmed.size:
            k = int(confirmed[i])  # the first confirmation after the last clearance: an alarm
            target, time = self.targets[int(np.argmax(ratio[k]))], round(float(t[k]), 9)
            events.append(Event(time, "detected", target, detector=self.name))
            if self.isolate and target is not None:
                events.append(Event(time, "isolated", target, detector=self.name))
            j = np.searchsorted(released, k, side="right")
            if self.latch or j == released.size:
                break
            k = int(released[j])  # the first release after it: cleared
            events.append(Event(round(float(t[k]), 9), "cleared", detector=self.name))
        return events

    def design(self) -> dict:
        """What the decision rule is designed for: per-sample and per-hour false-alarm rates and thresholds."""
        return {"detector": self.name, "rule": "|r_i| > given c_i" if self.given else "|r_i| > z sigma_i",
                "residuals": list(self.residuals),
                "sigma": self.sigma.tolist(), "thresholds": self.thresholds.tolist(),
                "false_alarms_per_hour": self.false_alarms_per_hour,
                "per_sample_probability": self.false_alarms_per_hour * self.dt / 3600.0,
                "confirm_samples": self.confirm, "release_samples": self.release, "latch": self.latch}


@dataclass(frozen=True)
class DoubleCriterion:
    """The LMS monitor ``monitor``'s fault flag on ``sensor`` as events (module docstring).

    settings: the monitor's order, window, hold and confirm (its block's description); parameters:
    its fixed (mu, eps0, r0); regressor, order: the input its filter regresses on and M. Deciding on
    a record warns (StepSizeWarning) when mu is at or beyond the mean-square bound ``1 / (M P_u)``
    of the record's input power P_u (:func:`uvsym.observers.lms.check_mu`)."""

    name: str
    monitor: str
    sensor: str
    settings: str = ""
    parameters: tuple[tuple[str, float], ...] = ()
    regressor: str | None = None
    order: int = 0

    def decide(self, result) -> list[Event]:
        from uvsym.observers.lms import check_mu

        mu = dict(self.parameters).get("mu")
        if mu is not None and self.regressor is not None:
            u = read_signal(result, self.regressor)
            check_mu(mu, self.order, float(np.mean(u ** 2)), what=f"{self.monitor}.mu")
        return flag_events(result, f"{self.monitor}.fault_{self.sensor}", self.sensor, self.name)

    def design(self) -> dict:
        return {"detector": self.name, "rule": "LMS double criterion (eps^2 > eps0 confirmed by R > r0)",
                "monitor": self.monitor, "sensor": self.sensor, "settings": self.settings,
                "parameters": dict(self.parameters)}



@dataclass(frozen=True)
class StepDecision:
    """The sensor-step monitor ``monitor``'s decisions on ``sensor`` as events (module docstring);
    settings: its block's description (the designed rate and threshold)."""

    name: str
    monitor: str
    sensor: str
    settings: str = ""

    def decide(self, result) -> list[Event]:
        events = flag_events(result, f"{self.monitor}.fault_{self.sensor}", self.sensor, self.name)
        t = np.asarray(result.t, dtype=float)
        offset = read_signal(result, f"{self.monitor}.offset_{self.sensor}")
        fault = read_signal(result, f"{self.monitor}.fault_{self.sensor}") > 0.5
        confirmed = read_signal(result, f"{self.monitor}.confirmed_{self.sensor}") > 0.5
        events += [Event(round(float(t[k]), 9), "identified", self.sensor, "bias", float(offset[k]), self.name)
                   for k in np.flatnonzero(confirmed & fault)]
        order = {"detected": 0, "isolated": 1, "identified": 2, "cleared": 3}
        return sorted(events, key=lambda e: (e.t, order[e.event]))

    def design(self) -> dict:
        return {"detector": self.name, "rule": "sensor step confirmed by g > h against every healthy model "
                "(trend, kink, glitch); P(g > h) <= exp(-h/2) under white Gaussian noise",
                "monitor": self.monitor, "sensor": self.sensor, "settings": self.settings}


@dataclass(frozen=True)
class EstimatedFault:
    """Detection by ``threshold`` (its events, named by it), identification by the logged estimate
    ``estimate`` (``<block>.<signal>``) times ``gain`` (module docstring); identify_after and
    average in s."""

    name: str
    threshold: ResidualThreshold
    estimate: str
    gain: float = 1.0
    identify_after: float = 0.5
    average: float = 0.1

    def __post_init__(self):
        if self.threshold.name != self.name:
            raise DiagnosisError(f"detector {self.name}: its threshold test is named {self.threshold.name!r}")
        for what in ("gain", "identify_after", "average"):
            value = getattr(self, what)
            if not (np.isfinite(value) and (value != 0 if what == "gain" else value >= 0)):
                raise DiagnosisError(f"detector {self.name}: {what} must be finite"
                                     + (" and non-zero" if what == "gain" else " and >= 0") + f", got {value!r}")

    def decide(self, result) -> list[Event]:
        """The threshold test's events and, after each detection, its identification (module docstring)."""
        t = np.asarray(result.t, dtype=float)
        estimate = self.gain * read_signal(result, self.estimate)
        events = self.threshold.decide(result)
        window = max(1, int(round(self.average / self.threshold.dt)))
        out = []
        for i, event in enumerate(events):
            out.append(event)
            if event.event != "detected":
                continue
            cleared = next((e.t for e in events[i + 1:] if e.event == "cleared"), np.inf)
            k = int(np.searchsorted(t, event.t + self.identify_after - 1e-9))
            if k < t.size and t[k] < cleared:
                value = float(np.mean(estimate[max(0, k - window + 1):k + 1]))
                out.append(Event(round(float(t[k]), 9), "identified", event.target, "bias", value, self.name))
        return sorted(out, key=lambda e: e.t)

    def design(self) -> dict:
        return {**self.threshold.design(), "estimate": self.estimate, "estimate_gain": self.gain,
                "identify_after_s": self.identify_after, "average_s": self.average}
