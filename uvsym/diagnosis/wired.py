"""The continuous actuator diagnosis as a detector of a scenario over a plant (``type = "fault_diagnosis"``).

It decides on the finished record, as the vehicle format's [diagnosis] does without ``correct``:
:class:`~uvsym.diagnosis.monitor.ActuatorDiagnosis` reads the measured states (``y``), the
commands the bias observer's block read (what healthy actuators deliver: the plant's inputs take
them at once in this format) and that block's ``f_hat.<force>``. ``observer`` names the
actuator_observer block (of kind bias); the other fields are the [diagnosis] table's (kinds,
actuators, window_s, period_s, confirm, false_alarm_rate, noise, ...), the noise defaulting to
the scenario's whole-run Gaussian noise on the vehicle's states. Events name the actuator (the
plant input) with the detector's name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from uvsym.diagnosis.detectors import read_signal
from uvsym.diagnosis.events import Event
from uvsym.diagnosis.monitor import ActuatorDiagnosis, residual_noise
from uvsym.diagnosis.settings import DiagnosisSettings
from uvsym.errors import ScenarioError
from uvsym.faults import SensorFault
from uvsym.sim.actuator_block import ActuatorObserverBlock
from uvsym.sim.fields import Fields

__all__ = ["WiredDiagnosis", "fault_diagnosis_detector"]


@dataclass(frozen=True)
class WiredDiagnosis:
    """The actuator diagnosis of the bias observer block ``observer`` (module docstring); commands:
    the logged signals (``<group>.<label>``) of the plant's inputs as commanded, in the inputs' order."""

    name: str
    observer: ActuatorObserverBlock
    commands: tuple[str, ...]
    settings: DiagnosisSettings

    def decide(self, result) -> list[Event]:
        block, model = self.observer, self.observer.model
        y = np.column_stack([read_signal(result, f"y.{label}") for label in model.state_labels])
        x0 = np.array([read_signal(result, f"x.{label}")[0] for label in model.state_labels])
        u_expected = np.column_stack([read_signal(result, name) for name in self.commands])
        f_hat = np.column_stack([read_signal(result, f"{block.name}.{name}")
                                 for name in block.publishes.names[model.dof:]])
        dt = float(block.dt)
        noise = residual_noise(model, block.design, block.K, dt, self.settings, x0)
        diagnosis = ActuatorDiagnosis(model, block.design, block.K, dt, noise, self.settings)
        diagnosis.update(np.asarray(result.t, dtype=float),
                         {"y": y, "u_expected": u_expected, f"f_hat/{self.settings.observer}": f_hat})
        return [replace(event, detector=self.name) for event in diagnosis.events]

    def design(self) -> dict:
        s = self.settings
        return {"detector": self.name, "rule": "GLR of actuator-fault hypotheses on the bias observer's estimate, "
                                               "threshold from a false-alarm rate per test (Bonferroni)",
                "observer": self.observer.name, "kinds": list(s.kinds), "window_s": s.window_s,
                "period_s": s.period_s, "confirm": s.confirm, "false_alarm_rate": s.false_alarm_rate,
                "noise": dict(s.noise)}


def fault_diagnosis_detector(fields: Fields, name: str, scenario_loop, z0, w0, step: float) -> WiredDiagnosis:
    """The detector of a ``[[detectors]]`` table of type fault_diagnosis (module docstring)."""
    from uvsym.sim.scenario import diagnosis_settings, whole_run_noise
    from uvsym.sim.system_scenario import logged_input

    blocks = {b.name: b for b in scenario_loop.blocks}
    candidates = [b for b, blk in blocks.items()
                  if isinstance(blk, ActuatorObserverBlock) and blk.design.kind == "bias"]
    observer = fields.raw("observer", candidates[0] if len(candidates) == 1 else None, "string",
                          "an actuator_observer block of kind bias", "the scenario's one such block")
    if observer not in candidates:
        raise ScenarioError(f"{fields.path}.observer: {observer!r} is not an actuator_observer block of kind bias; "
                            f"such blocks: {', '.join(candidates) or 'none (add one)'}")
    block = blocks[observer]
    plant = scenario_loop.plant
    noise = whole_run_noise([f for f in scenario_loop.faults if isinstance(f, SensorFault)], plant.y.names)
    settings = diagnosis_settings(fields, block.model, observer, noise, math.inf, step)
    if settings.correct:
        raise ScenarioError(f"{fields.path}.correct: a command correction changes the loop while it runs: it needs "
                            "the vehicle format's loop ([diagnosis] with correct = true); here the diagnosis "
                            "decides on the finished record")
    commands = tuple(logged_input(name, scenario_loop) for name in block.reads.names[2 * block.model.dof:])
    return WiredDiagnosis(name, block, commands, settings)
