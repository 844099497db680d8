"""Speed of many docking runs: the batched lanes, the scalar fast path and a warm start.

Run ``python benchmarks/campaign.py [--repeat 3]``; writes ``benchmarks/results/campaign.json``.
The docking closed loop (plant, controller, two observers; 100 s at 100 Hz) is timed the same way
for every contender: its compiled step rolled over batches of steps that take about 1 ms each,
the contenders taking turns batch by batch (so that the machine's other users slow them alike),
reporting the min time per batch (the headline: the least disturbed by the other users
of a shared machine) and the median, as simulated seconds per wall second.

- scalar: the roll :func:`simulate` uses (``compile_roll``, fast-path flags), and the same loop
  built with the default flags;
- batched: ``compile_lanes`` over ``LANES`` trajectories that differ in seed, faults and current
  (trajectory-seconds per wall second on this one core: nothing runs in parallel);
- ceilings: the scalar roll with every libm call replaced by a multiply-add (``scalar_math_free``, timed only:
  wrong dynamics), and that rate times the doubles per vector register, the batched rate if math were free and
  every lane vectorised perfectly: what this processor could give the targets at best;
- warm start: a second 100 s docking run in the same process end to end (``load_scenario`` and
  ``simulate_scenario``; the scenario's validation, the observers' gain design, the symbolic loop and
  the loaded library memoized by the first run), the whole call timed, its min and median over repeats;
  beside it the run after emptying those in-process memos (``warm_start_unmemoized_s``: built again,
  the compiled library from the on-disk compile cache), as the warm start was before the memos.

Every library is built with ``-fPIC`` as shipped. The machine is shared: the load average is
recorded before each repeat, and the headline ratios (batched / scalar, fast flags / default) are
compared over the repeats (their spread, max / min, should stay below 1.3). OpenBLAS is held to one
thread, as in ``benchmarks/sim.py``.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import finish  # noqa: E402

from uvsym.codegen.cache import clear_memos  # noqa: E402
from uvsym.codegen.compile import (  # noqa: E402
    _LANE_HELPERS,
    _STRAIGHT,
    _VECTOR_MATH,
    DEFAULT_FLAGS,
    FAST_FLAGS,
    _lane_body,
    _roller,
    compile_lanes,
    compile_roll,
    find_compiler,
)
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


class Contender:
    """A compiled roll over one or several trajectories, timed over batches of ``steps`` samples that continue
    the trajectories (from z0 again at the end of W)."""

    def __init__(self, roll, z0: np.ndarray, W: np.ndarray, n_out: int, trajectories: int):
        self.roll, self.z0, self.W, self.trajectories = roll, z0, W, trajectories
        self.out = np.empty((W.shape[0], n_out, *W.shape[2:]))
        self.z, self.start, self.steps, self.times = z0, 0, 200, []

    def batch(self) -> float:
        """Wall seconds of one batch."""
        if self.start + self.steps > self.W.shape[0] - 1:
            self.start, self.z = 0, self.z0
        begun = time.perf_counter()
        self.z = self.roll(self.z, self.W[self.start:self.start + self.steps], self.out[:self.steps])
        elapsed = time.perf_counter() - begun
        self.start += self.steps
        return elapsed

    def calibrate(self) -> None:
        """Steps per batch for batches of about BATCH_S, from the median of a few probes."""
        probes = [self.batch() for _ in range(10)]
        self.steps = int(min(max(self.steps * BATCH_S / np.median(probes[5:]), 10), self.W.shape[0] - 1))

    def summary(self, dt: float) -> dict:
        """min (best) and median trajectory-seconds per wall second over the timed batches."""
        times, simulated = np.array(self.times), self.trajectories * self.steps * dt
        return {"steps_per_batch": self.steps, "batches": len(times), "batch_s_min": float(times.min()),
                "batch_s_median": float(np.median(times)), "best": simulated / float(times.min()),
                "median": simulated / float(np.median(times)),
                "ns_per_trajectory_step_median": 1e9 * float(np.median(times)) / (self.steps * self.trajectories)}


def math_free_roll(step):
    """The scalar roll of ``step`` with every call of a libm function (sin, cos, atan2, exp, ...) replaced by one
    multiply-add on its first argument: wrong dynamics, timed only, as a ceiling on what any faster math library
    could give the scalar path (built as ``compile_roll`` builds the straight-line step, same flags)."""
    stand_ins = "".join(f"#define {name}(x, ...) ((x) * 0.999 + 1e-3)\n" for name in _VECTOR_MATH)
    sizes = {"name": step.name(), "n_z": step.nnz_in(0), "n_w": step.nnz_in(1), "n_out": step.nnz_out(1)}
    folder = Path(tempfile.mkdtemp(prefix="math-free-"))
    source, library = folder / "math_free.c", folder / "math_free.so"
    source.write_text(_LANE_HELPERS + stand_ins + "#define L 1\n" + _STRAIGHT.format(**sizes, body=_lane_body(step)))
    subprocess.run([find_compiler(), *FAST_FLAGS, str(source), "-o", str(library), "-lm"], check=True)
    return _roller(step, library, f"{step.name()}_roll", ())


def simd_doubles() -> int:
    """Doubles per vector register of this processor: 8 with AVX-512, 4 with AVX/AVX2, else 2 (SSE2)."""
    flags = set(Path("/proc/cpuinfo").read_text().split()) if Path("/proc/cpuinfo").exists() else set()
    return 8 if "avx512f" in flags else 4 if "avx" in flags else 2


def interleaved(contenders: dict[str, Contender], dt: float) -> dict[str, dict]:
    """Every contender timed over BATCHES batches, taking turns batch by batch, so that the other users of
    the machine slow them alike."""
    for contender in contenders.values():
        contender.calibrate()
    for _ in range(BATCHES):
        for contender in contenders.values():
            contender.times.append(contender.batch())
    return {name: contender.summary(dt) for name, contender in contenders.items()}


def measure(lanes: int) -> dict:
    """One repeat: the scalar and batched rates (also with other lane counts), the warm start, end-to-end batch."""
    load = list(os.getloadavg())
    scenarios = docking_runs(max(lanes, *OTHER_LANES))
    first = scenarios[0]
    dt = first.step
    observers = observer_blocks(first.model, first.observers, dt)

    scalar = prepare_run(first.model, first.controller, **scenario_arguments(first, observers))
    loop = build_closed_loop(first.model, first.controller, dt, observers=observers)
    batch = [prepare_run(s.model, s.controller, **scenario_arguments(s, observers), loop=loop) for s in scenarios]
    n_out = loop.step.nnz_out(1)
    contenders = {"scalar_fast_flags": Contender(compile_roll(scalar.loop.step), scalar.z0, scalar.W, n_out, 1),
                  "scalar_default_flags": Contender(compile_roll(scalar.loop.step, DEFAULT_FLAGS), scalar.z0,
                                                    scalar.W, n_out, 1),
                   "scalar_math_free": Contender(math_free_roll(scalar.loop.step), scalar.z0, scalar.W, n_out, 1)}
    for count in (lanes, *OTHER_LANES):
        contenders[f"lanes_{count}"] = Contender(
            compile_lanes(loop.step, count), np.ascontiguousarray(np.stack([run.z0 for run in batch[:count]], axis=-1)),
            np.ascontiguousarray(np.stack([run.W for run in batch[:count]], axis=-1)), n_out, count)
    timed = interleaved(contenders, dt)
    scalar_fast, scalar_default, batched = timed["scalar_fast_flags"], timed["scalar_default_flags"], \
        timed[f"lanes_{lanes}"]
    math_free = timed["scalar_math_free"]
    by_lanes = {count: timed[f"lanes_{count}"] for count in (lanes, *OTHER_LANES)}
    scenarios = scenarios[:lanes]

    warm, unmemoized = [], []
    for _ in range(7):
        clear_memos()
        begun = time.perf_counter()
        simulate_scenario(replace(load_scenario("docking_faults"), duration=DURATION))  # compiled library: cached
        unmemoized.append(time.perf_counter() - begun)
        begun = time.perf_counter()
        simulate_scenario(replace(load_scenario("docking_faults"), duration=DURATION))
        warm.append(time.perf_counter() - begun)

    simulate_batch(scenarios, lanes=lanes)
    begun = time.perf_counter()
    simulate_batch(scenarios, lanes=lanes)
    batch_wall = time.perf_counter() - begun
    return {"load_average_before": load, "scalar_fast_flags": scalar_fast, "scalar_default_flags": scalar_default,
            "scalar_math_free": math_free, "batched": batched,
            "batched_by_lanes": {str(k): {"best": v["best"], "median": v["median"]} for k, v in by_lanes.items()},
            "warm_start_s": {"min": min(warm), "median": float(np.median(warm))},
            "warm_start_unmemoized_s": {"min": min(unmemoized), "median": float(np.median(unmemoized))},
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


def ceilings(math_free: float, scalar: float) -> dict:
    """What this processor could give at best: the scalar rate with free math (the math-free roll), and the
    batched rate per core with free math and every lane in one vector register (``simd_doubles`` x the
    math-free scalar rate), each beside its target."""
    width = simd_doubles()
    batched = width * math_free
    return {"ceilings": {
        "scalar_math_free_sim_s_per_wall_s": math_free, "math_share_of_scalar_step": 1.0 - scalar / math_free,
        "simd_doubles": width, "batched_ceiling_traj_sim_s_per_wall_s_per_core": batched,
        "scalar_target_reachable_with_free_math": math_free >= TARGETS["scalar_sim_s_per_wall_s_min"],
        "batched_target_reachable_with_free_math_and_full_vectors":
            batched >= TARGETS["batched_traj_sim_s_per_wall_s_per_core_min"]}}


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
                     "the median of the repeats; warm start: min and median of 7 whole runs (each after one that "
                     "filled the in-process memos emptied before it: warm_start_unmemoized_s)",
        "batched_traj_sim_s_per_wall_s_per_core": _over(runs, "batched", "best"),
        "batched_traj_sim_s_per_wall_s_per_core_median": _over(runs, "batched", "median"),
        "scalar_sim_s_per_wall_s": _over(runs, "scalar_fast_flags", "best"),
        "scalar_sim_s_per_wall_s_median": _over(runs, "scalar_fast_flags", "median"),
        "scalar_default_flags_sim_s_per_wall_s": _over(runs, "scalar_default_flags", "best"),
        "scalar_default_flags_sim_s_per_wall_s_median": _over(runs, "scalar_default_flags", "median"),
        **ceilings(_over(runs, "scalar_math_free", "best"), _over(runs, "scalar_fast_flags", "best")),
        "warm_start_s": _over(runs, "warm_start_s", "min"),
        "warm_start_s_median": _over(runs, "warm_start_s", "median"),
        "warm_start_unmemoized_s": _over(runs, "warm_start_unmemoized_s", "min"),
        "warm_start_unmemoized_s_median": _over(runs, "warm_start_unmemoized_s", "median"),
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
