"""``uvsym codegen motor-luenberger``: the motor observer's step as a C package."""

from __future__ import annotations

from derivations.motor_luenberger.design import DECAY, DT, design
from uvsym.codegen.estimators import exported_observer
from uvsym.codegen.observer_sets import ObserverSet

__all__ = ["motor_luenberger"]


def motor_luenberger(decay: float = DECAY, dt: float = DT) -> ObserverSet:
    """The Luenberger observer of the induction motor, gain for ``decay`` (1/s), step of ``dt`` (s)."""
    obs = design(float(decay), float(dt)).observer
    return ObserverSet("uvsym_induction_motor", f"Luenberger observer of the induction motor (decay {decay:g} 1/s, "
                       f"step {dt:g} s)", (exported_observer(obs),))
