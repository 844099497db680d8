"""uvsym's continuous diagnosis in the study: the fault campaign and the corrected docking run.

Runs ``campaign.toml`` through :func:`uvsym.campaign.run_campaign` (the same file ``uvsym
campaign`` runs) and the shipped ``docking_diagnosis`` scenario (diagnosis and correction in the
loop); returns their figures for results.json and writes the campaign's table and figures.
"""

from __future__ import annotations

import csv
import tempfile
from collections import Counter
from pathlib import Path

import numpy as np

from derivations.actuator_observers.campaign import CAMPAIGN, correct, counts, size_intervals, targets
from derivations.actuator_observers.dock import cross_track_rms, dock_miss
from derivations.actuator_observers.figures import campaign_confusion_figure, campaign_delay_figure
from uvsym.campaign import load_campaign, run_campaign
from uvsym.campaign.limits import channel_limits, false_alarm_rates
from uvsym.progress import ProgressBar
from uvsym.sim.scenario import load_scenario
from uvsym.sim.simulation import simulate_scenario

__all__ = ["campaign_results", "corrected_docking", "TABLE_COLUMNS"]

# the columns of campaign_results.csv (the run's wall time is left out: the file stays the same)
TABLE_COLUMNS = ("case", "true_actuator", "true_kind", "true_value", "onset_s", "identifiable", "excited",
                 "detected", "detection_delay_s", "isolated_target", "isolated_kind", "isolation_delay_s",
                 "identified_value", "identified_std", "size_error_rel", "size_error_std", "false_alarms", "ambiguous",
                 "status", "error")


def _vehicle(case: str) -> str:
    return case.split(",")[0]


def fault_size(row: dict) -> float | None:
    """A fault's size for the limits: a proportional factor's distance from 1, a bias's magnitude; a stuck
    actuator's value is no size (how much it matters depends on the commands), so None."""
    if row["true_kind"] == "proportional":
        return abs(1.0 - row["true_value"])
    return abs(row["true_value"]) if row["true_kind"] == "bias" else None


def _noisy(faults) -> bool:
    """Whether a run's ``faults`` grid field (a list, or its text in a results table) holds sensor noise."""
    return bool(faults) and faults != "[]"


def _velocity_noise(row: dict) -> str:
    """A run's velocity-noise setting: none, told (the noisy cases' levels) or told x2 (twice them)."""
    if row["case"].endswith("noise x2"):
        return "told x2"
    return "told" if "sensor noise" in row["case"] or "10 h" in row["case"] or _noisy(row.get("faults")) else "none"


def _decided(row: dict) -> str:
    if row["isolated_target"] is None:
        return "ambiguous" if row["ambiguous"] else "none"
    return f"{row['isolated_kind']} {row['isolated_target']}"


def campaign_results(out_dir: Path, progress, workers: int | None = None) -> dict:
    """Run the campaign; write campaign_results.csv and its figures into out_dir; return its figures."""
    campaign = load_campaign(CAMPAIGN)
    progress(f"fault campaign: {len(campaign.runs)} runs of {CAMPAIGN.name}")
    with tempfile.TemporaryDirectory(prefix="uvsym-campaign-") as scratch:
        rows = run_campaign(campaign, Path(scratch) / "campaign", executor="local", workers=workers,
                            progress=ProgressBar(f"  {campaign.name}", unit="runs")).to_pylist()
    figures = counts(rows)
    faulty = [r for r in rows if r["status"] == "ok" and r["true_actuator"] is not None]
    counted = [r for r in faulty if r["identifiable"] and r["excited"]]
    confusion = Counter((f"{r['true_kind']} {r['true_actuator']}", _decided(r)) for r in counted)
    wrong = [{key: r[key] for key in ("case", "true_actuator", "true_kind", "true_value", "onset_s",
                                      "isolated_target", "isolated_kind", "identified_value", "size_error_rel")}
             for r in counted if not correct(r)]
    excluded = Counter((_vehicle(r["case"]), r["true_actuator"], r["true_kind"]) for r in faulty
                       if not (r["identifiable"] and r["excited"]))
    by_kind = {}
    for kind in sorted({r["true_kind"] for r in counted}):
        errors = [r["size_error_rel"] for r in counted if r["true_kind"] == kind and r["size_error_rel"] is not None]
        by_kind[kind] = {"runs": sum(r["true_kind"] == kind for r in counted),
                         "correct": sum(correct(r) for r in counted if r["true_kind"] == kind),
                         "median_size_error_rel": float(np.median(errors)) if errors else None,
                         "max_size_error_rel": float(np.max(errors)) if errors else None}
    _write_table(rows, out_dir / "campaign_results.csv")
    campaign_confusion_figure(confusion, out_dir / "campaign_confusion.svg")
    campaign_delay_figure(counted, out_dir / "campaign_delays.svg")
    limits = {vehicle: channel_limits(rows, cases=[c for c in dict.fromkeys(r["case"] for r in rows)
                                                   if _vehicle(c) == vehicle], size=fault_size)
              for vehicle in dict.fromkeys(_vehicle(r["case"]) for r in rows)}
    for row in rows:
        row["velocity_noise"] = _velocity_noise(row)
    diagnosis = load_scenario("docking_diagnosis").diagnosis
    return {"designed_false_alarms_per_hour": 3600.0 / diagnosis.period_s * diagnosis.false_alarm_rate,
            "decision_period_s": diagnosis.period_s, "window_false_alarm_rate": diagnosis.false_alarm_rate,
            **figures, "targets": targets(figures), "by_kind": by_kind, "wrong": wrong,
            "limits": limits, "fault_free": false_alarm_rates(rows, "velocity_noise"),
            "size_intervals": size_intervals(rows),
            "excluded": [{"vehicle": v, "actuator": a, "kind": k, "runs": n}
                         for (v, a, k), n in sorted(excluded.items())],
            "confusion": [{"true": t, "decided": d, "runs": n} for (t, d), n in sorted(confusion.items())]}


def corrected_docking(progress) -> dict:
    """The shipped docking_diagnosis scenario: the continuous diagnosis corrects the docking run."""
    scenario = load_scenario("docking_diagnosis")
    progress(f"docking with the continuous diagnosis in the loop ({scenario.name})")
    result = simulate_scenario(scenario)
    identified = {e["target"]: {"kind": e["kind"], "value": e["value"], "time_s": e["t"]}
                  for e in result.events if e["event"] == "identified"}
    isolated = [e["t"] for e in result.events if e["event"] == "isolated"]
    return {"scenario": scenario.name, "events": result.events, "identified": identified,
            "isolation_time_s": max(isolated) if isolated else None,
            "cross_track_rms_m": cross_track_rms(result, scenario), "dock_miss_m": dock_miss(result, scenario)}


def _write_table(rows: list[dict], path: Path) -> None:
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(TABLE_COLUMNS)
        for row in rows:
            writer.writerow(["" if row.get(c) is None else f"{row[c]:.6g}" if isinstance(row.get(c), float)
                             else row.get(c) for c in TABLE_COLUMNS])
