"""Cost of the C wrappers' finite check, and of measuring a float build, on the docking observers.

Run ``python benchmarks/codegen_checks.py``; writes ``benchmarks/results/codegen_checks.json``.
``step_ns_checked`` / ``step_ns_unchecked``: the combined actuator-observer step of the
docking AUV (18 states), timed in a C loop on row 0 of the package's example (the docking
experiment), with and without the NaN/infinity check of its 48 inputs and 36 outputs;
``finite_check_overhead``: their ratio. ``float_check_s``: wall time of
:func:`uvsym.codegen.precision.measure_float` on the example's 500 samples (write, compile, run,
compare). The machine is shared: compare the ratio, not the absolute times.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from c_timing import c_loop_ns  # noqa: E402
from common import finish  # noqa: E402

from uvsym.codegen import find_compiler
from uvsym.codegen.package import write_package
from uvsym.codegen.precision import measure_float
from uvsym.codegen.programs import c_array
from uvsym.derivation import observer_set

RESULTS = Path(__file__).resolve().parent / "results" / "codegen_checks.json"


def _step_ns(observers, finite_check: bool) -> float | None:
    name, example = observers.package_name, observers.example
    combined = next(e.function for e in observers.exported if e.function.name() == example.function)
    inputs = example.first_call()
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        write_package(folder, list(observers.exported), name, finite_check=finite_check)
        declared = "\n".join(f"  static {name}_real {combined.name_in(i)}[{combined.nnz_in(i)}] = {c_array(v)};"
                             for i, v in enumerate(inputs))
        declared += "\n" + "\n".join(f"  static {name}_real {combined.name_out(i)}[{combined.nnz_out(i)}];"
                                     for i in range(combined.n_out()))
        call = ", ".join([combined.name_in(i) for i in range(combined.n_in())]
                         + [combined.name_out(i) for i in range(combined.n_out())])
        return c_loop_ns([folder / "src" / f"{name}_casadi.c", folder / "src" / f"{name}.c"], folder / "include",
                         f"{name}.h", declared, f"{name}_{combined.name()}({call})", "nu[0]",
                         float(inputs[2][0]), "f_hat[6]")


def main() -> dict:
    observers = observer_set("actuator-observers", vehicle="docking_auv", form="momentum")
    checked, unchecked = _step_ns(observers, True), _step_ns(observers, False)
    combined = next(e for e in observers.exported if e.function.name() == observers.example.function)
    started = time.perf_counter()
    check = measure_float(combined, observers.example)
    return {"function": combined.function.name(), "vehicle": "docking_auv", "example": observers.example.source,
            "step_ns_checked": checked, "step_ns_unchecked": unchecked,
            "finite_check_overhead": checked / unchecked, "float_check_s": time.perf_counter() - started,
            "float_max_relative_difference": check.max_relative_difference}


if __name__ == "__main__":
    if find_compiler() is None:
        sys.exit("no C compiler: nothing to measure")
    finish(main(), {"finite_check_overhead_max": 1.25, "float_check_s_max": 10.0,
                    "float_max_relative_difference_max": 1e-3}, RESULTS)
