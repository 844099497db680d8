"""Block LMIs and the motor hybrid-observer loop: what the exact checks and the study cost.

Run ``python benchmarks/hybrid_lmi.py``; writes ``benchmarks/results/hybrid_lmi.json``:

- ``synthesis_s``: seconds for the corrected design's gain (6 states, one block, decay 20 1/s) by
  :func:`uvsym.verify.lmi.solve_block_lmi` (balanced LMI + exact rational re-check), and by
  :func:`uvsym.verify.synthesize_observer_gain` on the same (A, C) for comparison, with the
  slowest error eigenvalue each reaches (``slowest_real``, 1/s);
- ``refutation_s``: seconds to refute Theorems 1 and 2 (failed solve + exact dual certificate);
- ``loop_s_per_simulated_s``: wall seconds per simulated second of the study's closed loop
  (motor + four observers at 0.1 ms) as generated C and on CasADi's virtual machine (the study's
  10 s runs, building and compiling the loop included, as the report pays it).

Times are medians of repeated runs within this one run (the machine may be shared).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import finish  # noqa: E402

import derivations.motor_hybrid_observer.experiment as experiment  # noqa: E402
from derivations.motor_hybrid_observer.claims import paper_problems  # noqa: E402
from derivations.motor_hybrid_observer.design import CORRECTED_DECAY, design  # noqa: E402
from uvsym.verify import synthesize_observer_gain  # noqa: E402
from uvsym.verify.lmi import block_lmi, solve_block_lmi  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "hybrid_lmi.json"
TARGETS = {"refutation_theorem_2_s_max": 5.0, "loop_speedup_c_over_vm_min": 2.0}


def median_seconds(call, repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def loop_seconds(compiled: bool, repeat: int) -> float:
    experiment.COMPILED = compiled
    profile = experiment.CASES["case b (step)"]
    return median_seconds(lambda: experiment.run(profile), repeat) / experiment.DURATION


def main() -> dict:
    d = design()
    lin = d.corrected_plant.linearize()
    problem = block_lmi(lin.A, [("e", lin.C)], CORRECTED_DECAY)
    block_gain = solve_block_lmi(problem)[0].K[0]
    plain = synthesize_observer_gain(lin.A, lin.C, CORRECTED_DECAY)
    paper = paper_problems()
    c_loop, vm_loop = loop_seconds(True, 3), loop_seconds(False, 1)
    results = {
        "synthesis_s": {"block_lmi": median_seconds(lambda: solve_block_lmi(problem)),
                        "synthesize_observer_gain": median_seconds(
                            lambda: synthesize_observer_gain(lin.A, lin.C, CORRECTED_DECAY))},
        "slowest_real": {"block_lmi": float(np.linalg.eigvals(lin.A - block_gain @ lin.C).real.max()),
                         "synthesize_observer_gain": float(np.linalg.eigvals(lin.A - plain.L @ lin.C).real.max())},
        "largest_gain": {"block_lmi": float(np.abs(block_gain).max()),
                         "synthesize_observer_gain": float(np.abs(plain.L).max())},
        "refutation_theorem_1_s": median_seconds(lambda: solve_block_lmi(paper["theorem 1"])),
        "refutation_theorem_2_s": median_seconds(lambda: solve_block_lmi(paper["theorem 2"])),
        "loop_s_per_simulated_s": {"c": c_loop, "vm": vm_loop},
        "loop_speedup_c_over_vm": vm_loop / c_loop,
    }
    return finish(results, TARGETS, RESULTS)


if __name__ == "__main__":
    main()
