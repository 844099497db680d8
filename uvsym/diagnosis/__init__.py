"""Continuous, per-actuator fault diagnosis with a decision log (detection, isolation,
identification, clearing; ambiguous and unexcited where the data cannot tell)."""

from uvsym.diagnosis.events import EVENTS, Event, write_events
from uvsym.diagnosis.monitor import ActuatorDiagnosis, residual_noise
from uvsym.diagnosis.settings import DiagnosisSettings

__all__ = ["EVENTS", "ActuatorDiagnosis", "DiagnosisSettings", "Event", "residual_noise", "write_events"]
