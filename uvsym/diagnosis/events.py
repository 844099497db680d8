"""The decision log of a diagnosis: one record per state change, written as JSON.

Schema (stable): a JSON list of ``{"t": s, "event": one of EVENTS, "actuator": label or null,
"kind": fault kind or null, "value": number or null}``. ``actuator`` names one actuator, or for
``ambiguous`` the candidates joined by ``|``; ``value`` is a fault size in the kind's unit
(``-`` for kinds that scale the command, else the input's unit).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

from uvsym.errors import PathError

__all__ = ["EVENTS", "Event", "events_json", "write_events", "write_events_records"]

EVENTS = ("detected", "isolated", "identified", "cleared", "ambiguous", "unexcited")


@dataclass(frozen=True)
class Event:
    """t (s), event (one of EVENTS), actuator label, fault kind, value (see the module docstring)."""

    t: float
    event: str
    actuator: str | None = None
    kind: str | None = None
    value: float | None = None

    def as_dict(self) -> dict:
        record = asdict(self)
        if record["value"] is not None and not math.isfinite(record["value"]):
            record["value"] = None
        return record


def events_json(events: list[Event]) -> str:
    """The log as JSON text (a list, one object per event, in time order)."""
    return json.dumps([e.as_dict() for e in events], indent=1)


def write_events(events: list[Event], path) -> Path:
    """Write the log to ``path`` (JSON); returns the path."""
    return write_events_records([e.as_dict() for e in events], path)


def write_events_records(records: list[dict], path) -> Path:
    """Write a log already in its JSON form (``SimResult.events``) to ``path``; returns the path.

    Raises PathError when the folder does not exist (it is not created).
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise PathError(f"cannot write the decision log {path}: folder {path.parent} does not exist")
    path.write_text(json.dumps(records, indent=1) + "\n")
    return path
