"""Yu et al. 2018's observers on uvsym's induction motor, and the corrected design.

Plant: ``uvsym.plant("induction_motor")`` (the paper's eq. 23, MSL parameters), linearised at its
operating point; its E is the paper's (the disturbance ``d = dRr x``), the speed-sensor fault
enters as ``y = C x + F f_s`` with ``F = (0, 0, 2)`` (the paper prints (0 0 0 0 2)^T, a 5-vector
for 3 outputs; F2 = 2). Decoupling as printed: T = S = I, subsystem 1 = (i_sq, i_sd, lambda_rq,
lambda_rd) measured by (i_sq, i_sd), subsystem 2 = omega_m measured by the speed sensor.

Gains (the paper gives none, and its LMIs have no solution for this motor, see claims.py):
``K1`` injects the current residual into the current estimates only (``K1 = K1_CURRENT [I; 0]``);
the detection observer's ``L1``; the estimator's ``L2, Gamma, M1, M2``. The baseline [11] is the
full-order unknown-input observer with its gain from the block LMI at ``BASELINE_DECAY``. The
corrected design (the paper's structure dropped where it fails): no decoupling and one gain for
the motor's states and the fault together, from the LMI at ``CORRECTED_DECAY``, run as a
Luenberger observer of the motor with the fault as a constant state.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

import uvsym
from derivations.motor_luenberger.design import DT
from uvsym.errors import VerificationError
from uvsym.observers.base import Observer
from uvsym.observers.hybrid import (
    Decoupling,
    FaultEstimator,
    decouple,
    hybrid_observer,
    with_sensor_fault_states,
)
from uvsym.observers.luenberger import luenberger_observer
from uvsym.systems import Linearization, System
from uvsym.systems.signals import signals
from uvsym.verify.lmi import BlockGains, block_lmi, solve_block_lmi

__all__ = ["BASELINE_DECAY", "CORRECTED_DECAY", "DT", "Design", "ESTIMATOR", "F", "FAULT", "K1_CURRENT", "L1",
           "L2", "SUBSYSTEM_1", "design"]

F = np.array([[0.0], [0.0], [2.0]])  # y = C x + F f_s: the speed sensor reads omega_m + 2 f_s
FAULT = signals(("f_s", "rad/s", "speed-sensor fault (the sensor adds 2 f_s)"), group="fault")
SUBSYSTEM_1 = {"z1": ["i_sq", "i_sd", "lambda_rq", "lambda_rd"], "w1": ["i_sq", "i_sd"]}
K1_CURRENT = 200.0  # 1/s, current-error decay of the subsystem-1 UIO (uvsym's choice)
L1 = 5.0  # 1/s, the detection observer's speed gain (uvsym's choice: slow enough to see a 0.8 1/s drift)
L2 = 1.0  # 1/s, the estimator's speed gain
ESTIMATOR = FaultEstimator(Gamma=np.array([[1.0]]), M1=np.array([[250.0]]), M2=np.array([[1.0]]))
BASELINE_DECAY = 50.0  # 1/s, the baseline UIO's LMI decay rate (as the motor's Luenberger observer)
CORRECTED_DECAY = 20.0  # 1/s, the corrected observer's LMI decay rate


@dataclass(frozen=True)
class Design:
    """Plant, linearisation, the paper's decoupling, the full-order decoupling of the baseline, the
    gains and the four observers (detection, estimator, baseline, corrected)."""

    plant: System
    lin: Linearization
    split: Decoupling
    full: Decoupling
    K1: np.ndarray
    baseline: BlockGains
    corrected_plant: System
    corrected: BlockGains
    observers: dict[str, Observer]


@functools.lru_cache(maxsize=2)
def design(printed_typo: bool = False) -> Design:
    """Every observer of the study on ``uvsym.plant("induction_motor", printed_typo=...)``.

    Raises VerificationError where the operating point is not an equilibrium (the printed F_a)."""
    plant = uvsym.plant("induction_motor", printed_typo=printed_typo)
    lin = plant.linearize()
    _require_equilibrium(plant, lin)
    split = decouple(plant, lin, **SUBSYSTEM_1, F=F)
    full = decouple(plant, lin, z1=list(plant.x.names), w1=list(plant.y.names))
    K1 = K1_CURRENT * np.vstack([np.eye(2), np.zeros((2, 2))])
    baseline, certificate = solve_block_lmi(
        block_lmi(full.exact["Omega1"], [("e", full.exact["C1"])], BASELINE_DECAY),
        f"baseline UIO [11]: e' = (T A - K C) e decays at {BASELINE_DECAY:g} 1/s", "linearisation at the operating "
        "point; T = I - H C, T E = 0 in exact rationals")
    corrected_plant = with_sensor_fault_states(plant, F, FAULT)
    corrected_lin = corrected_plant.linearize()
    corrected, certificate_c = solve_block_lmi(
        block_lmi(corrected_lin.A, [("e", corrected_lin.C)], CORRECTED_DECAY),
        f"corrected design: the (x, f_s) error decays at {CORRECTED_DECAY:g} 1/s, one gain from all residuals",
        "linearisation at the operating point; no decoupling (T = I)")
    if baseline is None or corrected is None:
        raise VerificationError(f"motor hybrid observer: no gain ({certificate.status}, "
                                             f"{certificate_c.status})")
    observers = {
        "detection": hybrid_observer(plant, split, K1, [[L1]], DT, name="detection"),
        "estimator": hybrid_observer(plant, split, K1, [[L2]], DT, estimator=ESTIMATOR, faults=FAULT,
                                     name="estimator"),
        "baseline": hybrid_observer(plant, full, baseline.K[0], np.zeros((0, 0)), DT, name="baseline"),
        "corrected": luenberger_observer(corrected_plant, corrected.K[0], DT, name="corrected"),
    }
    return Design(plant, lin, split, full, K1, baseline, corrected_plant, corrected, observers)


def _require_equilibrium(plant: System, lin: Linearization) -> None:
    """VerificationError naming the states that move at the operating point (relative to their terms)."""
    moving = [n for n, m in zip(plant.x.names, lin.moving()) if m]
    if moving:
        raise VerificationError(f"{plant.name}: the operating point is not an equilibrium of the model "
                                             f"({', '.join(moving)} move); the linearisation would not describe a "
                                             "steady state")
