"""Speed of the docking closed loop (plant, controller, observers; 100 s at 100 Hz) per method.

Run ``python benchmarks/sim.py``; writes ``benchmarks/results/sim.json``. Simulated seconds per
wall-clock second for the fast path (compiled, best of several runs; interpreted), for each
CasADi integrator, and for the same plant in a plain numpy semi-implicit Euler loop. Compare
them as ratios within this one run: the machine is shared. OpenBLAS is held to one thread: its
idle workers spin and take the second core of a two-core machine from the loop being timed.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import docking_numpy  # noqa: E402
from common import finish  # noqa: E402

from uvsym.sim.scenario import load_scenario  # noqa: E402
from uvsym.sim.simulation import observer_blocks, scenario_observers, simulate_scenario  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "sim.json"
TARGETS = {"fast_sim_s_per_wall_s_min": 20000, "speedup_vs_numpy_min": 100,
           "cvodes_vs_rk4_max_abs_state_difference_max": 1e-6}
DURATION, STEP = 100.0, 0.01
INTEGRATORS = ("cvodes", "idas", "rk", "collocation")


def main() -> dict:
    scenario = replace(load_scenario("docking_faults"), duration=DURATION, step=STEP)
    runs = {}

    def timed(label, repeat=1, **options):
        best, result = float("inf"), None
        for _ in range(repeat):
            result = simulate_scenario(scenario, **options)
            best = min(best, result.meta["wall_s"])
        runs[label] = {"wall_s": best, "sim_s_per_wall_s": DURATION / best, "build_s": result.meta["build_s"]}
        print(f"{label:22s} {DURATION / best:10.0f} simulated s per wall s", file=sys.stderr)
        return result

    fast = timed("fast (compiled)", repeat=5, method="fast")
    timed("fast (interpreted)", method="fast", compiled=False)
    accurate = None
    for method in INTEGRATORS:
        result = timed(method, method=method)
        accurate = result if method == "cvodes" else accurate

    observers = scenario_observers(scenario.model, scenario.observers)
    baseline = docking_numpy.DockingNumpy(scenario.model)
    rng = np.random.default_rng(0)
    agreement = 0.0  # the numpy plant is the same plant: compare nu_dot at random states
    for _ in range(20):
        eta, nu = rng.normal(size=6) * 0.2, np.r_[1.5, 0.0, 0.0, 0.0, 0.0, 0.0] + rng.normal(size=6) * 0.1
        u = np.array([20.0, 0.1, -0.1, 0.05])
        ours = np.asarray(scenario.model.nu_dot(eta, nu, u, 0.0, 0.0)).ravel()
        agreement = max(agreement, float(np.max(np.abs(baseline.nu_dot(eta, nu, u) - ours)) / np.max(np.abs(ours))))
    started = time.perf_counter()
    docking_numpy.run(scenario.model, DURATION, STEP, observers["bias"][1], observers["proportional"][1])
    numpy_wall = time.perf_counter() - started
    print(f"{'numpy semi-implicit':22s} {DURATION / numpy_wall:10.0f} simulated s per wall s", file=sys.stderr)

    from uvsym.sim.closed_loop import build_closed_loop

    loop = build_closed_loop(scenario.model, scenario.controller, STEP,
                             observers=observer_blocks(scenario.model, scenario.observers, scenario.step),
                             actuator_faults=scenario.actuator_faults, current=scenario.current)
    fast_rate = runs["fast (compiled)"]["sim_s_per_wall_s"]
    return {
        "scenario": scenario.name,
        "duration_s": DURATION,
        "step_s": STEP,
        "closed_loop_sx_instructions_per_step": loop.step.n_instructions(),
        "methods": runs,
        "numpy_semi_implicit_euler": {"wall_s": numpy_wall, "sim_s_per_wall_s": DURATION / numpy_wall,
                                      "nu_dot_max_relative_difference_to_uvsym": agreement},
        "fast_sim_s_per_wall_s": fast_rate,
        "speedup_vs_numpy": fast_rate * numpy_wall / DURATION,
        "cvodes_vs_rk4_max_abs_state_difference": float(np.max(np.abs(accurate["x"].values - fast["x"].values))),
    }


if __name__ == "__main__":
    finish(main(), TARGETS, RESULTS)
