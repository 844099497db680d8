"""Claims of the motor observer: the linearisation identity, the LMI decay at the operating point,
and a negative control (without output injection the model's own error decays slower than DECAY).

The nonlinear decay on an error box (:func:`uvsym.verify.estimators.region_decay_claim`) was tried
on this motor and stays inconclusive after two million boxes (P's condition number is about 3500
and the flux-speed products are large), so it is not claimed here.
"""

from __future__ import annotations

import numpy as np

from derivations.motor_luenberger.design import DECAY, design
from uvsym.observers.luenberger import luenberger_observer
from uvsym.verify.estimators import linear_decay_claim, linearisation_claim

__all__ = ["motor_claims"]


def motor_claims() -> list:
    """Three certificates; the last is expected refuted."""
    d = design()
    L = d.synthesis.L
    open_loop = luenberger_observer(d.plant, np.zeros_like(L), d.observer.dt, name="open_loop")
    return [
        linearisation_claim(d.observer, d.plant, L),
        linear_decay_claim(d.observer, d.lin, L, DECAY),
        linear_decay_claim(open_loop, d.lin, np.zeros_like(L), DECAY, expected="refuted"),
    ]
