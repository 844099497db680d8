"""Claims of the motor observer: the linearisation identity, the decay of its linearised error at
the operating point, the contraction of its sampled step, and two negative controls (without
output injection the model's own error decays slower than DECAY; the same gain sampled four
times slower makes the sampled error map expand).

The nonlinear decay on an error box (:func:`uvsym.verify.estimators.region_decay_claim`) was tried
on this motor and stays inconclusive after two million boxes (P's condition number is about 3500
and the flux-speed products are large), so it is not claimed here.
"""

from __future__ import annotations

import numpy as np

from derivations.motor_luenberger.design import DECAY, DT, design
from uvsym.observers.luenberger import luenberger_observer
from uvsym.verify.estimators import linear_decay_claim, linearisation_claim, sampled_decay_claim

__all__ = ["SLOW_DT", "motor_claims"]

SLOW_DT = 4 * DT  # s, the negative control's sample period


def motor_claims() -> list:
    """Five certificates; the last two are expected refuted."""
    d = design()
    L = d.synthesis.L
    open_loop = luenberger_observer(d.plant, np.zeros_like(L), d.observer.dt, name="open_loop")
    slow = luenberger_observer(d.plant, L, SLOW_DT, name="luenberger_slow")
    return [
        linearisation_claim(d.observer, d.plant, L),
        linear_decay_claim(d.observer, d.plant, DECAY),
        sampled_decay_claim(d.observer, d.plant),
        linear_decay_claim(open_loop, d.plant, DECAY, expected="refuted"),
        sampled_decay_claim(slow, d.plant, expected="refuted"),
    ]
