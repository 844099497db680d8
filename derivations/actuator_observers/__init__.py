"""Actuator-fault diagnosis and fault-tolerant control of Liu et al. 2014 (:mod:`derivations.papers`), reproduced.

``uvsym report actuator-observers`` runs the docking experiment and its second case
(:mod:`.experiment`, text in :mod:`.report`, figures in :mod:`.figures`); ``uvsym verify
actuator-observers`` checks Theorems 1-3 and section 3.2 (:mod:`.claims`); ``uvsym codegen
actuator-observers`` writes the observers as C (:mod:`.observer_sets`). What the paper reports
and the targets of the reproduction are in :mod:`.paper`.
"""

from derivations.actuator_observers.claims import core_paper_claims
from derivations.actuator_observers.experiment import build
from derivations.actuator_observers.observer_sets import actuator_observers
from derivations.papers import paper
from uvsym.derivation import Derivation

__all__ = ["DERIVATION"]

DERIVATION = Derivation(
    name="actuator-observers",
    title=f"Actuator-fault diagnosis and fault-tolerant control ({paper('liu2014').short})",
    build=build,
    claims=core_paper_claims,
    observer_sets={"actuator-observers": actuator_observers},
)
