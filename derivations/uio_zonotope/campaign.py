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
from uvsym.campaign.limits import channel_limits, limits_table
from uvsym.campaign.summary import detector_rates
from uvsym.progress import ProgressBar

__all__ = ["CAMPAIGN", "DETECTOR", "campaign_results", "metrics", "section"]

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


def section(c: dict, scenarios: dict) -> str:
    """The report's campaign section (markdown) from :func:`campaign_results`'s figures and the shipped
    scenarios' decision logs (name -> events)."""
    from uvsym.report import markdown_table

    cases = [_row(key.split("|"), v) for key, v in c["by_case_and_noise"].items()]
    sizes = [_row([size], v) for size, v in c["abrupt_by_size"].items()]
    rates = [_row([rate], v) for rate, v in c["drift_by_rate"].items()]
    detected = min((float(k) for k, v in c["abrupt_by_size"].items() if v["detection_probability"] == 1.0),
                   default=float("nan"))
    isolated = min((float(k) for k, v in c["abrupt_by_size"].items() if v["correct_isolation"] == 1.0),
                   default=float("nan"))
    groups = c["by_case_and_noise"]
    below = [v for k, v in c["abrupt_by_size"].items() if float(k) < isolated and v["detection_probability"]]
    ambiguous = _cell(sum(v["ambiguous"] * v["runs"] for v in below)
                      / sum(v["detection_probability"] * v["runs"] for v in below)) if below else "-"
    beyond = [(level, groups[f"no fault, noise beyond the bound|{level}"],
               groups.get(f"abrupt, noise beyond the bound|{level}")) for level in ("2", "3")]
    noisy = "; ".join(f"at {level} times the bound a fraction {_cell(h['healthy_runs_alarmed'])} of the healthy runs "
                      f"alarm (median first alarm at {_cell(h['median_first_false_alarm_s'])} s) and the faults of "
                      f"{f['runs']} runs are detected in their window with probability "
                      f"{_cell(f['detection_probability'])}" for level, h, f in beyond)
    designed = [v for k, v in groups.items() if k.endswith("|1") and not k.startswith(("no fault", "nonlinear"))]
    wrong = sum(v["wrong_isolation"] * v["runs"] for v in designed)
    nonlinear = groups["nonlinear plant, abrupt|1"]
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

Per rotor at the designed noise (sizes tried: detected / runs; "detected in every run from": the
smallest size detected in every run of it and of every larger size; delays from the onset):

{markdown_table(["rotor", "fault kind", "sizes tried (V): detected / runs", "detected in every run from", "missed at",
                 "median delay (s)"], limits_table(c["limits"]["abrupt"], "V"))}

{markdown_table(["rotor", "fault kind (a ramp)", "rates tried (V/s): detected / runs", "detected in every run from",
                 "missed at", "median delay (s)"], limits_table(c["limits"]["drift"], "V/s"))}

Where the method fails:

- Small faults are not seen: every abrupt fault is detected from {detected:g} V on
  (of {', '.join(c['abrupt_by_size'])} V); below, the fault stays inside the bands, whose width is set by the
  worst-case noise, not by its typical size. Slow drifts likewise wait until they have grown to the
  band's width (the delays above).
- Isolation needs large faults: the bank isolates the right rotor in every run only from
  {isolated:g} V on; of the detected faults below that, a fraction {ambiguous} end ambiguous: the observer of
  the other rotor of the same pair (front and back, right and left: their columns differ mainly in the
  sign of one torque) stays inside its band for the whole isolation window. At the designed noise the
  bank named the wrong rotor in {wrong:.0f} of {sum(v["runs"] for v in designed)} fault runs (the "wrong rotor"
  column).
- The bands hold only for noise within the stated bound, and there is no threshold to trade: the
  designed false-alarm rate is zero for noise within the bound (the bands enclose every healthy residual,
  Machine-checked claims), and at the designed noise {_cell(groups['no fault|1']['false_alarms'])} false alarms in
  {_cell(groups['no fault|1']['healthy_hours'])} h of healthy runs; {noisy}. A false alarm before the onset
  latches (the residuals keep leaving their bands), so the fault itself is missed.
- The nonlinear quadrotor (the registered plant, the bank keeping its linear design at hover): of
  {nonlinear['runs']} abrupt faults the detection probability is {_cell(nonlinear['detection_probability'])},
  correct isolation {_cell(nonlinear['correct_isolation'])}, ambiguous {_cell(nonlinear['ambiguous'])}, unexplained
  {_cell(nonlinear['unexplained'])} and the wrong rotor {_cell(nonlinear['wrong_isolation'])}: away from hover the
  model mismatch moves the residuals of the observers that should stay inside.

Every per-run row is in [campaign_results.csv](campaign_results.csv).
"""
