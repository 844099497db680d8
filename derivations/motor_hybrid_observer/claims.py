"""Claims of the hybrid observer study, ``uvsym verify motor-hybrid-observer``.

The paper's statements as printed, for this motor (expected refuted, each with evidence checked
without the solver): Assumption 1, Theorem 1's LMI (11), Theorem 2's LMI (22). Theorem 2 is
posed for the error ``(e1, (e2, e_q))`` of the estimator as run (:mod:`uvsym.observers.hybrid`):
a common block-diagonal ``V = e1' P1 e1 + (e2, e_q)' P2 (e2, e_q)``, which contains the printed
``V1 + V2 + e_f' Gamma^-1 e_f``; if no such V exists, the printed one does not either. Both LMIs
are posed at decay 0 (the paper's strict ``< 0``).

The corrected design (expected proved): the motor's states and the fault in one block with one
gain from all three residuals, decay ``CORRECTED_DECAY``; its sampled step contracts. Negative
controls (expected refuted): the paper's block-diagonal gains without the decoupling (T = I),
and the corrected gain at three times its rate.
"""

from __future__ import annotations

import time

import sympy

from derivations.motor_hybrid_observer.design import CORRECTED_DECAY, design
from uvsym.verify.certificate import Certificate
from uvsym.verify.estimators import sampled_decay_claim
from uvsym.verify.lmi import block_lmi, block_lmi_claim
from uvsym.verify.lyapunov import lyapunov_decrease

__all__ = ["OVERSHOOT", "hybrid_claims", "paper_problems"]

OVERSHOOT = 3.0  # the negative control asks the corrected gain for this multiple of its rate


def paper_problems(identity_transform: bool = False) -> dict:
    """The block LMIs of Theorems 1 and 2 from the exact decoupling; ``identity_transform``: T = I
    (no decoupling: Omega = A's blocks) for the negative control."""
    d = design()
    ex, s = d.split.exact, d.split
    if identity_transform:
        A = sympy.Matrix(d.lin.A.shape[0], d.lin.A.shape[1], [sympy.Rational(float(v)) for v in d.lin.A.ravel()])
        blocks = {"Omega1": A.extract(list(s.iz1), list(s.iz1)), "Omega2": A.extract(list(s.iz1), list(s.iz2)),
                  "Omega3": A.extract(list(s.iz2), list(s.iz1)), "Omega4": A.extract(list(s.iz2), list(s.iz2))}
    else:
        blocks = {k: ex[k] for k in ("Omega1", "Omega2", "Omega3", "Omega4")}
    n1, n2, q = len(s.iz1), len(s.iz2), s.F2.shape[1]
    theorem1 = sympy.BlockMatrix([[blocks["Omega1"], blocks["Omega2"]], [blocks["Omega3"], blocks["Omega4"]]])
    zero = sympy.zeros
    theorem2 = sympy.BlockMatrix([[blocks["Omega1"], blocks["Omega2"], zero(n1, q)],
                                  [blocks["Omega3"], blocks["Omega4"], zero(n2, q)],
                                  [zero(q, n1), zero(q, n2), zero(q, q)]])
    C4a = sympy.Matrix.hstack(sympy.Matrix(s.C4.tolist()).applyfunc(sympy.Rational),
                              sympy.Matrix(s.F2.tolist()).applyfunc(sympy.Rational))
    C4 = sympy.Matrix(s.C4.tolist()).applyfunc(sympy.Rational)
    return {"theorem 1": block_lmi(theorem1.as_explicit(), [("e1", ex["C1"]), ("e2", C4)], 0.0),
            "theorem 2": block_lmi(theorem2.as_explicit(), [("e1", ex["C1"]), ("e2, e_f", C4a)], 0.0)}


def assumption_claim() -> Certificate:
    """Assumption 1, ``rank(C [B E]) = m + r``: refuted exactly when C has fewer rows than m + r,
    m = rank B and r = rank E bounded below by non-zero minors (numerical ranks as details)."""
    started = time.perf_counter()
    d = design()
    C, B, E = d.lin.C, d.lin.B, d.lin.E
    ranks = d.split.ranks
    exact_B, exact_E = (sympy.Matrix(M.tolist()).applyfunc(sympy.Rational).rank() for M in (B, E))
    bound = exact_B + min(ranks["E"], exact_E)  # exact rank >= numerical rank
    refuted = C.shape[0] < bound
    return Certificate("Assumption 1 on the motor: rank(C [B E]) = m + r", "the linearisation at the operating point",
                       "rank(C [B E]) <= rows of C; m = rank B and r = rank E (>= the numerical rank, a non-zero "
                       "minor) in exact rationals", "refuted" if refuted else "inconclusive", "refuted",
                       seconds=time.perf_counter() - started,
                       counterexample={"rows_of_C": C.shape[0], "m_plus_r_at_least": bound} if refuted else None,
                       details={"numerical_ranks": ranks})


def hybrid_claims() -> list:
    """Every claim with its expected status (module docstring)."""
    d = design()
    paper, identity = paper_problems(), paper_problems(identity_transform=True)
    A_cl = d.corrected_plant.linearize().A - d.corrected.K[0] @ d.corrected_plant.linearize().C
    return [
        assumption_claim(),
        block_lmi_claim(paper["theorem 1"], "Theorem 1 (LMI 11) for the motor: P1, P2 > 0, Y1, Y2 exist",
                        "UIO of subsystem 1 (T E1 = 0) and detection observer; decay 0", expected="refuted"),
        block_lmi_claim(paper["theorem 2"], "Theorem 2 (LMI 22) for the motor: P1, P2 > 0, Y1, Y2 exist",
                        "UIO of subsystem 1 and adaptive estimator of (omega_m, f_s); decay 0", expected="refuted"),
        d.baseline.certificate,
        d.corrected.certificate,
        sampled_decay_claim(d.observers["corrected"], d.corrected_plant),
        block_lmi_claim(identity["theorem 2"], "negative control: the paper's block-diagonal gains without the "
                        "decoupling (T = I)", "subsystem 1 sees the speed, subsystem 2 alone estimates f_s; decay 0",
                        expected="refuted"),
        lyapunov_decrease(f"negative control: the corrected gain decays at {OVERSHOOT:g} x {CORRECTED_DECAY:g} 1/s",
                          [A_cl], OVERSHOOT * CORRECTED_DECAY, "linearisation at the operating point",
                          expected="refuted"),
    ]

