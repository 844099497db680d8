"""Speed of many docking runs: the batched lanes, the scalar fast path and a warm start.

Run ``python benchmarks/campaign.py [--repeat 3]``; writes ``benchmarks/results/campaign.json``.
The docking closed loop (plant, controller, two observers; 100 s at 100 Hz) is timed the same way
for every contender: its compiled step rolled over batches of steps that take about 1 ms each,
repeated, reporting the min time per batch (the headline: the least disturbed by the other users
of a shared machine) and the median, as simulated seconds per wall second.

- scalar: the roll :func:`simulate` uses (``compile_roll``, fast-path flags), and the same loop
  built with the default flags;
- batched: ``compile_lanes`` over ``LANES`` trajectories that differ in seed, faults and current
  (trajectory-seconds per wall second on this one core: nothing runs in parallel);
- warm start: a second 100 s docking run end to end (scenario loaded, loop built, compiled
  library taken from the cache, run), the whole call timed, its min and median over repeats.

Every library is built with ``-fPIC`` as shipped. The machine is shared: the load average is
recorded before each repeat, and the headline ratios (batched / scalar, fast flags / default) are
compared over the repeats (their spread, max / min, should stay below 1.3). OpenBLAS is held to one
thread, as in ``benchmarks/sim.py``.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import finish  # noqa: E402

from uvsym.codegen.compile import DEFAULT_FLAGS, compile_lanes, compile_roll  # noqa: E402
from uvsym.faults import ActuatorFault, Profile  # noqa: E402
from uvsym.sim.batch import LANES, simulate_batch  # noqa: E402
from uvsym.sim.closed_loop import build_closed_loop  # noqa: E402
from uvsym.sim.scenario import load_scenario  # noqa: E402
from uvsym.sim.simulation import observer_blocks, prepare_run, scenario_arguments, simulate_scenario  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "campaign.json"
TARGETS = {"batched_traj_sim_s_per_wall_s_per_core_min": 150_000, "scalar_sim_s_per_wall_s_min": 25_000,
           "warm_start_s_max": 0.1, "dask_local_overhead_max": 1.2, "headline_ratio_spread_max": 1.3}
DURATION = 100.0
BATCH_S = 1e-3  # wall seconds per timed batch
BATCHES = 200
OTHER_LANES = (8, 16)  # lane counts measured besides the default, for the choice of LANES


def docking_runs(count: int):
    """``count`` docking scenarios of DURATION s differing in seed, actuator faults and current."""
    base = replace(load_scenario("docking_faults"), duration=DURATION)
    kinds = ((0, "bias", 13.0), (2, "proportional", 0.8), (1, "loss_of_effectiveness", 0.3), (3, "constant", 0.05))
    scenarios = []
    for i in range(count):
        actuator, kind, value = kinds[i % len(kinds)]
        fault = ActuatorFault(actuator, kind, value, Profile("step" if i % 2 else "ramp", onset=5.0 + i, duration=4.0))
        scenarios.append(replace(base, seed=i + 1, actuator_faults=base.actuator_faults[1:] + (fault,),
                                 current=(0.05 * (i % 3), 0.3 * i)))
    return scenarios


def timed_batches(roll, z, W, out, steps: int) -> np.ndarray:
    """Wall seconds of successive rolls of ``steps`` samples (the trajectory continues; restarts at its end)."""
    times, start, z0 = np.empty(BATCHES), 0, z
    for b in range(BATCHES):
        if start + steps > W.shape[0] - 1:
            start, z = 0, z0
        begun = time.perf_counter()
        z = roll(z, W[start:start + steps], out[:steps])
        times[b] = time.perf_counter() - begun
        start += steps
    return times


def rates(roll, z, W, out, trajectories: int, dt: float) -> dict:
    """min and median trajectory-seconds per wall second over ~1 ms batches (steps per batch calibrated)."""
    probe = 200
    timed_batches(roll, z, W, out, probe)  # warm the caches and pages
    per_step = np.median(timed_batches(roll, z, W, out, probe)) / probe
    steps = int(min(max(BATCH_S / per_step, 10), W.shape[0] - 1))
    times = timed_batches(roll, z, W, out, steps)
    simulated = trajectories * steps * dt
    return {"steps_per_batch": steps, "batch_s_min": float(times.min()), "batch_s_median": float(np.median(times)),
            "best": simulated / float(times.min()), "median": simulated / float(np.median(times)),
            "ns_per_trajectory_step_median": 1e9 * float(np.median(times)) / (steps * trajectories)}


def measure(lanes: int) -> dict:
    """One repeat: the scalar and batched rates (also with other lane counts), the warm start, end-to-end batch."""
    load = list(os.getloadavg())
    scenarios = docking_runs(max(lanes, *OTHER_LANES))
    first = scenarios[0]
    dt = first.step
    observers = observer_blocks(first.model, first.observers, dt)

    scalar = prepare_run(first.model, first.controller, **scenario_arguments(first, observers))
    out = np.empty((scalar.W.shape[0], scalar.loop.step.nnz_out(1)))
    scalar_fast = rates(compile_roll(scalar.loop.step), scalar.z0, scalar.W, out, 1, dt)
    scalar_default = rates(compile_roll(scalar.loop.step, DEFAULT_FLAGS), scalar.z0, scalar.W, out, 1, dt)

    loop = build_closed_loop(first.model, first.controller, dt, observers=observers)
    batch = [prepare_run(s.model, s.controller, **scenario_arguments(s, observers), loop=loop) for s in scenarios]
    by_lanes = {}
    for count in (lanes, *OTHER_LANES):
        W = np.ascontiguousarray(np.stack([run.W for run in batch[:count]], axis=-1))
        z0 = np.ascontiguousarray(np.stack([run.z0 for run in batch[:count]], axis=-1))
        out_lanes = np.empty((W.shape[0], loop.step.nnz_out(1), count))
        by_lanes[count] = rates(compile_lanes(loop.step, count), z0, W, out_lanes, count, dt)
    batched = by_lanes[lanes]
    scenarios = scenarios[:lanes]

    simulate_scenario(first)  # the first run compiles (or finds the library in the cache)
    warm = []
    for _ in range(7):
        begun = time.perf_counter()
        simulate_scenario(replace(load_scenario("docking_faults"), duration=DURATION))
        warm.append(time.perf_counter() - begun)

    simulate_batch(scenarios, lanes=lanes)
    begun = time.perf_counter()
    simulate_batch(scenarios, lanes=lanes)
    batch_wall = time.perf_counter() - begun
    return {"load_average_before": load, "scalar_fast_flags": scalar_fast, "scalar_default_flags": scalar_default,
            "batched": batched, "batched_median_by_lanes": {str(k): v["median"] for k, v in by_lanes.items()},
            "warm_start_s": {"min": min(warm), "median": float(np.median(warm))},
            "simulate_batch_end_to_end_s": batch_wall,
            "simulate_batch_end_to_end_traj_sim_s_per_wall_s": lanes * DURATION / batch_wall,
            "ratios": {"batched_vs_scalar": batched["best"] / scalar_fast["best"],
                       "fast_flags_vs_default": scalar_fast["best"] / scalar_default["best"]}}


def _over(runs: list[dict], contender: str, statistic: str) -> float:
    """The median over the repeats of one contender's statistic."""
    return float(np.median([r[contender][statistic] for r in runs]))


def dask_overhead() -> dict:
    """``dask_local_overhead`` and the details of ``campaign_executors.dask_overhead()`` (under ``dask``) when
    that file exists, else not measured."""
    if not (Path(__file__).resolve().parent / "campaign_executors.py").exists():
        return {"dask_local_overhead": None, "dask": "not measured: benchmarks/campaign_executors.py is missing"}
    from campaign_executors import dask_overhead as measure_dask

    details = measure_dask()
    return {"dask_local_overhead": details["dask_local_overhead"], "dask": details}


def main(repeat: int, lanes: int) -> dict:
    runs = []
    for i in range(repeat):
        runs.append(measure(lanes))
        last = runs[-1]
        print(f"repeat {i + 1}: scalar {last['scalar_fast_flags']['best']:,.0f} sim-s/s, batched "
              f"{last['batched']['best']:,.0f} traj-sim-s/s, warm start {last['warm_start_s']['min']:.3f} s "
              f"(load {last['load_average_before'][0]:.2f})", file=sys.stderr)
    spread = {name: max(r["ratios"][name] for r in runs) / min(r["ratios"][name] for r in runs)
              for name in runs[0]["ratios"]}
    return {
        "scenario": "docking_faults", "duration_s": DURATION, "lanes": lanes, "repeats": runs,
        "statistic": f"min (headline) and median wall time of {BATCHES} batches of ~{BATCH_S * 1e3:g} ms of steps, "
                     "the median of the repeats; warm start: min and median of 7 whole runs",
        "batched_traj_sim_s_per_wall_s_per_core": _over(runs, "batched", "best"),
        "batched_traj_sim_s_per_wall_s_per_core_median": _over(runs, "batched", "median"),
        "scalar_sim_s_per_wall_s": _over(runs, "scalar_fast_flags", "best"),
        "scalar_sim_s_per_wall_s_median": _over(runs, "scalar_fast_flags", "median"),
        "scalar_default_flags_sim_s_per_wall_s": _over(runs, "scalar_default_flags", "best"),
        "scalar_default_flags_sim_s_per_wall_s_median": _over(runs, "scalar_default_flags", "median"),
        "warm_start_s": _over(runs, "warm_start_s", "min"),
        "warm_start_s_median": _over(runs, "warm_start_s", "median"),
        "headline_ratio_spread_by_ratio": spread,
        "headline_ratio_spread": max(spread.values()) if repeat > 1 else None,
        **dask_overhead(),
    }


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="measurements, for the spread of the ratios")
    parser.add_argument("--lanes", type=int, default=LANES, help="trajectories per compiled step")
    arguments = parser.parse_args()
    finish(main(arguments.repeat, arguments.lanes), TARGETS, RESULTS)
