"""A bank of unknown-input observers with zonotope thresholds on a quadrotor (Yang, Hu & Zhang).

``uvsym report uio-zonotope`` (:mod:`.report`, with the campaign of ``campaign.toml``),
``uvsym verify uio-zonotope`` (:mod:`.claims`), ``uvsym simulate abrupt_actuator1`` (or
``drift_actuator2``): scenario files over the study's plant with the ``uio_bank`` block and the
``zonotope_bands`` detector.
"""

from pathlib import Path

from derivations.uio_zonotope.claims import band_claims, uio_claims
from derivations.uio_zonotope.report import build
from uvsym.derivation import Derivation

__all__ = ["DERIVATION"]

SCENARIOS = Path(__file__).with_name("scenarios")


def claims() -> list:
    """The existence claims (refuted and proved) and each bank observer's band."""
    return uio_claims() + band_claims()


DERIVATION = Derivation(
    name="uio-zonotope",
    title="Unknown-input observer bank with zonotope thresholds on a quadrotor",
    build=build,
    claims=claims,
    scenarios={path.stem: path for path in sorted(SCENARIOS.glob("*.toml"))},
)
