"""The verifier reads CasADi's operations as C does (fmod, copysign, atan2 at their kinks), checked
against CasADi's own numeric evaluation, which is C's and owes nothing to the sympy bridge."""

from __future__ import annotations

import math
from dataclasses import replace

import casadi as ca
import pytest
import sympy as sp

from uvsym.sympy_bridge import to_sympy
from uvsym.verify.borderline import C_GRID, C_SEMANTICS, c_semantics_cases, c_semantics_unsound
from uvsym.verify.identity import prove_identity
from uvsym.verify.mp_enclosure import enclose

x, y = ca.SX.sym("x"), ca.SX.sym("y")


def _differs(lhs, rhs, point, inputs=(x, y)) -> bool:
    """Whether CasADi's values (C semantics) of lhs and rhs, SX of the inputs, differ at the point."""
    a, b = (float(ca.Function("f", list(inputs), [e])(*point)) for e in (lhs, rhs))
    return math.isfinite(a) and math.isfinite(b) and abs(a - b) > 1e-9 * (1 + abs(a) + abs(b))


@pytest.mark.parametrize("lhs, rhs, point", [(ca.fmod(x + 1, 1), ca.fmod(x, 1), (-0.5, 0.0)),
                                             (ca.copysign(ca.fabs(x), y), ca.fabs(x) * ca.sign(y), (1.0, 0.0))])
def test_identities_false_in_c_are_refuted_where_c_says_so(lhs, rhs, point):
    assert _differs(lhs, rhs, point)  # what C gives: the claim is false
    certificate = prove_identity("false in C", lhs, rhs, [x, y], "the reals")
    assert certificate.status == "refuted"
    found = certificate.counterexample["point"]
    assert _differs(lhs, rhs, (found["x"], found["y"]))


def test_an_identity_true_in_c_at_zero_is_not_refuted():
    assert prove_identity("copysign(1, y)^2 = 1", ca.copysign(1, y) ** 2, 1, [y], "the reals").status == "proved"


@pytest.mark.parametrize("a, b", [(-0.5, 1.0), (5.5, -2.0), (-7.0, 3.0), (7.0, -3.0), (0.25, 0.5), (1e17, 3.0)])
def test_the_bridge_gives_fmod_copysign_and_atan2_their_c_values(a, b):
    X, Y = sp.Symbol("x", real=True), sp.Symbol("y", real=True)
    at = {X: sp.Rational(a), Y: sp.Rational(b)}
    assert float(to_sympy(ca.fmod(x, y), exact=True).subs(at)) == math.fmod(a, b)
    assert float(to_sympy(ca.copysign(x, y), exact=True).subs(at)) == math.copysign(a, b)
    assert float(to_sympy(ca.copysign(x, y - b), exact=True).subs(at)) == abs(a)  # at +0: |a|, not 0
    assert float(to_sympy(ca.atan2(y - b, x - a), exact=True).subs(at)) == math.atan2(0.0, 0.0) == 0.0


def test_mpmath_intervals_enclose_floor_and_ceiling():
    X = sp.Symbol("x", real=True)
    low, high = enclose([sp.floor(X / 3), sp.ceiling(X / 3)], {X: -1.0}, 30)
    assert low.a == low.b == -1 and high.a == high.b == 0
    assert enclose([sp.floor(X)], {X: 2.0}, 30)[0].a == 2


def test_generated_claims_over_the_c_operations_are_never_decided_wrongly():
    """Every verdict is re-checked by CasADi's evaluation (C) alone, and most false claims are found."""
    cases = c_semantics_cases(2 * len(C_SEMANTICS), seed=11)
    certificates = [prove_identity(case.kind, case.lhs, case.rhs, case.inputs, "the reals") for case in cases]
    assert [c_semantics_unsound(case, c) for case, c in zip(cases, certificates)] == [None] * len(cases)
    false = [c.status for case, c in zip(cases, certificates) if not case.holds]
    assert false.count("refuted") >= 0.9 * len(false)


def test_the_soundness_check_itself_can_fail():
    case = c_semantics_cases(2, seed=0)[1]  # fmod(x + 1, 1) against fmod(x, 1): equal at x = 0.25
    assert case.kind == "fmod_shift" and not case.holds
    proved = replace(prove_identity(case.kind, case.lhs, case.rhs, case.inputs, "the reals"), status="proved")
    assert c_semantics_unsound(case, proved) == f"{case.kind}: proved, false by construction"
    bogus = replace(proved, status="refuted", counterexample={"point": {"x": 0.25, "y": 0.25}})
    assert c_semantics_unsound(case, bogus) == "fmod_shift: refuted at (0.25, 0.25), where C gives equal sides"


def test_the_true_class_holds_in_c_on_the_grid():
    """The generator's truth, checked without the verifier: the true classes agree with C everywhere on the
    grid, each false class differs somewhere on it."""
    for case in c_semantics_cases(len(C_SEMANTICS) * 2, seed=5):
        differs = any(_differs(case.lhs, case.rhs, (a, b), case.inputs) for a in C_GRID for b in C_GRID)
        assert differs != case.holds, case.kind


def test_a_difference_whose_conditions_sympy_cannot_print_is_inconclusive_not_a_crash():
    """Found by the generated suite (benchmarks/soundness.py): fmod and copysign nested in the divisor sign class,
    whose converted conditions sympy rewrites into if-then-else terms its mpmath printer rejects (TypeError)."""
    a = ca.fmod(ca.copysign(x * y - 1.5, y), (ca.sign(2 * x - y - 1.5) * (y - 1.5)) ** 2 + 1)
    lhs, rhs = ca.fmod(a, -((y - 1.5) ** 2 + 1)), ca.fmod(a, (y - 1.5) ** 2 + 1)  # true in C for all x, y
    certificate = prove_identity("fmod divisor sign", lhs, rhs, [x, y], "the reals", symbolic_seconds=1.0)
    assert certificate.status in ("proved", "inconclusive")
    if certificate.status == "inconclusive":
        assert "cannot print" in certificate.reason or "timed out" in certificate.reason
