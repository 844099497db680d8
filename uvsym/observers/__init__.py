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

__all__ = [
    "FORMS",
    "KINDS",
    "ActuatorObserver",
    "actuator_observer",
    "bias_observer",
    "constant_observer",
    "init_state",
    "proportional_observer",
]
