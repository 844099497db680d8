"""Every field of every shipped campaign file, mutated (as tests/test_bad_scenario_fields.py does for
scenarios): a wrong type, NaN or a misspelt key is refused with a typed error naming the field; the
other mutations may be accepted or refused, never with a raw exception or a hang. The scenario values
a case's ``set`` and grid axes hold are mutated as wholes only (their fields are the scenario test's;
a grid axis may override what ``set`` gives). Each case is cut to its grid's first point and one
draw first, so that an accepted mutation expands to a few runs."""

from __future__ import annotations

import functools
import signal
import tomllib
from collections import Counter
from pathlib import Path

import pytest
from field_mutations import changed, folded, mutations, names_the_field, outcome

from uvsym.campaign.spec import parse_campaign

ROOT = Path(__file__).resolve().parents[1]
FILES = sorted(path for path in [*ROOT.glob("derivations/*/campaign*.toml"), *ROOT.glob("examples/**/campaign*.toml")]
               if "case" in tomllib.loads(path.read_text()))
FREE = {"name", "description"}  # free text


def _fields(table: dict):
    """(path, value) of the campaign's own fields: a case's ``set`` and each grid axis as one value."""
    for key, value in table.items():
        if key != "case" and isinstance(value, dict):
            yield from (((key, k), v) for k, v in value.items())
        elif key != "case":
            yield (key,), value
    for i, case in enumerate(table.get("case", [])):
        for key, value in case.items():
            if key == "grid":
                yield from (((("case", i, key, axis), values)) for axis, values in value.items())
            elif key == "monte_carlo":
                for name, draw in value.items():
                    if isinstance(draw, dict):
                        yield from ((("case", i, key, name, kind), args) for kind, args in draw.items())
                    else:
                        yield ("case", i, key, name), draw
            else:
                yield ("case", i, key), value


def _small(table: dict) -> dict:
    """The campaign with each case's grid axes cut to their first value and one Monte Carlo draw."""
    for case in table.get("case", []):
        for axis, values in (case.get("grid") or {}).items():
            case["grid"][axis] = values[:1]
        if "monte_carlo" in case:
            case["monte_carlo"]["runs"] = 1
    return table


@pytest.mark.skipif(not hasattr(signal, "SIGALRM"), reason="needs SIGALRM to stop a hanging parse")
@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_field_of_a_shipped_campaign_refuses_bad_values_by_name(path, capsys):
    table = _small(tomllib.loads(path.read_text()))
    parse = functools.partial(parse_campaign, root=path.parent, default_name=path.stem, confirm=True)
    assert outcome(parse, table) == ("accepted", "")  # the cut campaign itself is valid
    counts, failures = Counter(), []
    for field, value in _fields(table):
        if field[-1] in FREE and isinstance(value, str):
            trials = [("type", changed(table, field, 12345), True, 12345)]
        elif isinstance(value, dict):  # a case's set: as a whole
            trials = [("type", changed(table, field, "x"), True, "x")]
        else:
            trials = [(cls, changed(table, field, mutated), must, mutated) for cls, mutated, must in mutations(value)]
        if isinstance(field[-1], str):
            trials.append(("misspelt", changed(table, field, rename=f"{field[-1]}x"), True, f"{field[-1]}x"))
        for cls, mutated_table, must, mutated in trials:
            result, message = outcome(parse, mutated_table)
            counts[(cls, result)] += 1
            if (result in ("raw", "hang") or (result == "accepted" and must)
                    or (result == "typed" and must and not names_the_field(message, field, mutated))):
                failures.append(f"{folded(field)} <- {cls} {mutated!r}: {result} {message[:160]}")
    with capsys.disabled():
        print(f"\n{path.relative_to(ROOT)}:", ", ".join(f"{c} {r} {n}" for (c, r), n in sorted(counts.items())))
    assert sum(counts.values()) > 20
    assert not failures, "\n".join(failures)
