"""Fault-diagnosis observers, isolation, identification and fault-tolerant correction.

The names below are imported on first use (:mod:`uvsym.lazy`): ``import uvsym.observers.base``, as the
simulator and every campaign worker do, does not pay for scipy.signal and sympy, which only the UIO and
hybrid observers need.
"""

from uvsym.lazy import lazy_exports
from uvsym.observers.ekf import ekf  # named as their submodules: bound now, after them (importing the submodule
from uvsym.observers.ukf import ukf  # later would rebind the package's name to the module)

_EXPORTS = {  # name -> the submodule that defines it
    **dict.fromkeys(["FORMS", "KINDS", "ActuatorObserver", "actuator_observer", "bias_observer", "constant_observer",
                     "init_state", "proportional_observer"], "actuator"),
    **dict.fromkeys(["UIOMatrices", "uio_conditions", "uio_matrices", "uio_observer"], "uio"),
    "extended_filter": "ekf",
    **dict.fromkeys(["FaultEstimator", "decouple", "hybrid_observer", "with_sensor_fault_states"], "hybrid"),
    "mmae_bank": "mmae",
    "unscented_filter": "ukf",
    **dict.fromkeys(["lms_monitor", "lms_step"], "lms"),
    "SubstitutionSupervisor": "lms_supervisor",
}
__all__ = ["ekf", "ukf", *_EXPORTS]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
