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
PER_DETECTOR = ("detected", "detection_delay_s", "isolated_target", "identified_value", "false_alarms", "clear_delay_s",
                "isolated_targets", "unexplained")
ENDING, BOTH = "loss that ends", "both thrusters"  # the cases of a loss that ends and of two losses at once
RETURN_TARGET_S = 5.0  # s: back to "no fault" after any loss of 5 % or more ends (the target)


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
    """Per faulty run with a problem: the run and, per problem, the detectors that had it (runs of one fault
    that lasts the run: a loss that ends and two losses have their own table, :func:`_returns_section`)."""
    found = []
    for row in rows:
        if row["status"] != "ok" or row["n_faults"] != 1 or row["end_s"] is not None:
            continue
        problems: dict[str, list[str]] = {}
        for d in detectors:
            if (problem := _problems(row, d)) is not None:
                problems.setdefault(problem, []).append(d)
        found += [{"case": row["case"], "thruster": row["true_actuator"], "kind": row["true_kind"],
                   "value": row["true_value"], "noise": _noise(row), "problem": problem, "detectors": names}
                  for problem, names in problems.items()]
    return found


def _returns(rows: list[dict], detectors: list[str]) -> dict:
    """Losses that end: per detector, per run (thruster, delivered fraction) whether it was detected and how
    long after the end an alarm stood (None: to the end of the run), and the largest such time."""
    per = {}
    for d in detectors:
        runs = [{"thruster": r["true_actuator"], "value": r["true_value"], "detected": bool(r[f"{d}:detected"]),
                 "return_s": r[f"{d}:clear_delay_s"]} for r in rows]
        delays = [run["return_s"] for run in runs]
        finite = [x for x in delays if x is not None]
        per[d] = {"runs": runs, "never": sum(x is None for x in delays),
                  "largest_s": None if None in delays or not delays else max(delays),
                  "largest_finite_s": max(finite) if finite else None}
    return per


def _two_faults(rows: list[dict], detectors: list[str]) -> list[dict]:
    """Runs with both thrusters losing: the right one's fraction and onset, and per detector what it held at
    the end (``unexplained``, ``ambiguous``, the thrusters it isolated, or ``nothing``)."""
    def outcome(row: dict, d: str) -> str:
        if row[f"{d}:unexplained"]:
            return "unexplained"
        if row[f"{d}:ambiguous"]:
            return "ambiguous"
        return row[f"{d}:isolated_targets"] or ("detected, nothing isolated" if row[f"{d}:detected"] else "nothing")

    return [{"right_value": r.get("faults[1].value"), "right_onset_s": r.get("faults[1].onset"),
             "left": r["true_actuator"], "left_value": r["true_value"], "left_onset_s": r["onset_s"],
             "outcomes": {d: outcome(r, d) for d in detectors}} for r in rows]


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
    figures["returns"] = _returns([r for r in rows if r["case"] == ENDING and r["status"] == "ok"], detectors)
    figures["two_faults"] = _two_faults([r for r in rows if r["case"] == BOTH and r["status"] == "ok"], detectors)
    columns = list(ROW_COLUMNS) + [f"{d}:{c}" for d in detectors for c in PER_DETECTOR]
    with (out_dir / "campaign_results.csv").open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        writer.writerows([[r.get(c) for c in columns] for r in rows])
    return figures


def _f(value, digits: int = 3) -> str:
    return "-" if value is None else f"{value:.{digits}g}"


def _return_cell(seconds: float | None) -> str:
    if seconds is None:
        return "still alarmed at the end"
    return "released before the end" if seconds == 0.0 else f"{seconds:.2f} s"


def _returns_section(c: dict) -> str:
    """After a loss ends, and two losses at once: the runs per detector, and the targets."""
    detectors, returns, two = list(c["detectors"]), c["returns"], c["two_faults"]
    if not returns or not two:
        return ""
    first = returns[detectors[0]]["runs"]
    rows = [[f"{run['thruster']} {run['value']:g}"] + [
        ("missed, " if not returns[d]["runs"][i]["detected"] else "")
        + _return_cell(returns[d]["runs"][i]["return_s"]) for d in detectors] for i, run in enumerate(first)]
    both = [[f"{t['left']} {t['left_value']:g} from {t['left_onset_s']:g} s, the other {t['right_value']:g} from "
             f"{t['right_onset_s']:g} s"] + [t["outcomes"][d] for d in detectors] for t in two]

    def verdicts(d: str) -> list[str]:
        r = returns[d]
        back = ("met" if r["largest_s"] is not None and r["largest_s"] <= RETURN_TARGET_S else "**missed**")
        largest = f"{r['largest_s']:.2f} s" if r["largest_s"] is not None else (
            f"never in {r['never']} run(s)" + (f", else up to {r['largest_finite_s']:.1f} s"
                                               if r["largest_finite_s"] is not None else ""))
        culprits = sum(t["outcomes"][d] not in ("unexplained", "ambiguous") for t in two)
        return [d, largest, back, f"{len(two) - culprits} of {len(two)}", "met" if not culprits else "**missed**"]

    return f"""### After a loss ends, and two losses at once

Losses of 5 % to 80 % (case `{ENDING}`: on from 40 s to 70 s) -- how long after the loss ends an alarm
still stands ("released before the end": the detector had let the loss go while it lasted):

{markdown_table(["loss (delivered fraction)"] + detectors, rows)}

Both thrusters losing (case `{BOTH}`; the banks model one faulty thruster at a time) -- what each
detector holds at the end of the run (a single thruster named is a wrong culprit):

{markdown_table(["faults"] + detectors, both)}

{markdown_table(["detector", 'longest return to "no fault" after a loss ends', f"within {RETURN_TARGET_S:g} s",
                 "two losses: unexplained or ambiguous", "never a single culprit"], [verdicts(d) for d in detectors])}
"""


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
thresholds designed for 1 false alarm per hour at the sample period. Faults last to the end of their
run, but in `loss that ends` and `both thrusters` (below; onsets drawn in [30, 60] s elsewhere). A
detection counts from the onset on; every alarm event (`detected`,
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

{_returns_section(c)}

Where the banks fail (faulty runs on which a detector missed, ended on the wrong thruster, or sized
the loss more than {SIZE_TOLERANCE:g} off; computed from the runs above):

{markdown_table(["case", "fault", "noise", "what went wrong", "detectors"], failures) if failures else "none."}

Every run's row is in [campaign_results.csv](campaign_results.csv).
"""
