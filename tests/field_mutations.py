"""Mutations of a parsed TOML table's fields, and the outcome of parsing each: shared by the
bad-input tests of scenario and campaign files."""

from __future__ import annotations

import copy
import math
import signal

from uvsym.errors import UvsymError

HANG_S = 20  # a parse that takes longer is a hang


def leaves(node, path=()):
    """(path, value) of every field: tables entered, arrays of tables entered by index, other values leaves."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield from leaves(value, path + (key,))
    elif isinstance(node, list) and node and all(isinstance(item, dict) for item in node):
        for i, item in enumerate(node):
            yield from leaves(item, path + (i,))
    else:
        yield path, node


def folded(path) -> str:
    """The path with list indices folded (``blocks.[].kp``): one name for the same field of every entry."""
    return ".".join("[]" if isinstance(p, int) else str(p) for p in path)


def changed(table: dict, path, value=None, rename: str | None = None) -> dict:
    """A copy of ``table`` with the field at ``path`` set to ``value``, or its key renamed to ``rename``."""
    table = copy.deepcopy(table)
    node = table
    for p in path[:-1]:
        node = node[p]
    if rename is None:
        node[path[-1]] = value
    else:
        node[rename] = node.pop(path[-1])
    return table


def mutations(value) -> list[tuple[str, object, bool]]:
    """(class, mutated value, must be refused) for a field's value."""
    if isinstance(value, bool):
        return [("type", "yes", True), ("type", 1.5, True)]
    if isinstance(value, (int, float)):
        return [("type", "x", True), ("type", [1.0], True), ("nan", math.nan, True), ("inf", math.inf, False),
                ("huge", -1e300, False), ("zero", 0, False)]
    if isinstance(value, str):
        return [("type", 12345, True), ("unknown", value + "_nosuch", False), ("empty", "", False)]
    if isinstance(value, list):
        out = [("type", "x", True), ("empty", [], False)]
        if value and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            out += [("nan", [math.nan] * len(value), True), ("short", value[:-1], False),
                    ("long", [*value, 1.0], False)]
        if value and all(isinstance(v, list) and v for v in value):
            out.append(("nan", [[math.nan] * len(v) for v in value], True))
        return [m for m in out if m[1] != value]  # a mutation that changes nothing is none
    return []


class _Hang(Exception):
    pass


def outcome(parse, table: dict) -> tuple[str, str]:
    """(accepted | typed | hang | raw, message) of ``parse(table)``."""
    def stop(*_):
        raise _Hang

    previous = signal.signal(signal.SIGALRM, stop)
    signal.alarm(HANG_S)
    try:
        parse(table)
        return "accepted", ""
    except UvsymError as exc:
        return "typed", str(exc)
    except _Hang:
        return "hang", ""
    except Exception as exc:  # the failure these tests exist to catch
        return "raw", f"{type(exc).__name__}: {exc}"
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def names_the_field(message: str, field, value) -> bool:
    """The message names the key, its table (``blocks[2]``), or quotes the offending value."""
    keys = [str(p) for p in field if isinstance(p, str)]
    table = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in field[:2]).lstrip(".")
    return keys[-1] in message or table in message or repr(value) in message
