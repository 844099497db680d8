"""``uvsym codegen sensor-fdi-lms``: the LMS-FIR monitor's step as a C package."""

from __future__ import annotations

from derivations.papers import paper
from derivations.sensor_fdi_lms.design import ORDER, design
from uvsym.codegen.estimators import exported_observer
from uvsym.codegen.observer_sets import ObserverSet
from uvsym.codegen.package import Exported
from uvsym.observers.lms import lms_step

__all__ = ["lms_set"]


def lms_set(order: int = ORDER) -> ObserverSet:
    """The compass monitor (LMS-FIR of ``order`` taps; its step mu, eps0 and r0 are run-time parameters
    of every call, the paper's in the example) and the bare LMS step it is built on."""
    monitor = design(order=order).monitor
    bare = Exported(lms_step(int(order)),
                    (f"C: weights ({order}, rad per unit u)", f"U: [u_(k-1) ... u_(k-{order})] (-)",
                     "target: y - r (rad)", "u: the new input u_k (-)", "mu: LMS step (-)"),
                    ("C_next: updated weights", "U_next: shifted inputs", "d: prediction C . U (rad)",
                     "e: d - target (rad)"),
                    f"LMS-FIR step of order {order}: d = C.U, e = d - target, C_next = C - 2 mu e U")
    return ObserverSet("uvsym_sensor_fdi_lms", f"LMS-FIR compass monitor, order {order}, double criterion",
                       (exported_observer(monitor), bare),
                       citation=paper("zhu-lms").reference())
