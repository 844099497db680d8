"""Unit tests of ``prove_identity``'s outcomes: the certificate's fields, the sampled evidence (count, seed,
box, zero scales, mpmath evaluation) and the re-check that turns a large sampled difference into a refutation.

Expected values come from exact fractions of the double constants or from hand computation; claims are tiny
(one or two symbols) so that each proof takes well under a second.
"""

from __future__ import annotations

import time
from fractions import Fraction

import casadi as ca
import numpy as np
import pytest
import sympy as sp

from uvsym.verify import prove_identity
from uvsym.verify.identity import _points, _rational_function

SAMPLED = ("sampled: {points} points over {where}, mpmath 50 digits, each entry against the size of its terms, to the "
           "precision of the model's double constants (evidence, not a proof)")


def test_an_exact_proof_fills_every_field_of_its_certificate():
    x = ca.SX.sym("x")
    before = time.perf_counter()
    certificate = prove_identity("x (x + 1) = x^2 + x", x * (x + 1), x ** 2 + x, [x], "all x", expected="refuted",
                                 symbolic_seconds=1.0)
    elapsed = time.perf_counter() - before
    assert certificate.claim == "x (x + 1) = x^2 + x" and certificate.set == "all x"
    assert certificate.status == "proved" and certificate.expected == "refuted"
    assert certificate.method == ("exact rational arithmetic on the double constants (converted exactly), "
                                  "transcendental terms as independent symbols: the difference is zero")
    assert isinstance(certificate.seconds, float) and 0.0 < certificate.seconds <= elapsed


def test_a_proof_by_simplification_says_so():
    x, y = ca.SX.sym("x"), ca.SX.sym("y")  # exp(x), exp(y), exp(x + y) are independent atoms to the exact step
    certificate = prove_identity("e^x e^y = e^(x + y)", ca.exp(x) * ca.exp(y), ca.exp(x + y), [x, y], "all x, y",
                                 symbolic_seconds=1.0)
    assert certificate.status == "proved"
    assert certificate.method == "sympy simplification to zero, rational constants (exact)"


def test_sampling_evaluates_thirty_points_against_the_size_of_the_terms():
    # x (1 + 1e-13) - x over |x (1 + 1e-13)| + |x|: the same relative difference (a - 1) / (a + 1) at every x != 0,
    # with a the double 1 + 1e-13 taken exactly
    x = ca.SX.sym("x")
    certificate = prove_identity("near", x * (1 + 1e-13), x, [x], "all x", symbolic_seconds=1.0)
    a = Fraction(1 + 1e-13)
    assert certificate.status == "checked" and certificate.reason == "not shown zero symbolically"
    # 30 drawn, and 4 where sign, |.|, floor, fmod and copysign jump: x = 0, +-1/2, +-3/2
    assert certificate.method == SAMPLED.format(points=34, where="the reals at scales 1e-3 to 1e8")
    assert certificate.details["points"] == 34
    assert certificate.details["largest_relative_difference"] == float((a - 1) / (a + 1))


def test_the_default_seed_is_zero_and_the_seed_moves_the_points():
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    # relative difference 1e-13 |x| / (2 |x| + 2 |y| + 2): depends on the point, largest at the drawn large |x|
    lhs, rhs = x * (1 + 1e-13) + y + 1, x + y + 1
    default = prove_identity("near", lhs, rhs, [x, y], "all x, y", symbolic_seconds=1.0)
    zero = prove_identity("near", lhs, rhs, [x, y], "all x, y", seed=0, symbolic_seconds=1.0)
    one = prove_identity("near", lhs, rhs, [x, y], "all x, y", seed=1, symbolic_seconds=1.0)
    assert default.status == zero.status == one.status == "checked"
    assert default.details == zero.details
    assert one.details["largest_relative_difference"] != zero.details["largest_relative_difference"]


def test_a_box_is_sampled_instead_of_the_reals():
    # |x| = x holds on [1, 2] only: sampling the reals would meet x < 0 and refute it
    x = ca.SX.sym("x")
    certificate = prove_identity("|x| = x", ca.fabs(x), x, [x], "1 <= x <= 2", box=([1.0], [2.0]),
                                 symbolic_seconds=1.0)
    assert certificate.status == "checked"
    assert certificate.method == SAMPLED.format(points=30, where="the stated box")


def test_a_point_where_both_sides_and_their_size_vanish_counts_as_no_difference():
    # at x = 0 the difference and its scale are both exactly 0: relative difference 0, not 0 / 0
    x = ca.SX.sym("x")
    certificate = prove_identity("near", x * (1 + 1e-13), x, [x], "x = 0", box=([0.0], [0.0]), symbolic_seconds=1.0)
    assert certificate.status == "checked"
    assert certificate.details == {"largest_relative_difference": 0.0, "points": 30}


def test_a_sample_point_at_a_pole_is_skipped_and_sampling_goes_on():
    # (1 + 1e-13) / x against 1 / x over [0, 1]: the points at x = 0 (a box end) are not evaluable
    x = ca.SX.sym("x")
    certificate = prove_identity("near", (1 + 1e-13) / x, 1 / x, [x], "0 <= x <= 1", box=([0.0], [1.0]),
                                 symbolic_seconds=1.0)
    poles = int(np.sum(_points(np.random.default_rng(0), 1, (np.zeros(1), np.ones(1)), 30)[:, 0] == 0.0))
    assert 0 < poles < 29 and certificate.status == "checked"
    assert certificate.details["points"] == 30 - poles


def test_transcendental_terms_are_evaluated_with_mpmath():
    x = ca.SX.sym("x")
    certificate = prove_identity("near", ca.sin(x) * (1 + 1e-13), ca.sin(x), [x], "all x", symbolic_seconds=1.0)
    a = Fraction(1 + 1e-13)
    assert certificate.status == "checked" and certificate.details["points"] == 34
    assert certificate.details["largest_relative_difference"] == float((a - 1) / (a + 1))


def _scaled(gap: float):
    """a x against x at the single point x = 1.126, with a = 1 + gap / 1.126: the difference is ~gap and the size
    of the terms (a + 1) 1.126 ~ 2.252, so a refutation needs gap > 2e-10 * 2.252 = 4.504e-10."""
    x = ca.SX.sym("x")
    return prove_identity("a x = x", (1 + gap / 1.126) * x, x, [x], "x = 1.126", box=([1.126], [1.126]),
                          symbolic_seconds=1.0)


def test_a_gap_above_twice_the_threshold_is_refuted_by_intervals():
    certificate = _scaled(4.75e-10)  # 4.75e-10 > 4.504e-10 (but below 3e-10 * 2.252 and 2e-10 * 2.5)
    assert certificate.status == "refuted"
    assert certificate.method == ("mpmath evaluation at 50 digits, entry 0 against the size of its terms; "
                                  "re-checked by interval evaluation (outward rounding)")


def test_a_gap_below_twice_the_threshold_is_not_refuted():
    certificate = _scaled(4.3e-10)  # relative 4.3e-10 / 2.252 = 1.9e-10 > 1e-10, yet 4.3e-10 < 4.504e-10
    assert certificate.status == "inconclusive"


def test_where_the_graph_lacks_intervals_mpmath_interval_arithmetic_confirms_a_difference():
    # (x + 1e-9)^2 against x^2 at x = 0.5: difference ~1e-9, size of the terms 0.5^2 + 0.5^2 + 2 tan(0.5) ~ 1.59, so
    # a relative difference ~6.3e-10 > 1e-10 (lost at low precision, where x + 1e-9 rounds to x); tan (on both
    # sides, cancelled in the difference) leaves the CasADi graph's intervals out, not mpmath's
    x = ca.SX.sym("x")
    certificate = prove_identity("square", (x + 1e-9) ** 2 + ca.tan(x), x ** 2 + ca.tan(x), [x], "x = 0.5",
                                 box=([0.5], [0.5]), symbolic_seconds=1.0)
    assert certificate.status == "refuted"
    assert certificate.method == ("mpmath evaluation at 50 digits, entry 0 against the size of its terms; "
                                  "re-checked by mpmath interval arithmetic at 100 digits (outward rounding)")


def _cancelling(x):
    """(x + 1)^2 - x^2 - 2 x - 1: zero, but -1 at x = 1e30 and 50 digits (where (x + 1)^2, 200 bits, loses its
    last term), exactly 0 at 100 digits."""
    return (x + 1) ** 2 - x ** 2 - 2 * x - 1


def test_without_intervals_a_rounding_artefact_is_not_refuted():
    # (1 + 1e-13) / (D + 2) against 1/2: relative difference ~5e-14 at 100 digits (D = 0), 1/3 at 50 digits
    # (D = -1); tan (on both sides, cancelled in the difference) leaves intervals out
    x = ca.SX.sym("x")
    lhs = (1 + 1e-13) / (_cancelling(x) + 2) + ca.tan(x)
    certificate = prove_identity("artefact", lhs, 0.5 + ca.tan(x), [x], "x = 1e30", box=([1e30], [1e30]),
                                 symbolic_seconds=1.0)
    assert certificate.status == "inconclusive"


def test_a_recheck_that_fails_to_evaluate_is_not_a_refutation():
    # 1 / D against 0: relative difference 1 at 50 digits (D = -1), a division by zero at 100 (D = 0)
    x = ca.SX.sym("x")
    certificate = prove_identity("artefact", 1 / _cancelling(x), ca.SX(0), [x], "x = 1e30", box=([1e30], [1e30]),
                                 symbolic_seconds=1.0)
    assert certificate.status == "inconclusive"


def test_a_refutation_names_the_entry_and_the_point_by_the_symbols_names():
    # entry 0 agrees, entry 1 is 2 x against x: relative difference |2 x - x| / (2 |x| + |x|) = 1/3 at x = 3;
    # the symbol's name "p.x" is no Python identifier
    x = ca.SX.sym("p.x")
    certificate = prove_identity("(x, 2 x) = (x, x)", ca.vertcat(x, 2 * x), ca.vertcat(x, x), [x], "x = 3",
                                 expected="refuted", box=([3.0], [3.0]), symbolic_seconds=1.0)
    assert certificate.status == "refuted" and certificate.margin == -1 / 3
    assert certificate.counterexample == {"point": {"p.x": 3.0}, "entry": 1, "relative_difference": 1 / 3}
    assert certificate.method.startswith("mpmath evaluation at 50 digits, entry 1 against the size of its terms; ")


def test_a_gap_exactly_at_twice_the_threshold_is_not_refuted():
    # x + z against z at x = 2^-33, z = (S - 2^-33) / 2: the difference is x exactly (an exact interval), the size
    # of the terms x + 2 z = S exactly, and S is the double with 2e-10 * S rounding to 2^-33: a tie, not above it
    gap = 2.0 ** -33
    size = min((gap / 2e-10 + i * np.spacing(gap / 2e-10) for i in range(-20, 21)),
               key=lambda s: abs(2e-10 * s - gap))
    assert 2e-10 * size == gap
    z = (size - gap) / 2
    assert Fraction(gap) + 2 * Fraction(z) == Fraction(size)
    x, y = ca.SX.sym("x"), ca.SX.sym("z")
    certificate = prove_identity("tie", x + y, y, [x, y], "one point", box=([gap, z], [gap, z]), symbolic_seconds=1.0)
    assert certificate.status == "inconclusive"
    assert certificate.margin == -float(Fraction(gap) / Fraction(size))


def test_a_gap_equal_to_the_threshold_rounded_up_is_not_refuted():
    # a against b at a = y, b = w: the gap y - w = d = 3 2^-33 and the size y + w = s are exact in both the graph's and
    # mpmath's intervals; s is the double whose exact product 2e-10 s lies in (d - ulp, d], so twice the threshold,
    # rounded up, is d itself: a tie at every precision, not above it
    d = 3 * 2.0 ** -33
    near = float(Fraction(d) / Fraction(2e-10))
    s = next(c for c in (near + i * np.spacing(near) for i in range(-3, 4))
             if Fraction(np.nextafter(d, 0.0)) < Fraction(2e-10) * Fraction(c) <= Fraction(d))
    y, w = (s + d) / 2, (s - d) / 2
    assert Fraction(y) - Fraction(w) == Fraction(d) and Fraction(y) + Fraction(w) == Fraction(s)
    a, b = ca.SX.sym("a"), ca.SX.sym("b")
    certificate = prove_identity("tie", a, b, [a, b], "one point", box=([y, w], [y, w]), symbolic_seconds=1.0)
    assert certificate.status == "inconclusive"
    assert certificate.reason.endswith("is above 1e-10 at 50 digits, not confirmed by the interval re-check")


def test_rational_functions_are_told_from_other_expressions():
    x, y = sp.symbols("x y", real=True)
    for rational in (x, sp.Rational(3, 7), x + y, 2 * x * y, x ** -3 / (y + 1) - sp.Rational(1, 3)):
        assert _rational_function(rational), rational
    for other in (sp.sin(x), sp.sqrt(x) + 1, x ** sp.Rational(1, 3) * y, sp.pi * x, sp.Float(0.5) * x, sp.Abs(x)):
        assert not _rational_function(other), other


def test_without_the_graphs_intervals_a_cancellation_beyond_a_hundred_digits_is_not_a_refutation():
    # (1 + 1e-13) / (D + 2) against 1/2 at x = 1e60: D is exactly 0 (relative difference 5e-14, below rounding), but
    # (x + 1)^2 takes 400 bits: D is -1 at 50 and at 100 digits (a relative difference of 1/3 at one evaluation);
    # mpmath intervals at 100 digits hold D + 2 in an interval around 0, and from 121 digits on D is exactly 0
    x = ca.SX.sym("x")
    lhs = (1 + 1e-13) / (_cancelling(x) + 2) + ca.tan(x)
    certificate = prove_identity("artefact", lhs, 0.5 + ca.tan(x), [x], "x = 1e60", box=([1e60], [1e60]),
                                 symbolic_seconds=1.0)
    assert certificate.status == "inconclusive" and certificate.margin < -0.1
    assert certificate.reason.endswith("is above 1e-10 at 50 digits, not confirmed by the interval re-check")


def _threshold_tie(rest: Fraction, constant: float):
    """x + 1/4 / (D + 2) + w1 + w2 + tan(u) against constant + w1 + w2 + tan(u) at x = 1e-10 (the double), u = 0,
    v = 1e30 in D, with w1 + w2 = rest / 2 exactly (two doubles)."""
    w1 = float(rest / 2)
    w2 = float(rest / 2 - Fraction(w1))
    assert Fraction(w1) + Fraction(w2) == rest / 2
    x, a, b, v, u = (ca.SX.sym(name) for name in ("x", "a", "b", "v", "u"))
    lhs = x + 0.25 / (_cancelling(v) + 2) + a + b + ca.tan(u)
    rhs = constant + a + b + ca.tan(u)
    point = [1e-10, w1, w2, 1e30, 0.0]
    return prove_identity("tie", lhs, rhs, [x, a, b, v, u], "one point", box=(point, point), symbolic_seconds=1.0)


def test_without_intervals_a_relative_difference_exactly_at_the_threshold_is_not_confirmed():
    # t = 1/4 against t / 2, w1 + w2 = (3/4 - x) / 2: at 100 digits (D = 0) the difference is x and the size of the
    # terms x + 2 (w1 + w2) + 3 t / 2 - t / 2 = 1, a relative difference of exactly 1e-10, not above it; at 50 digits
    # (D = -1) it is large
    certificate = _threshold_tie(Fraction(3, 4) - Fraction(1e-10), 0.125)
    assert certificate.status == "inconclusive"


def test_a_sampled_relative_difference_exactly_at_the_threshold_is_not_rechecked():
    # t = 1/4 against t, w1 + w2 = (1/2 - x) / 2: at 50 digits (D = -1) the difference is x and the size of the terms
    # x + t + 2 (w1 + w2) + t = 1, a relative difference of exactly 1e-10, not above it (at 100 digits it is large)
    certificate = _threshold_tie(Fraction(1, 2) - Fraction(1e-10), 0.25)
    assert certificate.status == "inconclusive" and certificate.margin == -1e-10
    assert certificate.reason == ("not shown zero symbolically; largest relative difference 1e-10 is above rounding "
                                  "but below 1e-10")


def test_a_size_of_the_terms_inflated_by_a_cancellation_beyond_a_hundred_digits_does_not_hide_a_refutation():
    # (2 + 6.8e-10) y - y + sin(D) at y = 1, x = 1e60: exactly 1 + 6.8e-10 (D = 0), size 3 + 6.8e-10; the graph's
    # intervals bound the difference below by 6.8e-10 (sin(D) in [-1, 1]) > 2e-10 * 3: a refutation; one evaluation
    # at 100 digits (D = -1) adds |sin(-1)| = 0.84 to the size and 2e-10 * 3.84 = 7.7e-10 would hide it; intervals at
    # 100 digits bound the size by 4 + 6.8e-10 (too loose), at 200 digits by 3 + 6.8e-10
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    certificate = prove_identity("false", (2 + 6.8e-10) * y + ca.sin(_cancelling(x)), y, [x, y], "one point",
                                 box=([1e60, 1.0], [1e60, 1.0]), symbolic_seconds=1.0)
    assert certificate.status == "refuted"


def _sine_of_cancelling(at: float):
    """(2 + 6.8e-10) y + sin(D) against y at y = 1: false (the difference is 1 + 6.8e-10), refutable by the
    graph's gap bound 6.8e-10 once the size of the terms is bounded by less than 3.4 (it is 3 + 6.8e-10), which
    takes the digits of (x + 1)^2 at x = ``at``: 2 log10(at) of them."""
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    return prove_identity("false", (2 + 6.8e-10) * y + ca.sin(_cancelling(x)), y, [x, y], "one point",
                          box=([at, 1.0], [at, 1.0]), symbolic_seconds=1.0)


def test_the_recheck_raises_its_precision_to_four_hundred_digits_and_no_further():
    assert _sine_of_cancelling(1e150).status == "refuted"  # 300 digits needed
    beyond = _sine_of_cancelling(1e250)  # 500 digits needed
    assert beyond.status == "inconclusive" and "not confirmed by the interval re-check" in beyond.reason


def test_an_operation_without_an_interval_extension_is_never_refuted():
    # 2 erf(x) against erf(x) at x = 1.5: relative difference 1/3, plainly false, but erf has no
    # outward-rounded extension here: inconclusive, with the unconfirmed difference in the reason
    x = ca.SX.sym("x")
    certificate = prove_identity("2 erf = erf", 2 * ca.erf(x), ca.erf(x), [x], "x = 1.5", box=([1.5], [1.5]),
                                 symbolic_seconds=1.0)
    assert certificate.status == "inconclusive" and certificate.margin == -1 / 3
    assert certificate.reason == ("not shown zero symbolically; largest relative difference 0.333 is above 1e-10 at "
                                  "50 digits, not confirmed by the interval re-check")


@pytest.mark.parametrize("operation", [lambda a: ca.fmin(a, 1), lambda a: ca.fmax(a, 1), ca.sign,
                                       lambda a: ca.if_else(a > 1, a, 2 * a), ca.floor, ca.ceil,
                                       lambda a: ca.fmod(a, 1.25), lambda a: ca.copysign(a, a - 2)],
                         ids=["fmin", "fmax", "sign", "if_else", "floor", "ceil", "fmod", "copysign"])
def test_a_difference_through_a_decided_branch_is_refuted_by_mpmath_intervals(operation):
    # 2 op(x) + tan(x) against op(x) + tan(x) at x = 1.5 (op(x) = 1, 1.5, 1, 1.5, 1, 2, 0.25, -1.5): tan leaves
    # the CasADi graph's intervals out, and mpmath's decide min, max, sign, the branch, floor, ceil, C's fmod
    # and copysign at the point
    x = ca.SX.sym("x")
    certificate = prove_identity("2 op = op", 2 * operation(x) + ca.tan(x), operation(x) + ca.tan(x), [x], "x = 1.5",
                                 box=([1.5], [1.5]), symbolic_seconds=1.0)
    assert certificate.status == "refuted"
    assert certificate.method.endswith("re-checked by mpmath interval arithmetic at 100 digits (outward rounding)")


def test_a_rational_function_is_shown_nonzero_without_simplification(monkeypatch):
    # x (1 + 1e-13) + y - x - y is the rational function 1e-13 x (the double's excess, exactly): its nonzero numerator
    # settles it, so sympy.simplify (made to fail here, in the forked child too) is never reached; e^x e^y against
    # e^(x + y) still needs it (and fails with it here)
    def refuse(*args, **kwargs):
        raise RuntimeError("simplify called")

    monkeypatch.setattr("sympy.simplify", refuse)
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    rational = prove_identity("near", x * (1 + 1e-13) + y, x + y, [x, y], "all x, y", symbolic_seconds=1.0)
    assert rational.status == "checked" and rational.reason == "not shown zero symbolically"
    exponential = prove_identity("e^x e^y = e^(x + y)", ca.exp(x) * ca.exp(y), ca.exp(x + y), [x, y], "all x, y",
                                 symbolic_seconds=1.0)
    assert exponential.status == "checked" and exponential.reason == "symbolic steps over 1 s"
