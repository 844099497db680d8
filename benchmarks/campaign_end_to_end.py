"""``uvsym campaign`` end to end against the lanes kernel: how much of a campaign's wall time is simulation.

Run ``python benchmarks/campaign_end_to_end.py [RUNS] [REPEATS]`` (default 1000 runs, 3 repeats); writes
``benchmarks/results/campaign_end_to_end.json``. The campaign is ``docking_faults`` (thruster bias, two
actuator observers in the loop, no detector deciding on the record) at 100 s per run, its grid over
fault size, current and noise seed, on ``WORKERS`` local worker processes, run as a user runs it
(``uvsym campaign FILE --out DIR`` in a new process, into a fresh folder). Each repeat records:

- ``wall_s``: the command's wall time; ``startup_s``: the same command for a one-run campaign (imports,
  workers, the loop's build and compile-cache lookup, writing, the report: what does not grow with the runs);
- ``kernel_s``: the lanes kernel alone on the same loop (:func:`uvsym.codegen.compile.compile_lanes`, the
  roll of one group of lanes over the whole run, median of single calls, in this process), times the
  groups, divided by the workers: the wall time if nothing but the kernel ran;
- ``trajectory_s_per_wall_s``: simulated seconds of all runs per wall second, against the kernel's
  throughput times the workers (``kernel_throughput_share``, target at least 0.25), and
  ``not_simulation_share`` = 1 - kernel_s / wall_s (target at most 0.25; no detector runs here, so
  everything but the kernel is overhead);
- ``in_simulation_s``: the runs' own ``wall_s`` (each lane row's share of its batch: inputs, the lanes,
  the integration-accuracy check, the metrics) summed and divided by the workers, and
  ``outside_simulation_share`` = 1 - in_simulation_s / wall_s: imports, worker start, loop building,
  cache lookups, result writing and the report (the same bound of 0.25).

The load average before each repeat and the processor's vector width are recorded.
"""

from __future__ import annotations

import csv
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402
from common import finish  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "campaign_end_to_end.json"
WORKERS = 2
DURATION = 100.0
TARGETS = {"kernel_throughput_share_min": 0.25, "not_simulation_share_max": 0.25, "outside_simulation_share_max": 0.25,
           "startup_s_max": 2.0}


def _campaign_file(folder: Path, runs: int) -> Path:
    currents = [0.0, 0.05, 0.1, 0.15]
    sizes = [5.0 + 15.0 * i / 9 for i in range(10)]
    seeds = list(range(1, max(1, runs // (len(currents) * len(sizes))) + 1))
    if runs == 1:
        currents, sizes, seeds = [0.0], [10.0], [1]
    path = folder / f"bench_{runs}.toml"
    path.write_text(f'name = "bench_{runs}"\n[executor]\nworkers = {WORKERS}\n[[case]]\nname = "docking"\n'
                    f'scenario = "docking_faults"\nset = {{ "duration" = {DURATION} }}\n[case.grid]\n'
                    f'"current.speed" = {currents}\n"faults[0].value" = {sizes}\n"seed" = {seeds}\n')
    return path


def _command(path: Path, out: Path) -> float:
    uvsym = Path(sys.executable).with_name("uvsym")
    started = time.perf_counter()
    subprocess.run([str(uvsym), "campaign", str(path), "--out", str(out)], check=True, capture_output=True)
    return time.perf_counter() - started


def _kernel_step_s() -> tuple[float, int]:
    """(seconds per trajectory-step of the lanes kernel, lanes) on the campaign's loop."""
    from uvsym.codegen.compile import compile_lanes
    from uvsym.sim.batch import default_lanes
    from uvsym.sim.closed_loop import build_closed_loop
    from uvsym.sim.scenario import load_scenario
    from uvsym.sim.simulation import observer_blocks, prepare_run, scenario_arguments

    lanes = default_lanes()
    scenario = replace(load_scenario("docking_faults"), duration=DURATION)
    observers = observer_blocks(scenario.model, scenario.observers, scenario.step)
    loop = build_closed_loop(scenario.model, scenario.controller, scenario.step,
                             sensor_faults=scenario.sensor_faults, observers=observers)
    run = prepare_run(scenario.model, scenario.controller, **scenario_arguments(scenario, observers), loop=loop)
    W = np.ascontiguousarray(np.repeat(run.W[:, :, None], lanes, axis=2))
    z0 = np.ascontiguousarray(np.repeat(run.z0[:, None], lanes, axis=1))
    out = np.empty((W.shape[0] - 1, loop.discrete.size1_out("out"), lanes))
    roll = compile_lanes(loop.step, lanes)
    times = []
    for _ in range(7):
        started = time.perf_counter()
        roll(z0.copy(), W[:-1], out)
        times.append(time.perf_counter() - started)
    return statistics.median(times) / ((W.shape[0] - 1) * lanes), lanes


def main(runs: int = 1000, repeats: int = 3) -> dict:
    from uvsym.codegen.compile import vector_doubles
    from uvsym.sim.scenario import load_scenario

    step_s = load_scenario("docking_faults").step
    kernel_step_s, lanes = _kernel_step_s()
    results = {"runs": None, "workers": WORKERS, "duration_s": DURATION, "lanes": lanes,
               "vector_doubles": vector_doubles(), "kernel_ns_per_trajectory_step": kernel_step_s * 1e9,
               "repeats": []}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        big, one = _campaign_file(folder, runs), _campaign_file(folder, 1)
        _command(one, folder / "warm")  # the compile cache and the page cache warm
        for k in range(repeats):
            load = os.getloadavg()
            startup = _command(one, folder / f"one-{k}")
            wall = _command(big, folder / f"big-{k}")
            rows = list(csv.DictReader((folder / f"big-{k}" / "results.csv").open()))
            count, in_simulation = len(rows), sum(float(r["wall_s"]) for r in rows) / WORKERS
            steps = count * round(DURATION / step_s)
            kernel = kernel_step_s * steps / WORKERS
            results["runs"] = count
            results["repeats"].append({
                "load_average_before": list(load), "wall_s": wall, "startup_s": startup, "kernel_s": kernel,
                "trajectory_s_per_wall_s": count * DURATION / wall,
                "kernel_throughput_share": kernel / wall, "not_simulation_share": 1.0 - kernel / wall,
                "in_simulation_s": in_simulation, "outside_simulation_share": 1.0 - in_simulation / wall})
            print(f"repeat {k}: {count} runs in {wall:.1f} s (one-run campaign {startup:.2f} s), kernel alone "
                  f"{kernel:.2f} s: share {kernel / wall:.3f}", flush=True)
    for key in ("wall_s", "startup_s", "kernel_throughput_share", "not_simulation_share", "in_simulation_s",
                "outside_simulation_share", "trajectory_s_per_wall_s"):
        results[key] = statistics.median(r[key] for r in results["repeats"])
    return finish(results, TARGETS, RESULTS)


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:3]))
