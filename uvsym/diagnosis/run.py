"""The diagnosis of a scenario's [diagnosis] table, built for its vehicle and observers."""

from __future__ import annotations

import numpy as np

from uvsym.diagnosis.monitor import ActuatorDiagnosis, residual_noise
from uvsym.errors import DiagnosisError
from uvsym.sim.scenario import Scenario
from uvsym.sim.simulation import scenario_observers

__all__ = ["diagnosis_for"]


def diagnosis_for(scenario: Scenario) -> ActuatorDiagnosis:
    """An :class:`ActuatorDiagnosis` for ``scenario`` (which must have a [diagnosis] table), its noise
    levels taken at the initial state."""
    settings = scenario.diagnosis
    if settings is None:
        raise DiagnosisError(f"scenario {scenario.name!r} has no [diagnosis] table")
    observer, K = scenario_observers(scenario.model, scenario.observers)[settings.observer]
    y0 = np.concatenate([scenario.eta0, scenario.nu0])
    noise = residual_noise(scenario.model, observer, K, scenario.step, settings, y0)
    return ActuatorDiagnosis(scenario.model, observer, K, scenario.step, noise, settings)
