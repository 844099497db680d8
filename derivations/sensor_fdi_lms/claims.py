"""Claims of the LMS study: the paper's step mu = 0.01 is below the mean-square bound for the
healthy heading loop's input, and, as a negative control, twice the bound is refuted."""

from __future__ import annotations

import functools

import numpy as np

from derivations.sensor_fdi_lms.design import MU, ORDER
from derivations.sensor_fdi_lms.experiment import Run, run
from uvsym.observers.lms import mu_bound
from uvsym.verify.lms import lms_step_claim

__all__ = ["healthy_input", "lms_claims", "NEGATIVE_FACTOR"]

NEGATIVE_FACTOR = 2.0  # the negative control's mu, in units of the bound


@functools.lru_cache(maxsize=1)
def healthy_input() -> np.ndarray:
    """(RECORD,) thrust command u of the recorded part of the healthy run (seed 0)."""
    outcome = run(Run(size_deg=None, ftc=False))
    return outcome.result["u"]["u"][outcome.spec.warm_up:].copy()


def lms_claims() -> list:
    """Two certificates: mu = MU proved below the bound; NEGATIVE_FACTOR times the bound refuted."""
    u = healthy_input()
    above = NEGATIVE_FACTOR * mu_bound(ORDER, float(np.mean(u ** 2)))
    return [lms_step_claim(MU, ORDER, u, claim=f"paper's mu = {MU:g} is below 1 / (M P_u)"),
            lms_step_claim(above, ORDER, u, expected="refuted",
                           claim=f"negative control: mu = {NEGATIVE_FACTOR:g} / (M P_u) is below 1 / (M P_u)")]
