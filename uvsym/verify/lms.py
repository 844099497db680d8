"""The LMS step-size claim: ``mu < 1 / (M P_u)`` for a recorded input, checked in exact rationals.

For the update ``C <- C - 2 mu e U`` of an order-M FIR filter driven by u, independence theory
(Widrow & Stearns 1985) gives mean-square stability for ``0 < mu < 1 / tr R_UU`` with ``tr R_UU
= M P_u``, ``P_u = E[u^2]``. The claim takes P_u as the mean square of the recorded samples,
computed exactly from their binary floating-point values (``fractions.Fraction``), so the
inequality itself is decided without rounding: ``proved`` means ``mu M P_u < 1`` holds exactly
for that input; ``refuted`` carries the exact product. What the inequality implies about the
adaptive filter rests on the independence assumption; the certificate's method says so.
"""

from __future__ import annotations

import time
from fractions import Fraction

import numpy as np

from uvsym.errors import VerificationError
from uvsym.verify.certificate import Certificate

__all__ = ["lms_step_claim"]


def lms_step_claim(mu: float, order: int, u, *, expected: str = "proved", claim: str | None = None) -> Certificate:
    """Certificate of ``mu < 1 / (M P_u)`` with P_u the mean square of the samples u (module docstring).

    margin: ``1 - mu M P_u`` (float). VerificationError for a mu that is not positive and finite,
    an order below 1, or u empty or not finite.
    """
    started = time.perf_counter()
    u = np.asarray(u, dtype=float).reshape(-1)
    if not (isinstance(mu, (int, float)) and np.isfinite(mu) and mu > 0):
        raise VerificationError(f"lms step claim: mu must be positive and finite, got {mu!r}")
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 1:
        raise VerificationError(f"lms step claim: order M must be a positive integer, got {order!r}")
    if u.size == 0 or not np.all(np.isfinite(u)):
        raise VerificationError("lms step claim: the input samples u must be finite and at least one")
    power = sum((Fraction(float(v)) ** 2 for v in u), Fraction(0)) / u.size
    product = Fraction(float(mu)) * order * power
    bound = 1 / (order * power) if power > 0 else None
    status = "proved" if product < 1 else "refuted"
    details = {"mu": float(mu), "order": int(order), "input_power": float(power), "samples": int(u.size),
               "mu_M_P_u": float(product), "bound": None if bound is None else float(bound)}
    return Certificate(
        claim=claim or f"LMS step mu = {mu:g} below the mean-square bound 1 / (M P_u)",
        set=f"the recorded input ({u.size} samples, P_u = {float(power):.4g}), M = {order}",
        method="exact rational arithmetic on the samples' binary values; stability of the filter from the "
               "independence-theory bound (Widrow & Stearns 1985)",
        status=status, expected=expected, margin=float(1 - product), seconds=time.perf_counter() - started,
        counterexample=None if status == "proved" else {"mu_M_P_u": float(product), "bound": details["bound"]},
        reason="" if status == "proved" else f"mu M P_u = {float(product):.6g} >= 1", details=details)
