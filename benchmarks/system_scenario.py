"""What a user of scenario files over their own plant waits for: parse, simulate, decide, the CLI, a campaign.

On the DC motor of ``examples/dc_motor`` (PI loop, Luenberger observer, UKF, two threshold
detectors; 6 s at 1 ms), each figure the median of single calls:

- ``parse_first_s`` / ``parse_s``: :func:`parse_system_scenario` in a fresh process (gain design,
  wiring, calibration) and again in the same process (the plant and blocks memoized);
- ``simulate_s``: :func:`simulate_system_scenario` of the parsed scenario, with ``loop_s`` (the
  loop's own run, from the result's meta) and ``decide_s`` (every detector on the record) as parts;
- ``cli_s``: ``uvsym simulate FILE`` end to end in a new process (imports, parse, run, printing);
- ``hour_simulate_s`` / ``hour_decide_s``: a healthy hour at 10 ms (360,001 samples), simulation
  and the detectors' decisions on its record;
- ``new_fault_size_s``: parse and simulate a speed bias of a size not run before (the loop's
  compiled step is shared by every fault of one shape: nothing is compiled again);
- ``batch16_s`` / ``scalar16_s``: 16 variants (bias sizes, onsets, seeds) by
  :func:`~uvsym.sim.batch.simulate_batch` (4 lanes) and one :func:`simulate_system_scenario` after
  another, with ``batch_speedup`` their ratio;
- ``campaign_s``: ``uvsym campaign examples/dc_motor/campaign.toml`` (48 runs, 2 workers) end to
  end, with ``campaign_sim_s_per_wall_s`` the simulated seconds per wall second.

Run: ``python benchmarks/system_scenario.py`` (writes ``benchmarks/results/system_scenario.json``).
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

from common import finish

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "dc_motor"
SCENARIO = EXAMPLE / "speed_sensor_bias.toml"
REPEATS = 7


def _median(call, repeats: int = REPEATS) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def _vector_width() -> str:
    flags = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    return "avx512" if " avx512f" in flags else "avx2" if " avx2" in flags else "other"


def main() -> None:
    uvsym = Path(sys.executable).with_name("uvsym")
    first = subprocess.run([sys.executable, "-c", "import time, tomllib, pathlib; "
                            "from uvsym.sim.system_scenario import parse_system_scenario; "
                            f"p = pathlib.Path({str(SCENARIO)!r}); t = tomllib.loads(p.read_text()); "
                            "s = time.perf_counter(); parse_system_scenario(t, root=p.parent); "
                            "print(time.perf_counter() - s)"], capture_output=True, text=True, check=True)
    from uvsym.sim.system_scenario import parse_system_scenario, simulate_system_scenario

    table = tomllib.loads(SCENARIO.read_text())
    parse_system_scenario(table, root=EXAMPLE)
    results = {"parse_first_s": float(first.stdout.split()[-1]),
               "parse_s": _median(lambda: parse_system_scenario(table, root=EXAMPLE))}
    scenario = parse_system_scenario(table, root=EXAMPLE)
    simulate_system_scenario(scenario)  # the compiled roll built once
    runs = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        result = simulate_system_scenario(scenario)
        total = time.perf_counter() - start
        start = time.perf_counter()
        for detector in scenario.detectors:
            detector.decide(result)
        runs.append((total, result.meta["wall_s"], time.perf_counter() - start))
    results |= {"simulate_s": statistics.median(r[0] for r in runs), "loop_s": statistics.median(r[1] for r in runs),
                "decide_s": statistics.median(r[2] for r in runs)}
    results["cli_s"] = _median(lambda: subprocess.run([str(uvsym), "simulate", str(SCENARIO)], capture_output=True,
                                                      check=True), 5)

    sizes = iter(range(1, 1000))

    def new_size():
        fault = dict(table["faults"][0], value=0.1 * next(sizes) + 0.01)
        simulate_system_scenario(parse_system_scenario(dict(table, faults=[fault]), root=EXAMPLE))

    results["new_fault_size_s"] = _median(new_size)
    from uvsym.sim.batch import simulate_batch

    variants = [parse_system_scenario(dict(table, seed=k, faults=[dict(table["faults"][0], value=0.5 + k,
                                                                         onset=1.0 + 0.25 * k)]), root=EXAMPLE)
                for k in range(16)]
    simulate_batch(variants[:4])  # the lanes built once
    results["batch16_s"] = _median(lambda: simulate_batch(variants), 5)
    results["scalar16_s"] = _median(lambda: [simulate_system_scenario(v) for v in variants], 5)
    results["batch_speedup"] = results["scalar16_s"] / results["batch16_s"]

    hour = dict(table, faults=[], duration=3600.0, step=0.01)
    hourly = parse_system_scenario(hour, root=EXAMPLE)
    start = time.perf_counter()
    record = simulate_system_scenario(hourly)
    results["hour_simulate_s"] = time.perf_counter() - start
    results["hour_decide_s"] = _median(lambda: [d.decide(record) for d in hourly.detectors], 3)

    with tempfile.TemporaryDirectory() as folder:
        start = time.perf_counter()
        subprocess.run([str(uvsym), "campaign", str(EXAMPLE / "campaign.toml"), "--out", folder, "--workers", "2"],
                       capture_output=True, check=True, cwd=folder)
        results["campaign_s"] = time.perf_counter() - start
        import pyarrow.parquet as pq

        simulated = sum(pq.read_table(Path(folder) / "results.parquet").column("duration_s").to_pylist())
    results["campaign_sim_s_per_wall_s"] = simulated / results["campaign_s"]
    results["vector_width"] = _vector_width()
    finish(results, {}, ROOT / "benchmarks" / "results" / "system_scenario.json")
    for key, value in results.items():
        print(f"{key}: {value:.4g}" if isinstance(value, float) else f"{key}: {value}")


if __name__ == "__main__":
    main()
