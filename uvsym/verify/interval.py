"""Interval extension of a CasADi SX Function, with outward rounding, over many boxes at once.

``IntervalFunction(f)`` replays ``f``'s instruction list (the same graph CasADi evaluates and
generates C from) on intervals: each work variable holds (k,) lower and upper bounds, one
entry per box, so a batch of boxes costs one numpy operation per instruction. Every rounded
operation moves its bounds outward by one unit in the last place (``numpy.nextafter``), overflow
included (a bound that overflows to inf moves back to the largest double on the inner side);
IEEE ``+``, ``-``, ``*``, ``/`` and sqrt are correctly rounded, so that encloses the exact result; results
that are exact anyway (sums whose TwoSum error is 0, 2 x without overflow, and ``0 * x``, ``0 / x``)
stay unwidened, so that an equilibrium evaluates to exactly 0. Integer powers go by repeated
squaring of intervals (each step outward-rounded). Library functions (exp, sin, tanh, ...) are
accurate to within an ulp or two; they are widened by ``LIBM_ULPS`` units, except where their
value is exact: at an argument that is exactly 0, sin, tanh, atan, sinh, asinh, expm1, log1p
give 0 and exp, cos, cosh give 1. The enclosure is therefore rigorous: every value the
function takes on a box lies between the bounds returned for it.

``defined`` says, per box, whether every operation's argument stays in its domain (sqrt of
x >= 0, log of x > 0, log1p of x > -1, division by an interval without 0, a non-integer power of
x >= 0). Where it may not, the operation's bounds are the whole real line and the box is
"undefined": never provable, and reported as such by the callers.

``smooth`` says, per box, whether no non-smooth operation (abs, min/max, comparisons,
conditionals, sign, floor, ceil, fmod, copysign) has its kink inside the box; Taylor-type
arguments need it. fmod is C's (the sign of the dividend), undefined where the divisor may be 0;
copysign of a divisor box holding 0 takes either sign (C tells +0 from -0.0, the reals do not).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.errors import VerificationError
from uvsym.verify.interval_arithmetic import (
    LIBM_ULPS,
    clean,
    compare,
    div,
    even,
    exact_zeros,
    holds_zero,
    increasing,
    indicator,
    mul,
    periodic,
    power,
    round_down,
    round_up,
    signed_sum,
    square,
    truth,
    twice,
)

__all__ = ["IntervalFunction", "Intervals"]

_NAMES = {getattr(ca, name): name[3:].lower() for name in dir(ca) if name.startswith("OP_")}


def _outside_domain(op: int, args) -> np.ndarray | None:
    """(k,) True where the operation's argument may leave its domain; None for total operations."""
    a = args[0]
    if op == ca.OP_SQRT:
        return a[0] < 0
    if op == ca.OP_LOG:
        return a[0] <= 0
    if op == ca.OP_LOG1P:
        return a[0] <= -1
    if op == ca.OP_DIV:
        return holds_zero(args[1])
    if op == ca.OP_INV:
        return holds_zero(a)
    if op == ca.OP_FMOD:
        return holds_zero(args[1])
    if op in (ca.OP_CONSTPOW, ca.OP_POW):
        exponent = float(args[1][0][0])
        if exponent == np.floor(exponent):
            return holds_zero(a) if exponent < 0 else None
        return a[0] <= 0 if exponent < 0 else a[0] < 0
    return None


_MONOTONE = {
    ca.OP_EXP: np.exp, ca.OP_TANH: np.tanh, ca.OP_ATAN: np.arctan, ca.OP_SINH: np.sinh,
    ca.OP_ASINH: np.arcsinh, ca.OP_LOG1P: np.log1p, ca.OP_EXPM1: np.expm1,
}
_POSITIVE_DOMAIN = {ca.OP_LOG: np.log, ca.OP_SQRT: np.sqrt}
_ZERO_AT_ZERO = {ca.OP_SIN, ca.OP_TANH, ca.OP_ATAN, ca.OP_SINH, ca.OP_ASINH, ca.OP_EXPM1, ca.OP_LOG1P}
_ONE_AT_ZERO = {ca.OP_EXP, ca.OP_COS, ca.OP_COSH}


@dataclass(frozen=True)
class Intervals:
    """Bounds of a function's outputs over k boxes: lo, hi (k, m); smooth and defined (k,) as in the
    module docstring (bounds of an undefined box are meaningless)."""

    lo: np.ndarray
    hi: np.ndarray
    smooth: np.ndarray
    defined: np.ndarray


class IntervalFunction:
    """The interval extension of an SX Function with one dense vector input x (n,) and output (m,)."""

    def __init__(self, function: ca.Function):
        if not function.is_a("SXFunction"):
            raise VerificationError(f"{function.name()}: interval evaluation needs an SX Function (expand MX first)")
        if function.n_in() != 1 or function.n_out() != 1:
            raise VerificationError(f"{function.name()}: interval evaluation takes one input and one output, "
                                    f"got {function.n_in()} and {function.n_out()}")
        self.function = function
        self.n_in, self.n_out = function.nnz_in(0), function.nnz_out(0)
        if self.n_in != function.numel_in(0):
            raise VerificationError(f"{function.name()}: the input must be dense")
        self.program = [(function.instruction_id(k), function.instruction_input(k), function.instruction_output(k),
                         function.instruction_constant(k)) for k in range(function.n_instructions())]
        unsupported = sorted({_NAMES.get(op, str(op)) for op, *_ in self.program if not self._supported(op)})
        if unsupported:
            raise VerificationError(f"{function.name()}: interval evaluation does not support the operation(s) "
                                    f"{', '.join(unsupported)}")
        self.sparsity_out = function.sparsity_out(0)

    @staticmethod
    def _supported(op: int) -> bool:
        return op in _MONOTONE or op in _POSITIVE_DOMAIN or op in {
            ca.OP_INPUT, ca.OP_OUTPUT, ca.OP_CONST, ca.OP_ASSIGN, ca.OP_ADD, ca.OP_SUB, ca.OP_MUL, ca.OP_DIV,
            ca.OP_NEG, ca.OP_SQ, ca.OP_TWICE, ca.OP_INV, ca.OP_SIN, ca.OP_COS, ca.OP_COSH, ca.OP_FABS, ca.OP_SIGN,
            ca.OP_FMIN, ca.OP_FMAX, ca.OP_LT, ca.OP_LE, ca.OP_EQ, ca.OP_NE, ca.OP_NOT, ca.OP_AND, ca.OP_OR,
            ca.OP_IF_ELSE_ZERO, ca.OP_CONSTPOW, ca.OP_POW, ca.OP_FLOOR, ca.OP_CEIL, ca.OP_FMOD, ca.OP_COPYSIGN}

    def __call__(self, lo, hi) -> Intervals:
        """Bounds of the output over the boxes ``[lo, hi]`` (each (k, n) or (n,))."""
        lo, hi = np.atleast_2d(np.asarray(lo, dtype=float)), np.atleast_2d(np.asarray(hi, dtype=float))
        if lo.shape != hi.shape or lo.shape[1] != self.n_in:
            raise VerificationError(f"{self.function.name()}: boxes must be (k, {self.n_in}) lower and upper "
                                    f"bounds, got {lo.shape} and {hi.shape}")
        if np.any(~(lo <= hi)):
            raise VerificationError(f"{self.function.name()}: a box has a lower bound above its upper bound (or NaN)")
        k = lo.shape[0]
        work: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        out_lo, out_hi = np.zeros((k, self.n_out)), np.zeros((k, self.n_out))
        smooth, defined = np.ones(k, dtype=bool), np.ones(k, dtype=bool)
        if k == 0:  # no box: nothing to evaluate (a power reads its exponent from the first box)
            return Intervals(out_lo, out_hi, smooth, defined)
        for op, inputs, outputs, constant in self.program:
            if op == ca.OP_INPUT:
                work[outputs[0]] = (lo[:, inputs[1]], hi[:, inputs[1]])
            elif op == ca.OP_OUTPUT:
                out_lo[:, outputs[1]], out_hi[:, outputs[1]] = work[inputs[0]]
            elif op == ca.OP_CONST:
                if not np.isfinite(constant):
                    defined[:] = False
                work[outputs[0]] = clean(np.full(k, constant), np.full(k, constant))
            else:
                args = [work[i] for i in inputs]
                with np.errstate(all="ignore"):
                    result, kink = self._apply(op, args)
                if kink is not None:
                    smooth &= ~kink
                if op in _ZERO_AT_ZERO:
                    result = exact_zeros(result, args[0])
                elif op in _ONE_AT_ZERO:
                    result = exact_zeros(result, args[0], value=1.0)
                outside = _outside_domain(op, args)
                if outside is not None:
                    defined &= ~outside
                    result = (np.where(outside, -np.inf, result[0]), np.where(outside, np.inf, result[1]))
                work[outputs[0]] = clean(*result)
        return Intervals(out_lo, out_hi, smooth, defined)

    def _apply(self, op: int, args):
        """(lo, hi) of one operation, and where its kink lies inside the box (None for smooth ones)."""
        a = args[0]
        b = args[1] if len(args) > 1 else None
        if op == ca.OP_ASSIGN:
            return a, None
        if op == ca.OP_ADD:
            return signed_sum(a, b, 1.0), None
        if op == ca.OP_SUB:
            return signed_sum(a, b, -1.0), None
        if op == ca.OP_MUL:
            return mul(a, b), None
        if op == ca.OP_DIV:
            return div(a, b), None
        if op == ca.OP_INV:
            return div((np.ones_like(a[0]), np.ones_like(a[0])), a), None
        if op == ca.OP_NEG:
            return (-a[1], -a[0]), None
        if op == ca.OP_TWICE:
            return twice(a), None
        if op == ca.OP_SQ:
            return square(a), None
        if op == ca.OP_COSH:
            lo, hi = even(a, np.cosh)
            return clean(round_down(lo, LIBM_ULPS), round_up(hi, LIBM_ULPS)), None
        if op in _MONOTONE:
            return increasing(_MONOTONE[op])(a), None
        if op in _POSITIVE_DOMAIN:  # boxes reaching outside the domain are marked undefined by the caller
            clipped = (np.maximum(a[0], 0.0), np.maximum(a[1], 0.0))
            return increasing(_POSITIVE_DOMAIN[op], 1 if op == ca.OP_SQRT else LIBM_ULPS)(clipped), None
        if op == ca.OP_SIN:
            return periodic(a, np.sin, np.pi / 2, -np.pi / 2), None
        if op == ca.OP_COS:
            return periodic(a, np.cos, 0.0, np.pi), None
        if op in (ca.OP_CONSTPOW, ca.OP_POW):
            if not np.all(b[0] == b[1]) or not np.all(b[0] == b[0][0]) or not np.all(np.isfinite(b[0])):
                raise VerificationError("interval power needs a constant, finite exponent")
            return power(a, float(b[0][0])), None
        if op == ca.OP_FABS:
            kink = (a[0] < 0) & (a[1] > 0)
            return (np.where(a[0] >= 0, a[0], np.where(a[1] <= 0, -a[1], 0.0)),
                    np.maximum(np.abs(a[0]), np.abs(a[1]))), kink
        if op == ca.OP_SIGN:
            return (np.sign(a[0]), np.sign(a[1])), (a[0] <= 0) & (a[1] >= 0) & (a[0] < a[1])
        if op in (ca.OP_FLOOR, ca.OP_CEIL):
            function = np.floor if op == ca.OP_FLOOR else np.ceil
            lo, hi = function(a[0]), function(a[1])
            return (lo, hi), lo != hi
        if op == ca.OP_COPYSIGN:  # |a| with b's sign; where b may be 0 (+0 or -0.0 in C) either sign
            magnitude = (np.where(a[0] >= 0, a[0], np.where(a[1] <= 0, -a[1], 0.0)),
                         np.maximum(np.abs(a[0]), np.abs(a[1])))
            lo = np.where(b[0] > 0, magnitude[0], -magnitude[1])
            hi = np.where(b[1] < 0, -magnitude[0], magnitude[1])
            return (lo, hi), (b[0] <= 0) & (b[1] >= 0)
        if op == ca.OP_FMOD:
            return _fmod(a, b)
        if op in (ca.OP_FMIN, ca.OP_FMAX):
            pick = np.minimum if op == ca.OP_FMIN else np.maximum
            return (pick(a[0], b[0]), pick(a[1], b[1])), np.maximum(a[0], b[0]) <= np.minimum(a[1], b[1])
        if op in (ca.OP_LT, ca.OP_LE, ca.OP_EQ, ca.OP_NE):
            return compare(op, a, b)
        true, false = truth(a)
        if op == ca.OP_NOT:
            return indicator(false, true)
        if op in (ca.OP_AND, ca.OP_OR):
            b_true, b_false = truth(b)
            if op == ca.OP_AND:
                return indicator(true & b_true, false | b_false)
            return indicator(true | b_true, false & b_false)
        # OP_IF_ELSE_ZERO(condition, value)
        lo = np.where(true, b[0], np.where(false, 0.0, np.minimum(b[0], 0.0)))
        hi = np.where(true, b[1], np.where(false, 0.0, np.maximum(b[1], 0.0)))
        return (lo, hi), ~true & ~false


def _fmod(a, b):
    """(lo, hi) of C's fmod(a, b) = a - b trunc(a / b) (boxes where b may be 0 are undefined: the
    caller), and where trunc(a / b) may jump inside the box. Where trunc(a / b) is one integer q over
    the box, a - q b with outward rounding; elsewhere the bounds every fmod obeys: the sign of a and
    |fmod(a, b)| <= min(|a|, |b|)."""
    q_lo, q_hi = div(a, b)
    q_lo, q_hi = np.trunc(q_lo), np.trunc(q_hi)
    one = (q_lo == q_hi) & np.isfinite(q_lo)
    q = np.where(one, q_lo, 0.0)
    exact = signed_sum(a, mul((q, q), b), -1.0)
    bound = np.maximum(np.abs(b[0]), np.abs(b[1]))
    loose = (np.where(a[0] >= 0, 0.0, np.maximum(a[0], -bound)), np.where(a[1] <= 0, 0.0, np.minimum(a[1], bound)))
    return (np.where(one, exact[0], loose[0]), np.where(one, exact[1], loose[1])), ~one
