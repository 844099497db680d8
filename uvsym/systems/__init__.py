"""Systems: plants as frozen data plus named CasADi Functions over named, unit-carrying signals.

``System`` (continuous or discrete), ``linearize`` by ``casadi.jacobian``, ``discretize`` by exact
zero-order hold or symbolic RK4; a registry of plants beyond the marine vehicles
(``uvsym.plant(name)``), and every marine vehicle as a System through ``Model.as_system()``.
"""

from uvsym.systems.discretize import discretize, zoh_matrices
from uvsym.systems.registry import PLANTS, plant, plant_names
from uvsym.systems.signals import Signals, signals
from uvsym.systems.system import Linearization, System, system

__all__ = ["Linearization", "PLANTS", "Signals", "System", "discretize", "plant", "plant_names", "signals", "system",
           "zoh_matrices"]
