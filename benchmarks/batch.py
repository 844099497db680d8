"""What a user waits for running many scenarios at once: ``simulate_batch`` against one run after another.

Run ``python benchmarks/batch.py [--repeat 3] [--calls 7]``; writes ``benchmarks/results/batch.json``.
Two sets of scenarios, each run by the public calls a user makes:

- ``docking``: 12 variants of the docking_faults scenario (90 s at 100 Hz, two actuator-fault
  observers; its three actuator faults' sizes and onsets and the seed differ), by
  :func:`~uvsym.sim.batch.simulate_batch` against :func:`~uvsym.sim.simulation.simulate_scenario`
  of each (12, not more: each variant's scalar loop is its own, and the in-process memos hold 16
  loops -- more variants would time the scalar path rebuilding its loops);
- ``dc_motor``: 16 variants of examples/dc_motor/speed_sensor_bias.toml (6 s at 1 ms, PI loop,
  Luenberger observer, UKF, two threshold detectors; bias size, onset and seed differ), by
  ``simulate_batch`` against :func:`~uvsym.sim.system_scenario.simulate_system_scenario` of each.

``end_to_end``: the median of single calls (each on fresh outputs, as a user's call is), the two
contenders taking turns call by call so that the machine's other users slow them alike; the
speedup is the scalar median over the batch median. ``kernel``: the compiled roll alone on the
same runs -- the lanes (:func:`~uvsym.codegen.compile.compile_lanes`, its ``runs`` roll that
``simulate_batch`` calls) against the scalar ``compile_roll`` of the same step over each run one
after another (docking also against each variant's own scalar step, the one ``simulate_scenario``
rolls), fresh outputs per call, taking turns; with ns per trajectory-step. The batch call's parts
(the lanes' loop, the detectors' decisions) are recorded beside it.

Each repeat records the load average before it; the headlines are the medians over the repeats
(ratios within one repeat), and ``end_to_end_speedup`` is the smaller of the two scenarios'. The
target follows the processor's vector width (``vector_doubles``): at least 4x with AVX-512 (8
doubles), 2.5x with AVX2 (4); the issue names none for narrower vectors.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import tomllib  # noqa: E402
import warnings  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import finish  # noqa: E402

from uvsym.codegen.compile import compile_lanes, compile_roll, find_compiler, vector_doubles  # noqa: E402
from uvsym.errors import IntegrationAccuracyWarning  # noqa: E402
from uvsym.faults import ActuatorFault, Profile  # noqa: E402
from uvsym.sim.batch import default_lanes, simulate_batch  # noqa: E402
from uvsym.sim.closed_loop import build_closed_loop  # noqa: E402
from uvsym.sim.scenario import load_scenario  # noqa: E402
from uvsym.sim.simulation import observer_blocks, prepare_run, scenario_arguments, simulate_scenario  # noqa: E402
from uvsym.sim.system_scenario import parse_system_scenario, scenario_inputs, simulate_system_scenario  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results" / "batch.json"
EXAMPLE = ROOT / "examples" / "dc_motor"
TARGET_BY_WIDTH = {8: 4.0, 4: 2.5}  # AVX-512, AVX2 (issue 34)


def docking_variants(count: int = 12) -> list:
    """``count`` docking_faults scenarios: each actuator fault's size scaled and onset shifted, the seed changed."""
    base = load_scenario("docking_faults")
    variants = []
    for i in range(count):
        faults = tuple(ActuatorFault(f.actuator, f.kind, f.value * (0.6 + 0.05 * i),
                                     Profile(f.profile.kind, onset=f.profile.onset + 2.0 + 0.5 * i + j))
                       for j, f in enumerate(base.actuator_faults))
        variants.append(replace(base, name=f"docking_{i}", seed=i + 1, actuator_faults=faults))
    return variants


def dc_motor_variants(count: int = 16) -> list:
    """``count`` DC motor scenarios: the speed bias's size and onset and the seed changed."""
    table = tomllib.loads((EXAMPLE / "speed_sensor_bias.toml").read_text())
    return [parse_system_scenario(dict(table, name=f"dc_motor_{k}", seed=k, faults=[
        dict(table["faults"][0], value=0.5 + k, onset=1.0 + 0.25 * k)]), root=EXAMPLE) for k in range(count)]


def taking_turns(contenders: dict, calls: int) -> dict[str, list[float]]:
    """Wall seconds of ``calls`` single calls of each contender, one call of each in turn."""
    times = {name: [] for name in contenders}
    for _ in range(calls):
        for name, call in contenders.items():
            started = time.perf_counter()
            call()
            times[name].append(time.perf_counter() - started)
    return times


def _parts(results: list, lanes: int) -> dict:
    """The batch call's own account: the lanes' loops (each group's wall_s) and the detectors' decisions."""
    loops = sum(r.meta["wall_s"] for r in results[::lanes])
    decide = sum(sum(r.meta.get("detector_cpu_s", {}).values()) for r in results)
    return {"lanes_loop_s": loops, "detectors_decide_cpu_s": decide}


def end_to_end(variants: list, scalar, calls: int) -> dict:
    """simulate_batch of the variants against ``scalar`` of each one after another, taking turns."""
    lanes = default_lanes()
    kept = {}

    def batch():
        kept["results"] = simulate_batch(variants)

    times = taking_turns({"batch": batch, "scalar": lambda: [scalar(v) for v in variants]}, calls)
    batch_s, scalar_s = statistics.median(times["batch"]), statistics.median(times["scalar"])
    return {"batch_s": batch_s, "scalar_s": scalar_s, "speedup": scalar_s / batch_s, "lanes": lanes,
            "calls": calls, "batch_parts_of_last_call": _parts(kept["results"], lanes)}


def kernel(step, z0s: list, Ws: list, calls: int, own_steps: list | None = None) -> dict:
    """The lanes' runs roll over groups of the runs against the scalar roll of ``step`` over each run (and
    of each run's ``own_steps``), fresh outputs per call, taking turns: median seconds and ns per trajectory-step."""
    lanes, n_out = default_lanes(), step.nnz_out(1)
    roll, scalar = compile_lanes(step, lanes), compile_roll(step)
    N = Ws[0].shape[0] - 1
    Ws = [np.ascontiguousarray(W[:N]) for W in Ws]
    groups = []
    for first in range(0, len(Ws), lanes):
        members = list(range(first, min(first + lanes, len(Ws))))
        members += members[-1:] * (lanes - len(members))
        groups.append((np.stack([z0s[i] for i in members], axis=-1), [Ws[i] for i in members]))

    def lanes_call():  # every run's rows kept to the end of the call, as simulate_batch returns them
        kept = []
        for z, group in groups:
            kept.append([np.empty((N, n_out)) for _ in group])
            roll.runs(z, group, kept[-1])

    def scalar_call(rolls):  # likewise, as a list of simulate_scenario results holds them
        kept = []
        for z0, W, own in zip(z0s, Ws, rolls):
            kept.append(np.empty((N, n_out)))
            own(z0, W, kept[-1])

    contenders = {"lanes": lanes_call, "scalar": lambda: scalar_call([scalar] * len(Ws))}
    if own_steps is not None:
        own = [compile_roll(s) for s in own_steps]
        contenders["scalar_own_steps"] = lambda: scalar_call(own)
    for call in contenders.values():
        call()  # fresh memory touched once before the clock
    times = taking_turns(contenders, calls)
    steps = N * len(Ws)
    out = {name: {"s": statistics.median(t), "ns_per_trajectory_step": 1e9 * statistics.median(t) / steps}
           for name, t in times.items()}
    out["speedup"] = out["scalar"]["s"] / out["lanes"]["s"]
    if own_steps is not None:
        out["speedup_vs_own_steps"] = out["scalar_own_steps"]["s"] / out["lanes"]["s"]
    return {"lanes": lanes, "trajectories": len(Ws), "steps": N, **out}


def docking_kernel(variants: list, calls: int) -> dict:
    """The kernel figures of the docking variants: the shared step simulate_batch compiles (their one constant
    current built in), their own steps."""
    first = variants[0]
    observers = observer_blocks(first.model, first.observers, first.step)
    loop = build_closed_loop(first.model, first.controller, first.step, sensor_faults=first.sensor_faults,
                             observers=observers, current=tuple(first.current))
    shared = [prepare_run(s.model, s.controller, **scenario_arguments(s, observers), loop=loop) for s in variants]
    own = [prepare_run(s.model, s.controller, **scenario_arguments(s, observers)) for s in variants]
    return kernel(loop.step, [r.z0 for r in shared], [r.W for r in shared], calls, [r.loop.step for r in own])


def repeat(calls: int) -> dict:
    """One repeat: both scenario sets end to end and at the kernel, with the load average before it."""
    load = list(os.getloadavg())
    docking, dc = docking_variants(), dc_motor_variants()
    return {"load_average_before": load,
            "docking": {"end_to_end": end_to_end(docking, simulate_scenario, calls),
                        "kernel": docking_kernel(docking, calls)},
            "dc_motor": {"end_to_end": end_to_end(dc, simulate_system_scenario, calls),
                         "kernel": kernel(dc[0].loop.step, [s.z0 for s in dc], [scenario_inputs(s) for s in dc],
                                          calls)}}


def march() -> str | None:
    """The processor gcc builds for with -march=native (e.g. rocketlake), or None."""
    compiler = find_compiler()
    if compiler is None:
        return None
    done = subprocess.run([compiler, "-march=native", "-Q", "--help=target"], capture_output=True, text=True)
    for line in done.stdout.splitlines():
        if line.strip().startswith("-march="):
            return line.split()[-1]
    return None


def main(repeats: int, calls: int) -> dict:
    warnings.simplefilter("ignore", IntegrationAccuracyWarning)  # docking_faults' own RK4 check: not timed here
    docking, dc = docking_variants(), dc_motor_variants()
    simulate_batch(docking), simulate_batch(dc)  # every loop built and compiled (the compile cache) once
    [simulate_scenario(v) for v in docking], [simulate_system_scenario(v) for v in dc]
    runs = []
    for i in range(repeats):
        runs.append(repeat(calls))
        last = runs[-1]
        print(f"repeat {i + 1} (load {last['load_average_before'][0]:.2f}): " + ", ".join(
            f"{name} end to end {last[name]['end_to_end']['speedup']:.2f}x, "
            f"kernel {last[name]['kernel']['speedup']:.2f}x" for name in ("docking", "dc_motor")), file=sys.stderr)

    def over(name: str, part: str, key: str) -> float:
        return float(np.median([r[name][part][key] for r in runs]))

    results = {"statistic": f"median of {calls} single calls per contender, taking turns; headlines the median of "
                            f"{repeats} repeats", "repeats": runs,
               "vector_doubles": vector_doubles(), "march": march(), "lanes": default_lanes()}
    for name in ("docking", "dc_motor"):
        results[f"end_to_end_speedup_{name}"] = over(name, "end_to_end", "speedup")
        results[f"kernel_speedup_{name}"] = over(name, "kernel", "speedup")
    results["kernel_speedup_docking_vs_own_steps"] = over("docking", "kernel", "speedup_vs_own_steps")
    results["end_to_end_speedup"] = min(results["end_to_end_speedup_docking"], results["end_to_end_speedup_dc_motor"])
    results["speedup_spread"] = {name: max(r[name]["end_to_end"]["speedup"] for r in runs)
                                 / min(r[name]["end_to_end"]["speedup"] for r in runs)
                                 for name in ("docking", "dc_motor")}
    bound = TARGET_BY_WIDTH.get(vector_doubles())
    return finish(results, {} if bound is None else {"end_to_end_speedup_min": bound}, RESULTS)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="repeats (ratios within each)")
    parser.add_argument("--calls", type=int, default=7, help="single calls per contender per repeat")
    arguments = parser.parse_args()
    results = main(arguments.repeat, arguments.calls)
    for key in ("end_to_end_speedup_docking", "end_to_end_speedup_dc_motor", "kernel_speedup_docking",
                "kernel_speedup_docking_vs_own_steps", "kernel_speedup_dc_motor"):
        print(f"{key}: {results[key]:.3g}")
