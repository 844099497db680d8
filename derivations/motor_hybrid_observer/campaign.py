"""The study's fault campaign (``campaign.toml`` beside this file, over ``campaign_motor.toml``): run
by the report build through :func:`uvsym.campaign.run_campaign`, the same file ``uvsym campaign``
runs; every figure here is computed from its rows (per detector, from the event log).

Per detector (``hybrid``: the hybrid detection residual at z sigma for 1 false alarm per hour under
the stated noise; ``hybrid_study``: the same residual at the study's calibrated threshold;
``luenberger_fd``: the motor's Luenberger observer at z sigma): detection probability, missed
detections, median detection delay, median identification error and false alarms per hour, over
the whole campaign, per case and, for the long healthy runs, per noise level; for the
speed-sensor steps, the detection of every size at each noise level. CPU times are left out
(they change from run to run; the report must not).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from uvsym.campaign import load_campaign, run_campaign
from uvsym.campaign.summary import detector_rates
from uvsym.progress import ProgressBar

__all__ = ["CAMPAIGN", "DETECTORS", "TORQUE_BALANCE_CAMPAIGN", "campaign_results", "designed_rates", "figures",
           "torque_balance_healthy"]

CAMPAIGN = Path(__file__).with_name("campaign.toml")
TORQUE_BALANCE_CAMPAIGN = Path(__file__).with_name("campaign_torque_balance.toml")
DETECTORS = ("hybrid", "hybrid_study", "luenberger_fd")
STEP_CASE = "speed sensor step"
HEALTHY_CASES = "no fault"  # the prefix of the healthy cases' names
RATES = ("runs", "fault_runs", "detection_probability", "missed_detections", "median_detection_delay_s",
         "median_size_error_rel", "false_alarms", "healthy_hours", "false_alarms_per_hour")


def _rates(rows: list[dict]) -> dict:
    return {d: {k: detector_rates(rows, d)[k] for k in RATES} for d in DETECTORS}


def _label(row: dict) -> str:
    """The fault of a row in words: sensor, kind, profile and size."""
    if not row["n_faults"]:
        return "none"
    profile = row.get("faults[0].profile") or "step"
    shape = "" if row["true_kind"] != "bias" else f" {profile}" + (
        f" rate {row['faults[0].rate']:g}" if profile == "incipient" else
        f" period {row['faults[0].period']:g} duty {row['faults[0].duty']:g}" if profile == "intermittent" else "")
    return f"{row['true_sensor']} {row['true_kind']}{shape} {row['true_value']:g}"


def figures(rows: list[dict]) -> dict:
    """The campaign's figures (module docstring) from its result rows."""
    ok = [r for r in rows if r["status"] == "ok"]
    cases = list(dict.fromkeys(r["case"] for r in rows))
    steps = [r for r in ok if r["case"] == STEP_CASE]
    healthy = [r for r in ok if r["case"].startswith(HEALTHY_CASES)]
    sizes = sorted({r["true_value"] for r in steps})
    noises = sorted({r["noise.omega_m"] for r in steps})
    grid = {f"{noise:g}": {f"{size:g}": {d: next(r[f"{d}:detection_delay_s"] for r in steps
                                                 if r["true_value"] == size and r["noise.omega_m"] == noise)
                                         for d in DETECTORS} for size in sizes} for noise in noises}
    others = [{"case": r["case"], "fault": _label(r), "onset_s": r["onset_s"],
               "noise_omega_m": r.get("noise.omega_m"), "duration_s": r["duration_s"],
               **{f"{d}:{k}": r[f"{d}:{k}"] for d in DETECTORS
                  for k in ("detection_delay_s", "identified_value", "false_alarms")}}
              for r in ok if r["case"] != STEP_CASE and not r["case"].startswith(HEALTHY_CASES)]
    return {"runs": len(rows), "errors": len(rows) - len(ok), "overall": _rates(ok),
            "cases": {case: _rates([r for r in ok if r["case"] == case]) for case in cases},
            "step_detection_delay_s": grid, "other_runs": others,
            "healthy_by_noise": {f"{noise:g}": _rates([r for r in healthy if r["noise.omega_m"] == noise])
                                 for noise in sorted({r["noise.omega_m"] for r in healthy})}}


def _rows(campaign, what: str, progress, workers: int | None) -> list[dict]:
    """The result rows of ``campaign``, run in a scratch folder (local processes)."""
    progress(f"{what}: {len(campaign.runs)} runs of {campaign.path.name}")
    with tempfile.TemporaryDirectory(prefix="uvsym-campaign-") as scratch:
        return run_campaign(campaign, Path(scratch) / "campaign", executor="local", workers=workers,
                            progress=ProgressBar(f"  {campaign.name}", unit="runs")).to_pylist()


def campaign_results(progress, workers: int | None = None) -> dict:
    """Run the campaign and return its :func:`figures`."""
    campaign = load_campaign(CAMPAIGN)
    return figures(_rows(campaign, "fault campaign", progress, workers)) | {
        "designed_false_alarms_per_hour": designed_rates(campaign)}


def torque_balance_healthy(progress, workers: int | None = None) -> dict:
    """The torque-balance estimator's long healthy runs (``campaign_torque_balance.toml``), per speed-sensor
    noise (rad/s): runs, judged hours, false alarms (a detection or an unexplained torque) and their rate;
    ``errors``: runs that ended in an error."""
    rows = _rows(load_campaign(TORQUE_BALANCE_CAMPAIGN), "torque balance, long healthy runs", progress, workers)
    ok = [r for r in rows if r["status"] == "ok"]
    levels = {}
    for noise in sorted({r["noise.omega_m"] for r in ok}):
        group = [r for r in ok if r["noise.omega_m"] == noise]
        hours, alarms = sum(r["tb_judged_s"] for r in group) / 3600.0, sum(r["tb_false_alarms"] for r in group)
        levels[f"{noise:g}"] = {"runs": len(group), "hours": hours, "false_alarms": alarms,
                                "per_hour": alarms / hours}
    return {"levels": levels, "errors": len(rows) - len(ok)}


def designed_rates(campaign) -> dict:
    """Per detector, the false alarms per hour its rule is designed for under the stated noise (None for a
    given threshold: a calibrated constant, no noise model behind it)."""
    from uvsym.sim.system_scenario import parse_any_scenario

    scenario = parse_any_scenario(campaign.runs[0].scenario)
    return {d.name: d.design()["false_alarms_per_hour"] if "z sigma" in d.design()["rule"] else None
            for d in scenario.detectors if d.name in DETECTORS}
