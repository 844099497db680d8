"""The study's campaign (``campaign.toml`` beside this file, the same file ``uvsym campaign``
runs): run by the report build; per detector and per case its figures from the event log, the
false alarms per hour by sensor noise, the smallest loss detected per thruster, the per-run table, and
the measured limits read off them."""

from __future__ import annotations

import csv
import tempfile
from pathlib import Path

from derivations.usv_fukf_mmae.scenario import parsed
from uvsym.campaign import load_campaign, run_campaign
from uvsym.campaign.limits import NONE_SEEN_95, channel_limits, limits_table
from uvsym.campaign.summary import detector_names, detector_rates
from uvsym.progress import ProgressBar
from uvsym.report import limits_block, markdown_table

__all__ = ["CAMPAIGN", "run_study_campaign", "campaign_section", "limits_section"]

CAMPAIGN = Path(__file__).with_name("campaign.toml")
RATES = ("runs", "fault_runs", "detection_probability", "missed_detections", "median_detection_delay_s",
         "correct_isolation", "median_size_error_rel", "false_alarms", "healthy_hours", "false_alarms_per_hour")
SIZE_TOLERANCE = 0.05  # |identified - true| of a delivered fraction that counts as badly sized
ROW_COLUMNS = ("case", "true_actuator", "true_kind", "true_value", "onset_s", "noise.x", "status", "error")
PER_DETECTOR = ("detected", "detection_delay_s", "isolated_target", "identified_value", "false_alarms", "clear_delay_s",
                "isolated_targets", "unexplained")
ENDING, BOTH = "loss that ends", "both thrusters"  # the cases of a loss that ends and of two losses at once
STEP, NOISIER, STUCK = "step loss", "step loss, sensors 2 and 3 times noisier", "stuck thruster"
RETURN_TARGET_S = 5.0  # s: back to "no fault" after any loss of 5 % or more ends (the target)


def _noise(row: dict) -> str:
    """The run's sensor noise as a multiple of the paper's (x: 0.05 m), and whether the banks were told."""
    told = "banks told" in row["case"]
    return f"{(row.get('noise.x') or 0.05) / 0.05:g}x" + (", banks told" if told else "")


def _loss_percent(row: dict) -> float | None:
    """A proportional fault's loss in % of the command (None for another kind: no size)."""
    return round((1.0 - row["true_value"]) * 100.0, 6) if row["true_kind"] == "proportional" else None


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
        "cases": {c: {d: _case_rates([r for r in rows if r["case"] == c], d) for d in detectors} for c in cases},
        "healthy_by_noise": {n: {d: {k: detector_rates([r for r in rows if _noise(r) == n], d)[k]
                                     for k in ("runs", "false_alarms", "healthy_hours", "false_alarms_per_hour")}
                                 for d in detectors} for n in dict.fromkeys(_noise(r) for r in rows)},
    }
    figures["failures"] = _failures(rows, detectors)
    figures["returns"] = _returns([r for r in rows if r["case"] == ENDING and r["status"] == "ok"], detectors)
    figures["two_faults"] = _two_faults([r for r in rows if r["case"] == BOTH and r["status"] == "ok"], detectors)
    figures["limits"] = {d: channel_limits(rows, d, cases=(STEP, ENDING), size=_loss_percent) for d in detectors}
    figures["designed_false_alarms_per_hour"] = {  # every case sets the same detectors
        d.name: d.design().get("designed_false_alarms_per_hour") for d in parsed(campaign.runs[0].scenario).detectors}
    columns = list(ROW_COLUMNS) + [f"{d}:{c}" for d in detectors for c in PER_DETECTOR]
    with (out_dir / "campaign_results.csv").open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        writer.writerows([[r.get(c) for c in columns] for r in rows])
    return figures


def _case_rates(rows: list[dict], detector: str) -> dict:
    """A case's RATES of one detector, and how many of its runs the detector called ``unexplained``."""
    rates = detector_rates(rows, detector)
    unexplained = sum(bool(r[f"{detector}:unexplained"]) for r in rows if r["status"] == "ok")
    return {**{k: rates[k] for k in RATES}, "unexplained_runs": unexplained}


def _f(value, digits: int = 3) -> str:
    return "-" if value is None else f"{value:.{digits}g}"


def _return_cell(seconds: float | None) -> str:
    if seconds is None:
        return "still alarmed at the end"
    return "released before the end" if seconds == 0.0 else f"{seconds:.2f} s"


def _verdicts(c: dict) -> str:
    """Per detector: its longest return to "no fault" after a loss ends, and its answers to two losses at once,
    against the targets."""
    two = c["two_faults"]

    def row(d: str) -> list[str]:
        r = c["returns"][d]
        back = ("met" if r["largest_s"] is not None and r["largest_s"] <= RETURN_TARGET_S else "**missed**")
        largest = f"{r['largest_s']:.2f} s" if r["largest_s"] is not None else (
            f"never in {r['never']} run(s)" + (f", else up to {r['largest_finite_s']:.1f} s"
                                               if r["largest_finite_s"] is not None else ""))
        culprits = sum(t["outcomes"][d] not in ("unexplained", "ambiguous") for t in two)
        return [d, largest, back, f"{len(two) - culprits} of {len(two)}", "met" if not culprits else "**missed**"]

    return markdown_table(["detector", 'longest return to "no fault" after a loss ends',
                           f"within {RETURN_TARGET_S:g} s", "two losses: unexplained or ambiguous",
                           "never a single culprit"], [row(d) for d in c["detectors"]])


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
    return f"""### After a loss ends, and two losses at once

Losses of 5 % to 80 % (case `{ENDING}`: on from 40 s to 70 s) -- how long after the loss ends an alarm
still stands ("released before the end": the detector had let the loss go while it lasted):

{markdown_table(["loss (delivered fraction)"] + detectors, rows)}

Both thrusters losing (case `{BOTH}`; the banks model one faulty thruster at a time) -- what each
detector holds at the end of the run (a single thruster named is a wrong culprit):

{markdown_table(["faults"] + detectors, both)}

{_verdicts(c)}
"""


def _alarms_by_noise(c: dict) -> str:
    """The false alarms by sensor noise: per level and detector the count, hours and rate (with its 95 % bound
    when none was seen), under each detector's designed rate."""
    detectors, designed = list(c["detectors"]), c["designed_false_alarms_per_hour"]

    def cell(per: dict) -> str:
        bound = f" (< {NONE_SEEN_95 / per['healthy_hours']:.3g} /h, 95 %)" if not per["false_alarms"] else ""
        return f"{per['false_alarms']} in {_f(per['healthy_hours'])} h: {_f(per['false_alarms_per_hour'])} /h{bound}"

    rows = [["designed"] + ["none (a posterior threshold)" if designed[d] is None else f"at most {designed[d]:g} /h"
                            for d in detectors]]
    rows += [[noise] + [cell(per[d]) for d in detectors] for noise, per in c["healthy_by_noise"].items()]
    return markdown_table(["noise"] + detectors, rows)


def campaign_section(c: dict) -> str:
    """The report's campaign section from :func:`run_study_campaign`'s figures."""
    detectors = list(c["detectors"])
    overall = [[d, _f(r["detection_probability"]), r["missed_detections"], _f(r["median_detection_delay_s"]),
                _f(r["correct_isolation"]), _f(r["median_size_error_rel"]), r["false_alarms"],
                _f(r["healthy_hours"]), _f(r["false_alarms_per_hour"])] for d, r in c["detectors"].items()]
    cases = [[case] + [f"{_f(per[d]['detection_probability'], 2)} / {_f(per[d]['median_detection_delay_s'])} / "
                       f"{_f(per[d]['correct_isolation'], 2)} / {per[d]['false_alarms']}" for d in detectors]
             for case, per in c["cases"].items()]
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
while the sensors are as noisy as R says. The evidence rule's designed rate stands above its measured
ones in the table of false alarms by sensor noise (`unexplained` is not counted as an alarm).

{markdown_table(["detector", "detection probability", "missed", "median delay (s)", "correct isolation",
                 "median size error", "false alarms", "healthy hours", "false alarms per hour"], overall)}

Per case (detection probability / median delay s / correct isolation / false alarms):

{markdown_table(["case"] + detectors, cases)}

False alarms by sensor noise (a multiple of the paper's; the banks keep the paper's R unless told),
over the healthy runs and the stretches before each onset:

{_alarms_by_noise(c)}

{_returns_section(c)}

Where the banks fail (faulty runs on which a detector missed, ended on the wrong thruster, or sized
the loss more than {SIZE_TOLERANCE:g} off; computed from the runs above):

{markdown_table(["case", "fault", "noise", "what went wrong", "detectors"], failures) if failures else "none."}

Every run's row is in [campaign_results.csv](campaign_results.csv).
"""


def _grouped(per: dict[str, str]) -> str:
    """``d1, d2: text; d3: other`` from detector -> text, detectors of equal text together, empty texts left out."""
    groups: dict[str, list[str]] = {}
    for d, text in per.items():
        if text:
            groups.setdefault(text, []).append(d)
    return "; ".join(f"{', '.join(names)}: {text}" for text, names in groups.items()) or "none"


def _ended_losses(c: dict, keep) -> str:
    """Per detector the losses that end (thruster and % of the command) whose run ``keep(run)`` accepts."""
    return _grouped({d: ", ".join(f"{run['thruster']} {100 * (1 - run['value']):g} %" for run in r["runs"] if keep(run))
                     for d, r in c["returns"].items()})


def limits_section(c: dict) -> str:
    """The measured limits from :func:`run_study_campaign`'s figures, as the block the doc page includes."""
    detectors, designed = list(c["detectors"]), c["designed_false_alarms_per_hour"]
    channels = [[d, row[0], *row[2:]]  # row[1], the kind: proportional in every row
                for d in detectors for row in limits_table(c["limits"][d], "%")]
    overall = _grouped({d: f"{_f(r['detection_probability'])} / {_f(r['median_detection_delay_s'])} s"
                        for d, r in c["detectors"].items()})
    above, unconfirmed = {d: [] for d in detectors}, {d: [] for d in detectors}
    for noise, per in c["healthy_by_noise"].items():
        for d in detectors:
            rate, hours = per[d]["false_alarms_per_hour"], per[d]["healthy_hours"]
            if designed[d] is None or not hours:
                continue
            if rate > designed[d]:
                above[d].append(f"{noise} ({_f(rate)} /h)")
            elif not per[d]["false_alarms"] and NONE_SEEN_95 / hours > designed[d]:
                unconfirmed[d].append(f"{noise} ({_f(hours)} h)")
    above, unconfirmed = (_grouped({d: ", ".join(levels) for d, levels in found.items()})
                          for found in (above, unconfirmed))
    undesigned = ", ".join(d for d in detectors if designed[d] is None)
    held = _ended_losses(c, lambda run: run["return_s"] is None or run["return_s"] > RETURN_TARGET_S)
    let_go = _ended_losses(c, lambda run: run["detected"] and run["return_s"] == 0.0)
    noisy = c["cases"][NOISIER]
    noisy_detected = _grouped({d: _f(noisy[d]["detection_probability"]) for d in detectors})
    noisy_unexplained = _grouped({d: f"{noisy[d]['unexplained_runs']} of {noisy[d]['fault_runs']} runs"
                                  if noisy[d]["unexplained_runs"] else "" for d in detectors})
    stuck_faults: dict[str, list[str]] = {}
    for f in c["failures"]:
        if f["case"] == STUCK:
            stuck_faults.setdefault(f"{f['thruster']} stuck at {f['value']:g} N", []).append(
                f"{f['problem']} ({', '.join(f['detectors'])})")
    stuck = "; ".join(f"{fault}: {', '.join(problems)}" for fault, problems in stuck_faults.items())
    return limits_block(f"""Smallest loss detected, per thruster: the step losses at the paper's sensor noise (cases
`{STEP}` and `{ENDING}`), a loss in % of the command. Each size ran in the runs its cell counts, so "detected
in every run from" brackets the smallest detectable loss between the sizes tried; the campaign does not search
below them.

{markdown_table(["detector", "thruster", "losses tried (%): detected / runs", "detected in every run from",
                 "missed at", "median delay (s)"], channels)}

Over every faulty run of the campaign (every profile and noise level), detection probability / median delay:
{overall}.

False alarms per hour on the healthy runs and before each onset, by sensor noise (a multiple of the paper's;
the banks keep the paper's R unless told), each rate beside the healthy hours it rests on, under the designed
rate:

{_alarms_by_noise(c)}

Measured above the designed rate: {above}. None seen but too few healthy hours to confirm the designed rate at
95 %: {unconfirmed}. No rate is designed into {undesigned}: the threshold is a posterior probability of
likelihoods that carry R, so their rates hold only while the sensors are as noisy as R says.

After a loss ends (case `{ENDING}`), and two thrusters losing at once (case `{BOTH}`):

{_verdicts(c)}

Still alarmed more than {RETURN_TARGET_S:g} s after the loss ended, or to the end of the run: {held}. A fault
model whose efficiency estimate is near 1 explains healthy data about as well as the no-fault model, so after
a small loss the posterior has little evidence to move back. Let go while the loss lasted (released on a stretch
the no-fault model explains as well): {let_go}.

What the banks cannot see, and why:

- two thrusters losing at once: the banks model one faulty thruster at a time, so a rule that must name one
  names a wrong culprit (table above);
- sensors noisier than the banks' R (case `{NOISIER}`): detection probability {noisy_detected};
  `unexplained` (no model fits the innovations, no culprit named) in {noisy_unexplained};
- a thruster stuck at a thrust (case `{STUCK}`): {stuck or "every detector named the stuck thruster"}; the
  banks model a thruster delivering a fraction of its command, not a thrust of its own;
- by construction, a loss while the thruster's command is near zero: the efficiency multiplies the command,
  so nothing measured changes.""")
