"""Claims of the quadrotor UIO study, for ``uvsym verify uio-zonotope``.

- the paper's set-up (six attitude states, ``y = (phi, theta, psi)``): for the observer
  decoupling the yaw disturbance alone and for each bank observer (disturbance and actuator i),
  ``(C, T G)`` is not detectable: refuted with the exact eigenvalue -1 (the ZOH sampling zero of a
  double integrator) and its eigenvector, expected refuted;
- uvsym's set-up (all eight states measured): each bank observer's conditions hold and its
  designed gain makes ``F`` Schur stable, proved in exact rationals;
- each bank observer's band holds every healthy residual of its error recursion, for every initial
  error in the box and all noise within its bounds, at every one of the band's samples, as the
  decision compares them (``outside_band``'s limits): proved by outward-rounded interval arithmetic
  on the exact set's hull (:mod:`uvsym.verify.band_enclosure`). The Monte Carlo check of the
  simulated residuals (:mod:`.enclosure`) is reported beside it as a simulation check, not a claim.

The plant matrices are the exact zero-order hold (finite series: the hover model is a chain of
integrators) of the CasADi linearisation, whose double entries are taken as exact rationals.
"""

from __future__ import annotations

import functools
from fractions import Fraction

import numpy as np

from derivations.uio_zonotope.design import ATTITUDE, DT, ERROR_BOUND, design, linear_plant
from uvsym.observers.uio_bank import decision_limits, residual_recursion
from uvsym.verify.band_enclosure import band_enclosure_claim
from uvsym.verify.certificate import Certificate
from uvsym.verify.uio import exact_zoh, uio_existence_claim

__all__ = ["band_claims", "exact_plant", "uio_claims"]

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


def band_claims() -> list[Certificate]:
    """Per bank observer: its band holds every healthy residual of the recursion (module docstring)."""
    d = design()
    claims = []
    for obs, design_i, band in zip(d.bank.observers, d.bank.designs, d.bands):
        A, C, initial, noise = residual_recursion(design_i, d.noise_bound, np.full(len(design_i.F), ERROR_BOUND))
        lower, upper = decision_limits(band)
        claims.append(band_enclosure_claim(
            f"{obs.name}: every healthy residual lies in its zonotope band at every sample (as the decision "
            "compares them)", A, C, initial, noise, lower, upper,
            f"every initial error |e_0,j| <= {ERROR_BOUND:g} and noise |v_j| <= vbar_j, samples 0 to {len(lower) - 1}"))
    return claims
