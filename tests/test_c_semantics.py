"""The verifier reads CasADi's operations as C does (fmod, copysign, atan2 at their kinks), checked
against CasADi's own numeric evaluation, which is C's and owes nothing to the sympy bridge."""

from __future__ import annotations

import math

import casadi as ca
import pytest
import sympy as sp

from uvsym.sympy_bridge import to_sympy
from uvsym.verify.borderline import C_SEMANTICS, c_semantics_cases
from uvsym.verify.identity import prove_identity
from uvsym.verify.mp_enclosure import enclose

x, y = ca.SX.sym("x"), ca.SX.sym("y")
GRID = [v / 4 for v in range(-14, 15)]  # dyadic: every operation below is exact in doubles there


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
    """Every proved claim agrees with C on a dyadic grid, every refutation's point differs in C, and
    most false claims are found."""
    cases = c_semantics_cases(2 * len(C_SEMANTICS), seed=11)
    refuted_false = false = 0
    for case in cases:
        certificate = prove_identity(case.kind, case.lhs, case.rhs, case.inputs, "the reals")
        if certificate.status == "proved":
            assert case.holds, case.kind
            assert not any(_differs(case.lhs, case.rhs, (a, b), case.inputs) for a in GRID for b in GRID), case.kind
        if certificate.status == "refuted":
            assert not case.holds, case.kind
            found = certificate.counterexample["point"]
            assert _differs(case.lhs, case.rhs, (found["x"], found["y"]), case.inputs), case.kind
        false += not case.holds
        refuted_false += certificate.status == "refuted" and not case.holds
    assert refuted_false >= 0.9 * false


def test_the_true_class_holds_in_c_on_the_grid():
    """The generator's truth, checked without the verifier: the true classes agree with C everywhere on the
    grid, each false class differs somewhere on it."""
    for case in c_semantics_cases(len(C_SEMANTICS) * 2, seed=5):
        differs = any(_differs(case.lhs, case.rhs, (a, b), case.inputs) for a in GRID for b in GRID)
        assert differs != case.holds, case.kind
