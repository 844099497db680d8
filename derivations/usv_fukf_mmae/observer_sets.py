"""``uvsym codegen usv-fukf-mmae [--method ekf]``: a bank's step as a C package."""

from __future__ import annotations

from derivations.usv_fukf_mmae.experiment import bank
from derivations.usv_fukf_mmae.paper import CITATION
from derivations.usv_fukf_mmae.scenario import SHIPPED, load
from uvsym.codegen.estimators import exported_observer
from uvsym.codegen.observer_sets import ObserverSet
from uvsym.errors import UnknownNameError

__all__ = ["usv_fukf_mmae"]

METHODS = ("ukf", "ekf")


def usv_fukf_mmae(method: str = "ukf") -> ObserverSet:
    """The MMAE bank (no-fault, left, right models) of the Otter's thrusters, 'ukf' or 'ekf', tuned
    for the shipped scenario."""
    if method not in METHODS:
        raise UnknownNameError(f"unknown method {method!r}; known: {', '.join(METHODS)}")
    sc = load(SHIPPED["otter_thruster_faults"], "otter_thruster_faults")
    return ObserverSet(f"uvsym_otter_{method}_mmae", f"{method.upper()} MMAE bank of the Otter's thrusters "
                       f"(step {sc.dt:g} s)", (exported_observer(bank(sc, method)),), citation=CITATION)
