"""``uvsym codegen usv-fukf-mmae [--method ekf]``: a bank's step as a C package."""

from __future__ import annotations

from derivations.usv_fukf_mmae.experiment import disturbed_plant
from derivations.usv_fukf_mmae.paper import CITATION
from derivations.usv_fukf_mmae.scenario import block_table, read
from uvsym.codegen.estimators import exported_observer
from uvsym.codegen.observer_sets import ObserverSet
from uvsym.errors import UnknownNameError
from uvsym.observers.mmae_design import FILTERS, designed_bank
from uvsym.sim.fields import Fields

__all__ = ["usv_fukf_mmae", "shipped_bank"]


def shipped_bank(method: str = "ukf"):
    """The shipped scenario's MMAE bank (an Observer) of block ``method`` ('ukf' or 'ekf'), as the
    scenario designs it for the loop (no-fault, left and right models)."""
    if method not in FILTERS:
        raise UnknownNameError(f"unknown method {method!r}; known: {', '.join(FILTERS)}")
    table = read()
    return designed_bank(Fields(block_table(table, method), f"blocks.{method}"), disturbed_plant(), table["step"],
                         method)


def usv_fukf_mmae(method: str = "ukf") -> ObserverSet:
    """The MMAE bank (no-fault, left, right models) of the Otter's thrusters, 'ukf' or 'ekf', tuned
    for the shipped scenario."""
    obs = shipped_bank(method)
    return ObserverSet(f"uvsym_otter_{method}_mmae", f"{method.upper()} MMAE bank of the Otter's thrusters "
                       f"(step {obs.dt:g} s)", (exported_observer(obs),), citation=CITATION)
