"""Cost of one step of the three actuator observers of the REMUS 100, generated C versus Python.

Run ``python benchmarks/codegen.py``; writes ``benchmarks/results/codegen.json``. ``step_ns``: the
combined step (proportional, bias and constant observers, one RK4 step each) of the generated
package, timed in a C loop (best of five batches); beside it the same Function called from
Python. Compare as ratios within one run: the machine is shared.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import casadi as ca
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from c_timing import c_loop_ns  # noqa: E402
from common import finish  # noqa: E402

from uvsym.codegen import find_compiler
from uvsym.derivation import observer_set

RESULTS = Path(__file__).resolve().parent / "results" / "codegen.json"


def main() -> dict:
    observers = observer_set("actuator-observers", vehicle="remus100", form="momentum")
    name = observers.package_name
    combined = observers.exported[-1].function
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        observers.write(folder)
        setup = f"""
  static {name}_real x[18], eta[6] = {{0, 0, 5, 0.01, 0.02, 0.3}}, nu[6] = {{1.5, 0.1, 0.02, 0.01, 0.01, 0.02}};
  static {name}_real tau[6] = {{10, 1, 2, 0.1, 1, 0.5}}, K[18], dt[1] = {{0.01}}, x_next[18], f_hat[18];
  int k;
  for (k = 0; k < 18; ++k) K[k] = 1.0;"""
        step_ns = c_loop_ns([folder / "src" / f"{name}_casadi.c", folder / "src" / f"{name}.c"], folder / "include",
                            f"{name}.h", setup,
                            f"{name}_actuator_observers_step(x, eta, nu, tau, K, dt, x_next, f_hat)",
                            "nu[0]", 1.5, "f_hat[0]")
    args = [np.zeros(18), np.array([0, 0, 5, 0.01, 0.02, 0.3]), np.array([1.5, 0.1, 0.02, 0.01, 0.01, 0.02]),
            np.array([10, 1, 2, 0.1, 1, 0.5]), np.ones(18), np.array([0.01])]
    dm_args = [ca.DM(a) for a in args]
    best = float("inf")
    for _ in range(5):
        started = time.perf_counter()
        for _ in range(2000):
            combined(*dm_args)
        best = min(best, (time.perf_counter() - started) / 2000)
    return {"function": combined.name(), "vehicle": "remus100", "form": "momentum",
            "sx_instructions": combined.n_instructions(), "step_ns": step_ns,
            "python_dm_args_us_per_call": best * 1e6, "speedup_c_over_python": best * 1e9 / step_ns,
            }


if __name__ == "__main__":
    if find_compiler() is None:
        sys.exit("no C compiler: nothing to measure")
    finish(main(), {"step_ns_max": 300}, RESULTS)
