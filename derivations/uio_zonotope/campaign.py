"""The report's campaign (``campaign.toml`` beside this file): the zonotope_bands detector over what a
user meets, run by :func:`uvsym.campaign.run_campaign` (the same file ``uvsym campaign`` runs).

Every figure is the per-detector summary of :func:`uvsym.campaign.summary.detector_rates` over a
group of runs: by case and noise level (the noise bound of the run over the bound the bands are
designed for), and for the abrupt and drift cases at the designed noise, by fault size.
"""

from __future__ import annotations

import csv
import tempfile
from pathlib import Path

import numpy as np

from uvsym.campaign import load_campaign, run_campaign
from uvsym.campaign.limits import NONE_SEEN_95, channel_limits, every_size_from, limits_table
from uvsym.campaign.summary import detector_rates
from uvsym.progress import ProgressBar
from uvsym.report import limits_block, markdown_table

__all__ = ["CAMPAIGN", "DETECTOR", "campaign_results", "limits_section", "metrics", "section"]

CAMPAIGN = Path(__file__).with_name("campaign.toml")
DETECTOR = "bands"  # the detector of the shipped scenarios
DECISIONS = ("isolated", "ambiguous", "unexplained")
DRIFT_S = 3.0  # s: the drift case's ramp duration (campaign.toml), its rate = value / DRIFT_S
DESIGNED_W = 0.02  # m/s: the w noise bound of the scenarios (and of the bands); a run's over it is its noise level
# the per-run columns of campaign_results.csv (the run's wall time is left out: the file stays the same)
COLUMNS = ("case", "true_actuator", "true_kind", "true_value", "onset_s", "noise_level", "seed", "duration_s",
           f"{DETECTOR}:detected", f"{DETECTOR}:detection_delay_s", f"{DETECTOR}:isolated_target",
           f"{DETECTOR}:isolation_delay_s", f"{DETECTOR}:false_alarms", "first_alarm_s", "decision", "status",
           "error")


def _level(row: dict) -> float:
    """The run's noise bound in units of the designed bound (1 where the case keeps the scenario's)."""
    w = row.get("noise.w.uniform")
    return 1.0 if w is None else round(w / DESIGNED_W, 6)


def metrics(scenario, result, events) -> dict:
    """The campaign's extra columns (its ``metrics`` hook): ``first_alarm_s``, the first detection of
    the run (s); ``decision``, the first isolation decision at or after the fault's onset (the whole
    run without a fault): ``isolated <rotor>``, ``ambiguous``, ``unexplained`` or ``none``."""
    onset = min((f.profile.onset for f in scenario.actuator_faults), default=0.0)
    mine = [e for e in events if e["detector"] == DETECTOR]
    first = next((e["t"] for e in mine if e["event"] == "detected"), None)
    decision = next((e for e in mine if e["event"] in DECISIONS and e["t"] >= onset), None)
    return {"first_alarm_s": first, "decision": "none" if decision is None else
            f"isolated {decision['target']}" if decision["event"] == "isolated" else decision["event"]}


def _share(rows: list[dict], test) -> float | None:
    return sum(bool(test(r)) for r in rows) / len(rows) if rows else None


def _figures(rows: list[dict]) -> dict:
    rates = detector_rates(rows, DETECTOR)
    for timing in ("wall_s_per_simulated_hour", "decision_cpu_s_per_simulated_hour"):
        rates.pop(timing)  # timings: the report's figures stay those of the runs
    faulty = [r for r in rows if r["n_faults"]]
    healthy = [r for r in rows if not r["n_faults"]]
    rates |= {kind: _share(faulty, lambda r, kind=kind: r["decision"] == kind) for kind in ("ambiguous", "unexplained")}
    rates["wrong_isolation"] = _share(faulty, lambda r: r["decision"].startswith("isolated ")
                                      and r["decision"] != f"isolated {r['true_actuator']}")
    rates["healthy_runs_alarmed"] = _share(healthy, lambda r: r["first_alarm_s"] is not None)
    first = sorted(r["first_alarm_s"] for r in healthy if r["first_alarm_s"] is not None)
    rates["median_first_false_alarm_s"] = float(np.median(first)) if first else None
    return rates


def _groups(rows: list[dict], key) -> dict:
    groups: dict = {}
    for row in rows:
        groups.setdefault(key(row), []).append(row)
    return {k: _figures(members) for k, members in groups.items()}


def campaign_results(out_dir: Path, progress, workers: int | None = None) -> dict:
    """Run the campaign; write campaign_results.csv into out_dir; return its figures (module docstring)."""
    campaign = load_campaign(CAMPAIGN)
    progress(f"campaign: {len(campaign.runs)} runs of {CAMPAIGN.name}")
    with tempfile.TemporaryDirectory(prefix="uvsym-campaign-") as scratch:
        rows = run_campaign(campaign, Path(scratch) / "campaign", executor="local", workers=workers,
                            progress=ProgressBar(f"  {campaign.name}", unit="runs")).to_pylist()
    for row in rows:
        row["noise_level"] = _level(row)
    with open(out_dir / "campaign_results.csv", "w", newline="") as handle:
        writer = csv.DictWriter(handle, COLUMNS, extrasaction="ignore")
        writer.writeheader()
        writer.writerows({c: f"{v:.6g}" if isinstance(v := row.get(c), float) else v for c in COLUMNS} for row in rows)
    designed = [r for r in rows if r["noise_level"] == 1.0]
    return {"runs": len(rows), "errors": sum(r["status"] != "ok" for r in rows),
            "healthy_hours": sum(r["duration_s"] for r in rows if not r["n_faults"]) / 3600.0,
            "all": _figures(rows),
            "by_case_and_noise": {f"{case}|{level:g}": v for (case, level), v in
                                  _groups(rows, lambda r: (r["case"], r["noise_level"])).items()},
            "abrupt_by_size": {f"{size:g}": v for (case, size), v in
                               _groups([r for r in designed if r["case"] == "abrupt"],
                                       lambda r: (r["case"], r["true_value"])).items()},
            "drift_by_rate": {f"{size / DRIFT_S:g}": v for (case, size), v in
                              _groups([r for r in designed if r["case"] == "drift"],
                                      lambda r: (r["case"], r["true_value"])).items()},
            "limits": {"abrupt": channel_limits(designed, DETECTOR, cases=["abrupt"]),
                       "drift": channel_limits(designed, DETECTOR, cases=["drift"],
                                               size=lambda r: abs(r["true_value"]) / DRIFT_S)}}


def _cell(value, digits: int = 3) -> str:
    return "-" if value is None else f"{value:.{digits}g}" if isinstance(value, float) else str(value)


def _row(label: list, v: dict) -> list:
    return label + [v["runs"], _cell(v["detection_probability"]), v["missed_detections"],
                    _cell(v["median_detection_delay_s"]), _cell(v["correct_isolation"]), _cell(v["ambiguous"]),
                    _cell(v["unexplained"]), _cell(v["wrong_isolation"]), _cell(v["median_isolation_delay_s"]),
                    _cell(v["false_alarms_per_hour"]), _cell(v["healthy_hours"])]


HEADER = ["runs", "detection probability", "missed", "median detection delay (s)", "correct isolation",
          "ambiguous", "unexplained", "wrong rotor", "median isolation delay (s)", "false alarms per hour",
          "healthy hours"]


def section(c: dict, scenarios: dict, bands_proved: int, observers: int) -> str:
    """The report's campaign section (markdown) from :func:`campaign_results`'s figures, the shipped
    scenarios' decision logs (name -> events) and how many of the observers' bands the claims proved."""
    cases = [_row(key.split("|"), v) for key, v in c["by_case_and_noise"].items()]
    sizes = [_row([size], v) for size, v in c["abrupt_by_size"].items()]
    rates = [_row([rate], v) for rate, v in c["drift_by_rate"].items()]
    logs = [[name, "; ".join(f"{e['event']} {e['target'] or ''} at {e['t']:g} s".replace("  ", " ") for e in events)]
            for name, events in scenarios.items()]
    return f"""## Scenario files and the campaign

The study's experiments ship as scenario files (`uvsym simulate abrupt_actuator1`,
`uvsym simulate drift_actuator2`): the study's plant (`derivations.uio_zonotope.design:hover_plant`),
an `lqr` block, the `uio_bank` block (one observer per rotor, F's eigenvalues from the file) and the
`zonotope_bands` detector (bands from the stated noise and initial-error bounds). On the same draws
they give the study code's states and residuals to 1e-9 and its alarm sample and isolated rotor
(tests/test_uio_zonotope_scenarios.py). Two draws differ from the study's runs: the files' noise is
uniform in its box (`[noise]` entries `{{ uniform = bound }}`), where the study also draws every fourth
run on the box's vertices; and the files' yaw torque is constant (`[initial] d`), where the study's is
a sinusoid plus a random walk. Every observer decouples the yaw torque exactly, so the residuals do not
depend on it (tested). Their decision logs:

{markdown_table(["scenario", "events"], logs)}

The campaign ([campaign.toml](../../derivations/uio_zonotope/campaign.toml); `uvsym campaign
derivations/uio_zonotope/campaign.toml` runs the same file) has {c['runs']} runs ({c['errors']} ending in an
error), {c['healthy_hours']:.3g} h of them without a fault. Noise is uniform in its box at the bound the bands are
designed for (noise level 1) or at 2 and 3 times it, the detector keeping the designed bound. A false
alarm is an alarm (detected or isolated) outside a fault's window (before its onset, or in a run without
a fault); correct isolation: the faulty rotor isolated in the window; "ambiguous or unexplained": a
detected fault whose window left several observers inside (ambiguous) or none (unexplained).

By case and noise level:

{markdown_table(["case", "noise level"] + HEADER, cases)}

Abrupt faults at the designed noise, by size (V):

{markdown_table(["size (V)"] + HEADER, sizes)}

Drifts at the designed noise, by rate (V/s):

{markdown_table(["rate (V/s)"] + HEADER, rates)}

Every per-run row is in [campaign_results.csv](campaign_results.csv).

{limits_section(c, bands_proved, observers)}
"""


def _delays(by_size: dict, seen: float | None, unit: str) -> str:
    """The median detection delay at the size ``seen`` (from which every rotor is detected) and at the largest."""
    ends = ([] if seen is None else [f"{seen:g}"]) + [max(by_size, key=float)]
    return " to ".join(f"{_cell(by_size[k]['median_detection_delay_s'])} s at {k} {unit}" for k in dict.fromkeys(ends))


def _missed(limits: list[dict], unit: str) -> str:
    """The largest size missed in some run of some rotor."""
    missed = [item["missed_up_to"] for item in limits if item["missed_up_to"] is not None]
    return f"up to {max(missed):g} {unit}" if missed else "of no size tried"


def _designed_rate(healthy: dict, proved: bool = True) -> str:
    """What the fault-free runs measure beside the 0 per hour the bands guarantee (``proved``: by the claims,
    for the shipped bound; else by the design's construction alone)."""
    alarms, hours = healthy["false_alarms"], healthy["healthy_hours"]
    zero, agrees = ("the 0 proved", "as proved") if proved else ("the 0 of the design", "as designed")
    if alarms:
        return (f"{alarms} false alarms in {hours:.3g} h ({_cell(healthy['false_alarms_per_hour'])} per hour): "
                f"**not {zero}**")
    return (f"0 false alarms in {hours:.3g} h, {agrees}; on their own these hours bound the rate only below "
            f"{NONE_SEEN_95 / hours:.2g} per hour (95 %, no event in a Poisson count)")


def _alarms_once(healthy: dict) -> bool:
    """Whether every fault-free run of the group alarms, and once."""
    return healthy["healthy_runs_alarmed"] == 1.0 and healthy["false_alarms"] == healthy["runs"]


def _beyond(level: str, healthy: dict, faulty: dict | None) -> str:
    """What noise at ``level`` times the bound does to the fault-free runs and, if any, to the faults'."""
    runs = "every fault-free run alarms once" if _alarms_once(healthy) else \
        f"a fraction {_cell(healthy['healthy_runs_alarmed'])} of the fault-free runs alarm"
    text = f"at {level} times it {runs}, first at {_cell(healthy['median_first_false_alarm_s'])} s (median)"
    if faulty:
        text += f", and faults are detected in their window with probability {_cell(faulty['detection_probability'])}"
    return text


def _told(groups: dict) -> str:
    """The bullet on the bands designed for twice the bound (the cases ``... bands told twice the bound``)."""
    healthy, faulty = groups.get("no fault, bands told twice the bound|2"), groups.get(
        "abrupt, bands told twice the bound|2")
    if healthy is None:
        return ""
    text = ("- Told the larger bound (the bands designed for twice it, the noise at twice it; the claims prove only "
            f"the shipped bands): {_designed_rate(healthy, proved=False)}")
    if faulty:
        text += (f"; abrupt faults are then detected with probability {_cell(faulty['detection_probability'])} "
                 f"({faulty['fault_runs']} runs, median delay {_cell(faulty['median_detection_delay_s'])} s): the "
                 "wider bands cost the small faults")
    return text + "."


def limits_section(c: dict, bands_proved: int, observers: int) -> str:
    """The report's measured limits (the block the doc page includes) from :func:`campaign_results`'s figures:
    per rotor the smallest abrupt fault and drift detected and the delays, the false alarms per hour within and
    beyond the noise bound beside the proved guarantee, and what the bank cannot see."""
    from derivations.uio_zonotope.design import SAMPLES
    from uvsym.diagnosis.zonotope_bands import HELD_TOLERANCE

    groups, sizes, rates, limits = c["by_case_and_noise"], c["abrupt_by_size"], c["drift_by_rate"], c["limits"]
    seen = {kind: [item["seen_from"] for item in items] for kind, items in limits.items()}
    every = {kind: None if not s or None in s else max(s) for kind, s in seen.items()}  # every rotor detected
    runs = max(n for items in limits.values() for item in items for _, n, _ in item["sizes"])
    isolated = every_size_from(sorted((float(k), v["correct_isolation"] == 1.0) for k, v in sizes.items()))
    below = [v for k, v in sizes.items() if (isolated is None or float(k) < isolated) and v["detection_probability"]]
    ambiguous = _cell(sum(v["ambiguous"] * v["runs"] for v in below)
                      / sum(v["detection_probability"] * v["runs"] for v in below)) if below else "-"
    designed = [v for k, v in groups.items() if k.endswith("|1") and not k.startswith(("no fault", "nonlinear"))]
    wrong = sum(v["wrong_isolation"] * v["runs"] for v in designed)
    healthy = sorted((k.split("|"), v) for k, v in groups.items() if not v["fault_runs"])
    alarms = [[case, level, v["runs"], f"{v['healthy_hours']:.3g}", v["false_alarms"],
               _cell(v["false_alarms_per_hour"]), _cell(v["healthy_runs_alarmed"]),
               _cell(v["median_first_false_alarm_s"])] for (case, level), v in healthy]
    noisy = {level: groups[f"no fault, noise beyond the bound|{level}"] for level in ("2", "3")}
    beyond = "; ".join(_beyond(level, h, groups.get(f"abrupt, noise beyond the bound|{level}"))
                       for level, h in noisy.items())
    if any(_alarms_once(h) for h in noisy.values()):
        beyond += " (where each run alarms once, the per-hour figure counts runs, not hours)"
    nonlinear = groups["nonlinear plant, abrupt|1"]
    return "### Limits (measured by this report's campaign)\n\n" + limits_block(f"""
Smallest fault detected per rotor at the designed noise: each size or rate was tried in {runs} runs per rotor
(onsets drawn), so "detected in every run from" brackets the limit between two sizes tried; delays are
from the onset, median over the detected runs.

{markdown_table(["rotor", "fault kind", "sizes tried (V): detected / runs", "detected in every run from", "missed at",
                 "median delay (s)"], limits_table(limits["abrupt"], "V"))}

{markdown_table(["rotor", "fault kind (a ramp)", "rates tried (V/s): detected / runs", "detected in every run from",
                 "missed at", "median delay (s)"], limits_table(limits["drift"], "V/s"))}

Over the four rotors the median detection delay runs from {_delays(sizes, every["abrupt"], "V")} (abrupt) and
from {_delays(rates, every["drift"], "V/s")} (drifts).

False alarms of the fault-free runs (noise level: the noise bound over the one the shipped bands are designed
for; the detector keeps that bound, but where the case says the bands are told the larger one):

{markdown_table(["case", "noise level", "runs", "hours", "false alarms", "per hour", "runs that alarm",
                 "median first alarm (s)"], alarms)}

- The guarantee: for the linear model, with noise and initial error within their bounds, no healthy residual
  leaves its band. The claims prove it for {bands_proved} of {observers} observers over samples 0 to
  {SAMPLES - 1}; past them the detector holds the last band, what older noise adds staying below
  ||A^{SAMPLES}||_2 < {HELD_TOLERANCE:g} (checked when the detector is built, not proved). So 0 false alarms
  per hour by construction, and no threshold to trade against detection.
- Measured at the designed noise: {_designed_rate(groups["no fault|1"])}. The nonlinear plant's
  {groups["nonlinear plant, no fault|1"]["healthy_hours"]:.2g} h are too few to say anything about its rate.
- Noise beyond the bound voids the guarantee: {beyond}. An alarm before a fault's onset latches (the
  residuals keep leaving their bands), so the fault itself is missed.
{_told(groups)}

What the bank cannot see:

- Abrupt faults {_missed(limits["abrupt"], "V")} and drifts {_missed(limits["drift"], "V/s")} are missed in
  some run: the fault stays inside the bands, whose width is set by the worst-case noise, not by its typical
  size; a drift is seen only once it has grown to that width.
- Which rotor it is, below {_cell(isolated)} V (the size from which the right rotor is isolated in every run): of
  the detected faults below it a fraction {ambiguous} end ambiguous, the observer of the other rotor of the
  same pair (front and back, right and left: their columns differ mainly in the sign of one torque) staying
  inside its band for the whole isolation window. The wrong rotor was named in {wrong:.0f} of
  {sum(v["runs"] for v in designed)} fault runs at the designed noise.
- A fault that acts as a yaw torque alone (front and back rotors up, right and left down, together): every
  observer decouples the yaw disturbance's column by design.
- Model mismatch: on the nonlinear quadrotor (the bank keeping its linear design at hover) {nonlinear["runs"]}
  abrupt faults are detected with probability {_cell(nonlinear["detection_probability"])}, isolated correctly
  in a fraction {_cell(nonlinear["correct_isolation"])}, ambiguous {_cell(nonlinear["ambiguous"])} and
  unexplained {_cell(nonlinear["unexplained"])}: away from hover the residuals of the observers that should
  stay inside move.""")
