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
from uvsym.observers.uio import UIOMatrices, uio_conditions, uio_matrices, uio_observer

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
]
