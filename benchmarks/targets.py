"""Every shipped observer set on Cortex-M4F (float, soft-float double) and Cortex-M7 (double), beside x86.

Run ``python benchmarks/targets.py``; writes ``benchmarks/results/targets.json``. Per set, target and
precision, and per exported function: flash and RAM of the package (bytes), the stack bound of its
own code and the high-water mark measured under qemu (bytes), instructions per call (the largest
over its test vectors, counted with qemu's ``-icount``) and the time they take at the target's
stated clock (168 MHz M4F, 600 MHz M7) at one instruction per cycle (an optimistic M4F, a
pessimistic dual-issue M7), the findings of cppcheck's MISRA C:2012 addon (None: not analysed).
``x86_ns``: the function on its first test vector in a C loop on the build machine (-O3
-march=native, double, best of five batches of ``X86_CALLS``; shared machine). Figures are computed
by this run, by :meth:`uvsym.codegen.observer_sets.ObserverSet.write` with ``target=`` as
``uvsym codegen --target`` does; the sets run in ``WORKERS`` processes (each build in its own folder).
"""

from __future__ import annotations

import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from c_timing import c_loop_ns  # noqa: E402
from common import finish  # noqa: E402

from uvsym.codegen.package import write_package
from uvsym.codegen.programs import c_array
from uvsym.codegen.target_run import missing_tools
from uvsym.codegen.targets import TARGETS, target_vectors
from uvsym.derivation import observer_set

RESULTS = Path(__file__).resolve().parent / "results" / "targets.json"
SETS = ("actuator-observers", "motor-luenberger", "sensor-fdi-lms", "usv-fukf-mmae", "motor-hybrid-observer")
BUILDS = (("cortex-m4f", "float"), ("cortex-m4f", "double"), ("cortex-m7", "double"))
WORKERS = 2
X86_CALLS = 200_000


def _x86_ns(made) -> dict[str, float | None]:
    """ns per call of every function of the set on the build machine, on its first test vector."""
    name, times = made.package_name, {}
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        write_package(folder, list(made.exported), name)
        for e, vector in zip(made.exported, target_vectors(list(made.exported), made.example)):
            f, inputs = e.function, [a[0] for a in vector.inputs]
            declared = "\n".join(f"  static {name}_real {f.name_in(i)}[{max(1, f.nnz_in(i))}] = {c_array(v)};"
                                 for i, v in enumerate(inputs))
            declared += "\n" + "\n".join(f"  static {name}_real {f.name_out(i)}[{max(1, f.nnz_out(i))}];"
                                         for i in range(f.n_out()))
            call = ", ".join([f.name_in(i) for i in range(f.n_in())] + [f.name_out(i) for i in range(f.n_out())])
            vary = next(i for i in range(f.n_in()) if f.nnz_in(i))
            times[f.name()] = c_loop_ns([folder / "src" / f"{name}_casadi.c", folder / "src" / f"{name}.c"],
                                        folder / "include", f"{name}.h", declared, f"{name}_{f.name()}({call})",
                                        f"{f.name_in(vary)}[0]", float(inputs[vary][0]),
                                        f"{f.name_out(f.n_out() - 1)}[0]", calls=X86_CALLS)
    return times


def _set_rows(set_name: str) -> tuple[list[dict], str]:
    """The rows of one set (module docstring) and the cross compiler's version."""
    made, rows = observer_set(set_name), []
    x86 = _x86_ns(made)
    for target, precision in BUILDS:
        with tempfile.TemporaryDirectory() as scratch:
            figures = made.write(scratch, precision, target=target)["target"]
        check = figures["cppcheck"]
        misra = check["misra"].get("findings") if check and check.get("misra") else None
        for function, f in figures["functions"].items():
            rows.append({"set": set_name, "target": target, "precision": precision, "function": function,
                         "flash": figures["flash"], "ram": figures["ram"], "stack_bound": f["stack_bound"],
                         "stack_measured": f["stack_measured"], "instructions": f["instructions"],
                         "us_at_clock": round(f["instructions"] / figures["clock_mhz"], 2),
                         "clock_mhz": figures["clock_mhz"], "difference": f["difference"],
                         "misra_findings": misra, "x86_ns": x86[function]})
            print(" ".join(f"{k}={v}" for k, v in rows[-1].items()), flush=True)
    return rows, figures["compiler"]


def main() -> dict:
    with ProcessPoolExecutor(WORKERS) as pool:
        done = list(pool.map(_set_rows, SETS))
    rows, compiler, results = [r for rows, _ in done for r in rows], done[0][1], {}
    pick = {(r["set"], r["target"], r["precision"], r["function"]): r for r in rows}
    worst = lambda key, s, t, p: max(r[key] if key != "stack" else max(r["stack_bound"], r["stack_measured"])  # noqa: E731
                                     for (ss, tt, pp, _), r in pick.items() if (ss, tt, pp) == (s, t, p))
    results["actuator_step_stack_m4f_float"] = worst("stack", "actuator-observers", "cortex-m4f", "float")
    results["actuator_step_instructions_m4f_float"] = pick["actuator-observers", "cortex-m4f", "float",
                                                           "actuator_observers_step"]["instructions"]
    results["lms_stack_m4f_float"] = worst("stack", "sensor-fdi-lms", "cortex-m4f", "float")
    results["lms_instructions_m4f_float"] = worst("instructions", "sensor-fdi-lms", "cortex-m4f", "float")
    results["ukf_bank_us_m4f_float"] = worst("us_at_clock", "usv-fukf-mmae", "cortex-m4f", "float")
    results["ukf_bank_us_m7_double"] = worst("us_at_clock", "usv-fukf-mmae", "cortex-m7", "double")
    results["double_ulps_worst"] = max(r["difference"] for r in rows if r["precision"] == "double")
    results["rows"] = rows
    results["compiler"] = compiler
    return results


if __name__ == "__main__":
    missing = sorted({tool for target in ("cortex-m4f", "cortex-m7") for tool in missing_tools(TARGETS[target])})
    if missing:
        sys.exit(f"{', '.join(missing)} not installed (scripts/install-arm-toolchain.sh): nothing to measure")
    finish(main(), {"actuator_step_stack_m4f_float_max": 5120, "actuator_step_instructions_m4f_float_max": 50000,
                    "lms_stack_m4f_float_max": 5120, "lms_instructions_m4f_float_max": 50000,
                    "ukf_bank_us_m4f_float_max": 1000.0, "ukf_bank_us_m7_double_max": 1000.0,
                    "double_ulps_worst_max": 16}, RESULTS)
