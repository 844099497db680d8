"""The experiment as a TOML scenario (``study = "usv-fukf-mmae"``), validated field by field."""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from uvsym.errors import ScenarioError
from uvsym.sim.controllers import LineOfSight

__all__ = ["Scenario", "ThrusterFault", "parse", "load", "SHIPPED"]

SHIPPED = {"otter_thruster_faults": Path(__file__).resolve().parent / "scenarios" / "otter_thruster_faults.toml"}
VEHICLES = ("otter3dof",)
THRUSTERS = ("T_L", "T_R")
STATES = ("x", "y", "psi", "u", "v", "r")
KEYS = {"": {"vehicle", "dt", "duration", "seed", "path", "disturbance", "noise", "faults"},
        "path": {"waypoints", "speed", "lookahead", "turn_radius"}, "disturbance": {"alpha_d"},
        "noise": set(STATES), "faults": {"thruster", "efficiency", "onset", "end"}}


@dataclass(frozen=True)
class ThrusterFault:
    """``thruster`` delivers ``efficiency`` times its command on [onset, end) s."""

    thruster: str
    efficiency: float
    onset: float
    end: float


@dataclass(frozen=True)
class Scenario:
    """vehicle; dt, duration (s); seed; path (LineOfSight) and speed (m/s); alpha_d (3,) in N, N,
    N m; noise: state -> standard deviation; faults."""

    name: str
    vehicle: str
    dt: float
    duration: float
    seed: int
    path: LineOfSight
    speed: float
    alpha_d: tuple[float, float, float]
    noise: dict
    faults: tuple[ThrusterFault, ...]


def _number(table: dict, key: str, where: str, low: float = -math.inf, low_open: bool = False) -> float:
    if key not in table:
        raise ScenarioError(f"{where}{key}: missing")
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ScenarioError(f"{where}{key}: expected a finite number, got {value!r}")
    if value < low or (low_open and value == low):
        raise ScenarioError(f"{where}{key}: must be {'>' if low_open else '>='} {low:g}, got {value!r}")
    return float(value)


def _table(table: dict, key: str) -> dict:
    value = table.get(key)
    if not isinstance(value, dict):
        raise ScenarioError(f"{key}: expected a table, got {value!r}")
    _known(value, key)
    return value


def _known(table: dict, section: str) -> None:
    unknown = sorted(set(table) - KEYS[section])
    if unknown:
        prefix = f"{section}." if section else ""
        raise ScenarioError(f"{prefix}{unknown[0]}: unknown field; known: {', '.join(sorted(KEYS[section]))}")


def _fault(entry, k: int, duration: float) -> ThrusterFault:
    where = f"faults[{k}]."
    if not isinstance(entry, dict):
        raise ScenarioError(f"faults[{k}]: expected a table, got {entry!r}")
    unknown = sorted(set(entry) - KEYS["faults"])
    if unknown:
        raise ScenarioError(f"{where}{unknown[0]}: unknown field; known: {', '.join(sorted(KEYS['faults']))}")
    if entry.get("thruster") not in THRUSTERS:
        raise ScenarioError(f"{where}thruster: unknown value {entry.get('thruster')!r}; known: {', '.join(THRUSTERS)}")
    efficiency = _number(entry, "efficiency", where, 0.0)
    if efficiency >= 1.0:
        raise ScenarioError(f"{where}efficiency: must be in [0, 1) (1 is healthy), got {efficiency!r}")
    onset = _number(entry, "onset", where, 0.0)
    end = _number(entry, "end", where, onset, low_open=True)
    if end > duration:
        raise ScenarioError(f"{where}end: {end:g} s is after the run ends ({duration:g} s)")
    return ThrusterFault(entry["thruster"], efficiency, onset, end)


def parse(table: dict, name: str) -> Scenario:
    """A validated Scenario from the parsed TOML (without ``study``); ScenarioError naming the field."""
    _known(table, "")
    vehicle = table.get("vehicle", "otter3dof")
    if vehicle not in VEHICLES:
        raise ScenarioError(f"vehicle: unknown value {vehicle!r}; known: {', '.join(VEHICLES)} (twin thrusters)")
    dt = _number(table, "dt", "", 0.0, low_open=True)
    duration = _number(table, "duration", "", dt)
    seed = table.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ScenarioError(f"seed: expected a non-negative integer, got {seed!r}")
    path = _table(table, "path")
    speed = _number(path, "speed", "path.", 0.0, low_open=True)
    try:
        los = LineOfSight(tuple(map(tuple, path.get("waypoints", ()))), lookahead=_number(path, "lookahead", "path."),
                          turn_radius=_number(path, "turn_radius", "path.", 0.0))
    except (TypeError, ValueError) as exc:
        raise ScenarioError(exc if isinstance(exc, ScenarioError) else f"path.waypoints: {exc}") from None
    disturbance = _table(table, "disturbance")
    alpha_d = disturbance.get("alpha_d")
    if not (isinstance(alpha_d, list) and len(alpha_d) == 3):
        raise ScenarioError(f"disturbance.alpha_d: expected three amplitudes (N, N, N m), got {alpha_d!r}")
    alpha_d = tuple(_number({"alpha_d": a}, "alpha_d", "disturbance.", 0.0) for a in alpha_d)
    noise_table = _table(table, "noise")
    noise = {state: _number(noise_table, state, "noise.", 0.0, low_open=True) for state in STATES}
    faults = table.get("faults", [])
    if not isinstance(faults, list):
        raise ScenarioError(f"faults: expected an array of tables, got {faults!r}")
    return Scenario(name, vehicle, dt, duration, seed, los, speed, alpha_d, noise,
                    tuple(_fault(entry, k, duration) for k, entry in enumerate(faults)))


def load(path: Path, name: str) -> Scenario:
    """The scenario of a TOML file (its ``study`` key set aside)."""
    table = tomllib.loads(Path(path).read_text())
    table.pop("study", None)
    return parse(table, name)
