"""What the vehicle format's own loop carries that a scenario over a plant does not, measured.

A vehicle plant in a scenario over a plant (``plant = "docking_auv"``) takes its inputs at once;
the vehicle format's loop (:mod:`uvsym.sim.closed_loop`) integrates the actuators' own lag with
the faults on the delivered value, gives the observers ``tau(y, a_expected)``, and lets the
diagnosis correct the commands while the run goes on. On the shipped docking runs this measures
what each of these changes, all in the vehicle format:

- ``lag``: as shipped (fin servo and thrust time constants 0.1 s);
- ``no_lag``: both time constants 1 ms, integrated with 10 RK4 substeps per 10 ms sample (the
  instantaneous actuators of the plant format, to within 1 ms);
- ``no_correction`` (docking_diagnosis only): the same decisions on the finished record, no
  command correction in the loop.

Per variant: the largest and the mean absolute cross-track error after the turn (m, t > 40 s),
the largest difference in north-east position from the shipped run (m), and the diagnosis's
decisions (time, event, actuator, kind, value). Run: ``python benchmarks/vehicle_loop.py`` (writes
``benchmarks/results/vehicle_loop.json``).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
from common import finish

from uvsym import vehicle
from uvsym.sim.scenario import load_scenario
from uvsym.sim.simulation import simulate_scenario

ROOT = Path(__file__).resolve().parents[1]


def _outcome(scenario, reference=None, **options) -> tuple[dict, np.ndarray]:
    """(the variant's figures, its north-east track (N, 2) in m); reference: the shipped run's track."""
    result = simulate_scenario(scenario, **options)
    track = np.column_stack([result["x"]["x"], result["x"]["y"]])
    cross = np.abs(result["reference"]["cross_track"][result.t > 40.0])
    difference = 0.0 if reference is None else float(np.max(np.linalg.norm(track - reference, axis=1)))
    return {"max_cross_track_after_turn_m": float(np.max(cross)),
            "mean_cross_track_after_turn_m": float(np.mean(cross)), "max_track_difference_m": difference,
            "events": [(e["t"], e["event"], e["target"], e["kind"], e["value"]) for e in result.events
                       if e["event"] != "unexcited"]}, track


def main() -> dict:
    results = {}
    for name in ("docking_diagnosis", "docking_faults"):
        shipped = load_scenario(name)
        fast = replace(shipped, model=vehicle("docking_auv", T_delta=1e-3, T_thrust=1e-3))
        variants, track = {}, None
        variants["lag"], track = _outcome(shipped)
        variants["no_lag"] = _outcome(fast, track, substeps=10)[0]
        if shipped.diagnosis is not None and shipped.diagnosis.correct:
            uncorrected = replace(shipped, diagnosis=replace(shipped.diagnosis, correct=False))
            variants["no_correction"] = _outcome(uncorrected, track)[0]
        results[name] = variants
        for variant, outcome in variants.items():
            print(f"{name:18s} {variant:14s} cross-track after the turn: max "
                  f"{outcome['max_cross_track_after_turn_m']:6.3f} m, mean "
                  f"{outcome['mean_cross_track_after_turn_m']:6.3f} m; track differs by up to "
                  f"{outcome['max_track_difference_m']:7.3f} m; {len(outcome['events'])} decisions")
    return finish(results, {}, ROOT / "benchmarks" / "results" / "vehicle_loop.json")


if __name__ == "__main__":
    main()
