"""How fast the ``uvsym`` command answers, and what compressing a long result costs.

Run ``python benchmarks/cli.py``; writes ``benchmarks/results/cli.json``. Wall seconds (best of
``REPEATS``, end to end, a new process each) of ``uvsym --help``, of every ``uvsym COMMAND --help``
and of a misspelt name for each command that takes one: none imports CasADi, scipy or a
derivation. Then a 1000 s docking run at 100 Hz written as .npz plainly (the default) and with
``compress=True``: seconds to write and read, and megabytes. Last, ``uvsym simulate`` end to end of the
shipped docking run (90 s at 100 Hz) and of the same run lasting 1000 s written with ``--out x.npz``: the
wall time above the simulation's own (the ``s wall`` the command prints), best of ``REPEATS``.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import finish  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "cli.json"
TARGETS = {"slowest_answer_s_max": 0.5, "simulate_above_simulation_s_max": 0.5,
           "simulate_1000_s_out_above_simulation_s_max": 1.0}
REPEATS = 3
CALLS = [["--help"], *[[command, "--help"] for command in ("models", "report", "simulate", "codegen", "campaign",
                                                            "verify")],
         ["simulate", "nosuch"], ["verify", "nosuch"], ["codegen", "nosuch"], ["campaign", "nosuch"],
         ["report", "nosuch"]]


def _command() -> list[str]:
    """The console script beside this Python, else the module."""
    script = Path(sys.executable).with_name("uvsym")
    return [str(script)] if script.is_file() else [sys.executable, "-m", "uvsym.cli"]


def _answer_s(call: list[str]) -> float:
    best = float("inf")
    for _ in range(REPEATS):
        started = time.perf_counter()
        subprocess.run([*_command(), *call], capture_output=True, timeout=120)
        best = min(best, time.perf_counter() - started)
    return best


def _save_figures() -> dict:
    from uvsym.sim.result import SimResult
    from uvsym.sim.scenario import load_scenario
    from uvsym.sim.simulation import simulate_scenario

    result = simulate_scenario(replace(load_scenario("docking_faults"), duration=1000.0))
    figures = {"samples": int(result.t.size)}
    with tempfile.TemporaryDirectory() as folder:
        for label, compress in (("plain", False), ("compressed", True)):
            path = Path(folder) / f"{label}.npz"
            started = time.perf_counter()
            result.save(path, compress=compress)
            written = time.perf_counter()
            SimResult.load(path)
            figures[label] = {"write_s": written - started, "read_s": time.perf_counter() - written,
                              "megabytes": path.stat().st_size / 1e6}
    return figures


def _above_simulation_s(call: list[str]) -> dict:
    """Best of REPEATS: wall seconds of ``uvsym simulate ...`` end to end, and above its printed simulation time."""
    best = {"end_to_end_s": float("inf"), "simulation_s": None, "above_s": float("inf")}
    for _ in range(REPEATS):
        for leftover in Path(tempfile.gettempdir()).glob("uvsym-bench-*.npz"):
            leftover.unlink()
        started = time.perf_counter()
        done = subprocess.run([*_command(), "simulate", *call], capture_output=True, text=True, timeout=300)
        wall = time.perf_counter() - started
        simulated = float(re.search(r"method \w+: ([\d.e-]+) s wall", done.stdout).group(1))
        if wall - simulated < best["above_s"]:
            best = {"end_to_end_s": wall, "simulation_s": simulated, "above_s": wall - simulated}
    return best


def _simulate_figures() -> dict:
    from uvsym.sim.scenario import shipped_scenarios

    shipped = shipped_scenarios()["docking_faults"]
    with tempfile.TemporaryDirectory() as folder:
        long = Path(folder) / "docking_1000_s.toml"
        long.write_text(re.sub(r"(?m)^duration = .*$", "duration = 1000.0", shipped.read_text()))
        out = Path(tempfile.gettempdir()) / "uvsym-bench-out.npz"
        figures = {"docking_faults": _above_simulation_s(["docking_faults"]),
                   "docking_1000_s_out": _above_simulation_s([str(long), "--out", str(out)])}
        out.unlink(missing_ok=True)
    return figures


def main() -> dict:
    answers = {" ".join(call): _answer_s(call) for call in CALLS}
    for call, seconds in answers.items():
        print(f"uvsym {call}: {seconds:.3f} s")
    save = _save_figures()
    for label in ("plain", "compressed"):
        print(f"1000 s result, {label} .npz: write {save[label]['write_s']:.2f} s, read {save[label]['read_s']:.2f} s, "
              f"{save[label]['megabytes']:.1f} MB")
    simulate = _simulate_figures()
    for name, figures in simulate.items():
        print(f"uvsym simulate {name}: {figures['end_to_end_s']:.2f} s end to end, {figures['above_s']:.2f} s above "
              f"its {figures['simulation_s']:.3g} s of simulation")
    return finish({"answer_s": answers, "slowest_answer_s": max(answers.values()), "npz_1000_s_run": save,
                   "simulate": simulate, "simulate_above_simulation_s": simulate["docking_faults"]["above_s"],
                   "simulate_1000_s_out_above_simulation_s": simulate["docking_1000_s_out"]["above_s"]},
                  TARGETS, RESULTS)


if __name__ == "__main__":
    main()
