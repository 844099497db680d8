"""Fault-diagnosis observers, isolation, identification and fault-tolerant correction."""

from uvsym.observers.actuator import (
    FORMS,
    KINDS,
    ActuatorObserver,
    actuator_observer,
    bias_observer,
    constant_observer,
    init_state,
    proportional_observer,
)
from uvsym.observers.ekf import ekf, extended_filter
from uvsym.observers.hybrid import FaultEstimator, decouple, hybrid_observer, with_sensor_fault_states
from uvsym.observers.lms import lms_monitor, lms_step
from uvsym.observers.lms_supervisor import SubstitutionSupervisor
from uvsym.observers.mmae import mmae_bank
from uvsym.observers.uio import UIOMatrices, uio_conditions, uio_matrices, uio_observer
from uvsym.observers.ukf import ukf, unscented_filter

__all__ = [
    "FORMS",
    "KINDS",
    "ActuatorObserver",
    "actuator_observer",
    "bias_observer",
    "constant_observer",
    "init_state",
    "proportional_observer",
    "UIOMatrices",
    "uio_conditions",
    "uio_matrices",
    "uio_observer",
    "ekf",
    "extended_filter",
    "FaultEstimator",
    "decouple",
    "hybrid_observer",
    "with_sensor_fault_states",
    "mmae_bank",
    "ukf",
    "unscented_filter",
    "lms_monitor",
    "lms_step",
    "SubstitutionSupervisor",
]
