"""The study's shipped scenario files (the scenario format of :mod:`uvsym.sim.system_scenario`)
and what the report reads of them: the thruster faults as efficiencies, a block's table."""

from __future__ import annotations

import copy
import tomllib
from dataclasses import dataclass
from pathlib import Path

from uvsym.errors import ScenarioError
from uvsym.sim.system_scenario import SystemScenario, parse_system_scenario

__all__ = ["SHIPPED", "SCENARIO", "ThrusterFault", "read", "parsed", "block_table", "thruster_faults"]

FOLDER = Path(__file__).resolve().parent / "scenarios"
SCENARIO = "otter_thruster_faults"
SHIPPED = {SCENARIO: FOLDER / f"{SCENARIO}.toml"}
EFFICIENCY = {"proportional": lambda value: value, "loss_of_effectiveness": lambda value: 1.0 - value}


@dataclass(frozen=True)
class ThrusterFault:
    """``thruster`` delivers ``efficiency`` times its command on [onset, end) s (at full profile)."""

    thruster: str
    efficiency: float
    onset: float
    end: float


def read(name: str = SCENARIO) -> dict:
    """The parsed TOML of the shipped scenario ``name`` (a fresh copy, free to edit)."""
    return copy.deepcopy(tomllib.loads(SHIPPED[name].read_text()))


def parsed(table: dict, name: str = SCENARIO) -> SystemScenario:
    """The validated scenario of a table read from this folder (its plant found from here)."""
    return parse_system_scenario(table, default_name=name, root=FOLDER)


def block_table(table: dict, name: str) -> dict:
    """The ``[[blocks]]`` table called ``name``; ScenarioError naming the blocks otherwise."""
    for entry in table.get("blocks", []):
        if entry.get("name") == name:
            return entry
    raise ScenarioError(f"blocks: no block {name!r}; blocks: {', '.join(b.get('name', '?') for b in table['blocks'])}")


def thruster_faults(scenario: SystemScenario) -> tuple[ThrusterFault, ...]:
    """The scenario's efficiency faults (kinds proportional and loss_of_effectiveness) by thruster."""
    names = scenario.plant.u.names
    return tuple(ThrusterFault(names[f.actuator], EFFICIENCY[f.kind](f.value), f.profile.onset, f.profile.end)
                 for f in scenario.actuator_faults if f.kind in EFFICIENCY)
