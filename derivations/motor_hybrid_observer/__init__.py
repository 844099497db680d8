"""Yu et al. 2018 (:mod:`derivations.papers`) on uvsym's induction motor: its hybrid
unknown-input / adaptive observer, its LMI theorems checked by machine (refuted for this motor, with
exact evidence) and a corrected design that uvsym proves.

``uvsym report motor-hybrid-observer``, ``uvsym verify motor-hybrid-observer``,
``uvsym codegen motor-hybrid-observer -o DIR``, ``uvsym simulate incipient_speed_sensor`` (case a),
``step_speed_sensor`` (case b), ``healthy_motor`` (no fault): the shipped scenarios in ``scenarios/``.
"""

from pathlib import Path

from derivations.motor_hybrid_observer.claims import hybrid_claims
from derivations.motor_hybrid_observer.observer_sets import motor_hybrid
from derivations.motor_hybrid_observer.report import build
from uvsym.derivation import Derivation

__all__ = ["DERIVATION"]

SCENARIOS = Path(__file__).with_name("scenarios")

DERIVATION = Derivation(
    name="motor-hybrid-observer",
    title="Incipient speed-sensor faults: hybrid unknown-input / adaptive observer, LMIs machine-checked",
    build=build,
    claims=hybrid_claims,
    observer_sets={"motor-hybrid-observer": motor_hybrid},
    scenarios={path.stem: path for path in sorted(SCENARIOS.glob("*.toml"))},
)
