"""A detector's limits read off a campaign's rows: the smallest fault it sees, its delays, its false alarms.

From the rows of :func:`uvsym.campaign.run_campaign` (dicts with the columns of
:mod:`uvsym.campaign.metrics`), for one detector (its ``D:<metric>`` columns, or the generic ones):

- per channel (the true actuator or sensor, and the fault's kind): the fault sizes tried (``|true_value|``),
  how many runs of each were detected, the smallest size detected in every run of it and in every run
  of every larger size (``seen_from``: none when the largest size tried is missed in some run), the
  largest size missed in some run, and the median detection delay (s) of the detected runs;
- per noise level (a grid field the caller names): the fault-free runs' hours and false alarms,
  and the false alarms per hour (a rate with no alarm in few hours is an upper bound of
  nothing: the hours are given beside it).
"""

from __future__ import annotations

import math
import statistics

from uvsym.errors import CampaignError

__all__ = ["NONE_SEEN_95", "channel_limits", "every_size_from", "false_alarm_rates", "limits_table",
           "false_alarm_table"]

NONE_SEEN_95 = math.log(20.0)  # no event in H hours: a Poisson rate below NONE_SEEN_95 / H per hour at 95 %


def _column(rows: list[dict], detector: str | None, metric: str):
    key = metric if detector is None else f"{detector}:{metric}"
    if rows and not any(key in row for row in rows):
        raise CampaignError(f"no column {key!r} in the campaign's rows (detectors: "
                            f"{sorted({k.split(':')[0] for r in rows for k in r if ':' in k}) or 'none'})")
    return lambda row: row.get(key)


def channel_limits(rows: list[dict], detector: str | None = None, cases=None, size=None) -> list[dict]:
    """One dict per (channel, kind) with a fault (module docstring): channel, kind, sizes (list of
    (size, runs, detected)), seen_from, missed_up_to, median_delay_s; ``cases``: the case names to read
    (None: every case); ``size``: row -> the fault's size (default ``|true_value|``; None leaves the run
    out, e.g. a kind whose value is no size). Runs that ended in an error are left out."""
    size = size or (lambda row: abs(row["true_value"]))
    detected, delay = _column(rows, detector, "detected"), _column(rows, detector, "detection_delay_s")
    groups: dict[tuple, dict[float, list]] = {}
    for row in rows:
        if row.get("status") != "ok" or not row.get("n_faults") or (cases is not None and row["case"] not in cases):
            continue
        channel = row.get("true_actuator") or row.get("true_sensor")
        if channel is None or row.get("true_value") is None:
            continue
        magnitude = size(row)
        if magnitude is not None:
            groups.setdefault((channel, row["true_kind"]), {}).setdefault(magnitude, []).append(row)
    limits = []
    for (channel, kind), by_size in sorted(groups.items()):
        sizes = [(size, len(runs), sum(bool(detected(r)) for r in runs)) for size, runs in sorted(by_size.items())]
        seen_from = every_size_from([(size, hits == runs) for size, runs, hits in sizes])
        missed = [size for size, runs, hits in sizes if hits < runs]
        delays = [delay(r) for runs in by_size.values() for r in runs if detected(r) and delay(r) is not None]
        limits.append({"channel": channel, "kind": kind, "sizes": sizes, "seen_from": seen_from,
                       "missed_up_to": max(missed) if missed else None,
                       "median_delay_s": statistics.median(delays) if delays else None})
    return limits


def every_size_from(sizes) -> float | None:
    """The smallest size from which every larger size tried holds too, of (size, holds) pairs in ascending
    size; None when the largest does not hold."""
    found = None
    for size, holds in reversed(list(sizes)):
        if not holds:
            break
        found = size
    return found


def false_alarm_rates(rows: list[dict], noise_field: str, detector: str | None = None) -> list[dict]:
    """Per value of ``noise_field`` (sorted): hours of fault-free runs, false alarms, and per hour
    (None without an hour). CampaignError when no row has the field."""
    if rows and not any(noise_field in row for row in rows):
        raise CampaignError(f"no grid field {noise_field!r} in the campaign's rows")
    alarms = _column(rows, detector, "false_alarms")
    levels: dict = {}
    for row in rows:
        if row.get("status") != "ok" or row.get("n_faults") or row.get(noise_field) is None:
            continue
        hours, count = levels.get(row[noise_field], (0.0, 0))
        levels[row[noise_field]] = (hours + row["duration_s"] / 3600.0, count + int(alarms(row) or 0))
    return [{"noise": level, "hours": hours, "false_alarms": count, "per_hour": count / hours if hours else None}
            for level, (hours, count) in sorted(levels.items())]


def _size(value) -> str:
    return "-" if value is None else f"{value:g}"


def limits_table(limits: list[dict], unit: str = "") -> list[list[str]]:
    """Rows for a Markdown table: channel, kind, sizes tried (detected/runs each), seen from, missed up to,
    median delay (s)."""
    suffix = f" {unit}" if unit else ""
    return [[item["channel"], item["kind"],
             ", ".join(f"{size:g}: {hits}/{runs}" for size, runs, hits in item["sizes"]),
             _size(item["seen_from"]) + (suffix if item["seen_from"] is not None else ""),
             _size(item["missed_up_to"]) + (suffix if item["missed_up_to"] is not None else ""),
             "-" if item["median_delay_s"] is None else f"{item['median_delay_s']:.3g}"] for item in limits]


def false_alarm_table(rates: list[dict]) -> list[list[str]]:
    """Rows for a Markdown table: noise level, fault-free hours, false alarms, per hour."""
    return [[f"{r['noise']:g}" if isinstance(r["noise"], float) else str(r["noise"]), f"{r['hours']:.3g}",
             str(r["false_alarms"]), "-" if r["per_hour"] is None else f"{r['per_hour']:.3g}"] for r in rates]
