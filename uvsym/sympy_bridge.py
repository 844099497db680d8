"""CasADi SX -> sympy by walking the expression graph, and LaTeX with the papers' symbol names.

``str()`` of an SX is not a safe source (it prints constants to 6 digits and shares terms as
``@k``); this converter walks the graph itself: every node by its operation and dependencies,
memoised on ``element_hash()`` so that shared sub-expressions are converted once. Symbols stay
symbols (``nu_3`` -> sympy ``nu_3``), constants keep every bit (17 significant digits), and the
result evaluates to the same numbers as the CasADi expression.
"""

from __future__ import annotations

import math
import re

import casadi as ca
import sympy as sp

from uvsym.errors import UvsymError

__all__ = ["to_sympy", "latex", "LATEX_NAMES"]

# base symbol name -> LaTeX; vector entries get their index as a subscript
LATEX_NAMES = {
    "eta": r"\eta", "nu": r"\nu", "nu_r": r"\nu_r", "tau": r"\tau", "tau_d": r"\tau_d", "tau_d_dot": r"\dot\tau_d",
    "f": "f", "f_hat": r"\hat f", "e": "e", "x": "x", "K": "k", "V_c": "V_c", "beta_c": r"\beta_c",
    "u": "u", "u_cmd": r"u_{\mathrm{cmd}}", "dt": r"\Delta t", "t": "t",
}

_UNARY = {
    ca.OP_NEG: lambda a: -a, ca.OP_EXP: sp.exp, ca.OP_LOG: sp.log, ca.OP_SQRT: sp.sqrt, ca.OP_SQ: lambda a: a**2,
    ca.OP_TWICE: lambda a: 2 * a, ca.OP_SIN: sp.sin, ca.OP_COS: sp.cos, ca.OP_TAN: sp.tan, ca.OP_ASIN: sp.asin,
    ca.OP_ACOS: sp.acos, ca.OP_ATAN: sp.atan, ca.OP_FABS: sp.Abs, ca.OP_SIGN: sp.sign, ca.OP_FLOOR: sp.floor,
    ca.OP_CEIL: sp.ceiling, ca.OP_INV: lambda a: 1 / a, ca.OP_SINH: sp.sinh, ca.OP_COSH: sp.cosh,
    ca.OP_TANH: sp.tanh, ca.OP_ASINH: sp.asinh, ca.OP_ACOSH: sp.acosh, ca.OP_ATANH: sp.atanh, ca.OP_ERF: sp.erf,
    ca.OP_NOT: lambda a: sp.Piecewise((1, sp.Eq(a, 0)), (0, True)),
    ca.OP_LOG1P: lambda a: sp.log(1 + a), ca.OP_EXPM1: lambda a: sp.exp(a) - 1,
}
_BINARY = {
    ca.OP_ADD: lambda a, b: a + b, ca.OP_SUB: lambda a, b: a - b, ca.OP_MUL: lambda a, b: a * b,
    ca.OP_DIV: lambda a, b: a / b, ca.OP_POW: lambda a, b: a**b, ca.OP_CONSTPOW: lambda a, b: a**b,
    ca.OP_ATAN2: lambda y, x: _c_atan2(y, x), ca.OP_FMIN: sp.Min, ca.OP_FMAX: sp.Max,
    ca.OP_HYPOT: lambda a, b: sp.sqrt(a**2 + b**2), ca.OP_FMOD: lambda a, b: _c_fmod(a, b),
    ca.OP_COPYSIGN: lambda a, b: _c_copysign(a, b),
    ca.OP_LT: lambda a, b: _indicator(sp.Lt(a, b)), ca.OP_LE: lambda a, b: _indicator(sp.Le(a, b)),
    ca.OP_EQ: lambda a, b: _indicator(sp.Eq(a, b)), ca.OP_NE: lambda a, b: _indicator(sp.Ne(a, b)),
    ca.OP_AND: lambda a, b: _indicator(sp.And(sp.Ne(a, 0), sp.Ne(b, 0))),
    ca.OP_OR: lambda a, b: _indicator(sp.Or(sp.Ne(a, 0), sp.Ne(b, 0))),
    ca.OP_IF_ELSE_ZERO: lambda c, a: sp.Piecewise((a, sp.Ne(c, 0)), (0, True)),
}


def _indicator(condition):
    return sp.Piecewise((1, condition), (0, True))


# C's semantics where sympy's functions differ (a real zero is +0: IEEE's -0.0 has no real counterpart)
def _c_fmod(a, b):
    """C fmod: ``a - b trunc(a / b)``, the sign of a (sympy's Mod is floored: the sign of b); NaN at b = 0."""
    if b == 0:
        return sp.nan
    q = a / b
    return a - b * sp.Piecewise((sp.floor(q), q >= 0), (sp.ceiling(q), True))


def _c_copysign(a, b):
    """C copysign: |a| with the sign of b, so |a| at b = 0 (``|a| sign(b)`` would give 0 there)."""
    return sp.Piecewise((sp.Abs(a), b >= 0), (-sp.Abs(a), True))


def _c_atan2(y, x):
    """C atan2: 0 at y = x = 0 (sympy's atan2 is undefined there), sympy's atan2 elsewhere."""
    return sp.Piecewise((0, sp.And(sp.Eq(y, 0), sp.Eq(x, 0))), (sp.atan2(y, x), True))


def _constant(value: float, exact: bool = False):
    if exact and math.isfinite(value):
        return sp.Rational(value)  # the double's exact binary value
    if value == int(value) and abs(value) < 2**53:
        return sp.Integer(int(value))
    return sp.Float(repr(value), 17)


def to_sympy(expression, exact: bool = False) -> sp.Matrix | sp.Expr:
    """The sympy form of an SX scalar or matrix (a Matrix of the same shape for a matrix).

    ``exact=True`` gives every constant as the rational it stores, so that sympy's arithmetic on
    them is exact (Floats would be combined at 17 digits).

    Raises UvsymError for an MX expression or an operation without a sympy equivalent.
    """
    if isinstance(expression, ca.MX):
        raise UvsymError("to_sympy converts SX expressions; expand MX with Function.expand() first")
    expression = ca.SX(expression)
    memo: dict[int, sp.Expr] = {}

    def convert(node: ca.SX):
        key = node.element_hash()
        if key in memo:
            return memo[key]
        if node.is_symbolic():
            result = sp.Symbol(node.name(), real=True)
        elif node.is_constant():
            result = _constant(float(node), exact)
        else:
            op = node.op()
            if node.n_dep() == 1 and op in _UNARY:
                result = _UNARY[op](convert(node.dep(0)))
            elif node.n_dep() == 2 and op in _BINARY:
                result = _BINARY[op](convert(node.dep(0)), convert(node.dep(1)))
            else:
                raise UvsymError(f"CasADi operation {op} ({node}) has no sympy equivalent here")
        memo[key] = result
        return result

    rows, cols = expression.shape
    entries = [[convert(expression[i, j]) if expression.has_nz(i, j) else sp.Integer(0) for j in range(cols)]
               for i in range(rows)]
    return entries[0][0] if (rows, cols) == (1, 1) else sp.Matrix(entries)


def _symbol_latex(name: str) -> str:
    """LaTeX of one symbol, indexed from 1 as in the papers: CasADi's element ``nu_3`` (0-based)
    -> ``\\nu_{4}``, ``tau_d_2`` -> ``\\tau_{d,3}``."""
    match = re.fullmatch(r"(.*?)_(\d+)", name)
    base, index = (match.group(1), str(int(match.group(2)) + 1)) if match else (name, None)
    if base not in LATEX_NAMES:
        tex = r"\mathrm{" + base.replace("_", r"\_") + "}"
        return tex if index is None else f"{tex}_{{{index}}}"
    tex = LATEX_NAMES[base]
    if index is None:
        return tex
    if "_" in tex:  # already subscripted (\tau_d): the index joins the subscript
        head, subscript = tex.split("_", 1)
        if subscript.startswith("{") and subscript.endswith("}"):
            subscript = subscript[1:-1]
        return f"{head}_{{{subscript},{index}}}"
    return f"{tex}_{{{index}}}"


def latex(expression, digits: int = 6, zero_below: float = 0.0, names: dict[str, str] | None = None) -> str:
    """LaTeX of an SX or sympy expression, symbols named as in the papers (``nu_3`` -> ``\\nu_{3}``).

    Constants are shown to ``digits`` significant digits (the conversion itself keeps all);
    coefficients of magnitude below ``zero_below`` are shown as 0 and those that round to 1 as 1
    (for rounding residues such as those of ``M M^-1`` in doubles: say so where it is used).
    ``names`` maps symbol names to their LaTeX, overriding the papers' names.
    """
    value = expression if isinstance(expression, (sp.Basic, sp.MatrixBase)) else to_sympy(expression)
    names = {s: (names or {}).get(s.name) or _symbol_latex(s.name) for s in value.free_symbols}

    def shown(number: sp.Float):
        if abs(number) < zero_below:
            return sp.Integer(0)
        if zero_below and abs(abs(number) - 1) < zero_below:
            return sp.Integer(1 if number > 0 else -1)
        return sp.Float(number, digits)

    rounded = value.xreplace({n: shown(n) for n in value.atoms(sp.Float)})
    return sp.latex(rounded, symbol_names=names, mat_delim="", mat_str="bmatrix")
