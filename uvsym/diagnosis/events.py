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

__all__ = ["EVENTS", "Event", "write_events"]

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


def write_events(records: list[dict], path) -> Path:
    """Write a log in its JSON form (``SimResult.events``, ``Event.as_dict``) to ``path``; returns the path.

    Raises PathError when the folder does not exist (it is not created).
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise PathError(f"cannot write the decision log {path}: folder {path.parent} does not exist")
    path.write_text(json.dumps(records, indent=1) + "\n")
    return path
