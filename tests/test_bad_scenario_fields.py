"""Every field of every shipped scenario file, mutated: a wrong type, NaN, a misspelt key (and an empty
name) must be refused with a typed error (uvsym.errors) that names the field; infinity, a huge or zero
number, an empty or unknown string, a list too short or too long may be accepted or refused, never with
a raw exception or a hang. Each distinct field (per vehicle or plant, list indices folded) is mutated
once, in the file that parses fastest, so that the suite stays in seconds; the counts per class are
printed."""

from __future__ import annotations

import functools
import signal
import tomllib
from collections import Counter
from pathlib import Path

import pytest
from field_mutations import changed, folded, leaves, mutations, names_the_field, outcome

from uvsym.sim.system_scenario import is_system_scenario, parse_any_scenario

ROOT = Path(__file__).resolve().parents[1]
FILES = sorted([*ROOT.glob("uvsym/sim/scenarios/*.toml"), *ROOT.glob("uvsym/sim/scenarios/plants/*.toml"),
                *ROOT.glob("derivations/*/scenarios/*.toml")])
# fields whose keys are data (hypothesis names), so a "misspelt" key is another valid name
DATA_KEYS = {"models"}
# fields that take a number or a signal name, or a matrix as a number, its diagonal or its rows
EITHER = {("type", "reference"), ("type", "r"), ("type", "q"), ("type", "p0"), ("type", "gamma"),
          ("type", "m1"), ("type", "m2"), ("type", "l"), ("type", "k1"), ("type", "k2")}


def _fields():
    """(file, path, value) for each distinct field, in the file that parses fastest among those holding it."""
    chosen, order = {}, []
    for path in FILES:
        table = tomllib.loads(path.read_text())
        order.append((len(str(table)), path, table))
    for _, path, table in sorted(order, key=lambda item: item[0]):
        kind = table.get("plant") or table.get("vehicle")
        for field, value in leaves(table):
            chosen.setdefault((is_system_scenario(table), kind, folded(field)), (path, table, field, value))
    return list(chosen.values())


@pytest.mark.skipif(not hasattr(signal, "SIGALRM"), reason="needs SIGALRM to stop a hanging parse")
def test_every_field_of_every_shipped_scenario_refuses_bad_values_by_name(capsys):
    counts, failures = Counter(), []
    for path, table, field, value in _fields():
        trials = [(cls, changed(table, field, mutated), must or (cls == "empty" and field[-1] == "name"), mutated)
                  for cls, mutated, must in mutations(value)]  # an empty name names nothing
        if isinstance(field[-1], str) and not DATA_KEYS & set(map(str, field[:-1])):
            trials.append(("misspelt", changed(table, field, rename=f"{field[-1]}x"), True, f"{field[-1]}x"))
        parse = functools.partial(parse_any_scenario, root=str(path.parent))
        for cls, mutated_table, must, mutated in trials:
            result, message = outcome(parse, mutated_table)
            if result == "accepted" and must and (cls, field[-1]) in EITHER:
                result = "accepted (a valid form)"
            counts[(cls, result)] += 1
            wrong = (result in ("raw", "hang") or (result == "accepted" and must)
                     or (result == "typed" and must and not names_the_field(message, field, mutated)))
            if wrong:
                failures.append(f"{path.relative_to(ROOT)} {folded(field)} <- {cls} {mutated!r}: {result} "
                                f"{message[:160]}")
    with capsys.disabled():
        print("\nbad scenario fields, by class and outcome:",
              ", ".join(f"{cls} {result} {n}" for (cls, result), n in sorted(counts.items())))
    assert sum(counts.values()) > 2000  # the suite really ran over the shipped files
    assert not failures, "\n".join(failures)


def test_a_misspelt_key_is_named_when_its_table_fails_for_another_reason():
    """A campaign that sets ``blocks[0].valuesx`` leaves the file's own values (one row) beside two times: the
    shape error comes first, and names the misspelling that caused it."""
    path = ROOT / "derivations/motor_luenberger/scenarios/motor_luenberger_step.toml"
    table = tomllib.loads(path.read_text())
    table["blocks"][0] |= {"times": [0.0, 1.0], "valuesx": [[1.0, 2.0], [3.0, 4.0]]}
    result, message = outcome(functools.partial(parse_any_scenario, root=str(path.parent)), table)
    assert result == "typed" and "one row of 2 value(s) per time" in message
    assert message.endswith("(is 'blocks[0].valuesx' a misspelt 'values'?)")
    table["blocks"][0] = {**table["blocks"][0], "values": [[1.0, 2.0], [3.0, 4.0]]}  # both given: unknown field
    result, message = outcome(functools.partial(parse_any_scenario, root=str(path.parent)), table)
    assert result == "typed" and "valuesx: unknown field (did you mean 'values'?)" in message
