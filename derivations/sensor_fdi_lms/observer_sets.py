"""``uvsym codegen sensor-fdi-lms``: the LMS-FIR monitor's step as a C package."""

from __future__ import annotations

from derivations.sensor_fdi_lms.design import MU, ORDER, design
from uvsym.codegen.estimators import exported_observer
from uvsym.codegen.observer_sets import ObserverSet

__all__ = ["lms_set"]


def lms_set(order: int = ORDER, mu: float = MU) -> ObserverSet:
    """The compass monitor (LMS-FIR of ``order`` taps, default step ``mu``; mu, eps0, r0 are run-time parameters)."""
    monitor = design(order=int(order), mu=float(mu)).monitor
    return ObserverSet("uvsym_sensor_fdi_lms", f"LMS-FIR compass monitor, order {order}, double criterion",
                       (exported_observer(monitor),),
                       citation="Zhu Daqi et al., sensor fault diagnosis of an underwater robot with an adaptive "
                                "FIR filter (LMS), double criterion and measurement substitution")
