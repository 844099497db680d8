"""A campaign's summary (``summary.json``) and report (``report.md``, ``report.html``, SVG figures).

Rates are fractions of the runs that finished without error: detection and isolation rates over
the runs with a fault, the false-alarm rate (runs with at least one false alarm) over all. The
confusion matrix counts true fault target (actuator or sensor; "none" without a fault) against
the final isolated actuator ("none" without one). ROC: one point (false-alarm rate, detection
probability) per value of the ``roc_by`` fields, e.g. a swept diagnosis threshold.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from uvsym.report.html import write_html
from uvsym.report.markdown import markdown_table, write_json

__all__ = ["summarize", "write_report"]

_NO_EVENTS = ("\nNo run logged a diagnosis event (a scenario needs a [diagnosis] table for its event log): the "
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
            "isolation_rate": _rate(faulty, lambda r: r["isolated_actuator"] == _target(r)),
            "false_alarm_rate": _rate(ok, lambda r: r["false_alarms"]),
            "ambiguous_rate": _rate(ok, lambda r: r["ambiguous"]),
            "unexcited_rate": _rate(ok, lambda r: r["unexcited"])}


def summarize(rows: list[dict], name: str, total_runs: int, roc_by: tuple[str, ...] = ()) -> dict:
    """The summary of a campaign's result rows (module docstring); ``total_runs``: how many it has."""
    ok = [r for r in rows if r["status"] == "ok"]
    confusion: dict[str, dict[str, int]] = {}
    for row in ok:
        cell = confusion.setdefault(_target(row), {})
        isolated = row["isolated_actuator"] or "none"
        cell[isolated] = cell.get(isolated, 0) + 1
    groups: dict[tuple, list[dict]] = {}
    for row in rows:
        groups.setdefault(tuple(row.get(c) for c in roc_by), []).append(row)
    roc = [{"group": dict(zip(roc_by, key)), "runs": rates["runs"], "detection_probability": rates["detection_rate"],
            "false_alarm_rate": rates["false_alarm_rate"]}
           for key, rates in ((key, _rates(members)) for key, members in groups.items())]
    cases: dict[str, list[dict]] = {}
    for row in rows:
        cases.setdefault(row["case"], []).append(row)
    return {"campaign": name, "total_runs": total_runs, **_rates(rows),
            "confusion": {true: dict(sorted(cell.items())) for true, cell in sorted(confusion.items())},
            **{column: _quantiles(r[column] for r in ok) for column in _DISTRIBUTIONS},
            "roc_by": list(roc_by), "roc": roc, "cases": {case: _rates(members) for case, members in cases.items()}}


def _shown(value) -> str:
    return "-" if value is None else f"{value:.3g}"


def _label(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _figures(folder: Path, summary: dict, rows: list[dict]) -> None:
    from uvsym.report.figures import plt, save_svg  # here: a campaign's worker processes never draw

    labels_true = list(summary["confusion"])
    labels_isolated = sorted({k for cell in summary["confusion"].values() for k in cell})
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    if labels_true:
        counts = np.array([[summary["confusion"][t].get(i, 0) for i in labels_isolated] for t in labels_true])
        ax.imshow(counts, cmap="Blues")
        for (y, x), count in np.ndenumerate(counts):
            ax.text(x, y, str(count), ha="center", va="center",
                    color="white" if count > counts.max() / 2 else "black")
        ax.set_xticks(range(len(labels_isolated)), labels_isolated)
        ax.set_yticks(range(len(labels_true)), labels_true)
    ax.set_xlabel("isolated actuator")
    ax.set_ylabel("true fault")
    ax.set_title("confusion matrix (runs)")
    fig.tight_layout()
    save_svg(fig, folder / "confusion.svg")

    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    points = sorted((p["false_alarm_rate"], p["detection_probability"], ", ".join(map(_label, p["group"].values())))
                    for p in summary["roc"]
                    if p["detection_probability"] is not None and p["false_alarm_rate"] is not None)
    ax.plot([p[0] for p in points], [p[1] for p in points], "o-")
    for x, y, label in points:
        ax.annotate(label, (x, y), xytext=(-4 if x > 0.5 else 4, 4), textcoords="offset points", fontsize=8,
                    ha="right" if x > 0.5 else "left")
    ax.plot([0, 1], [0, 1], ":", color="grey")
    ax.set_xlim(-0.02, 1.02)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("false-alarm rate")
    ax.set_ylabel("detection probability")
    ax.set_title("ROC" + (f" over {', '.join(summary['roc_by'])}" if summary["roc_by"] else ""))
    fig.tight_layout()
    save_svg(fig, folder / "roc.svg")

    fig, axes = plt.subplots(1, 2, figsize=(9, 3.5))
    for ax, column in zip(axes, ("detection_delay_s", "isolation_delay_s")):
        values = [r[column] for r in rows if r["status"] == "ok" and r[column] is not None]
        if values:
            ax.hist(values, bins=min(30, max(5, len(values) // 5)))
        else:
            ax.text(0.5, 0.5, "none", ha="center", va="center", transform=ax.transAxes)
        ax.set_xlabel(column.replace("_s", " (s)").replace("_", " "))
        ax.set_ylabel("runs")
    fig.tight_layout()
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
