"""``uvsym codegen motor-hybrid-observer``: the study's four observers' steps as one C package."""

from __future__ import annotations

from derivations.motor_hybrid_observer.design import design
from derivations.papers import paper
from uvsym.codegen.estimators import exported_observer
from uvsym.codegen.observer_sets import ObserverSet

__all__ = ["motor_hybrid"]


def motor_hybrid() -> ObserverSet:
    """The hybrid detection observer and fault estimator, the baseline UIO and the corrected design
    of the induction motor, one step of 0.1 ms each."""
    observers = design().observers
    return ObserverSet("uvsym_motor_hybrid", "Induction motor: hybrid UIO detection observer and adaptive fault "
                       "estimator (Yu et al. 2018), baseline UIO, corrected design",
                       tuple(exported_observer(observers[name]) for name in ("detection", "estimator", "baseline",
                                                                             "corrected")),
                       citation=paper("yu2018").reference())
