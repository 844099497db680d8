"""Monte Carlo check of the bands: every sampled healthy residual inside its zonotope.

For each healthy run and observer, the residual the simulation gave (plant System and the
Observer's CasADi step) is compared with its zonotope ``<c_k, G_k>`` in two ways:

- a witness: the run's own initial state and noise, as coefficients of the initial and noise
  generators, carried through every order reduction (:func:`uvsym.sets.carry_coefficients`); the
  point is inside when ``c_k + G_k a_k`` reproduces the simulated residual and ``||a_k||_inf <= 1``
  (a sufficient condition, so a pass is a membership proof for that sample, up to rounding);
- a linear program (:meth:`uvsym.sets.Zonotope.contains`) for a seeded subset, and for every
  sample whose witness fails, so that a violation is only reported when the LP agrees.

Numerical evidence about the bands, not a proof that every admissible run stays inside.
"""

from __future__ import annotations

import numpy as np

from derivations.uio_zonotope.design import ERROR_BOUND, design
from derivations.uio_zonotope.experiment import Runs
from uvsym.sets import carry_coefficients

__all__ = ["LP_SUBSET", "check_enclosure"]

LP_SUBSET = 50  # samples per observer also checked by linear programming
MATCH_TOLERANCE = 1e-9  # |c + G a - r| relative to the band's half-width


def check_enclosure(runs: Runs, seed: int = 0) -> dict:
    """samples, violations (LP-confirmed), witness_failures, lp_checked, lp_outside, worst
    witness coefficient and worst reproduction error (relative), with the first violation."""
    d = design()
    vbar = d.noise_bound
    samples = violations = witness_failures = lp_checked = lp_outside = 0
    worst_coefficient, worst_mismatch, first = 0.0, 0.0, None
    rng = np.random.default_rng(seed)
    for obs, band, residuals in zip(d.bank.observers, d.bands, runs.residuals):
        N, _, R = residuals.shape
        initial = np.vstack([runs.x0 / ERROR_BOUND, runs.noise[0] / vbar[:, None]])
        coefficients = carry_coefficients(band, initial, runs.noise / vbar[None, :, None])
        failed = []
        for k, Z in enumerate(band.outputs[:N]):
            a = coefficients[k, :Z.order]
            point = Z.center[:, None] + Z.generators @ a
            half = np.maximum(band.upper[k] - band.lower[k], 1e-300)[:, None] / 2
            mismatch = np.max(np.abs(point - residuals[k]) / half, axis=0)
            size = np.max(np.abs(a), axis=0)
            worst_mismatch, worst_coefficient = max(worst_mismatch, mismatch.max()), max(worst_coefficient, size.max())
            failed += [(k, j) for j in np.flatnonzero((mismatch > MATCH_TOLERANCE) | (size > 1 + 1e-9))]
        samples += N * R
        witness_failures += len(failed)
        chosen = {(int(k), int(j)) for k, j in zip(rng.integers(0, N, LP_SUBSET), rng.integers(0, R, LP_SUBSET))}
        for k, j in sorted(chosen | set(failed)):
            lp_checked += 1
            inside = band.outputs[k].contains(residuals[k, :, j])
            lp_outside += not inside
            if not inside and (k, j) in set(failed):
                violations += 1
                first = first or {"observer": obs.name, "sample": k, "run": j,
                                  "residual": residuals[k, :, j].tolist()}
    return {"samples": samples, "violations": violations, "witness_failures": witness_failures,
            "lp_checked": lp_checked, "lp_outside": lp_outside, "worst_coefficient": worst_coefficient,
            "worst_mismatch": worst_mismatch, "first_violation": first}
