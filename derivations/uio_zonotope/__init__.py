"""A bank of unknown-input observers with zonotope thresholds on a quadrotor (Yang, Hu & Zhang).

``uvsym report uio-zonotope`` (:mod:`.report`), ``uvsym verify uio-zonotope`` (:mod:`.claims`),
``uvsym simulate FILE.toml`` for a file with ``study = "uio-zonotope"`` (:mod:`.scenario`; shipped:
``abrupt_actuator1``, ``drift_actuator2``).
"""

from pathlib import Path

from derivations.uio_zonotope.claims import enclosure_claim, uio_claims
from derivations.uio_zonotope.report import build
from derivations.uio_zonotope.scenario import simulate
from uvsym.derivation import Derivation

__all__ = ["DERIVATION"]

SCENARIOS = Path(__file__).with_name("scenarios")


def claims() -> list:
    """The existence claims (refuted and proved) and the Monte Carlo enclosure check."""
    return uio_claims() + [enclosure_claim()]


DERIVATION = Derivation(
    name="uio-zonotope",
    title="Unknown-input observer bank with zonotope thresholds on a quadrotor",
    build=build,
    claims=claims,
    simulate=simulate,
    scenarios={path.stem: path for path in sorted(SCENARIOS.glob("*.toml"))},
)
