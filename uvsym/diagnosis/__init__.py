"""Continuous, per-actuator fault diagnosis with a decision log (detection, isolation,
identification, clearing; ambiguous and unexcited where the data cannot tell).

The names below are imported on first use (:mod:`uvsym.lazy`): reading or writing a decision log
(:mod:`uvsym.diagnosis.events`, as every ``uvsym simulate`` does) does not import the diagnosis itself.
"""

from uvsym.lazy import lazy_exports

_EXPORTS = {  # name -> the submodule that defines it
    **dict.fromkeys(["EVENTS", "Event", "write_events"], "events"),
    **dict.fromkeys(["ActuatorDiagnosis", "residual_noise"], "monitor"),
    "DiagnosisSettings": "settings",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
