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

The threshold is a posterior probability: the bank's likelihoods already carry its noise model
(R and Q), so it is not calibrated again from a false-alarm rate; the rate it gives is measured
(the study's campaign).
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass

import numpy as np

from uvsym.diagnosis.detectors import check_samples, read_signal
from uvsym.diagnosis.events import Event
from uvsym.errors import DiagnosisError, ScenarioError
from uvsym.faults import ACTUATOR_KINDS

__all__ = ["HypothesisSwitch", "bank_hypotheses", "mmae_detector"]


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
        spread = {(m, u): self._spread(read_signal(result, f"{self.bank}.{m}.alpha_{u}_hat"))
                  for m, inputs in self.models for u in inputs}
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
            model, inputs = self.models[current]
            for u in inputs:
                width, value = spread[model, u][0][k], float(spread[model, u][1][k])
                if width <= self.resolution and abs(value - identified.get(u, np.inf)) > self.resolution:
                    identified[u] = value
                    events.append(Event(time, "identified", u, self.kind, value, detector=self.name))
        return events

    def _spread(self, estimate: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(range over the last ``settle`` samples, inf before there are that many; the estimate)."""
        spread = np.full(estimate.size, np.inf)
        if estimate.size >= self.settle:
            windows = np.lib.stride_tricks.sliding_window_view(estimate, self.settle)
            spread[self.settle - 1:] = windows.max(axis=1) - windows.min(axis=1)
        return spread, estimate

    def design(self) -> dict:
        return {"detector": self.name, "rule": "argmax_i p_i > threshold for dwell samples in a row switches the "
                "hypothesis", "bank": self.bank, "threshold": self.threshold, "dwell_samples": self.dwell,
                "identify_settle_samples": self.settle, "identify_resolution": self.resolution,
                "ignore_before_s": self.ignore_before, "kind": self.kind,
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


def mmae_detector(fields, name: str, scenario_loop, z0, w0, step: float) -> HypothesisSwitch:
    """``type = "mmae"``: the switches of the mmae block named ``bank`` (module docstring)."""
    bank = fields.text("bank")
    banks = {b.name: h for b in scenario_loop.blocks if (h := bank_hypotheses(b)) is not None}
    if bank not in banks:
        near = difflib.get_close_matches(bank, list(banks), n=1)
        raise ScenarioError(f"{fields.path}.bank: {bank!r} is not an mmae block of the scenario"
                            + (f" (did you mean {near[0]!r}?)" if near else "")
                            + f"; mmae blocks: {', '.join(banks) or 'none'}")
    threshold = fields.number("threshold", 0.9)
    if not 0.5 <= threshold < 1.0:
        raise ScenarioError(f"{fields.path}.threshold: must be in [0.5, 1) (a probability), got {threshold!r}")
    return HypothesisSwitch(name, bank, banks[bank], threshold,
                            fields.integer("dwell", 1, minimum=1, unit="samples"),
                            fields.integer("settle", 20, minimum=1, unit="samples"),
                            fields.number("resolution", 0.02, positive=True),
                            fields.number("ignore_before", 0.0, minimum=0.0),
                            fields.text("kind", "proportional", choices=tuple(ACTUATOR_KINDS)))
