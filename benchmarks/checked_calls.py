"""Cost of the checked-call layer (uvsym.checked): one numeric call of a Model's, System's and
Observer's Function, checked against ``.raw``.

Run ``python benchmarks/checked_calls.py``; writes ``benchmarks/results/checked_calls.json``.
Times are medians of repeated batches within this one run; compare them as ratios (the machine is
shared). Loops that call a Function per sample in Python can use ``.raw``; uvsym's own loops roll
the symbolic graph (mapaccum or generated C) and pay nothing.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import finish  # noqa: E402
from rhs import median_time  # noqa: E402

import uvsym  # noqa: E402
from uvsym.observers.luenberger import luenberger_observer  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "checked_calls.json"
TARGETS = {"model_f_ratio_max": 3.0, "system_f_ratio_max": 3.0, "observer_step_ratio_max": 3.0,
           "worst_overhead_us_max": 100.0}


def main() -> dict:
    model = uvsym.vehicle("docking_auv")
    x, u, p = np.linspace(0.01, 0.12, 12), np.array([10.0, 0.05, -0.05, 0.02]), np.zeros(2)
    motor = uvsym.plant("induction_motor")
    xm, um, dm, pm = motor.x_op, motor.u_op, np.zeros(motor.d.size), motor.p0
    lin = motor.linearize()
    observer = luenberger_observer(motor, 0.01 * np.ones((lin.A.shape[0], lin.C.shape[0])), 1e-4)
    s, y, uo, po = (np.zeros(observer.state.size), np.ones(observer.reads_y.size), np.ones(observer.reads_u.size),
                    observer.p0)
    cases = {"model_f": (lambda: model.f(x, u, p), lambda: model.f.raw(x, u, p)),
             "system_f": (lambda: motor.f(xm, um, dm, pm), lambda: motor.f.raw(xm, um, dm, pm)),
             "observer_step": (lambda: observer.step(s, y, uo, po), lambda: observer.step.raw(s, y, uo, po))}
    results = {}
    for name, (checked_call, raw_call) in cases.items():
        checked_s, raw_s = median_time(checked_call), median_time(raw_call)
        results |= {f"{name}_checked_us": 1e6 * checked_s, f"{name}_raw_us": 1e6 * raw_s,
                    f"{name}_ratio": checked_s / raw_s}
    results["worst_overhead_us"] = max(results[f"{n}_checked_us"] - results[f"{n}_raw_us"] for n in cases)
    return finish(results, TARGETS, RESULTS)


if __name__ == "__main__":
    main()
