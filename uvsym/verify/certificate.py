"""Certificates: what was claimed, over which set, by which method, with which margin and outcome."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from uvsym.errors import VerificationError

__all__ = ["STATUSES", "Certificate"]

STATUSES = ("proved", "checked", "refuted", "inconclusive")


@dataclass(frozen=True)
class Certificate:
    """One checked claim. ``status`` says what was shown:

    - ``proved``: a rigorous argument (exact rationals, or outward-rounded intervals) over the whole set;
    - ``checked``: numerical evidence only (e.g. sampling at N points of the set, stated in ``method``),
      never counted as a proof;
    - ``refuted``: a ``counterexample``, re-checked rigorously (exact arithmetic or interval bounds);
    - ``inconclusive``: neither, with the ``reason``.

    ``expected`` is the status the claim should have (negative controls expect refuted); ``margin``
    how far from failing (method-specific, stated in ``method``)."""

    claim: str
    set: str
    method: str
    status: str
    expected: str = "proved"
    margin: float | None = None
    seconds: float = 0.0
    counterexample: dict | None = None
    reason: str = ""
    details: dict = field(default_factory=dict)

    def __post_init__(self):
        for name in ("status", "expected"):
            if getattr(self, name) not in STATUSES:
                raise VerificationError(f"certificate {name} must be one of {STATUSES}, got {getattr(self, name)!r}")

    @property
    def proved(self) -> bool:
        """True only for a rigorous proof (``checked`` evidence is not one)."""
        return self.status == "proved"

    @property
    def as_expected(self) -> bool:
        """True when the outcome is the expected one."""
        return self.status == self.expected

    def counterexample_summary(self, digits: int = 3) -> str:
        """One line on what the counterexample shows ("" without one), numbers to ``digits`` digits."""
        example = self.counterexample or {}
        if "eigenvalue_modulus" in example:
            return (f"the sampled map has an eigenvalue of modulus {example['eigenvalue_modulus']:.{digits}g} "
                    f">= {example['rho']:.{digits}g}")
        if "eigenvalue_real" in example:
            return (f"a vertex's eigenvalue has real part {example['eigenvalue_real']:.{digits}g} "
                    f"> -gamma = {0.0 - example['gamma']:.{digits}g}")
        if "V_dot" in example:
            point = ", ".join(f"{name} = {value:.{digits}g}" for name, value in example["x"].items())
            return f"at {point}: V' = {example['V_dot']:.{digits}g} > {example['bound']:.{digits}g}"
        if "reached" in example:
            return (f"at step {example['step']}, output {example['output']}: a vertex reaches "
                    f"{example['reached']:.{digits}g}, beyond the limit {example['limit']:.{digits}g}")
        if "relative_difference" in example:
            return (f"the two sides differ by {example['relative_difference']:.{digits}g} (relative to the size of "
                    f"their terms) at a sampled point")
        return ""

    def to_dict(self) -> dict:
        """JSON-friendly form (margins that are not finite become None)."""
        margin = self.margin if self.margin is None or math.isfinite(self.margin) else None
        return {"claim": self.claim, "set": self.set, "method": self.method, "status": self.status,
                "expected": self.expected, "margin": margin, "seconds": self.seconds,
                "counterexample": self.counterexample, "reason": self.reason, "details": self.details}
