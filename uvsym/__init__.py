"""uvsym: marine-vehicle dynamics and fault-diagnosis observers, built symbolically in CasADi."""

from uvsym import errors
from uvsym.models import (
    Model,
    fixed_thrusters,
    identifiability,
    vectored_thrusters,
    vehicle,
    vehicle_names,
)
from uvsym.systems import plant, plant_names

__version__ = "0.1.0"

__all__ = [
    "Model",
    "__version__",
    "errors",
    "fixed_thrusters",
    "identifiability",
    "plant",
    "plant_names",
    "vectored_thrusters",
    "vehicle",
    "vehicle_names",
]
