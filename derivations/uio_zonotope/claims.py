"""Claims of the quadrotor UIO study, for ``uvsym verify uio-zonotope``.

- the paper's set-up (six attitude states, ``y = (phi, theta, psi)``): for the observer
  decoupling the yaw disturbance alone and for each bank observer (disturbance and actuator i),
  ``(C, T G)`` is not detectable: refuted with the exact eigenvalue -1 (the ZOH sampling zero of a
  double integrator) and its eigenvector, expected refuted;
- uvsym's set-up (all eight states measured): each bank observer's conditions hold and its
  designed gain makes ``F`` Schur stable, proved in exact rationals;
- the bands enclose the healthy residuals: Monte Carlo over the healthy runs (numerical
  evidence: status "checked", never "proved"; a violation confirmed by LP refutes it).

The plant matrices are the exact zero-order hold (finite series: the hover model is a chain of
integrators) of the CasADi linearisation, whose double entries are taken as exact rationals.
"""

from __future__ import annotations

import functools
import time
from fractions import Fraction

import numpy as np

from derivations.uio_zonotope.design import ATTITUDE, DT, design, linear_plant
from derivations.uio_zonotope.enclosure import check_enclosure
from derivations.uio_zonotope.experiment import simulate_runs
from uvsym.verify.certificate import Certificate
from uvsym.verify.uio import exact_zoh, uio_existence_claim

__all__ = ["HEALTHY_RUNS", "HEALTHY_SEED", "enclosure_claim", "exact_plant", "uio_claims"]

HEALTHY_RUNS = 100
HEALTHY_SEED = 0
EXACT_DT = Fraction(DT).limit_denominator(10**6)  # 1/100 s exactly
SET = "hover linearisation (CasADi, doubles taken exactly), exact ZOH at 1/100 s"


@functools.lru_cache(maxsize=2)
def exact_plant(states: tuple | None = None):
    """(G, H, D1) of the exact ZOH, as Fraction matrices, over ``states`` (default all eight)."""
    plant = linear_plant(states)
    lin = plant.linearize()
    m = plant.u.size
    G, HD = exact_zoh(lin.A, np.hstack([lin.B, lin.E]), EXACT_DT)
    return G, [row[:m] for row in HD], [row[m:] for row in HD]


def _columns(*blocks):
    return [sum((list(row) for row in rows), []) for rows in zip(*blocks)]


def uio_claims() -> list[Certificate]:
    """Refuted paper set-up (5), proved full-state bank (4)."""
    d = design()
    names = d.plant.u.names
    claims = []
    G6, H6, D6 = exact_plant(ATTITUDE)
    C6 = [[Fraction(int(i == j)) for j in range(6)] for i in range(3)]
    claims.append(uio_existence_claim("paper's set-up, y = (phi, theta, psi): a UIO decoupling the yaw disturbance "
                                      "exists ((C, T G) detectable)", G6, C6, D6, set_description=SET,
                                      expected="refuted"))
    for i, name in enumerate(names):
        claims.append(uio_existence_claim(f"paper's set-up, y = (phi, theta, psi): the bank's UIO decoupling the yaw "
                                          f"disturbance and {name} exists", G6, C6,
                                          _columns(D6, [[row[i]] for row in H6]), set_description=SET,
                                          expected="refuted"))
    G, H, D1 = exact_plant(None)
    C = [[Fraction(int(i == j)) for j in range(8)] for i in range(8)]
    for i, (name, design_i) in enumerate(zip(names, d.bank.designs)):
        claims.append(uio_existence_claim(f"all states measured: the UIO decoupling the yaw disturbance and {name} "
                                          "exists and its gain makes F = T G - K1 C Schur stable", G, C,
                                          _columns(D1, [[row[i]] for row in H]), K1=design_i.K1, set_description=SET))
    return claims


def enclosure_claim(report: dict | None = None) -> Certificate:
    """The healthy residuals of HEALTHY_RUNS seeded runs against their zonotopes (numerical evidence)."""
    started = time.perf_counter()
    if report is None:
        report = check_enclosure(simulate_runs(HEALTHY_SEED, HEALTHY_RUNS))
    claim = "every healthy residual of every bank observer lies in its zonotope band"
    where = (f"{HEALTHY_RUNS} seeded healthy runs x {report['samples'] // HEALTHY_RUNS} residual vectors "
             f"(= {report['samples']} samples), uniform and vertex noise")
    method = (f"Monte Carlo: witness coefficients carried through every reduction, {report['lp_checked']} samples "
              "re-checked by LP (numerical evidence, not a proof)")
    if report["violations"]:
        return Certificate(claim, where, method, "refuted", "checked", seconds=time.perf_counter() - started,
                           counterexample=report["first_violation"])
    return Certificate(claim, where, method, "checked", "checked", margin=1 - report["worst_coefficient"],
                       seconds=time.perf_counter() - started,
                       reason=f"0 of {report['samples']} samples outside: evidence, not a proof", details=report)
