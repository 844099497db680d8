"""Symbolic identities ``lhs == rhs``: an exact proof where one exists, else sampling, labelled as such.

``prove_identity`` converts ``lhs - rhs`` (CasADi SX) to sympy by walking the graph, with every
double constant converted exactly to a rational. Then, in a child process with a time budget
(``SYMBOLIC_SECONDS`` of CPU time, so that a loaded machine gives the same outcome; a symbolic step
that takes longer is abandoned, never waited for):

1. exact rational arithmetic: each entry, with its transcendental sub-expressions (sin, exp,
   atan2, ...) as independent symbols, is expanded (or cancelled, with a symbolic denominator);
   zero means the identity holds for every input where both sides are defined: ``proved``;
2. for small entries that step leaves nonzero, ``sympy.simplify`` (knows sin^2 + cos^2 = 1), unless the
   entry is a rational function of the symbols: its nonzero numerator already shows it is not zero.

Otherwise the difference is sampled with mpmath at ``DIGITS`` significant digits, at points over
the claim's stated set (its ``box``; without one, at scales from 1e-3 to 1e8 besides N(0, 2^2) and
small integers, then at 0 and half-integers, where sign, abs, floor, fmod and copysign jump). Each entry is
measured against its own scale, the sum of the absolute values of the terms of its two sides (what
the rounding of the model's double constants can move it by).
An entry above ``REFUTE`` (1e-10) refutes the claim once re-checked rigorously at the point: a lower
bound of the gap must exceed twice the threshold times an upper bound of the size of the terms. The
size is bounded by mpmath interval arithmetic (outward rounding, at ``RECHECK_DIGITS`` digits, each
tried in turn, ``mp_enclosure``); the gap by an outward-rounded interval evaluation of the CasADi
graph, or, where the graph has an operation those intervals lack, by mpmath interval arithmetic on the
converted entry (said so in the method). An entry that mpmath's intervals cannot enclose is never
refuted. Every entry below ``ROUNDING`` (1e-12) at every point makes the claim ``checked``
(numerical evidence at N points, never a proof); anything between is inconclusive.
"""

from __future__ import annotations

import math
import multiprocessing
import resource
import time

import casadi as ca
import mpmath
import numpy as np
import sympy as sp

from uvsym.errors import VerificationError
from uvsym.sympy_bridge import to_sympy
from uvsym.verify.certificate import Certificate
from uvsym.verify.interval import IntervalFunction
from uvsym.verify.mp_enclosure import enclose

__all__ = ["prove_identity", "exact_zero"]

DIGITS = 50
RECHECK_DIGITS = (100, 200, 400)  # precisions of the interval re-check, tried in turn until one decides
REFUTE, ROUNDING = 1e-10, 1e-12
SYMBOLIC_SECONDS = 4.0  # CPU seconds of the symbolic steps
WALL_FACTOR = 20  # wall-clock allowance of a loaded machine, per CPU second
SIMPLIFY_OPS = 200  # entries larger than this are not handed to sympy.simplify


def _atomised(expression: sp.Expr) -> sp.Expr:
    """Non-rational sub-expressions (functions, non-integer powers) replaced by fresh symbols, so
    that what is left is a rational function (its arguments normalised first)."""
    atoms: dict[sp.Expr, sp.Symbol] = {}

    def walk(e):
        if e.is_Atom:
            return e
        if isinstance(e, (sp.Add, sp.Mul)):
            return e.func(*[walk(a) for a in e.args])
        if isinstance(e, sp.Pow) and e.exp.is_Integer:
            return walk(e.base) ** e.exp
        key = e.func(*[sp.expand(walk(a)) if isinstance(a, sp.Expr) else a for a in e.args])
        return atoms.setdefault(key, sp.Dummy(f"atom{len(atoms)}"))

    return walk(expression)


def exact_zero(expression: sp.Expr) -> bool:
    """Whether a sympy expression with rational constants is identically zero as a rational
    function of its symbols and transcendental atoms (a True is a proof; False proves nothing)."""
    rational = _atomised(expression)
    numerator, denominator = sp.fraction(sp.together(rational))
    return sp.expand(numerator) == 0 and denominator != 0


def _rational_function(expression: sp.Expr) -> bool:
    """Whether ``expression`` is a rational function of its symbols with rational constants: then a
    nonzero expanded numerator proves it is not identically zero, and simplification has nothing to add."""
    return all(e.is_Symbol or e.is_Rational or isinstance(e, (sp.Add, sp.Mul))
               or (isinstance(e, sp.Pow) and e.exp.is_Integer) for e in sp.preorder_traversal(expression))


def _symbolic_outcome(entries: list[sp.Expr], channel, seconds: float) -> None:
    """In the child: send "exact", "simplify" or "" (not shown to be zero) for the whole difference;
    the child is stopped after ``seconds`` of CPU time (so a loaded machine does not change the outcome), or
    earlier at a finite hard limit the process inherited (a batch job's ``ulimit -t``), which it keeps."""
    _, hard = resource.getrlimit(resource.RLIMIT_CPU)
    soft = max(1, math.ceil(seconds)) + int(time.process_time())
    resource.setrlimit(resource.RLIMIT_CPU, (soft if hard == resource.RLIM_INFINITY else min(soft, hard), hard))
    how = "exact"
    for entry in entries:
        if exact_zero(entry):
            continue
        if not _rational_function(entry) and sp.count_ops(entry) <= SIMPLIFY_OPS and _simplifies_to_zero(entry):
            how = "simplify"
            continue
        how = ""
        break
    channel.send(how)


def _simplifies_to_zero(entry: sp.Expr) -> bool:
    """Whether sympy.simplify gives 0; False where simplify itself fails (it raises on some Piecewise
    with undefined branches: not shown zero, which proves nothing either way)."""
    try:
        return sp.simplify(entry) == 0
    except (ValueError, TypeError, ArithmeticError, RecursionError, NotImplementedError, AttributeError):
        return False


def _symbolic(entries: list[sp.Expr], seconds: float) -> str:
    """"exact", "simplify", "" (not zero) or "timeout", from a child process given ``seconds`` of CPU
    time (and at most ``WALL_FACTOR`` times that of wall-clock time)."""
    context = multiprocessing.get_context("fork")
    receive, send = context.Pipe(duplex=False)
    child = context.Process(target=_symbolic_outcome, args=(entries, send, seconds), daemon=True)
    child.start()
    send.close()
    try:
        outcome = receive.recv() if receive.poll(WALL_FACTOR * max(1.0, seconds)) else "timeout"
    except EOFError:  # the child hit its CPU limit
        outcome = "timeout"
    if child.is_alive():
        child.kill()
    child.join()
    return outcome


def _entries(expression: ca.SX) -> list[sp.Expr]:
    """The entries of vec(expression) in sympy, constants as the exact rationals they store."""
    converted = to_sympy(ca.densify(ca.vec(expression)), exact=True)
    return list(converted) if isinstance(converted, sp.MatrixBase) else [converted]


def _magnitude(expression: sp.Expr) -> sp.Expr:
    """The sum of the absolute values of ``expression``'s terms, recursively through + and *."""
    if isinstance(expression, (sp.Add, sp.Mul)):
        return expression.func(*[_magnitude(a) for a in expression.args])
    if isinstance(expression, sp.Pow) and expression.exp.is_Integer and expression.exp > 0:
        return _magnitude(expression.base) ** expression.exp
    return sp.Abs(expression)


def _points(rng, n: int, box, samples: int) -> np.ndarray:
    """(samples, n) points over the box, or over the reals at many scales without one."""
    if box is not None:
        lower, upper = box
        uniform = lower + (upper - lower) * rng.uniform(size=(samples, n))
        ends = np.where(rng.uniform(size=(samples, n)) < 0.5, lower, upper)
        near_zero = np.clip(np.sign(rng.uniform(-1, 1, size=(samples, n))) * 10.0 ** rng.uniform(-6, 0, (samples, n))
                            * np.maximum(np.abs(lower), np.abs(upper)), lower, upper)
        choice = rng.uniform(size=(samples, n))
        return np.where(choice < 0.6, uniform, np.where(choice < 0.8, ends, near_zero))
    normal = rng.normal(size=(samples, n)) * 2.0
    scaled = np.sign(rng.uniform(-1, 1, size=(samples, n))) * 10.0 ** rng.uniform(-3, 8, size=(samples, n))
    integers = rng.integers(-10, 11, size=(samples, n)).astype(float)
    choice = rng.uniform(size=(samples, n))
    return np.where(choice < 0.5, normal, np.where(choice < 0.85, scaled, integers))


def _kink_points(rng, n: int) -> np.ndarray:
    """Points where sign, |.|, floor, fmod and copysign jump: the origin, and each coordinate in turn (four
    drawn ones beyond four) at 0, +-1/2 and +-3/2 with the others N(0, 2^2): (1 + 3 min(n, 4), n)."""
    rows = [np.zeros(n)]
    for value in (0.0, 0.5, 1.5):
        for i in (range(n) if n <= 4 else rng.choice(n, 4, replace=False)):
            row = rng.normal(size=n) * 2.0
            row[i] = value * rng.choice([-1.0, 1.0])
            rows.append(row)
    return np.array(rows)


def _symbols(inputs, lhs, rhs) -> list[ca.SX]:
    """The inputs' symbols, in order; VerificationError for non-symbols and for free symbols of lhs, rhs."""
    if not isinstance(inputs, (list, tuple)) or not all(isinstance(v, ca.SX) for v in inputs):
        raise VerificationError("inputs must be a list of CasADi SX symbol vectors")
    symbols = [s for v in inputs for s in ca.vertsplit(ca.vec(v))]
    if not all(s.is_symbolic() for s in symbols):
        raise VerificationError("inputs must hold symbols only (no expressions or constants)")
    free = sorted({s.name() for s in ca.symvar(ca.vertcat(ca.vec(lhs), ca.vec(rhs)))} - {s.name() for s in symbols})
    if free:
        raise VerificationError(f"lhs/rhs use symbols not among the inputs: {', '.join(free)} (list them in inputs)")
    return symbols


def _box(box, n: int):
    if box is None:
        return None
    try:
        lower, upper = (np.asarray(b, dtype=float).ravel() for b in box)
    except (TypeError, ValueError):
        raise VerificationError("box must be a pair (lower, upper) of arrays, one entry per input symbol") from None
    if lower.shape != (n,) or upper.shape != (n,) or not (np.all(np.isfinite(lower)) and np.all(np.isfinite(upper))):
        raise VerificationError(f"box must be finite lower and upper bounds with {n} entries (one per input symbol)")
    if np.any(lower > upper):
        raise VerificationError("box has a lower bound above its upper bound")
    return lower, upper


def _certain_gap(lhs: ca.SX, rhs: ca.SX, symbols: list[ca.SX], point, k: int) -> float | None:
    """A rigorous lower bound of ``|lhs_k - rhs_k|`` at the point (outward-rounded interval
    evaluation of the CasADi graph), or None where the graph has an operation intervals lack."""
    try:
        difference = IntervalFunction(ca.Function("difference", [ca.vertcat(*symbols)], [ca.vec(lhs - rhs)]))
    except VerificationError:
        return None
    bounds = difference(point, point)
    lo, hi = bounds.lo[0, k], bounds.hi[0, k]
    return float(max(lo, -hi, 0.0)) if bounds.defined[0] else 0.0


def prove_identity(claim: str, lhs: ca.SX, rhs: ca.SX, inputs: list[ca.SX], set_description: str,
                   expected: str = "proved", samples: int = 30, seed: int = 0, box=None,
                   symbolic_seconds: float = SYMBOLIC_SECONDS) -> Certificate:
    """Certificate for ``lhs == rhs`` for every value of the symbols in ``inputs`` (module docstring).

    lhs, rhs: SX of the same shape; inputs: SX symbol vectors (every symbol of lhs and rhs);
    box: optional (lower, upper) over the inputs' symbols in order, the stated set sampled.
    VerificationError for mismatched shapes, non-symbolic inputs, free symbols or a bad box.
    """
    started = time.perf_counter()
    lhs, rhs = ca.SX(lhs), ca.SX(rhs)
    if lhs.shape != rhs.shape:
        raise VerificationError(f"lhs and rhs must have the same shape, got {lhs.shape} and {rhs.shape}")
    symbols = _symbols(inputs, lhs, rhs)
    box = _box(box, len(symbols))

    def certificate(method, status, **fields):
        return Certificate(claim, set_description, method, status, expected, seconds=time.perf_counter() - started,
                           **fields)

    left, right = _entries(lhs), _entries(rhs)
    entries = [a - b for a, b in zip(left, right)]
    outcome = _symbolic(entries, symbolic_seconds)
    if outcome == "exact":
        return certificate("exact rational arithmetic on the double constants (converted exactly), transcendental "
                           "terms as independent symbols: the difference is zero", "proved")
    if outcome == "simplify":
        return certificate("sympy simplification to zero, rational constants (exact)", "proved")
    sym = [sp.Symbol(s.name(), real=True) for s in symbols]
    sizes = [_magnitude(a) + _magnitude(b) for a, b in zip(left, right)]
    try:
        numeric = sp.lambdify(sym, entries, modules="mpmath")
        magnitude = sp.lambdify(sym, sizes, modules="mpmath")
    except (RecursionError, TypeError) as exc:  # the printer recurses once per level of nesting, and cannot print
        # a condition sympy rewrote into nested if-then-else terms with piecewise arguments (TypeError)
        why = ("is nested too deeply for sympy to print it" if isinstance(exc, RecursionError)
               else "has conditions sympy cannot print")
        return certificate("sampling by mpmath", "inconclusive",
                           reason=f"{'not shown zero symbolically' if outcome == '' else 'symbolic steps timed out'}; "
                                  f"the difference {why} for mpmath")

    def relative(point, digits):
        with mpmath.workdps(digits):
            args = [mpmath.mpf(float(p)) for p in point]
            values, scales = numeric(*args), magnitude(*args)
            return [float(abs(v) / s) if s != 0 else (0.0 if v == 0 else float("inf"))
                    for v, s in zip(values, scales)]

    def _recheck(point, k) -> str:
        """How the gap at the point was bounded rigorously above twice the threshold ("" when it was not)."""
        graph_gap = _certain_gap(lhs, rhs, symbols, point, k)
        for digits in RECHECK_DIGITS:
            bounds = enclose([entries[k], sizes[k]], dict(zip(sym, point)), digits)
            if bounds is None:
                return ""
            gap, size = bounds
            threshold = (2 * REFUTE * size.b).b  # rounded up
            if graph_gap is not None and graph_gap > threshold:
                return "re-checked by interval evaluation (outward rounding)"
            if max(gap.a, -gap.b) > threshold:
                return f"re-checked by mpmath interval arithmetic at {digits} digits (outward rounding)"
        return ""

    rng = np.random.default_rng(seed)
    worst, evaluated = 0.0, 0
    points = _points(rng, len(sym), box, samples)
    if box is None:
        points = np.concatenate([points, _kink_points(rng, len(sym))])
    for point in points:
        try:
            differences = relative(point, DIGITS)
        except (ZeroDivisionError, ValueError, TypeError, OverflowError):  # a pole or a domain edge: not a sample
            continue
        evaluated += 1
        k = int(np.argmax(differences))
        if differences[k] > REFUTE and (recheck := _recheck(point, k)):
            return certificate(f"mpmath evaluation at {DIGITS} digits, entry {k} against the size of its terms; "
                               f"{recheck}", "refuted", margin=-differences[k],
                               counterexample={"point": {str(s): float(p) for s, p in zip(sym, point)},
                                               "entry": k, "relative_difference": differences[k]})
        worst = max(worst, max(differences))
    where = "the stated box" if box is not None else "the reals at scales 1e-3 to 1e8"
    reason = {"timeout": f"symbolic steps over {symbolic_seconds:g} s; ", "": "not shown zero symbolically; "}[outcome]
    method = (f"sampled: {evaluated} points over {where}, mpmath {DIGITS} digits, each entry against the size of "
              f"its terms, to the precision of the model's double constants (evidence, not a proof)")
    if evaluated == 0:
        return certificate(method, "inconclusive", reason=f"{reason}no sample point was evaluable")
    if worst > ROUNDING:
        level = (f"above {REFUTE:g} at {DIGITS} digits, not confirmed by the interval re-check" if worst > REFUTE
                 else f"above rounding but below {REFUTE:g}")
        return certificate(method, "inconclusive", margin=-worst,
                           reason=f"{reason}largest relative difference {worst:.3g} is {level}")
    return certificate(method, "checked", margin=ROUNDING - worst, reason=reason.rstrip("; "),
                       details={"largest_relative_difference": worst, "points": evaluated})
