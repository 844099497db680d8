"""The scenario file's schema, read off the validator itself so that it cannot drift.

:func:`scenario_schema` parses every shipped scenario with a recording
:class:`~uvsym.sim.fields.Fields` and returns each field the validator read: its path
(``faults[].kind``), type, default (``required``, ``none``, ``optional`` or the value) and rule.
Between fields, :func:`uvsym.sim.scenario.parse_scenario` also checks: ``step`` divides
``duration``; fault onsets lie in ``[0, duration)``; a fault's value is not the kind's healthy
value and a proportional factor is >= 0; each observer kind appears once, and a proportional
observer's ``tau_d`` is not zero in every channel; ``initial.eta`` keeps pitch away from 90 deg;
the run fits in memory.
"""

from __future__ import annotations

from uvsym.sim.scenario import parse_scenario, read_scenario_file, shipped_scenarios

__all__ = ["schema_markdown", "scenario_schema"]


def scenario_schema() -> list[dict]:
    """Every field the validator reads, in the order it reads them: dicts with ``field``, ``type``,
    ``default`` and ``rule``, collected over the shipped scenarios (which together use every table)."""
    schema: dict[str, dict] = {}
    for name, path in shipped_scenarios().items():
        parse_scenario(read_scenario_file(path), default_name=name, schema=schema)
    return list(schema.values())


def schema_markdown() -> str:
    """:func:`scenario_schema` as a Markdown table (what README.md shows and ``uvsym simulate --schema`` prints)."""
    rows = ["| field | type | default | rule |", "|---|---|---|---|"]
    rows += [f"| `{r['field']}` | {r['type']} | {r['default']} | {r['rule']} |" for r in scenario_schema()]
    return "\n".join(rows)
