"""Symbolic vehicle models: building blocks, actuator configurations and the vehicle library."""

from uvsym.models.configurations import (
    ActuatorConfiguration,
    Identifiability,
    fixed_thrusters,
    identifiability,
    vectored_thrusters,
)
from uvsym.models.model import Model
from uvsym.models.parameters import Parameter, ParameterSet
from uvsym.models.registry import VEHICLES, vehicle, vehicle_names

__all__ = [
    "ActuatorConfiguration",
    "Identifiability",
    "Model",
    "Parameter",
    "ParameterSet",
    "VEHICLES",
    "fixed_thrusters",
    "identifiability",
    "vectored_thrusters",
    "vehicle",
    "vehicle_names",
]
