"""A Luenberger observer of the induction motor through every stage of uvsym (plant, LMI gain,
closed loop with a speed-sensor fault, C, claims, report): the general layer at work on a
plant that is not a vehicle.

``uvsym report motor-luenberger``, ``uvsym verify motor-luenberger``,
``uvsym codegen motor-luenberger -o DIR [--decay RATE] [--dt STEP]``, ``uvsym simulate motor_luenberger_step``
(and ``motor_luenberger_incipient``): the shipped scenarios in ``scenarios/``.
"""

from pathlib import Path

from derivations.motor_luenberger.claims import motor_claims
from derivations.motor_luenberger.observer_sets import motor_luenberger
from derivations.motor_luenberger.report import build
from uvsym.derivation import Derivation

__all__ = ["DERIVATION"]

SCENARIOS = Path(__file__).with_name("scenarios")

DERIVATION = Derivation(
    name="motor-luenberger",
    title="Luenberger observer of the induction motor: every stage on a non-marine plant",
    build=build,
    claims=motor_claims,
    observer_sets={"motor-luenberger": motor_luenberger},
    scenarios={path.stem: path for path in sorted(SCENARIOS.glob("*.toml"))},
)
