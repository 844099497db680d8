"""The scenario files' schemas, read off the validators themselves so that they cannot drift.

:func:`scenario_schema` parses every shipped vehicle scenario with a recording
:class:`~uvsym.sim.fields.Fields` and returns each field the validator read: its path
(``faults[].kind``), type, default (``required``, ``none``, ``optional`` or the value) and rule.
Between fields, :func:`uvsym.sim.scenario.parse_scenario` also checks: ``step`` divides
``duration``; fault onsets lie in ``[0, duration)``; a fault's value is not the kind's healthy
value and a proportional factor is >= 0; each observer kind appears once, and a proportional
observer's ``tau_d`` is not zero in every channel; ``initial.eta`` keeps pitch away from 90 deg;
the run fits in memory. :func:`scenario_schema` with ``kind="plant"`` does the same over every
shipped scenario over a plant (uvsym's and the installed derivations'), with each block and detector
type's own fields under ``blocks[<type>]`` and ``detectors[<type>]``.
"""

from __future__ import annotations

from uvsym.sim.scenario import parse_scenario, read_scenario_file
from uvsym.sim.shipped import every_shipped_scenario, shipped_scenarios

__all__ = ["schema_markdown", "scenario_schema"]


def scenario_schema(kind: str = "vehicle") -> list[dict]:
    """Every field the validator of ``kind`` ("vehicle" or "plant") reads, in the order it reads them:
    dicts with ``field``, ``type``, ``default`` and ``rule``, collected over the shipped scenarios of
    that kind (which together use every table)."""
    from uvsym.sim.system_scenario import is_system_scenario, parse_system_scenario

    schema: dict[str, dict] = {}
    if kind == "vehicle":
        for name, path in shipped_scenarios().items():
            parse_scenario(read_scenario_file(path), default_name=name, schema=schema)
    else:
        for name, path in every_shipped_scenario().items():
            table = read_scenario_file(path)
            if is_system_scenario(table):
                parse_system_scenario(table, default_name=name, root=path.parent, schema=schema)
    return list(schema.values())


def schema_markdown(kind: str = "vehicle") -> str:
    """:func:`scenario_schema` as a Markdown table (what README.md shows and ``uvsym simulate --schema
    [kind]`` prints)."""
    rows = ["| field | type | default | rule |", "|---|---|---|---|"]
    rows += [f"| `{r['field']}` | {r['type']} | {r['default']} | {r['rule']} |" for r in scenario_schema(kind)]
    return "\n".join(rows)
