"""Every field of every shipped scenario file, mutated: a wrong type, NaN, a misspelt key (and an empty
name) must be refused with a typed error (uvsym.errors) that names the field; infinity, a huge or zero
number, an empty or unknown string, a list too short or too long may be accepted or refused, never with
a raw exception or a hang. Each distinct field (per vehicle or plant, list indices folded) is mutated
once, in the file that parses fastest, so that the suite stays in seconds; the counts per class are
printed."""

from __future__ import annotations

import copy
import math
import signal
import tomllib
from collections import Counter
from pathlib import Path

import pytest

from uvsym.errors import UvsymError
from uvsym.sim.system_scenario import is_system_scenario, parse_any_scenario

ROOT = Path(__file__).resolve().parents[1]
FILES = sorted([*ROOT.glob("uvsym/sim/scenarios/*.toml"), *ROOT.glob("uvsym/sim/scenarios/plants/*.toml"),
                *ROOT.glob("derivations/*/scenarios/*.toml")])
HANG_S = 20  # a parse that takes longer is a hang
# fields whose keys are data (hypothesis names), so a "misspelt" key is another valid name
DATA_KEYS = {"models"}
# fields that take a number or a signal name, or a matrix as a number, its diagonal or its rows
EITHER = {("type", "reference"), ("type", "r"), ("type", "q"), ("type", "p0"), ("type", "gamma"),
          ("type", "m1"), ("type", "m2"), ("type", "l"), ("type", "k1"), ("type", "k2")}


def _leaves(node, path=()):
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _leaves(value, path + (key,))
    elif isinstance(node, list) and node and all(isinstance(item, dict) for item in node):
        for i, item in enumerate(node):
            yield from _leaves(item, path + (i,))
    else:
        yield path, node


def _folded(path) -> str:
    return ".".join("[]" if isinstance(p, int) else str(p) for p in path)


def _changed(table: dict, path, value=None, rename: str | None = None) -> dict:
    table = copy.deepcopy(table)
    node = table
    for p in path[:-1]:
        node = node[p]
    if rename is None:
        node[path[-1]] = value
    else:
        node[rename] = node.pop(path[-1])
    return table


def _mutations(value) -> list[tuple[str, object, bool]]:
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
        if value and all(isinstance(v, list) for v in value):
            out.append(("nan", [[math.nan] * len(v) for v in value], True))
        return out
    return []


def _fields():
    """(file, path, value) for each distinct field, in the file that parses fastest among those holding it."""
    chosen, order = {}, []
    for path in FILES:
        table = tomllib.loads(path.read_text())
        order.append((len(str(table)), path, table))
    for _, path, table in sorted(order, key=lambda item: item[0]):
        kind = table.get("plant") or table.get("vehicle")
        for field, value in _leaves(table):
            chosen.setdefault((is_system_scenario(table), kind, _folded(field)), (path, table, field, value))
    return list(chosen.values())


class _Hang(Exception):
    pass


def _outcome(table: dict, folder: Path) -> tuple[str, str]:
    def stop(*_):
        raise _Hang

    previous = signal.signal(signal.SIGALRM, stop)
    signal.alarm(HANG_S)
    try:
        parse_any_scenario(table, root=str(folder))
        return "accepted", ""
    except UvsymError as exc:
        return "typed", str(exc)
    except _Hang:
        return "hang", ""
    except Exception as exc:  # the failure this test exists to catch
        return "raw", f"{type(exc).__name__}: {exc}"
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def _names_the_field(message: str, field, value) -> bool:
    """The message names the key, its table (``blocks[2]``), or quotes the offending value."""
    keys = [str(p) for p in field if isinstance(p, str)]
    table = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in field[:2]).lstrip(".")
    return keys[-1] in message or table in message or repr(value) in message


@pytest.mark.skipif(not hasattr(signal, "SIGALRM"), reason="needs SIGALRM to stop a hanging parse")
def test_every_field_of_every_shipped_scenario_refuses_bad_values_by_name(capsys):
    counts, failures = Counter(), []
    for path, table, field, value in _fields():
        trials = [(cls, _changed(table, field, mutated), must or (cls == "empty" and field[-1] == "name"), mutated)
                  for cls, mutated, must in _mutations(value)]  # an empty name names nothing
        if isinstance(field[-1], str) and not DATA_KEYS & set(map(str, field[:-1])):
            trials.append(("misspelt", _changed(table, field, rename=f"{field[-1]}x"), True, f"{field[-1]}x"))
        for cls, mutated_table, must, mutated in trials:
            outcome, message = _outcome(mutated_table, path.parent)
            if outcome == "accepted" and must and (cls, field[-1]) in EITHER:
                outcome = "accepted (a valid form)"
            counts[(cls, outcome)] += 1
            wrong = (outcome in ("raw", "hang") or (outcome == "accepted" and must)
                     or (outcome == "typed" and must and not _names_the_field(message, field, mutated)))
            if wrong:
                failures.append(f"{path.relative_to(ROOT)} {_folded(field)} <- {cls} {mutated!r}: {outcome} "
                                f"{message[:160]}")
    with capsys.disabled():
        print("\nbad scenario fields, by class and outcome:",
              ", ".join(f"{cls} {outcome} {n}" for (cls, outcome), n in sorted(counts.items())))
    assert sum(counts.values()) > 2000  # the suite really ran over the shipped files
    assert not failures, "\n".join(failures)
