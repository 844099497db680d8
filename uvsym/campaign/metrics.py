"""Per-run metrics of a campaign: the truth from the scenario, the diagnosis from the event log.

Events are the dicts of :mod:`uvsym.diagnosis.events` (``t``, ``event``, ``target``, ``kind``,
``value``, ``detector``). The generic columns judge every event of the run together (any detector);
a scenario with detectors also gets, per detector D, the columns ``D:<metric>`` of
:data:`DETECTOR_COLUMNS` judged on D's events alone, so detectors in one loop are compared on the
same runs.

The run's fault is its earliest (actuator faults before sensor faults at equal onsets); sensor
noise acting for the whole run is the sensors' specification, not a fault (as for the diagnosis,
whose noise levels it sets), so a run with only such noise has no fault. The fault's window runs
from the onset to the first "cleared" event at or after its end (a fault without an end lasts
the run). An alarm (detected, isolated, identified) outside the window, or in a run
without a fault, is a false alarm; the alarms one detector publishes at one time are one decision
(a monitor that detects and isolates at once raises one false alarm, not two).
"""

from __future__ import annotations

import math

import numpy as np

from uvsym.diagnosis.events import ALARMS

__all__ = ["ALARMS", "DETECTOR_COLUMNS", "METRIC_COLUMNS", "truth", "event_metrics", "run_metrics", "signal_labels",
           "detector_names"]

DIAGNOSIS = "diagnosis"  # the detector name of a vehicle scenario's [diagnosis]
# the columns each detector of a scenario gets, as D:<column>
DETECTOR_COLUMNS = ("detected", "detection_delay_s", "isolated_target", "isolated_targets", "isolation_delay_s",
                    "identified_value", "identified_std", "size_error_rel", "size_error_std", "false_alarms",
                    "ambiguous", "unexplained", "clear_delay_s")
# every generic column a run gets, with its type (the run's grid fields and the hook's columns follow)
METRIC_COLUMNS = {
    "run_id": "string", "case": "string", "draw": "int64", "status": "string", "error": "string",
    "n_faults": "int64", "true_actuator": "string", "true_sensor": "string", "true_kind": "string",
    "true_value": "float64", "onset_s": "float64", "end_s": "float64",
    "events": "int64", "detected": "bool", "detection_delay_s": "float64", "isolated_target": "string",
    "isolated_kind": "string", "isolated_targets": "string",
    "isolation_delay_s": "float64", "identified_value": "float64", "identified_std": "float64",
    "size_error_rel": "float64", "size_error_std": "float64",
    "false_alarms": "int64", "ambiguous": "bool", "unexplained": "bool", "unexcited": "bool",
    "clear_delay_s": "float64", "path_error_rms_m": "float64",
    "duration_s": "float64", "wall_s": "float64",
}


def signal_labels(scenario) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(input labels, output labels) that a scenario's actuator and sensor faults index: a plant's
    inputs and outputs, or a vehicle's inputs and (measured) states."""
    if hasattr(scenario, "plant"):
        return scenario.input_labels, scenario.output_labels
    return scenario.model.input_labels, scenario.model.state_labels


def detector_names(scenario) -> tuple[str, ...]:
    """The names of the scenario's detectors (a vehicle's continuous diagnosis is ``diagnosis``)."""
    if hasattr(scenario, "detectors"):
        return tuple(d.name for d in scenario.detectors)
    return (DIAGNOSIS,) if getattr(scenario, "diagnosis", None) is not None else ()


def truth(scenario) -> dict:
    """n_faults (whole-run sensor noise not counted: module docstring) and the run's fault:
    true_actuator or true_sensor (label), true_kind, true_value, onset_s and end_s (None when it
    lasts the run); None throughout without a fault."""
    inputs, outputs = signal_labels(scenario)
    faults = [(f.profile.onset, 0, i, inputs[f.actuator], None, f) for i, f in enumerate(scenario.actuator_faults)]
    faults += [(f.profile.onset, 1, i, None, outputs[f.channel], f)
               for i, f in enumerate(scenario.sensor_faults)
               if not (f.kind_object.noise and f.profile.onset == 0.0 and math.isinf(f.profile.end))]
    row = {"n_faults": len(faults), "true_actuator": None, "true_sensor": None, "true_kind": None,
           "true_value": None, "onset_s": None, "end_s": None}
    if faults:
        onset, _, _, actuator, sensor, fault = min(faults, key=lambda f: f[:3])
        end = fault.profile.end
        row |= {"true_actuator": actuator, "true_sensor": sensor, "true_kind": fault.kind,
                "true_value": float(fault.value), "onset_s": float(onset),
                "end_s": None if math.isinf(end) else float(end)}
    return row


def event_metrics(true: dict, events: list[dict]) -> dict:
    """Diagnosis metrics of one run from its events and :func:`truth`'s row.

    detected / detection_delay_s: a "detected" event in the fault's window, the first one's time
    after the onset (s); isolated_target / isolated_kind: the last "isolated" decision not
    cleared by the end of the run (a "cleared" naming its actuator, or none, clears it), and
    isolated_targets: every actuator isolated and not cleared then, in the order of isolation,
    joined by "|";
    isolation_delay_s: the first "isolated" event in the window naming the true actuator or sensor;
    identified_value / identified_std: the last "identified" value in the window for it (or naming none)
    and the standard deviation the detector stated for it (None where it states none);
    size_error_rel: ``abs(identified - true) / abs(true)`` (None when true is 0); size_error_std: the
    error in stated standard deviations, ``abs(identified - true) / identified_std``; false_alarms: alarms
    outside the window (module docstring); ambiguous, unexplained: any such event; unexcited: such an
    event naming the run's own actuator or sensor (or none: another actuator's idling is not this run's
    business); clear_delay_s: for a fault that ends, how long after its end the detector still holds an
    alarm (:func:`_return_delay`; s, None when the fault lasts the run or an alarm stands to its end);
    events: how many.
    """
    events = sorted(events, key=lambda e: e["t"])
    target = true["true_actuator"] or true["true_sensor"]
    onset = true["onset_s"]
    end = math.inf if true["end_s"] is None else true["end_s"]
    closed = next((e["t"] for e in events if e["event"] == "cleared" and e["t"] >= end), math.inf)

    def in_window(e: dict) -> bool:
        return onset is not None and onset <= e["t"] <= closed

    detections = [e for e in events if e["event"] == "detected" and in_window(e)]
    isolations = [e for e in events if e["event"] == "isolated" and in_window(e) and e.get("target") == target]
    identified = [e for e in events if e["event"] == "identified" and in_window(e)
                  and e.get("target") in (target, None) and e.get("value") is not None]
    standing: dict = {}  # actuator -> its isolation not cleared since (a diagnosis may hold several)
    for e in events:
        if e["event"] == "isolated":
            standing.pop(e.get("target"), None)
            standing[e.get("target")] = e
        elif e["event"] == "cleared":
            if e.get("target") is None:
                standing.clear()
            standing.pop(e.get("target"), None)
    decision = list(standing.values())[-1] if standing else None
    value = float(identified[-1]["value"]) if identified else None
    std = identified[-1].get("std") if identified else None
    true_value = true["true_value"]
    return {
        "events": len(events),
        "detected": bool(detections),
        "detection_delay_s": detections[0]["t"] - onset if detections else None,
        "isolated_target": None if decision is None else decision.get("target"),
        "isolated_kind": None if decision is None else decision.get("kind"),
        "isolated_targets": "|".join(str(a) for a in standing) or None,
        "isolation_delay_s": isolations[0]["t"] - onset if isolations else None,
        "identified_value": value,
        "identified_std": std,
        "size_error_std": abs(value - true_value) / std if std and true_value is not None else None,
        "size_error_rel": None if value is None or not true_value else abs(value - true_value) / abs(true_value),
        "false_alarms": len({(e.get("detector"), e["t"]) for e in events if e["event"] in ALARMS and not in_window(e)}),
        "ambiguous": any(e["event"] == "ambiguous" for e in events),
        "unexplained": any(e["event"] == "unexplained" for e in events),
        "clear_delay_s": _return_delay(events, end),
        "unexcited": any(e["event"] == "unexcited" and e.get("target") in (target, None) for e in events),
    }


def _return_delay(events: list[dict], end: float) -> float | None:
    """Seconds from ``end`` until the events (sorted by time) hold no alarm: 0 when none stands at ``end``
    (cleared before it, or never raised), None when one stands to the last event (inf: no end). An alarm
    stands from a "detected" or "isolated" until a "cleared" of its target (none: of every target)."""
    if math.isinf(end):
        return None
    standing: set = set()
    for e in events:
        if e["t"] > end and not standing:
            break
        if e["event"] in ("detected", "isolated"):
            standing.add(e.get("target") if e["event"] == "isolated" else "detected")
        elif e["event"] == "cleared":
            standing = set() if e.get("target") is None or standing <= {e.get("target"), "detected"} else \
                standing - {e.get("target")}
            if e["t"] >= end and not standing:
                return e["t"] - end
    return None if standing else 0.0


def run_metrics(scenario, result, events: list[dict]) -> dict:
    """:func:`truth`, :func:`event_metrics`, duration_s (simulated s), path_error_rms_m (RMS of the
    reference's cross-track error over the run, m; None when the result has none) and, per
    detector D, ``D:<metric>`` for each of :data:`DETECTOR_COLUMNS` (module docstring) and
    ``D:decision_cpu_s``, the processor time D took to decide on the record (s; None where the
    decisions are made in the loop)."""
    true = truth(scenario)
    reference = result.signals.get("reference")
    rms = None
    if reference is not None and "cross_track" in reference.labels:
        rms = float(np.sqrt(np.mean(np.square(reference["cross_track"]))))
    row = true | event_metrics(true, events) | {"path_error_rms_m": rms,
                                                "duration_s": float(result.t[-1] - result.t[0])}
    names = detector_names(scenario)
    if len(names) > 1 or hasattr(scenario, "detectors"):
        for name in names:
            own = event_metrics(true, [e for e in events if e.get("detector") == name])
            row |= {f"{name}:{column}": own[column] for column in DETECTOR_COLUMNS}
            row[f"{name}:decision_cpu_s"] = result.meta.get("detector_cpu_s", {}).get(name)
    return row
