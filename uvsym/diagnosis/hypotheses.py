"""The decisions of a multiple-model bank (:mod:`uvsym.observers.mmae`) as events: the detector
``type = "mmae"`` of a scenario's ``[[detectors]]`` (fields ``bank``, the mmae block's name;
``threshold``; ``dwell``; ``settle``; ``resolution``; ``ignore_before``; ``kind``).

Rule: at sample k the leading hypothesis is ``argmax_i p_i(k)`` when ``max_i p_i(k) > threshold``
(none otherwise). The decision starts at the no-fault hypothesis (the model without efficiency
states) and switches to a hypothesis once it has led for ``dwell`` samples in a row (samples
before ``ignore_before`` s lead nowhere). On a switch away from a fault hypothesis: ``cleared``
on each of its inputs; onto one: ``detected`` (on its input, or none for a hypothesis of several
inputs), then per input ``isolated``, of ``kind`` (default ``proportional``: the size is the
fraction of the command delivered, as the efficiency is). The estimate
``<model>.alpha_<input>_hat`` converges after the switch: while the hypothesis stands,
``identified`` (of ``kind``, with the estimate as value) follows at each sample at which the
estimate has stayed within ``resolution`` over the last ``settle`` samples (it has settled) and
lies more than ``resolution`` from the last value identified since the switch (the first time:
from none), so a fault that keeps growing is identified again where it settles.

That rule (``rule = "posterior"``, the paper's, the default) is not calibrated: its rate is
measured (the study's campaign). ``rule = "evidence"`` (:class:`EvidenceSwitch`) decides from the
bank's log-likelihoods and NIS with thresholds from a designed false-alarm rate
``false_alarms_per_hour`` F at the sample period dt, split evenly between its two tests (per-sample
budget ``a = F dt / 3600 / 2`` each):

- detection, per fault model i (m of them), the CUSUM of the log-likelihood ratio against the
  no-fault model, ``g_i <- max(0, g_i + l_i - l_0)``, alarms at ``g_i > h``; Lorden's bound (the
  ratio of two predictive densities has mean 1 while the no-fault model is right) gives a mean run
  length >= e^h samples per model, so ``h = log(m / a)``; the largest ``g_i`` above h is isolated;
- release: a fault hypothesis ends (``cleared``, every g back to 0) when the ratio summed over the
  last ``clear_window`` samples is <= 0 (the no-fault model explains them as well): a loss that has
  ended is cleared within about clear_window samples, whatever evidence was stored before;
- consistency: when even the best model's NIS summed over the last ``nis_window`` samples exceeds
  ``chi2.isf(a, n_y nis_window)`` (n_y measurements; the no-fault model's sum is chi-square with
  that many degrees of freedom while it is right) no hypothesis fits: ``unexplained`` (no culprit,
  any fault hypothesis cleared), and ``cleared`` (no target) once a model fits again.

A rate so designed is an upper bound (each alarm needs a sample beyond its threshold), valid while
the filters' noise model (R, Q) is the sensors' and the sea's.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from uvsym.diagnosis.detectors import check_samples, read_signal
from uvsym.diagnosis.events import Event
from uvsym.errors import DiagnosisError, ScenarioError
from uvsym.faults import ACTUATOR_KINDS

__all__ = ["HypothesisSwitch", "EvidenceSwitch", "bank_hypotheses", "mmae_detector"]
RULES = ("posterior", "evidence")


def _settled(estimate: np.ndarray, settle: int) -> np.ndarray:
    """Range of ``estimate`` over the last ``settle`` samples, inf before there are that many."""
    spread = np.full(estimate.size, np.inf)
    if estimate.size >= settle:
        windows = np.lib.stride_tricks.sliding_window_view(estimate, settle)
        spread[settle - 1:] = windows.max(axis=1) - windows.min(axis=1)
    return spread


def _spreads(detector, result) -> dict:
    """(model, input) -> (range over the last settle samples, the efficiency estimate)."""
    spread = {}
    for m, inputs in detector.models:
        for u in inputs:
            estimate = read_signal(result, f"{detector.bank}.{m}.alpha_{u}_hat")
            spread[m, u] = (_settled(estimate, detector.settle), estimate)
    return spread


def _identify(detector, spread: dict, time: float, k: int, model: str, inputs, identified: dict) -> list[Event]:
    """``identified`` events at sample k of the standing hypothesis (module docstring); updates identified."""
    events = []
    for u in inputs:
        width, value = spread[model, u][0][k], float(spread[model, u][1][k])
        if width <= detector.resolution and abs(value - identified.get(u, np.inf)) > detector.resolution:
            identified[u] = value
            events.append(Event(time, "identified", u, detector.kind, value, detector=detector.name))
    return events


def _moving_sum(v: np.ndarray, window: int) -> np.ndarray:
    """Sum over the last ``window`` rows (fewer at the start), along axis 0."""
    c = np.cumsum(v, axis=0)
    c[window:] = c[window:] - c[:-window]
    return c


@dataclass(frozen=True)
class HypothesisSwitch:
    """The bank ``bank``'s hypothesis switches (module docstring). models: (hypothesis, its inputs
    with an efficiency state) in the bank's order, exactly one with none; dwell in samples."""

    name: str
    bank: str
    models: tuple[tuple[str, tuple[str, ...]], ...]
    threshold: float = 0.9
    dwell: int = 1
    settle: int = 20
    resolution: float = 0.02
    ignore_before: float = 0.0
    kind: str = "proportional"

    def __post_init__(self):
        healthy = [m for m, inputs in self.models if not inputs]
        if len(healthy) != 1 or len(self.models) < 2:
            raise DiagnosisError(f"detector {self.name}: bank {self.bank} needs exactly one no-fault model (no "
                                 f"efficiency state) among at least two, has {[m for m, _ in self.models]}")
        if not 0.5 <= self.threshold < 1.0:
            raise DiagnosisError(f"detector {self.name}: threshold must be in [0.5, 1) (a probability that "
                                 f"only one hypothesis can exceed), got {self.threshold!r}")
        check_samples(self, "dwell", "settle")

    def decide(self, result) -> list[Event]:
        t = np.asarray(result.t, dtype=float)
        P = np.column_stack([read_signal(result, f"{self.bank}.p_{m}") for m, _ in self.models])
        leading = np.where(P.max(axis=1) > self.threshold, P.argmax(axis=1), -1)
        leading[t < self.ignore_before - 1e-9 * max(1.0, abs(self.ignore_before))] = -1
        spread = _spreads(self, result)
        current = next(i for i, (_, inputs) in enumerate(self.models) if not inputs)
        events, candidate, run, identified = [], -1, 0, {}
        for k, lead in enumerate(leading):
            candidate, run = (candidate, run + 1) if lead == candidate else (int(lead), 1)
            time = round(float(t[k]), 9)
            if lead >= 0 and lead != current and run >= self.dwell:
                events += [Event(time, "cleared", u, detector=self.name) for u in self.models[current][1]]
                current = int(lead)
                model, inputs = self.models[current]
                if inputs:
                    events.append(Event(time, "detected", inputs[0] if len(inputs) == 1 else None,
                                        detector=self.name))
                events += [Event(time, "isolated", u, self.kind, detector=self.name) for u in inputs]
                identified = {}
            events += _identify(self, spread, time, k, *self.models[current], identified)
        return events

    def design(self) -> dict:
        return {"detector": self.name, "rule": "argmax_i p_i > threshold for dwell samples in a row switches the "
                "hypothesis", "bank": self.bank, "threshold": self.threshold, "dwell_samples": self.dwell,
                "identify_settle_samples": self.settle, "identify_resolution": self.resolution,
                "ignore_before_s": self.ignore_before, "kind": self.kind,
                "models": {m: list(inputs) for m, inputs in self.models}}


@dataclass(frozen=True)
class EvidenceSwitch:
    """``rule = "evidence"`` (module docstring): the calibrated decisions of bank ``bank``. models as
    :class:`HypothesisSwitch`; dt the sample period (s); n_y the bank's measurements; windows in samples."""

    name: str
    bank: str
    models: tuple[tuple[str, tuple[str, ...]], ...]
    dt: float
    n_y: int
    false_alarms_per_hour: float = 1.0
    clear_window: int = 60
    nis_window: int = 20
    settle: int = 20
    resolution: float = 0.02
    ignore_before: float = 0.0
    kind: str = "proportional"

    def __post_init__(self):
        HypothesisSwitch(self.name, self.bank, self.models, settle=self.settle)  # the same bank checks
        check_samples(self, "clear_window", "nis_window", "n_y")
        if not (self.dt > 0 and 0.0 < self.budget < 0.5):
            raise DiagnosisError(f"detector {self.name}: false_alarms_per_hour must be positive and below "
                                 f"{1800.0 / self.dt:g} at dt = {self.dt:g} s, got {self.false_alarms_per_hour!r}")

    @property
    def budget(self) -> float:
        """a: the per-sample false-alarm probability of each test."""
        return self.false_alarms_per_hour * self.dt / 3600.0 / 2.0

    @property
    def cusum_threshold(self) -> float:
        """h = log(m / a) (nats)."""
        return float(np.log(sum(1 for _, inputs in self.models if inputs) / self.budget))

    @property
    def nis_threshold(self) -> float:
        """chi2.isf(a, n_y nis_window)."""
        return float(chi2.isf(self.budget, self.n_y * self.nis_window))

    def decide(self, result) -> list[Event]:
        t = np.asarray(result.t, dtype=float)
        names = [m for m, _ in self.models]
        healthy = next(i for i, (_, inputs) in enumerate(self.models) if not inputs)
        faulty = [i for i, (_, inputs) in enumerate(self.models) if inputs]
        L = np.column_stack([read_signal(result, f"{self.bank}.loglik_{m}") for m in names])
        llr = L[:, faulty] - L[:, [healthy]]
        nis = np.column_stack([read_signal(result, f"{self.bank}.nis_{m}") for m in names])
        fits = (_moving_sum(nis, self.nis_window).min(axis=1) <= self.nis_threshold) | (
            np.arange(t.size) < self.nis_window - 1)
        recent = _moving_sum(llr, self.clear_window)
        start = t >= self.ignore_before - 1e-9 * max(1.0, abs(self.ignore_before))
        spread, h = _spreads(self, result), self.cusum_threshold
        events, g, current, lost, identified = [], np.zeros(len(faulty)), -1, False, {}
        for k in np.flatnonzero(start):
            time = round(float(t[k]), 9)
            g = np.maximum(0.0, g + llr[k])
            if not fits[k]:
                if not lost:
                    events += self._clear(time, current)
                    events.append(Event(time, "unexplained", detector=self.name))
                lost, current, g = True, -1, np.zeros_like(g)
                continue
            if lost:
                events.append(Event(time, "cleared", detector=self.name))
                lost = False
            if current >= 0 and recent[k, current] <= 0.0:
                events += self._clear(time, current)
                current, g = -1, np.zeros_like(g)
            best = int(np.argmax(g))
            if g[best] > h and best != current and (current < 0 or g[best] > g[current]):
                events += self._clear(time, current)
                current, identified = best, {}
                inputs = self.models[faulty[best]][1]
                events.append(Event(time, "detected", inputs[0] if len(inputs) == 1 else None, detector=self.name))
                events += [Event(time, "isolated", u, self.kind, detector=self.name) for u in inputs]
            if current >= 0:
                events += _identify(self, spread, time, k, *self.models[faulty[current]], identified)
        return events

    def _clear(self, time: float, current: int) -> list[Event]:
        faulty = [inputs for _, inputs in self.models if inputs]
        return [] if current < 0 else [Event(time, "cleared", u, detector=self.name) for u in faulty[current]]

    def design(self) -> dict:
        return {"detector": self.name, "rule": "evidence: CUSUM of l_i - l_0 > h detects and isolates; the ratio "
                "summed over clear_window samples <= 0 clears; windowed NIS of every model above its chi-square "
                "threshold: unexplained", "bank": self.bank, "designed_false_alarms_per_hour":
                self.false_alarms_per_hour, "sample_period_s": self.dt, "per_sample_probability_per_test":
                self.budget, "cusum_threshold_nats": self.cusum_threshold, "nis_window_samples": self.nis_window,
                "nis_threshold": self.nis_threshold, "nis_degrees_of_freedom": self.n_y * self.nis_window,
                "clear_window_samples": self.clear_window, "identify_settle_samples": self.settle,
                "identify_resolution": self.resolution, "ignore_before_s": self.ignore_before, "kind": self.kind,
                "models": {m: list(inputs) for m, inputs in self.models}}


def bank_hypotheses(block) -> tuple[tuple[str, tuple[str, ...]], ...] | None:
    """(hypothesis, inputs) of an mmae block from what it publishes (``p_<model>``,
    ``<model>.alpha_<input>_hat``), or None for a block that is not a bank."""
    names = block.publishes.names
    models = [n[2:] for n in names if n.startswith("p_")]
    if len(models) < 2 or f"loglik_{models[0]}" not in names:
        return None
    return tuple((m, tuple(n[len(m) + 7:-4] for n in names if n.startswith(f"{m}.alpha_") and n.endswith("_hat")))
                 for m in models)


def mmae_detector(fields, name: str, scenario_loop, z0, w0, step: float):
    """``type = "mmae"``: the switches of the mmae block named ``bank`` (module docstring), by
    ``rule`` (``posterior``, the default, or ``evidence``)."""
    bank = fields.text("bank")
    blocks = {b.name: b for b in scenario_loop.blocks if bank_hypotheses(b) is not None}
    if bank not in blocks:
        near = difflib.get_close_matches(bank, list(blocks), n=1)
        raise ScenarioError(f"{fields.path}.bank: {bank!r} is not an mmae block of the scenario"
                            + (f" (did you mean {near[0]!r}?)" if near else "")
                            + f"; mmae blocks: {', '.join(blocks) or 'none'}")
    models = bank_hypotheses(blocks[bank])
    shared = dict(settle=fields.integer("settle", 20, minimum=1, unit="samples"),
                  resolution=fields.number("resolution", 0.02, positive=True),
                  ignore_before=fields.number("ignore_before", 0.0, minimum=0.0),
                  kind=fields.text("kind", "proportional", choices=tuple(ACTUATOR_KINDS)))
    if fields.text("rule", "posterior", choices=RULES) == "evidence":
        dt = blocks[bank].dt or step
        return EvidenceSwitch(name, bank, models, dt, blocks[bank].source.reads_y.size,
                              fields.number("false_alarms_per_hour", 1.0, positive=True),
                              fields.integer("clear_window", 60, minimum=1, unit="samples"),
                              fields.integer("nis_window", 20, minimum=1, unit="samples"), **shared)
    threshold = fields.number("threshold", 0.9)
    if not 0.5 <= threshold < 1.0:
        raise ScenarioError(f"{fields.path}.threshold: must be in [0.5, 1) (a probability), got {threshold!r}")
    return HypothesisSwitch(name, bank, models, threshold, fields.integer("dwell", 1, minimum=1, unit="samples"),
                            **shared)
