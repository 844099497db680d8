"""Rigorous enclosures of sympy expressions at a point, by mpmath's interval arithmetic (``mpmath.iv``).

``enclose(expressions, point, digits)`` walks each expression tree once (shared sub-expressions once)
and evaluates every node with outward rounding at ``digits`` significant digits, so the exact real
value of each expression at the point lies in the interval it returns. Functions mpmath's interval
context lacks are built from identities that hold wherever the function is defined (``FUNCTIONS``);
``Min``, ``Max``, ``sign``, ``floor``, ``ceiling`` and ``Piecewise`` are evaluated where the intervals decide them (a
condition that the intervals cannot decide gives no enclosure). Anything else (an unknown function,
a complex value, a domain edge) gives ``None``: no enclosure, never a guess.
"""

from __future__ import annotations

import mpmath
import sympy as sp

__all__ = ["FUNCTIONS", "enclose"]

iv = mpmath.iv


def _asin(a):
    return iv.atan2(a, iv.sqrt((1 - a) * (1 + a)))


def _acos(a):
    return iv.atan2(iv.sqrt((1 - a) * (1 + a)), a)


FUNCTIONS = {sp.sin: iv.sin, sp.cos: iv.cos, sp.tan: iv.tan, sp.exp: iv.exp, sp.log: iv.ln, sp.atan2: iv.atan2,
             sp.atan: lambda a: iv.atan2(a, iv.mpf(1)), sp.asin: _asin, sp.acos: _acos,
             sp.sinh: lambda a: (iv.exp(a) - iv.exp(-a)) / 2, sp.cosh: lambda a: (iv.exp(a) + iv.exp(-a)) / 2,
             sp.tanh: lambda a: 1 - 2 / (iv.exp(2 * a) + 1)}


class _Undecided(Exception):
    """The intervals cannot evaluate a node rigorously (unknown operation, undecided condition, domain edge)."""


def _hull(lower, upper):
    """The interval [lower, upper] (numbers or point intervals, exact at the working precision)."""
    return iv.mpf([lower, upper])


def _compare(relation, a, b):
    """True, False, or _Undecided for ``a relation b`` on intervals (decided only if it holds for all values)."""
    if relation in (sp.Eq, sp.Ne):
        if a.a == a.b == b.a == b.b:
            return relation is sp.Eq
        if a.b < b.a or b.b < a.a:
            return relation is sp.Ne
        raise _Undecided
    strict = relation in (sp.StrictLessThan, sp.StrictGreaterThan)
    low, high = (a, b) if relation in (sp.StrictLessThan, sp.LessThan) else (b, a)
    if (low.b < high.a) if strict else (low.b <= high.a):
        return True
    if (low.a >= high.b) if strict else (low.a > high.b):
        return False
    raise _Undecided


def _evaluator(point: dict):
    """``value(expression)``: its enclosure at the point, each distinct sub-expression evaluated once."""
    memo: dict = {}

    def condition(c) -> bool:
        if c is sp.true or c is sp.false:
            return bool(c)
        if isinstance(c, sp.Not):
            return not condition(c.args[0])
        if isinstance(c, (sp.And, sp.Or)):
            values = [condition(a) for a in c.args]
            return all(values) if isinstance(c, sp.And) else any(values)
        if isinstance(c, sp.core.relational.Relational):
            return _compare(type(c), value(c.lhs), value(c.rhs))
        raise _Undecided

    def value(e):
        if e not in memo:
            memo[e] = node(e)
        return memo[e]

    def node(e):
        if e.is_Symbol:
            return iv.mpf(point[e])
        if e.is_Rational or e.is_Float:
            exact = sp.Rational(e)  # a Float's binary value, exactly
            return iv.mpf(exact.p) / exact.q
        if e is sp.pi or e is sp.E:
            return iv.mpf(iv.pi if e is sp.pi else iv.e)  # the constant at the working precision
        args = [value(a) for a in e.args] if not isinstance(e, sp.Piecewise) else None
        if isinstance(e, sp.Add):
            return sum(args[1:], args[0])
        if isinstance(e, sp.Mul):
            product = args[0]
            for a in args[1:]:
                product = product * a
            return product
        if isinstance(e, sp.Pow):
            return args[0] ** args[1]  # an integer exponent (a point) is taken as mpmath's integer power
        if isinstance(e, sp.Abs):
            return abs(args[0])
        if e.func in FUNCTIONS:
            return FUNCTIONS[e.func](*args)
        if isinstance(e, (sp.Min, sp.Max)):
            pick = min if isinstance(e, sp.Min) else max
            return _hull(pick(a.a for a in args), pick(a.b for a in args))  # points: always ordered
        if isinstance(e, sp.sign):
            (a,) = args
            return _hull(-1 if a.a < 0 else 0 if a.a == 0 else 1, 1 if a.b > 0 else 0 if a.b == 0 else -1)
        if isinstance(e, (sp.floor, sp.ceiling)):
            (a,) = args
            rounding = mpmath.floor if isinstance(e, sp.floor) else mpmath.ceil
            return _hull(rounding(mpmath.mpf(a.a)), rounding(mpmath.mpf(a.b)))  # integers: exact
        if isinstance(e, sp.Piecewise):
            for expression, c in e.args:
                if condition(c):
                    return value(expression)
        raise _Undecided

    return value


def enclose(expressions: list[sp.Expr], point: dict, digits: int) -> list | None:
    """Intervals (``mpmath.iv.mpf``) holding each expression's exact value at ``point`` ({Symbol: float}),
    computed with outward rounding at ``digits`` significant digits; None where any expression cannot be
    enclosed (an operation without an interval extension, an undecided condition, a domain edge, a complex
    value)."""
    precision = iv.prec
    try:
        iv.dps = digits
        value = _evaluator(point)
        enclosures = [value(sp.sympify(e)) for e in expressions]
    except (_Undecided, RecursionError, ZeroDivisionError, ValueError, TypeError, OverflowError,
            mpmath.libmp.ComplexResult):
        return None
    finally:
        iv.prec = precision
    return enclosures if all(isinstance(v, iv.mpf) for v in enclosures) else None
