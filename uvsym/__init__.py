"""uvsym: marine-vehicle dynamics and fault-diagnosis observers, built symbolically in CasADi.

The names below are imported on first use (:mod:`uvsym.lazy`): ``import uvsym.cli`` answers ``--help``
without CasADi or scipy.
"""

from uvsym import errors
from uvsym.lazy import lazy_exports

__version__ = "0.1.0"

_EXPORTS = {  # name -> the submodule that defines it
    **dict.fromkeys(["Model", "fixed_thrusters", "identifiability", "vectored_thrusters", "vehicle", "vehicle_names"],
                    "models"),
    **dict.fromkeys(["plant", "plant_names"], "systems"),
}
__all__ = ["__version__", "errors", *_EXPORTS]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
