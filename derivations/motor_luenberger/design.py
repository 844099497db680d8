"""The induction motor's Luenberger observer: plant, operating point, LMI gain (uvsym's choices).

The plant is uvsym's ``induction_motor`` (Yu et al. 2018, eq. 23; MSL parameters). The
gain L makes ``A - L C`` at the operating point decay at ``DECAY`` 1/s; it comes from the LMI
``A^T P + P A - C^T Y^T - Y C + 2 DECAY P < 0``, ``L = P^-1 Y``
(:func:`uvsym.verify.synthesize_observer_gain`). The observer runs at ``DT`` (a 10 kHz drive
sample rate) on the nonlinear model.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

import uvsym
from uvsym.errors import ObserverError
from uvsym.observers.base import Observer
from uvsym.observers.luenberger import luenberger_observer
from uvsym.systems import Linearization, System
from uvsym.verify import GainSynthesis, synthesize_observer_gain

__all__ = ["DECAY", "DT", "Design", "design"]

DECAY = 50.0  # 1/s, the observer error's guaranteed decay rate at the operating point (the motor alone: 31.7)
DT = 1e-4  # s, the observer's sample period


@dataclass(frozen=True)
class Design:
    """plant, its linearisation at the operating point, the gain synthesis and the observer."""

    plant: System
    lin: Linearization
    synthesis: GainSynthesis
    observer: Observer


@functools.lru_cache(maxsize=8)
def design(decay: float = DECAY, dt: float = DT, name: str = "luenberger") -> Design:
    """The observer with its gain synthesised for ``decay`` (1/s), sampled every ``dt`` (s).

    Raises ObserverError for a decay or dt that is not positive and finite."""
    for what, value in (("decay", decay), ("dt", dt)):
        if not (np.isfinite(value) and value > 0):
            raise ObserverError(f"motor observer: {what} must be positive and finite, got {value}")
    plant = uvsym.plant("induction_motor")
    lin = plant.linearize()
    synthesis = synthesize_observer_gain(lin.A, lin.C, decay, claim=f"A - L C decays at {decay:g} 1/s")
    return Design(plant, lin, synthesis, luenberger_observer(plant, synthesis.L, dt, name=name))
