"""The compass-fault campaign (``campaign.toml`` beside this file), run by the report build.

Runs the file through :func:`uvsym.campaign.run_campaign` (as ``uvsym campaign`` does) and reduces
its rows per detector (:func:`uvsym.campaign.summary.detector_rates`): detection probability, missed
detections, median detection delay (s after the onset), correct isolation, false alarms and false
alarms per hour, overall and per case; and, for the bias steps, the detections per size and noise
level and each detector's limits per noise level (:func:`uvsym.campaign.limits.channel_limits`), for the
long healthy runs per noise level, the pulses per length, and the false alarms per hour each detector is
designed for. Run times are left out (they differ from build to build).
"""

from __future__ import annotations

import csv
import math
import tempfile
from pathlib import Path

from uvsym.campaign import load_campaign, run_campaign
from uvsym.campaign.limits import channel_limits
from uvsym.campaign.summary import detector_rates
from uvsym.progress import ProgressBar

__all__ = ["CAMPAIGN", "DETECTORS", "campaign_results"]

CAMPAIGN = Path(__file__).with_name("campaign.toml")
DETECTORS = ("double_criterion", "error_threshold", "step_test")  # the detectors of the scenario files, in their order
FIGURES = ("runs", "fault_runs", "detection_probability", "missed_detections", "median_detection_delay_s",
           "correct_isolation", "false_alarms", "healthy_hours", "false_alarms_per_hour")
BIAS_CASE, HEALTHY_CASE, PULSE_CASE = "bias step", "no fault", "pulse"
STEP_S = 0.2  # s: the scenario's sample period
NOMINAL_NOISE = 0.008726646259971648  # rad: the scenario's compass noise (0.5 deg), where a row leaves it unset
TABLE_COLUMNS = ("case", "true_kind", "true_value", "onset_s", "end_s", "seed", "noise.psi", "faults[0].duration",
                 "faults[0].rate", "faults[0].period", "setpoints[0].values") + tuple(
    f"{d}:{c}" for d in DETECTORS for c in ("detected", "detection_delay_s", "isolated_target", "false_alarms"))


def _figures(rows: list[dict]) -> dict:
    """FIGURES of :func:`detector_rates` per detector over ``rows``."""
    return {d: {key: detector_rates(rows, d)[key] for key in FIGURES} for d in DETECTORS}


def _noise_deg(row: dict) -> float:
    return round(math.degrees(row.get("noise.psi") or NOMINAL_NOISE), 6)


def _size_deg(row: dict) -> float:
    return round(math.degrees(abs(row["true_value"])), 6)


def _healthy_by_noise(rows: list[dict]) -> list[dict]:
    """The long healthy runs: per compass noise (deg), the figures of every detector."""
    healthy = [r for r in rows if r["case"] == HEALTHY_CASE]
    return [{"noise_deg": noise, **_figures([r for r in healthy if _noise_deg(r) == noise])}
            for noise in sorted({_noise_deg(r) for r in healthy})]


def _by_size(rows: list[dict]) -> list[dict]:
    """Bias steps: per size (deg) and compass noise (deg), runs, detections and false alarms per detector."""
    groups: dict[tuple[float, float], list[dict]] = {}
    for row in rows:
        if row["case"] == BIAS_CASE and row["status"] == "ok":
            groups.setdefault((_size_deg(row), _noise_deg(row)), []).append(row)
    return [{"size_deg": size, "noise_deg": noise, "runs": len(members),
             **{d: {"detected": sum(bool(r[f"{d}:detected"]) for r in members),
                    "false_alarms": sum(r[f"{d}:false_alarms"] or 0 for r in members)} for d in DETECTORS}}
            for (size, noise), members in sorted(groups.items())]


def _bias_limits(rows: list[dict]) -> list[dict]:
    """Bias steps per compass noise (deg): each detector's :func:`channel_limits` (sizes in deg)."""
    steps = [r for r in rows if r["case"] == BIAS_CASE]
    return [{"noise_deg": noise,
             **{d: channel_limits([r for r in steps if _noise_deg(r) == noise], d, size=_size_deg) for d in DETECTORS}}
            for noise in sorted({_noise_deg(r) for r in steps})]


def _designed_rates(scenario: dict) -> dict:
    """Per detector, the false alarms per hour it is designed for: its own ``false_alarms_per_hour`` or its
    monitor block's (None: not designed)."""
    blocks = {b["name"]: b for b in scenario["blocks"]}
    detectors = {d["name"]: d for d in scenario["detectors"]}
    return {d: detectors[d].get("false_alarms_per_hour",
                                blocks.get(detectors[d].get("monitor"), {}).get("false_alarms_per_hour"))
            for d in DETECTORS}


def _pulses(rows: list[dict]) -> list[dict]:
    """Pulses of the bias (glitches and longer): per length (samples), runs and detections per detector."""
    groups: dict[int, list[dict]] = {}
    for row in rows:
        if row["case"] == PULSE_CASE and row["status"] == "ok":
            samples = math.ceil((row["end_s"] - row["onset_s"]) / STEP_S - 1e-9)  # the samples the bias is on
            groups.setdefault(samples, []).append(row)
    return [{"samples": length, "runs": len(members),
             **{d: sum(bool(r[f"{d}:detected"]) for r in members) for d in DETECTORS}}
            for length, members in sorted(groups.items())]


def campaign_results(out_dir: Path, progress, workers: int | None = None) -> dict:
    """Run the campaign; write campaign_results.csv into out_dir; return its figures (module docstring)."""
    campaign = load_campaign(CAMPAIGN)
    progress(f"compass-fault campaign: {len(campaign.runs)} runs of {CAMPAIGN.name}")
    with tempfile.TemporaryDirectory(prefix="uvsym-campaign-") as scratch:
        rows = run_campaign(campaign, Path(scratch) / "campaign", executor="local", workers=workers,
                            progress=ProgressBar(f"  {campaign.name}", unit="runs")).to_pylist()
    _write_table(rows, out_dir / "campaign_results.csv")
    cases: dict[str, list[dict]] = {}
    for row in rows:
        cases.setdefault(row["case"], []).append(row)
    errors = [{"case": r["case"], "error": r["error"]} for r in rows if r["status"] != "ok"]
    return {"runs": len(rows), "errors": errors,
            "simulated_hours": sum(r["duration_s"] or 0.0 for r in rows) / 3600.0,
            "detectors": _figures(rows), "cases": {case: _figures(members) for case, members in cases.items()},
            "bias_by_size": _by_size(rows), "bias_limits": _bias_limits(rows),
            "healthy_by_noise": _healthy_by_noise(rows), "pulses": _pulses(rows),
            "designed_per_hour": _designed_rates(campaign.runs[0].scenario)}


def _write_table(rows: list[dict], path: Path) -> None:
    """One line per run, TABLE_COLUMNS (floats to 6 significant digits, None empty)."""
    def shown(value):
        return "" if value is None else f"{value:.6g}" if isinstance(value, float) else value

    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, TABLE_COLUMNS)
        writer.writeheader()
        writer.writerows({column: shown(row.get(column)) for column in TABLE_COLUMNS} for row in rows)
