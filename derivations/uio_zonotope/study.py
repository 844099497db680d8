"""The study's numbers: healthy runs, fault runs on every actuator, drift rates, enclosure check.

Every figure in ``results.json`` is computed here by the run that writes the report.
"""

from __future__ import annotations

import numpy as np

from derivations.uio_zonotope.design import SAMPLES, design
from derivations.uio_zonotope.enclosure import check_enclosure
from derivations.uio_zonotope.experiment import ABRUPT_SIZE, DRIFT_RATE, Fault, detection, simulate_runs

__all__ = ["DRIFT_RATES", "FAULT_RUNS", "FAULT_SEED", "HEALTHY_RUNS", "HEALTHY_SEED", "run_study"]

HEALTHY_RUNS = 100
HEALTHY_SEED = 0

FAULT_RUNS = 20  # seeded runs per fault case
FAULT_SEED = 1  # other draws than the healthy runs
DRIFT_RATES = (5.0, 10.0, DRIFT_RATE, 40.0)  # V/s, drift rates whose detection delay is reported


def _delays(fault: Fault) -> dict:
    """Detection and isolation over FAULT_RUNS runs of one fault case."""
    found = detection(simulate_runs(FAULT_SEED, FAULT_RUNS, fault), fault.onset)
    delays = [k for k in found["delay"] if k is not None]
    faulty = design().bank.decoupled[fault.actuator]
    return {"detected": len(delays), "runs": FAULT_RUNS, "delay_max": max(delays) if delays else None,
            "delay_median": float(np.median(delays)) if delays else None,
            "isolated_correctly": sum(iso == [faulty] for iso in found["isolated"]),
            "isolated_sets": sorted({",".join(iso) if iso else "none" for iso in found["isolated"] if iso is not None})}


def run_study(progress=lambda message: None) -> dict:
    """Everything the report tabulates (see the module docstring)."""
    d = design()
    progress(f"{HEALTHY_RUNS} healthy runs of {SAMPLES} samples")
    healthy = simulate_runs(HEALTHY_SEED, HEALTHY_RUNS)
    found = detection(healthy, 0)
    progress("enclosure check of every healthy residual")
    enclosure = check_enclosure(healthy)
    progress("abrupt faults on every actuator, drifts at several rates")
    abrupt = {name: _delays(Fault(i, "abrupt", ABRUPT_SIZE)) for i, name in enumerate(d.bank.decoupled)}
    drift = {rate: _delays(Fault(1, "drift", rate)) for rate in DRIFT_RATES}
    return {"healthy": {"runs": HEALTHY_RUNS, "samples": SAMPLES,
                        "runs_with_alarm": sum(k is not None for k in found["alarm"]),
                        "alarm_samples": int(found["outside"].any(axis=1).sum())},
            "enclosure": enclosure, "abrupt": abrupt, "drift": drift, "healthy_runs_data": healthy}
