"""LMI synthesis of observer gains: ``Y = P L`` makes the design convex, then the result is certified.

For ``e' = (A - L C) e`` a decay rate alpha holds with ``V = e^T P e`` when
``(A - L C)^T P + P (A - L C) + 2 alpha P < 0``; with ``Y = P L`` this is linear in (P, Y):
``A^T P + P A - C^T Y^T - Y C + 2 alpha P < 0``. Optional equality constraints ``E P = F`` (the
unknown-input observer's ``(P L) ... = ...`` conditions) enter as they are. The gain returned
is ``L = P^-1 Y``, and the closed loop ``A - L C`` -- computed exactly in rationals from the doubles
A, L and C, not the floating-point ``fl(A - L C)`` -- is re-certified by :func:`lyapunov_decrease`
independently of the solver. Without equality constraints L is first rounded to ``GAIN_DIGITS``
significant digits of its largest entry: an interior-point solution's last digits move with the
solver's build and the processor (observed: 4e-9 relative in a threshold derived from the gain), so
the gain, every figure derived from it and the reports repeat across machines. The rounded gain is
the one certified, or where rounding leaves too little margin (a rate at the edge of what the LMI
reaches) the solver's own; with equalities (exact decoupling conditions) the solver's is kept.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from uvsym.errors import UvsymError, VerificationError
from uvsym.verify.certificate import Certificate
from uvsym.verify.exact import as_fraction_matrix, matmul
from uvsym.verify.lyapunov import lyapunov_decrease

__all__ = ["DESIGN_MARGIN", "GAIN_DIGITS", "GainSynthesis", "rounded_gain", "synthesize_observer_gain"]

DESIGN_MARGIN = 1.01  # the LMI asks for 1 % more than the rate certified
GAIN_DIGITS = 5  # significant digits (of the largest entry) a solver's gain is rounded to


def rounded_gain(L: np.ndarray) -> np.ndarray:
    """L (any shape) rounded to ``GAIN_DIGITS`` significant digits of its largest entry (a zero L as it is):
    what an interior-point solver's answer is certified as, so that it repeats across machines."""
    scale = float(np.max(np.abs(L))) if L.size else 0.0
    if not scale > 0 or not np.isfinite(scale):
        return L
    return np.round(L, int(GAIN_DIGITS - 1 - np.floor(np.log10(scale)))) + 0.0  # no -0.0


@dataclass(frozen=True)
class GainSynthesis:
    """L (n, p) the observer gain, P (n, n) the Lyapunov matrix, certificate of A - L C's decay."""

    L: np.ndarray
    P: np.ndarray
    certificate: Certificate


def synthesize_observer_gain(A, C, decay: float, equalities: list | None = None,
                             claim: str = "observer error decays") -> GainSynthesis:
    """A gain L with ``e' = (A - L C) e`` decaying at rate ``decay`` (1/s), by LMI, then certified.

    The LMI is solved for ``DESIGN_MARGIN`` times the rate, so that the gain is certified at the
    rate asked for with room to spare (the optimum otherwise sits on the boundary, where the
    exact re-check can go either way); where that is infeasible, at the rate itself.
    equalities: optional list of callables
    ``(P, Y) -> cvxpy constraint`` (e.g. unknown-input decoupling).

    Raises
    ------
    UvsymError
        For non-finite or wrongly sized A or C, a decay that is negative or not finite, an LMI
        without a solution, or a gain that the exact re-check cannot certify.
    """
    A_exact, C_exact = as_fraction_matrix(A, "A"), as_fraction_matrix(C, "C")
    A, C = np.array(A_exact, dtype=float), np.array(C_exact, dtype=float)
    n, p = A.shape[0], C.shape[0]
    if A.shape != (n, n) or C.shape[1] != n:
        raise VerificationError(f"A must be square and C have {n} columns; got A {A.shape}, C {C.shape}")
    if not (isinstance(decay, (int, float, np.floating, np.integer)) and np.isfinite(decay) and decay >= 0):
        raise VerificationError(f"decay must be a finite rate >= 0 (1/s), got {decay!r}")
    tried = []
    for design in (DESIGN_MARGIN * decay + 1e-6, decay):  # with room to spare; else exactly the rate asked
        P, Y = cp.Variable((n, n), symmetric=True), cp.Variable((n, p))
        M = A.T @ P + P @ A - C.T @ Y.T - Y @ C + 2 * design * P
        constraints = [P >> np.eye(n), 0.5 * (M + M.T) << -1e-6 * np.eye(n)]
        constraints += [make(P, Y) for make in (equalities or [])]
        problem = cp.Problem(cp.Minimize(cp.trace(P) + cp.norm(Y, "fro")), constraints)
        with warnings.catch_warnings():  # an inaccurate solution is re-checked exactly below
            warnings.filterwarnings("ignore", message="Solution may be inaccurate")
            try:
                problem.solve(solver=cp.CLARABEL)
            except cp.SolverError as exc:  # numerically out of reach (a rate of 1e300 1/s): no gain from here
                tried.append(f"{design:.6g} 1/s: the solver failed ({exc})")
                continue
        tried.append(f"{design:.6g} 1/s: {problem.status}")
        if P.value is not None and problem.status in ("optimal", "optimal_inaccurate"):
            break
    else:
        raise VerificationError(f"no observer gain with decay {decay} 1/s: the LMI at {' and at '.join(tried)}")
    solved = np.linalg.solve(P.value, Y.value)
    for L in ([solved] if equalities else [rounded_gain(solved), solved]):  # rounded where it certifies
        L_exact = as_fraction_matrix(L, "L")
        closed_loop = [[a - lc for a, lc in zip(row_a, row_lc)]
                       for row_a, row_lc in zip(A_exact, matmul(L_exact, C_exact))]
        certificate = lyapunov_decrease(claim, [closed_loop], decay,
                                        f"A - L C (exact, in rationals) with the synthesised L, decay {decay:g} 1/s")
        if certificate.status == "proved":
            break
    if certificate.status != "proved":
        raise UvsymError(f"the synthesised gain could not be certified at decay {decay:g} 1/s "
                         f"({certificate.status}: {certificate.reason or certificate.method})")
    return GainSynthesis(L=L, P=np.asarray(P.value), certificate=certificate)
