"""What ``prove_identity`` claims once the symbolic steps give up: the sampled certificate's status at the
rounding boundary, its margin, and its method and reason when no point is evaluable, when the largest difference
lies between rounding and refutation, and when the symbolic steps ran out of time.

Expected values come from exact fractions of the double constants; each claim samples a single point (a box with
equal bounds) so that it takes a fraction of a second.
"""

from __future__ import annotations

from fractions import Fraction

import casadi as ca

from uvsym.verify import identity, prove_identity

SAMPLED = ("sampled: {n} points over {where}, mpmath 50 digits, each entry against the size of its terms, to the "
           "precision of the model's double constants (evidence, not a proof)")


def _scaled(factor: float, samples: int = 1, symbolic_seconds: float = 1.0):
    """factor x against x at the single point x = 1: relative difference |factor - 1| / (factor + 1)."""
    x = ca.SX.sym("x")
    return prove_identity("c x = x", factor * x, x, [x], "x = 1", box=([1.0], [1.0]), samples=samples,
                          symbolic_seconds=symbolic_seconds)


def _relative(factor: float) -> float:
    a = Fraction(factor)
    return float(abs(a - 1) / (a + 1))


def test_no_evaluable_point_is_inconclusive_and_says_so():
    # (1 + 1e-13) / x against 1 / x at x = 0 only: every sample is a pole
    x = ca.SX.sym("x")
    certificate = prove_identity("pole", (1 + 1e-13) / x, 1 / x, [x], "x = 0", box=([0.0], [0.0]), samples=3,
                                 symbolic_seconds=1.0)
    assert certificate.status == "inconclusive"
    assert certificate.method == SAMPLED.format(n=0, where="the stated box")
    assert certificate.reason == "not shown zero symbolically; no sample point was evaluable"
    assert certificate.margin is None and certificate.counterexample is None and certificate.details == {}


def test_a_single_evaluated_point_is_evidence():
    certificate = _scaled(1 + 1e-13)
    assert certificate.status == "checked" and certificate.details["points"] == 1
    assert certificate.method == SAMPLED.format(n=1, where="the stated box")


def test_a_largest_difference_exactly_at_rounding_is_still_checked_with_zero_margin():
    # x + z against z at (d, z) with d = 1e-12 and 2 z the double nearest 1 - d: relative difference d / (d + 2 z),
    # which rounds to the double 1e-12 = ROUNDING itself (a tie: not above rounding)
    d = 1e-12
    z = (1 - d) / 2
    assert float(Fraction(d) / (Fraction(d) + 2 * Fraction(z))) == 1e-12
    x, y = ca.SX.sym("x"), ca.SX.sym("z")
    certificate = prove_identity("tie", x + y, y, [x, y], "one point", box=([d, z], [d, z]), samples=2,
                                 symbolic_seconds=1.0)
    assert certificate.status == "checked"
    assert certificate.margin == 0.0
    assert certificate.details == {"largest_relative_difference": 1e-12, "points": 2}


def test_the_margin_of_checked_evidence_is_rounding_minus_the_largest_difference():
    certificate = _scaled(1 + 1e-13)
    worst = _relative(1 + 1e-13)  # ~5e-14
    assert certificate.status == "checked"
    assert certificate.margin == 1e-12 - worst and certificate.margin > 0


def test_a_difference_between_rounding_and_refutation_is_inconclusive_with_its_size():
    certificate = _scaled(1 + 2e-11, samples=2)  # relative difference 2e-11 / (2 + 2e-11) ~ 1e-11
    worst = _relative(1 + 2e-11)
    assert f"{worst:.3g}" == "1e-11"
    assert certificate.status == "inconclusive"
    assert certificate.margin == -worst
    assert certificate.method == SAMPLED.format(n=2, where="the stated box")
    assert certificate.reason == ("not shown zero symbolically; largest relative difference 1e-11 is above rounding "
                                  "but below 1e-10")


def test_symbolic_steps_out_of_time_are_named_in_the_reason(monkeypatch):
    monkeypatch.setattr(identity, "_symbolic", lambda entries, seconds: "timeout")
    checked = _scaled(1 + 1e-13, symbolic_seconds=0.25)
    assert checked.status == "checked" and checked.reason == "symbolic steps over 0.25 s"
    band = _scaled(1 + 2e-11, symbolic_seconds=0.25)
    assert band.status == "inconclusive"
    assert band.reason == ("symbolic steps over 0.25 s; largest relative difference 1e-11 is above rounding but "
                           "below 1e-10")
