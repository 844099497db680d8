"""Sensor-fault diagnosis with an adaptive LMS-FIR filter and fault-tolerant heading hold (paper 001).

``uvsym report sensor-fdi-lms``, ``uvsym verify sensor-fdi-lms``, ``uvsym codegen sensor-fdi-lms -o DIR``,
``uvsym simulate compass_30deg`` (the scenario files of ``scenarios/``).
"""

from pathlib import Path

from derivations.sensor_fdi_lms.claims import lms_claims
from derivations.sensor_fdi_lms.observer_sets import lms_set
from derivations.sensor_fdi_lms.report import build
from uvsym.derivation import Derivation

__all__ = ["DERIVATION"]

SCENARIOS = Path(__file__).with_name("scenarios")

DERIVATION = Derivation(
    name="sensor-fdi-lms",
    title="Sensor-fault diagnosis with an adaptive LMS-FIR filter, and fault-tolerant heading hold",
    build=build,
    claims=lms_claims,
    observer_sets={"sensor-fdi-lms": lms_set},
    scenarios={path.stem: path for path in sorted(SCENARIOS.glob("*.toml"))},
)
