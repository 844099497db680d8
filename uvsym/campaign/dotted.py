"""Dotted paths into a parsed TOML table: ``controller.speed.kp``, ``faults[0].onset``.

A path is keys joined by dots, each key optionally followed by list indices ``[i]``. Setting a
value creates missing tables on the way, and a missing list entry (index = the list's length)
as a table; a table value is merged into the table at the path (recursively), any other value
replaces what is there.
"""

from __future__ import annotations

import copy
import datetime
import re

from uvsym.errors import CampaignError

__all__ = ["parse_path", "set_path", "flatten", "new_entry", "copied"]

_STEP = re.compile(r"(?P<key>[A-Za-z0-9_-]+)(?P<indices>(?:\[\d+\])*)")


_SHARED_LEAVES = (str, int, float, bool, type(None), datetime.date, datetime.time)  # TOML's leaves: immutable


def copied(value):
    """A deep copy of a parsed TOML value (what ``copy.deepcopy`` gives, at a fifth of its time for TOML's
    tables, lists and leaves: a campaign copies its scenario table for every run); anything else (a tuple or
    array in a table built in Python) goes through ``copy.deepcopy``."""
    if isinstance(value, dict):
        return {key: copied(item) for key, item in value.items()}
    if isinstance(value, list):
        return [copied(item) for item in value]
    return value if isinstance(value, _SHARED_LEAVES) else copy.deepcopy(value)


def parse_path(path: str) -> tuple[str | int, ...]:
    """The steps of ``path``: keys (str) and list indices (int); CampaignError naming a malformed path."""
    if not isinstance(path, str) or not path:
        raise CampaignError(f"{path!r}: a field path is a non-empty string such as 'faults[0].onset'")
    steps: list[str | int] = []
    for part in path.split("."):
        match = _STEP.fullmatch(part)
        if match is None:
            raise CampaignError(f"{path!r}: malformed field path at {part!r} (keys of letters, digits, _ and -, "
                                "each optionally followed by [index])")
        steps.append(match.group("key"))
        steps += [int(i) for i in re.findall(r"\[(\d+)\]", match.group("indices"))]
    return tuple(steps)


def _merge(target: dict, value: dict) -> None:
    for key, item in value.items():
        if isinstance(item, dict) and isinstance(target.get(key), dict):
            _merge(target[key], item)
        else:
            target[key] = copied(item)


def set_path(data: dict, path: str, value) -> None:
    """Set ``value`` at ``path`` in ``data`` (in place; see the module docstring); CampaignError naming the
    path where it leads through something that is not a table or list, or skips list entries."""
    steps = parse_path(path)
    node = data
    for depth, (step, nxt) in enumerate(zip(steps, steps[1:] + (None,))):
        where = _shown(steps[:depth + 1])
        if isinstance(step, int):
            if not isinstance(node, list):
                raise CampaignError(f"{path}: {_shown(steps[:depth])} is not a list, cannot take [{step}]")
            if step > len(node):
                raise CampaignError(f"{path}: {_shown(steps[:depth])} has {len(node)} entries; [{step}] would leave "
                                    "a gap (a missing entry is made only at the end)")
            if step == len(node):
                node.append({})
        elif not isinstance(node, dict):
            raise CampaignError(f"{path}: {_shown(steps[:depth]) or 'the scenario'} is not a table, cannot take "
                                f"{step!r}")
        elif nxt is not None and step not in node:
            node[step] = [] if isinstance(nxt, int) else {}
        if nxt is None:
            current = node[step] if isinstance(step, int) or step in node else None
            if isinstance(value, dict) and isinstance(current, dict):
                _merge(current, value)
            else:
                node[step] = copied(value)
            return
        node = node[step]
        if not isinstance(node, (dict, list)):
            raise CampaignError(f"{path}: {where} is a {type(node).__name__}, not a table or list")


def new_entry(data: dict, path: str) -> str | None:
    """The list entry (``faults[1]``) that setting ``path`` in ``data`` would make, or None."""
    node, steps = data, parse_path(path)
    for depth, step in enumerate(steps):
        if isinstance(step, int) and isinstance(node, list) and step >= len(node):
            return _shown(steps[:depth + 1])
        if isinstance(node, dict) and step in node or isinstance(node, list) and isinstance(step, int):
            node = node[step]
        else:
            return None
    return None


def _shown(steps) -> str:
    text = ""
    for step in steps:
        text += f"[{step}]" if isinstance(step, int) else (f".{step}" if text else step)
    return text


def flatten(path: str, value) -> dict:
    """Column name -> value for a field set at ``path``: a table becomes one column per entry
    (``faults[0].kind``), recursively; anything else one column."""
    if not isinstance(value, dict):
        return {path: value}
    columns = {}
    for key, item in value.items():
        columns |= flatten(f"{path}.{key}", item)
    return columns
