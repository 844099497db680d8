"""Thruster-fault diagnosis of the Otter USV by banks of UKFs and EKFs with multiple-model adaptive
estimation and federated fusion (Li et al. 2025, the FUKF-MMAE paper), reproduced with uvsym's
generic filters (:mod:`uvsym.observers.ukf`, :mod:`~uvsym.observers.ekf`, :mod:`~uvsym.observers.mmae`).

``uvsym report usv-fukf-mmae``, ``uvsym simulate otter_thruster_faults`` (or any TOML with
``study = "usv-fukf-mmae"``), ``uvsym codegen usv-fukf-mmae -o DIR [--method ekf]``.
"""

from derivations.usv_fukf_mmae.experiment import run_scenario
from derivations.usv_fukf_mmae.observer_sets import usv_fukf_mmae
from derivations.usv_fukf_mmae.report import build
from derivations.usv_fukf_mmae.scenario import SHIPPED, parse
from uvsym.derivation import Derivation

__all__ = ["DERIVATION", "simulate"]


def simulate(table: dict, *, name: str, progress=None, method: str | None = None):
    """``uvsym simulate``: the scenario ``table`` (validated, ScenarioError naming the field) run
    with both banks; signals ``ukf_bank`` and ``ekf_bank`` beside the plant's."""
    return run_scenario(parse(table, name), method, progress)


DERIVATION = Derivation(
    name="usv-fukf-mmae",
    title="Thruster faults of the Otter USV: federated UKF and EKF banks with MMAE",
    build=build,
    observer_sets={"usv-fukf-mmae": usv_fukf_mmae},
    simulate=simulate,
    scenarios=SHIPPED,
)
