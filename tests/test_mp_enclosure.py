"""``enclose``: rigorous mpmath interval enclosures of sympy expressions at a point.

Each enclosure is compared with an independent evaluation: mpmath's ordinary (non-interval) functions at 130
digits, or exact rationals; a width bound shows the enclosure is tight, not merely true.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
import pytest
import sympy as sp

from uvsym.verify.mp_enclosure import _compare, _Undecided, enclose

x, y = sp.symbols("x y", real=True)

FUNCTIONS = {"asin": (sp.asin, mpmath.asin), "acos": (sp.acos, mpmath.acos), "atan": (sp.atan, mpmath.atan),
             "sinh": (sp.sinh, mpmath.sinh), "cosh": (sp.cosh, mpmath.cosh), "tanh": (sp.tanh, mpmath.tanh),
             "sin": (sp.sin, mpmath.sin), "cos": (sp.cos, mpmath.cos), "tan": (sp.tan, mpmath.tan),
             "exp": (sp.exp, mpmath.exp), "log": (sp.log, mpmath.log),
             "atan2": (lambda a: sp.atan2(a, -2), lambda a: mpmath.atan2(a, -2)),
             "cube root": (lambda a: a ** sp.Rational(1, 3), mpmath.cbrt),
             "square root": (sp.sqrt, mpmath.sqrt), "inverse square": (lambda a: a ** -2, lambda a: a ** -2),
             "pi, e": (lambda a: sp.pi * a + sp.E, lambda a: mpmath.pi * a + mpmath.e),
             "abs": (lambda a: sp.Abs(a - 1), lambda a: abs(a - 1))}


@pytest.mark.parametrize("name", FUNCTIONS)
@pytest.mark.parametrize("at", [0.3, 0.9990234375])
def test_each_function_is_enclosed_tightly(name, at):
    symbolic, reference = FUNCTIONS[name]
    (enclosure,) = enclose([symbolic(x)], {x: at}, 100)
    with mpmath.workdps(130):
        exact = reference(mpmath.mpf(at))
        assert enclosure.a <= exact <= enclosure.b
        assert enclosure.b - enclosure.a < mpmath.mpf(10) ** -95


@pytest.mark.parametrize("digits", [20, 60])
def test_the_width_follows_the_digits(digits):
    (enclosure,) = enclose([sp.sin(x) / 3], {x: 1.0}, digits)
    with mpmath.workdps(digits + 30):
        width = enclosure.b - enclosure.a
        assert 0 < width < mpmath.mpf(10) ** (2 - digits)


def _exact(endpoint) -> Fraction:
    """An interval's endpoint (a point interval) as the exact fraction it is."""
    with mpmath.workprec(100000):
        value = mpmath.mpf(endpoint)
    return (-1 if value < 0 else 1) * Fraction(int(value.man)) * Fraction(2) ** int(value.exp) if value else Fraction(0)


def test_rationals_and_floats_enter_exactly():
    # 1/3 is no binary number: its enclosure must straddle it; the Float 0.1 is a double and enters as its binary value
    (third, tenth) = enclose([sp.Rational(1, 3) + 0 * x, sp.Float(0.1) + 0 * x], {x: 0.0}, 40)
    assert _exact(third.a) < Fraction(1, 3) < _exact(third.b)
    assert _exact(third.b) - _exact(third.a) < Fraction(1, 10 ** 39)
    assert _exact(tenth.a) == _exact(tenth.b) == Fraction(0.1)


@pytest.mark.parametrize("expression, expected", [
    (sp.Min(x, y, 1), Fraction(-2)), (sp.Max(x, y, -5), Fraction(0.3)), (sp.sign(x), 1), (sp.sign(y), -1),
    (sp.sign(x - x), 0),
    (sp.Piecewise((x, sp.Lt(x, y)), (2 * x, True)), 2 * Fraction(0.3)),
    (sp.Piecewise((1, sp.Ne(x, 0)), (0, True)), 1),
    (sp.Piecewise((1, sp.And(sp.Gt(x, 0), sp.Le(y, -2))), (0, True)), 1),
    (sp.Piecewise((1, sp.Or(sp.Gt(x, 1), sp.Not(sp.Ge(y, -2)))), (0, True)), 0),
    # 0.3 (the double) is below 3/10, and 3 * 0.3 is not 9/10
    (sp.Piecewise((1, sp.Lt(x, sp.Rational(3, 10))), (0, True)), 1),
    (sp.Piecewise((1, sp.Eq(3 * x, sp.Rational(9, 10))), (0, True)), 0)])
def test_min_max_sign_and_branches_are_decided_exactly_at_a_point(expression, expected):
    (enclosure,) = enclose([expression], {x: 0.3, y: -2.0}, 50)
    assert _exact(enclosure.a) == _exact(enclosure.b) == Fraction(expected)


def test_min_and_max_of_intervals_take_the_hull_of_their_ends():
    # sin(1) and 0.8414709848...: too close to order at 5 digits, so the minimum is the hull of both lower ends
    close = sp.Rational(841470984807897, 10 ** 15)  # sin(1) = 0.841470984807896506...
    (low, high) = enclose([sp.Min(sp.sin(x), close), sp.Max(sp.sin(x), close)], {x: 1.0}, 5)
    with mpmath.workdps(40):
        assert low.a <= mpmath.sin(1) <= low.b and high.a <= mpmath.mpf(close.p) / close.q <= high.b


@pytest.mark.parametrize("expression", [
    sp.Piecewise((1, sp.Lt(sp.sin(x), sp.Rational(841470984807897, 10 ** 15))), (0, True)),  # undecided at 5 digits
    sp.Piecewise((1, sp.Eq(sp.sin(x), sp.sin(y))), (0, True)),  # equal intervals are not equal values
    sp.erf(x), sp.Function("f")(x)])
def test_an_undecided_condition_or_an_unknown_operation_gives_no_enclosure(expression):
    assert enclose([expression], {x: 1.0, y: 1.0}, 5) is None


@pytest.mark.parametrize("expression, at", [("log(x)", -1.0), ("asin(x)", 2.0), ("acos(x)", -1.5), ("sqrt(x)", -4.0),
                                            ("x**(1/3)", -8.0), ("x**(3/2)", -4.0)])
def test_an_evaluation_outside_the_domain_gives_no_enclosure(expression, at):
    assert enclose([sp.sympify(expression, locals={"x": x})], {x: at}, 100) is None


def test_an_interval_through_a_pole_is_unbounded():
    (enclosure,) = enclose([1 / x], {x: 0.0}, 100)
    assert enclosure.a == -mpmath.inf and enclosure.b == mpmath.inf


def test_the_working_precision_is_restored_even_after_a_failure():
    before = mpmath.iv.prec
    assert enclose([sp.log(x)], {x: -1.0}, 300) is None
    assert enclose([sp.log(x)], {x: 2.0}, 300) is not None
    assert mpmath.iv.prec == before


@pytest.mark.parametrize("at, expected", [(-0.5, (-1, -1)), (0.0, (0, 0)), (0.5, (1, 1))])
def test_sign_of_a_point(at, expected):
    (enclosure,) = enclose([sp.sign(x)], {x: at}, 30)
    assert (_exact(enclosure.a), _exact(enclosure.b)) == expected


@pytest.mark.parametrize("wrap, expected", [(lambda a: a, (-1, 1)), (lambda a: sp.Max(a, 0), (0, 1)),
                                           (lambda a: sp.Min(a, 0), (-1, 0))], ids=["both", "max", "min"])
def test_sign_of_an_interval_takes_every_sign_it_holds(wrap, expected):
    # x^2 - 2 at x = sqrt(2) (the double) is 2.7e-16, but at 10 digits its enclosure straddles 0; Max and Min with 0
    # pin one end at exactly 0
    (straddle, enclosure) = enclose([x * x - 2, sp.sign(wrap(x * x - 2))], {x: 2 ** 0.5}, 10)
    assert straddle.a < 0 < straddle.b
    assert (_exact(enclosure.a), _exact(enclosure.b)) == expected


@pytest.mark.parametrize("relation, expected", [(sp.Eq, 1), (sp.Ne, 0)])
def test_equal_points_are_equal(relation, expected):
    (enclosure,) = enclose([sp.Piecewise((1, relation(x, y)), (0, True))], {x: 0.5, y: 0.5}, 30)
    assert _exact(enclosure.a) == _exact(enclosure.b) == expected


def _interval(lower, upper):
    return mpmath.iv.mpf([lower, upper])


@pytest.mark.parametrize("relation", [sp.Eq, sp.Ne])
@pytest.mark.parametrize("a, b", [((0, 1), (1, 2)), ((1, 2), (0, 1)), ((0, 1), (0, 1)), ((1, 1), (0, 2)),
                                  ((0, 2), (1, 1))])
def test_touching_or_overlapping_intervals_leave_equality_undecided(relation, a, b):
    # [0, 1] and [1, 2] share the value 1; equal intervals [0, 1] need not hold equal values; a point inside an interval
    with pytest.raises(_Undecided):
        _compare(relation, _interval(*a), _interval(*b))


@pytest.mark.parametrize("relation, a, b, expected", [
    # disjoint intervals: decided either way
    (sp.Lt, (0, 1), (2, 3), True), (sp.Lt, (2, 3), (0, 1), False), (sp.Ge, (2, 3), (0, 1), True),
    (sp.Eq, (0, 1), (2, 3), False), (sp.Ne, (2, 3), (0, 1), True),
    # touching at one value: a non-strict relation holds there, a strict one fails there
    (sp.Le, (0, 1), (1, 2), True), (sp.Ge, (1, 2), (0, 1), True), (sp.Lt, (1, 2), (0, 1), False),
    (sp.Gt, (0, 1), (1, 2), False),
    # equal points
    (sp.Le, (1, 1), (1, 1), True), (sp.Lt, (1, 1), (1, 1), False), (sp.Ge, (1, 1), (1, 1), True),
    (sp.Gt, (1, 1), (1, 1), False)])
def test_relations_decided_where_they_hold_or_fail_for_every_value(relation, a, b, expected):
    assert _compare(relation, _interval(*a), _interval(*b)) is expected


@pytest.mark.parametrize("relation, a, b", [
    (sp.Lt, (0, 1), (1, 2)), (sp.Gt, (1, 2), (0, 1)),  # equal at 1: not <, elsewhere <
    (sp.Le, (1, 2), (0, 1)), (sp.Ge, (0, 1), (1, 2)),  # equal at 1: <=, elsewhere not
    (sp.Lt, (0, 2), (1, 3)), (sp.Le, (0, 2), (1, 3))])
def test_relations_that_hold_for_some_values_only_are_undecided(relation, a, b):
    with pytest.raises(_Undecided):
        _compare(relation, _interval(*a), _interval(*b))


@pytest.mark.parametrize("condition, expected", [
    (sp.And(sp.Gt(x, 0), sp.Lt(y, -5)), 0), (sp.And(sp.Gt(x, 0), sp.Lt(y, 0)), 1),
    (sp.Or(sp.Gt(x, 1), sp.Lt(y, 0)), 1), (sp.Or(sp.Gt(x, 1), sp.Lt(y, -5)), 0),
    (sp.Not(sp.And(sp.Gt(x, 0), sp.Lt(y, 0))), 0), (sp.Not(sp.Or(sp.Gt(x, 1), sp.Lt(y, -5))), 1),
    (sp.Not(sp.And(sp.Gt(x, 1), sp.Lt(y, 0))), 1)])
def test_and_or_not_combine_decided_conditions(condition, expected):
    # at x = 0.3, y = -2
    (enclosure,) = enclose([sp.Piecewise((1, condition), (0, True))], {x: 0.3, y: -2.0}, 30)
    assert _exact(enclosure.a) == _exact(enclosure.b) == expected


def test_a_negative_base_takes_an_integer_power_and_refuses_a_fractional_one():
    (cube, square) = enclose([x ** 3, x ** -2], {x: -2.0}, 30)
    assert _exact(cube.a) == _exact(cube.b) == -8 and _exact(square.a) == _exact(square.b) == Fraction(1, 4)
    assert enclose([x ** sp.Rational(1, 2)], {x: -2.0}, 30) is None
