"""A campaign's summary (``summary.json``) and report (``report.md``, ``report.html``, SVG figures).

Rates are fractions of the runs that finished without error: detection and isolation rates over
the runs with a fault, the false-alarm rate (runs with at least one false alarm) over all. The
confusion matrix counts true fault target (actuator or sensor; "none" without a fault) against
the final isolated actuator ("none" without one). ROC: one point (false-alarm rate, detection
probability) per value of the ``roc_by`` fields, e.g. a swept diagnosis threshold, for all
detectors together and for each detector.

Per detector D (the runs' ``D:<metric>`` columns): detection probability and missed detections
over the runs with a fault, median detection and isolation delays (s), correct isolation (the
true target isolated within the fault's window), median identification error, and false alarms per
hour of healthy time (the whole run without a fault, the time before the onset with one); its
decision CPU time per simulated hour (processor time of its decisions on the records), and the
wall time per simulated hour of the whole runs (simulation, estimators and every detector).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from uvsym.report.html import write_html
from uvsym.report.markdown import markdown_table, write_json

__all__ = ["summarize", "write_report", "detector_names", "detector_rates"]

_NO_EVENTS = ("\nNo run logged a diagnosis event (a scenario needs a [diagnosis] table or [[detectors]] for its event "
              "log): the "
              "rates above count no detection, isolation or alarm.\n")
_DISTRIBUTIONS = ("detection_delay_s", "isolation_delay_s", "size_error_rel", "path_error_rms_m", "wall_s")


def _rate(rows: list[dict], test) -> float | None:
    return sum(bool(test(r)) for r in rows) / len(rows) if rows else None


def _target(row: dict) -> str:
    return row.get("true_actuator") or row.get("true_sensor") or "none"


def _quantiles(values) -> dict:
    data = np.array([v for v in values if v is not None and math.isfinite(v)], dtype=float)
    if not data.size:
        return {"n": 0}
    p10, median, p90 = np.quantile(data, [0.1, 0.5, 0.9])
    return {"n": int(data.size), "min": float(data.min()), "p10": float(p10), "median": float(median),
            "p90": float(p90), "max": float(data.max()), "mean": float(data.mean())}


def _rates(rows: list[dict]) -> dict:
    ok = [r for r in rows if r["status"] == "ok"]
    faulty = [r for r in ok if r["n_faults"]]
    return {"runs": len(rows), "ok": len(ok), "errors": len(rows) - len(ok), "fault_runs": len(faulty),
            "no_fault_runs": len(ok) - len(faulty), "runs_with_events": sum(bool(r["events"]) for r in ok),
            "detection_rate": _rate(faulty, lambda r: r["detected"]),
            "isolation_rate": _rate(faulty, lambda r: r["isolated_target"] == _target(r)),
            "false_alarm_rate": _rate(ok, lambda r: r["false_alarms"]),
            "ambiguous_rate": _rate(ok, lambda r: r["ambiguous"]),
            "unexcited_rate": _rate(ok, lambda r: r["unexcited"])}


def detector_names(rows: list[dict]) -> list[str]:
    """The detectors whose columns (``D:detected``) the rows hold, in first-seen order."""
    return list(dict.fromkeys(key[:-len(":detected")] for row in rows for key in row if key.endswith(":detected")))


def _median(values) -> float | None:
    data = [v for v in values if v is not None and math.isfinite(v)]
    return float(np.median(data)) if data else None


def detector_rates(rows: list[dict], name: str) -> dict:
    """The per-detector figures of the module docstring for detector ``name`` over ``rows``."""
    ok = [r for r in rows if r["status"] == "ok" and f"{name}:detected" in r]
    faulty = [r for r in ok if r["n_faults"]]
    healthy_s = sum(r["onset_s"] if r["n_faults"] and r["onset_s"] is not None else (r.get("duration_s") or 0.0)
                    for r in ok)
    simulated_s = sum(r.get("duration_s") or 0.0 for r in ok)
    alarms = sum(r[f"{name}:false_alarms"] or 0 for r in ok)
    return {"runs": len(ok), "fault_runs": len(faulty),
            "detection_probability": _rate(faulty, lambda r: r[f"{name}:detected"]),
            "missed_detections": sum(not r[f"{name}:detected"] for r in faulty),
            "median_detection_delay_s": _median(r[f"{name}:detection_delay_s"] for r in faulty),
            "median_isolation_delay_s": _median(r[f"{name}:isolation_delay_s"] for r in faulty),
            "correct_isolation": _rate(faulty, lambda r: r[f"{name}:isolation_delay_s"] is not None),
            "median_size_error_rel": _median(r[f"{name}:size_error_rel"] for r in faulty),
            "false_alarms": alarms, "healthy_hours": healthy_s / 3600.0,
            "false_alarms_per_hour": alarms / (healthy_s / 3600.0) if healthy_s > 0 else None,
            "wall_s_per_simulated_hour": (sum(r["wall_s"] for r in ok) / simulated_s * 3600.0) if simulated_s else None,
            "decision_cpu_s_per_simulated_hour": _per_hour([r.get(f"{name}:decision_cpu_s") for r in ok], simulated_s)}


def _per_hour(seconds: list, simulated_s: float) -> float | None:
    """Seconds per simulated hour of the runs that measured them (None when none did)."""
    measured = [s for s in seconds if s is not None and math.isfinite(s)]
    return sum(measured) / simulated_s * 3600.0 if measured and simulated_s else None


def summarize(rows: list[dict], name: str, total_runs: int, roc_by: tuple[str, ...] = ()) -> dict:
    """The summary of a campaign's result rows (module docstring); ``total_runs``: how many it has."""
    ok = [r for r in rows if r["status"] == "ok"]
    confusion: dict[str, dict[str, int]] = {}
    for row in ok:
        cell = confusion.setdefault(_target(row), {})
        isolated = row["isolated_target"] or "none"
        cell[isolated] = cell.get(isolated, 0) + 1
    groups: dict[tuple, list[dict]] = {}
    for row in rows:
        groups.setdefault(tuple(row.get(c) for c in roc_by), []).append(row)
    detectors = detector_names(rows)
    roc = [{"group": dict(zip(roc_by, key)), "runs": rates["runs"], "detection_probability": rates["detection_rate"],
            "false_alarm_rate": rates["false_alarm_rate"],
            "detectors": {d: _detector_roc(members, d) for d in detectors}}
           for key, rates, members in ((key, _rates(members), members) for key, members in groups.items())]
    cases: dict[str, list[dict]] = {}
    for row in rows:
        cases.setdefault(row["case"], []).append(row)
    return {"campaign": name, "total_runs": total_runs, **_rates(rows),
            "confusion": {true: dict(sorted(cell.items())) for true, cell in sorted(confusion.items())},
            **{column: _quantiles(r[column] for r in ok) for column in _DISTRIBUTIONS},
            "roc_by": list(roc_by), "roc": roc, "cases": {case: _rates(members) for case, members in cases.items()},
            "detectors": {d: detector_rates(rows, d) for d in detectors}}


def _detector_roc(rows: list[dict], name: str) -> dict:
    """One ROC point of detector ``name``: detection probability over the runs with a fault, and the
    fraction of runs with a false alarm."""
    ok = [r for r in rows if r["status"] == "ok" and f"{name}:detected" in r]
    return {"detection_probability": _rate([r for r in ok if r["n_faults"]], lambda r: r[f"{name}:detected"]),
            "false_alarm_rate": _rate(ok, lambda r: r[f"{name}:false_alarms"])}


def _shown(value) -> str:
    return "-" if value is None else f"{value:.3g}"


def _label(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _figures(folder: Path, summary: dict, rows: list[dict]) -> None:
    """confusion.svg, roc.svg and delays.svg in uvsym's figure style (:mod:`uvsym.report.style`)."""
    from uvsym.report.figures import figure_style, plt, save_svg  # here: a campaign's worker processes never draw
    from uvsym.report.style import confusion_matrix, delay_histograms, roc_curves

    with figure_style():
        labels_true = list(summary["confusion"])
        labels_isolated = sorted({k for cell in summary["confusion"].values() for k in cell})
        fig, ax = plt.subplots(figsize=(2.6 + 0.5 * max(len(labels_isolated), 2), 1.6 + 0.4 * max(len(labels_true), 2)))
        if labels_true:
            counts = np.array([[summary["confusion"][t].get(i, 0) for i in labels_isolated] for t in labels_true])
            confusion_matrix(ax, counts, labels_true, labels_isolated, "true fault target", "isolated target")
        else:
            ax.text(0.5, 0.5, "no run finished", ha="center", va="center", transform=ax.transAxes)
            ax.set_axis_off()
        ax.set_title("Confusion matrix (runs)")
        save_svg(fig, folder / "confusion.svg")

        fig, ax = plt.subplots(figsize=(6.5, 4.2))
        curves, labels = {}, {}
        for name, rates in [("all detectors", lambda p: p)] + [(d, lambda p, d=d: p["detectors"][d])
                                                               for d in summary["detectors"]]:
            points = sorted((rates(p)["false_alarm_rate"], rates(p)["detection_probability"],
                             ", ".join(map(_label, p["group"].values()))) for p in summary["roc"]
                            if rates(p)["detection_probability"] is not None
                            and rates(p)["false_alarm_rate"] is not None)
            curves[name] = ([q[0] for q in points], [q[1] for q in points])
            labels[name] = [q[2] for q in points]
        roc_curves(ax, curves, labels if summary["roc_by"] else None)
        ax.set_title("ROC" + (f" over {', '.join(summary['roc_by'])}" if summary["roc_by"] else ""))
        save_svg(fig, folder / "roc.svg")

        ok = [r for r in rows if r["status"] == "ok"]
        names = summary["detectors"] or [None]
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.4), squeeze=False)
        for ax, column, what in zip(axes[0], ("detection_delay_s", "isolation_delay_s"),
                                    ("detection delay after the onset", "isolation delay after the onset")):
            delays = {name or "all detectors": [r.get(column if name is None else f"{name}:{column}") for r in ok]
                      for name in names}
            seen = [v for vs in delays.values() for v in vs if v is not None]
            width = max(float(np.ptp(seen)) / 20, 0.05) if seen else 1.0
            delay_histograms(ax, delays, bin_width=float(f"{width:.1g}"), unit="s", what=what)
        save_svg(fig, folder / "delays.svg")


def write_report(folder, summary: dict, rows: list[dict], description: str = "") -> Path:
    """Write summary.json, the figures, report.md and report.html into ``folder``; the report's path."""
    folder = Path(folder)
    write_json(folder / "summary.json", summary)
    _figures(folder, summary, rows)
    rates = [[key.replace("_", " "), _shown(summary[key])] for key in
             ("detection_rate", "isolation_rate", "false_alarm_rate", "ambiguous_rate", "unexcited_rate")]
    labels = sorted({k for cell in summary["confusion"].values() for k in cell})
    confusion = markdown_table(["true \\ isolated", *labels], [[true, *(cell.get(k, 0) for k in labels)]
                                                               for true, cell in summary["confusion"].items()])
    spread = markdown_table(["metric", "n", "min", "p10", "median", "p90", "max"],
                            [[column, summary[column]["n"], *(_shown(summary[column].get(k))
                                                              for k in ("min", "p10", "median", "p90", "max"))]
                             for column in _DISTRIBUTIONS])
    roc = markdown_table([*(summary["roc_by"] or ["group"]), "runs", "false-alarm rate", "detection probability"],
                         [[*(p["group"].values() if p["group"] else ["all"]), p["runs"], _shown(p["false_alarm_rate"]),
                           _shown(p["detection_probability"])] for p in summary["roc"]])
    cases = markdown_table(["case", "runs", "ok", "errors", "detection rate", "false-alarm rate"],
                           [[case, c["runs"], c["ok"], c["errors"], _shown(c["detection_rate"]),
                             _shown(c["false_alarm_rate"])] for case, c in summary["cases"].items()])
    per_detector = markdown_table(
        ["detector", "runs", "detection probability", "missed", "median delay (s)", "correct isolation",
         "median isolation delay (s)", "false alarms per hour", "healthy hours", "decision CPU s per simulated hour",
         "run wall s per simulated hour"],
        [[d, f["runs"], _shown(f["detection_probability"]), f["missed_detections"],
          _shown(f["median_detection_delay_s"]), _shown(f["correct_isolation"]), _shown(f["median_isolation_delay_s"]),
          _shown(f["false_alarms_per_hour"]), _shown(f["healthy_hours"]),
          _shown(f["decision_cpu_s_per_simulated_hour"]), _shown(f["wall_s_per_simulated_hour"])]
         for d, f in summary["detectors"].items()])
    detectors = f"## Detectors side by side\n\n{per_detector}\n" if summary["detectors"] else ""
    errors = [r for r in rows if r["status"] != "ok"]
    error_list = "\n".join(f"- `{r['run_id']}` ({r['case']}): {r['error']}" for r in errors[:20]) or "- none"
    if len(errors) > 20:
        error_list += f"\n- and {len(errors) - 20} more (results.csv, column error)"
    text = f"""# Campaign {summary['campaign']}

{description}

{summary['runs']} of {summary['total_runs']} runs finished: {summary['ok']} ok, {summary['errors']} with an error;
{summary['fault_runs']} with a fault, {summary['no_fault_runs']} without. Every run is a row of
[results.csv](results.csv) and [results.parquet](results.parquet); the figures below are in
[summary.json](summary.json).

{markdown_table(["rate", "value"], rates)}
{"" if summary["runs_with_events"] else _NO_EVENTS}
{detectors}
## Cases

{cases}

## Confusion matrix

{confusion}

![confusion matrix](confusion.svg)

## ROC

{roc}

![ROC](roc.svg)

## Delays and errors

{spread}

![delay histograms](delays.svg)

## Runs that failed

{error_list}
"""
    (folder / "report.md").write_text(text)
    write_html(folder)
    return folder / "report.md"
