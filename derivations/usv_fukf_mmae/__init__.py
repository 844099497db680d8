"""Thruster-fault diagnosis of the Otter USV by banks of UKFs and EKFs with multiple-model adaptive
estimation and federated fusion (Li et al. 2025, the FUKF-MMAE paper), reproduced with uvsym's
generic filters (:mod:`uvsym.observers.ukf`, :mod:`~uvsym.observers.ekf`, :mod:`~uvsym.observers.mmae`)
as blocks of a scenario file (``mmae``, ``autopilot``) and the banks' hypothesis switches as
detectors (:mod:`uvsym.diagnosis.hypotheses`).

``uvsym report usv-fukf-mmae``, ``uvsym simulate otter_thruster_faults``, ``uvsym campaign
derivations/usv_fukf_mmae/campaign.toml``, ``uvsym codegen usv-fukf-mmae -o DIR [--method ekf]``.
"""

from derivations.usv_fukf_mmae.observer_sets import usv_fukf_mmae
from derivations.usv_fukf_mmae.report import build
from derivations.usv_fukf_mmae.scenario import SHIPPED
from uvsym.derivation import Derivation

__all__ = ["DERIVATION"]

DERIVATION = Derivation(
    name="usv-fukf-mmae",
    title="Thruster faults of the Otter USV: federated UKF and EKF banks with MMAE",
    build=build,
    observer_sets={"usv-fukf-mmae": usv_fukf_mmae},
    scenarios=SHIPPED,
)
