"""The study's campaign (``campaign.toml`` beside this file, the same file ``uvsym campaign``
runs): run by the report build; per detector and per case its figures from the event log, the
false alarms per hour by sensor noise, and the per-run table."""

from __future__ import annotations

import csv
import math
import tempfile
from pathlib import Path

from uvsym.campaign import load_campaign, run_campaign
from uvsym.campaign.summary import detector_names, detector_rates
from uvsym.progress import ProgressBar
from uvsym.report import markdown_table

__all__ = ["CAMPAIGN", "run_study_campaign", "campaign_section"]

CAMPAIGN = Path(__file__).with_name("campaign.toml")
RATES = ("runs", "fault_runs", "detection_probability", "missed_detections", "median_detection_delay_s",
         "correct_isolation", "median_size_error_rel", "false_alarms", "healthy_hours", "false_alarms_per_hour")
NONE_SEEN = -math.log(0.05)  # none seen in H hours: a Poisson rate below NONE_SEEN / H per hour at 95 %
SIZE_TOLERANCE = 0.05  # |identified - true| of a delivered fraction that counts as badly sized
ROW_COLUMNS = ("case", "true_actuator", "true_kind", "true_value", "onset_s", "noise.x", "status", "error")
PER_DETECTOR = ("detected", "detection_delay_s", "isolated_target", "identified_value", "false_alarms")


def _noise(row: dict) -> str:
    """The run's sensor noise as a multiple of the paper's (x: 0.05 m), and whether the banks were told."""
    told = "banks told" in row["case"]
    return f"{(row.get('noise.x') or 0.05) / 0.05:g}x" + (", banks told" if told else "")


def _problems(row: dict, detector: str) -> str | None:
    """What a detector got wrong on a faulty run (missed, wrong thruster, not or badly sized), or None."""
    if not row[f"{detector}:detected"]:
        return "missed"
    wrong = []
    if row[f"{detector}:isolated_target"] != row["true_actuator"]:
        wrong.append(f"isolated {row[f'{detector}:isolated_target'] or 'nothing'} at the end")
    value = row[f"{detector}:identified_value"]
    if value is None:
        wrong.append("never sized (the estimate did not settle)")
    elif row["true_kind"] == "proportional" and abs(value - row["true_value"]) > SIZE_TOLERANCE:
        wrong.append(f"sized {value:.3g}")
    return "; ".join(wrong) or None


def _failures(rows: list[dict], detectors: list[str]) -> list[dict]:
    """Per faulty run with a problem: the run and, per problem, the detectors that had it."""
    found = []
    for row in rows:
        if row["status"] != "ok" or not row["n_faults"]:
            continue
        problems: dict[str, list[str]] = {}
        for d in detectors:
            if (problem := _problems(row, d)) is not None:
                problems.setdefault(problem, []).append(d)
        found += [{"case": row["case"], "thruster": row["true_actuator"], "kind": row["true_kind"],
                   "value": row["true_value"], "noise": _noise(row), "problem": problem, "detectors": names}
                  for problem, names in problems.items()]
    return found


def run_study_campaign(out_dir: Path, progress, workers: int | None = 2) -> dict:
    """Run the campaign; write campaign_results.csv into out_dir; return its figures (no timings:
    the report stays the same from one build to the next)."""
    campaign = load_campaign(CAMPAIGN)
    progress(f"campaign: {len(campaign.runs)} runs of {CAMPAIGN.name}")
    with tempfile.TemporaryDirectory(prefix="uvsym-campaign-") as scratch:
        rows = run_campaign(campaign, Path(scratch) / "campaign", executor="local", workers=workers,
                            progress=ProgressBar(f"  {campaign.name}", unit="runs")).to_pylist()
    detectors = detector_names(rows)
    cases = list(dict.fromkeys(r["case"] for r in rows))
    figures = {
        "runs": len(rows), "errors": sum(r["status"] != "ok" for r in rows),
        "simulated_s": sum(r.get("duration_s") or 0.0 for r in rows),
        "detectors": {d: {k: detector_rates(rows, d)[k] for k in RATES} for d in detectors},
        "cases": {c: {d: {k: detector_rates([r for r in rows if r["case"] == c], d)[k] for k in RATES}
                      for d in detectors} for c in cases},
        "healthy_by_noise": {n: {d: {k: detector_rates([r for r in rows if _noise(r) == n], d)[k]
                                     for k in ("runs", "false_alarms", "healthy_hours", "false_alarms_per_hour")}
                                 for d in detectors} for n in dict.fromkeys(_noise(r) for r in rows)},
    }
    figures["failures"] = _failures(rows, detectors)
    columns = list(ROW_COLUMNS) + [f"{d}:{c}" for d in detectors for c in PER_DETECTOR]
    with (out_dir / "campaign_results.csv").open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        writer.writerows([[r.get(c) for c in columns] for r in rows])
    return figures


def _f(value, digits: int = 3) -> str:
    return "-" if value is None else f"{value:.{digits}g}"


def campaign_section(c: dict) -> str:
    """The report's campaign section from :func:`run_study_campaign`'s figures."""
    detectors = list(c["detectors"])
    overall = [[d, _f(r["detection_probability"]), r["missed_detections"], _f(r["median_detection_delay_s"]),
                _f(r["correct_isolation"]), _f(r["median_size_error_rel"]), r["false_alarms"],
                _f(r["healthy_hours"]), _f(r["false_alarms_per_hour"])] for d, r in c["detectors"].items()]
    cases = [[case] + [f"{_f(per[d]['detection_probability'], 2)} / {_f(per[d]['median_detection_delay_s'])} / "
                       f"{_f(per[d]['correct_isolation'], 2)} / {per[d]['false_alarms']}" for d in detectors]
             for case, per in c["cases"].items()]
    healthy = [[noise] + [f"{per[d]['false_alarms']} in {_f(per[d]['healthy_hours'])} h: "
                          f"{_f(per[d]['false_alarms_per_hour'])} /h"
                          + (f" (< {NONE_SEEN / per[d]['healthy_hours']:.3g} /h, 95 %)" if not per[d]["false_alarms"]
                             else "") for d in detectors]
               for noise, per in c["healthy_by_noise"].items()]
    failures = [[f["case"], f"{f['thruster']} {f['kind']} {f['value']:g}", f["noise"], f["problem"],
                 ", ".join(f["detectors"])] for f in c["failures"]]
    return f"""## Campaign: what a user meets

[campaign.toml](../../derivations/usv_fukf_mmae/campaign.toml) ({c["runs"]} runs, {c["simulated_s"] / 60:.0f} min
simulated, {c["errors"]} ending in an error), run by this build; `uvsym campaign
derivations/usv_fukf_mmae/campaign.toml` runs the same file. Every run starts from the shipped
scenario with both banks in the loop, so the four detectors decide on the same runs: `ukf_mmae` and
`ekf_mmae` are the shipped rule (the bank's most probable hypothesis above 0.9 for one sample),
`*_1s` the same rule with a dwell of 20 samples (1 s), and `ukf_evidence` the calibrated rule
(`rule = "evidence"`, :class:`uvsym.diagnosis.hypotheses.EvidenceSwitch`): a CUSUM of each fault model's
log-likelihood ratio against the no-fault model, released when the ratio over the last 3 s is no
longer positive, and `unexplained` when every model's innovations fail their chi-square test,
thresholds designed for 1 false alarm per hour at the sample period. Faults last to the end of their run (onsets
drawn in [30, 60] s). A detection counts from the onset on; every alarm event (`detected`,
`isolated`, `identified`) outside a fault's window is a false alarm, counted over the healthy time
(healthy runs and the stretches before each onset). Isolation is correct when the thruster isolated
in the window is the faulty one; the size error is `|identified - true| / true` of the delivered
fraction (a stuck thruster's true value is its thrust in N, so its size error is not comparable).
The shipped rule's threshold is a posterior probability: the banks' likelihoods carry their noise
model (R, Q), so no false-alarm rate is designed into it; the rates below are measured, and hold only
while the sensors are as noisy as R says. The evidence rule's designed rate (1 per hour) stands
beside its measured one in the tables (`unexplained` is not counted as an alarm).

{markdown_table(["detector", "detection probability", "missed", "median delay (s)", "correct isolation",
                 "median size error", "false alarms", "healthy hours", "false alarms per hour"], overall)}

Per case (detection probability / median delay s / correct isolation / false alarms):

{markdown_table(["case"] + detectors, cases)}

False alarms by sensor noise (a multiple of the paper's; the banks keep the paper's R unless told),
over the healthy runs and the stretches before each onset:

{markdown_table(["noise"] + detectors, healthy)}

Where the banks fail (faulty runs on which a detector missed, ended on the wrong thruster, or sized
the loss more than {SIZE_TOLERANCE:g} off; computed from the runs above):

{markdown_table(["case", "fault", "noise", "what went wrong", "detectors"], failures) if failures else "none."}

Every run's row is in [campaign_results.csv](campaign_results.csv).
"""
