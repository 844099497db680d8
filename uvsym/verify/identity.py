"""Symbolic identities ``lhs == rhs`` over all inputs: sympy simplification, else high-precision sampling.

``prove_identity`` converts ``lhs - rhs`` (CasADi SX) to sympy by walking the graph. If sympy
simplifies it to zero the identity is proved exactly. Otherwise the difference is evaluated with
mpmath at 50 significant digits at random points. The model's constants are doubles (M^-1
times M is the identity only to about 1e-16), so a relative difference above ``REFUTE`` (1e-10)
refutes the claim -- the point is the counterexample -- while differences below ``ROUNDING``
(1e-12) at every point make it proved by randomised identity testing up to the precision of the
constants (the method says so); anything between is inconclusive.
"""

from __future__ import annotations

import time

import casadi as ca
import mpmath
import numpy as np
import sympy as sp

from uvsym.sympy_bridge import to_sympy
from uvsym.verify.certificate import Certificate

__all__ = ["prove_identity"]

DIGITS = 50
REFUTE, ROUNDING = 1e-10, 1e-12


def prove_identity(claim: str, lhs: ca.SX, rhs: ca.SX, inputs: list[ca.SX], set_description: str,
                   expected: str = "proved", samples: int = 30, seed: int = 0) -> Certificate:
    """Certificate for ``lhs == rhs`` for every value of the symbols in ``inputs`` (see the module docstring)."""
    started = time.perf_counter()
    difference = to_sympy(ca.densify(lhs - rhs))
    entries = list(difference) if isinstance(difference, sp.MatrixBase) else [difference]
    if all(sp.simplify(e) == 0 for e in entries):
        return Certificate(claim, set_description, "sympy simplification to zero (exact)", "proved", expected,
                           margin=None, seconds=time.perf_counter() - started)
    symbols = [s for v in inputs for s in ca.vertsplit(v)]
    sym = [sp.Symbol(s.name(), real=True) for s in symbols]
    numeric = sp.lambdify(sym, entries, modules="mpmath")
    sides = to_sympy(ca.densify(ca.vertcat(ca.vec(lhs), ca.vec(rhs))))
    magnitude = sp.lambdify(sym, list(sides) if isinstance(sides, sp.MatrixBase) else [sides], modules="mpmath")
    rng = np.random.default_rng(seed)
    worst = 0.0
    with mpmath.workdps(DIGITS):
        for _ in range(samples):
            point = rng.normal(size=len(sym)) * 2.0
            values = [abs(v) for v in numeric(*[mpmath.mpf(float(p)) for p in point])]
            scale = max([1] + [abs(v) for v in magnitude(*[mpmath.mpf(float(p)) for p in point])])
            relative = float(max(values) / scale)
            worst = max(worst, relative)
            if relative > REFUTE:
                counterexample = {str(s): float(p) for s, p in zip(sym, point)}
                return Certificate(claim, set_description, f"mpmath evaluation at {DIGITS} digits", "refuted", expected,
                                   margin=-relative, seconds=time.perf_counter() - started,
                                   counterexample={"point": counterexample, "relative_difference": relative})
    method = (f"randomised identity test: {samples} points, mpmath {DIGITS} digits, to the precision of the "
              f"model's double constants")
    if worst > ROUNDING:
        return Certificate(claim, set_description, method, "inconclusive", expected, margin=-worst,
                           seconds=time.perf_counter() - started,
                           reason=f"largest relative difference {worst:.3g} is above rounding but below {REFUTE:g}")
    return Certificate(claim, set_description, method, "proved", expected, margin=ROUNDING - worst,
                       seconds=time.perf_counter() - started, details={"largest_relative_difference": worst})
