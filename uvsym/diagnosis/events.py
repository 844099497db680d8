"""The decision log of a diagnosis: one record per state change, written as JSON.

Schema (stable), one vocabulary for every detector: a JSON list of ``{"t": s, "event": one of
EVENTS, "target": signal name or null, "kind": fault kind or null, "value": number or null,
"detector": the deciding block's name or null, "std": number or null}``. ``target`` names the input (an actuator) or the
output (a sensor) the decision is about, or for ``ambiguous`` the candidates joined by ``|``;
``value`` is a fault size in the kind's unit (``-`` for kinds that scale a signal, else the
signal's unit); ``std``, where the detector states one, is the standard deviation of ``value`` under
the noise model it was told (same unit; ``value +- 2 std`` is an approximate 95 % interval).

Events: ``detected`` (something is wrong), ``isolated`` (it is this target), ``identified`` (its
size), ``cleared`` (the fault, or with no target every fault, is gone), ``ambiguous`` (the data
cannot tell the candidates apart), ``unexcited`` (the target is not excited enough to be judged),
``unexplained`` (no hypothesis of the detector fits the data).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

from uvsym.errors import DiagnosisError, PathError

__all__ = ["ALARMS", "EVENTS", "Event", "write_events"]

EVENTS = ("detected", "isolated", "identified", "cleared", "ambiguous", "unexcited", "unexplained")
ALARMS = ("detected", "isolated", "identified")  # the events that say a fault is present


@dataclass(frozen=True)
class Event:
    """t (s), event (one of EVENTS), target signal, fault kind, value, detector, std of value (module docstring)."""

    t: float
    event: str
    target: str | None = None
    kind: str | None = None
    value: float | None = None
    detector: str | None = None
    std: float | None = None

    def __post_init__(self):
        if self.event not in EVENTS:
            raise DiagnosisError(f"event {self.event!r} is not one of {', '.join(EVENTS)}")

    def as_dict(self) -> dict:
        record = asdict(self)
        for key in ("value", "std"):
            if record[key] is not None and not math.isfinite(record[key]):
                record[key] = None
        return record


def write_events(records: list[dict], path) -> Path:
    """Write a log in its JSON form (``SimResult.events``, ``Event.as_dict``) to ``path``; returns the path.

    Raises PathError when the folder does not exist (it is not created).
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise PathError(f"cannot write the decision log {path}: folder {path.parent} does not exist")
    path.write_text(json.dumps(records, indent=1) + "\n")
    return path
