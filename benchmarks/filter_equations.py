"""Time to render a Kalman filter's equations in their structured form (model, Jacobians, prediction,
gain, update; :func:`uvsym.report.equations.filter_equations`) with the default size guard.

Run ``python benchmarks/filter_equations.py``; writes ``benchmarks/results/filter_equations.json``.
``dc_motor_ekf_s``: the EKF of a 2-state DC motor with tanh friction (1 RK4 step per sample);
``otter_ekf_s`` / ``otter_ukf_s``: the left-thruster model (7 states) of the FUKF-MMAE study's
banks. Each the best of three runs (wall-clock; the machine is shared), with the number of
entries the guard left out.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import casadi as ca

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import finish  # noqa: E402

from derivations.usv_fukf_mmae.experiment import disturbed_plant  # noqa: E402
from derivations.usv_fukf_mmae.scenario import block_table, read  # noqa: E402
from uvsym.observers.ekf import extended_filter  # noqa: E402
from uvsym.observers.mmae_design import bank_filters  # noqa: E402
from uvsym.report.equations import filter_equations  # noqa: E402
from uvsym.sim.fields import Fields  # noqa: E402
from uvsym.systems import signals, system  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "filter_equations.json"


def dc_motor():
    """Current i and speed omega of a DC motor driven by v, with tanh friction; the speed is measured."""
    return system("dc_motor", "DC motor", x=signals(("i", "A"), ("omega", "rad/s")), u=signals(("v", "V")),
                  p=signals(("R", "ohm"), ("L", "H"), ("k", "N m/A"), ("J", "kg m^2"), ("b", "N m s")),
                  p0=[1.0, 0.5, 0.01, 0.01, 0.1], y=signals(("omega_meas", "rad/s")), output=lambda x, u, p: x[1],
                  rhs=lambda x, u, d, p: ca.vertcat((u[0] - p[0] * x[0] - p[2] * x[1]) / p[1],
                                                    (p[2] * x[0] - p[4] * x[1] - 0.02 * ca.tanh(x[1])) / p[3]))


def best(filt) -> tuple[float, int]:
    """(best of three render times in s, entries skipped by the guard)."""
    times = []
    for _ in range(3):
        start = time.perf_counter()
        parts = filter_equations(filt)
        times.append(time.perf_counter() - start)
    return min(times), sum(len(part.skipped) for part in parts.values())


def main() -> None:
    table = read()
    otter = {method: bank_filters(Fields(block_table(table, method), f"blocks.{method}"), disturbed_plant(),
                                  table["step"])["left"] for method in ("ekf", "ukf")}
    results = {}
    for key, filt in (("dc_motor_ekf", extended_filter(dc_motor(), dt=0.01, Q=1e-4, R=1e-2, P0=1.0)),
                      ("otter_ekf", otter["ekf"]), ("otter_ukf", otter["ukf"])):
        results[f"{key}_s"], results[f"{key}_skipped_entries"] = best(filt)
        print(f"{key}: {results[f'{key}_s']:.3g} s, {results[f'{key}_skipped_entries']} entries skipped")
    finish(results, {"dc_motor_ekf_s_max": 5.0, "otter_ekf_s_max": 10.0, "otter_ukf_s_max": 10.0}, RESULTS)


if __name__ == "__main__":
    main()
