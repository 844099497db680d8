"""Vehicle parameters as data: value, unit and meaning of every number, validated on load.

A vehicle's parameters live in a TOML file beside its module, one table per parameter::

    [rho]
    value = 1026.0
    unit = "kg/m^3"
    description = "density of sea water"
    min = 0.0            # optional bounds; exclusive unless *_inclusive = true
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import numpy as np

from uvsym.errors import ModelError

__all__ = ["Parameter", "ParameterSet", "load_parameters"]

_KNOWN_KEYS = {"value", "unit", "description", "min", "max", "min_inclusive", "max_inclusive"}


@dataclass(frozen=True)
class Parameter:
    """One named number or vector with its unit (SI, angles in rad unless the unit says deg)."""

    name: str
    value: float | tuple[float, ...]
    unit: str
    description: str

    def array(self) -> np.ndarray:
        """The value as a float numpy array (0-d for a scalar)."""
        return np.asarray(self.value, dtype=float)


class ParameterSet(Mapping):
    """Immutable mapping name -> Parameter; ``params.v("rho")`` gives the bare value."""

    def __init__(self, vehicle: str, parameters: Mapping[str, Parameter]):
        self.vehicle = vehicle
        self._parameters = MappingProxyType(dict(parameters))

    def __getitem__(self, name: str) -> Parameter:
        try:
            return self._parameters[name]
        except KeyError:
            raise ModelError(f"{self.vehicle}: no parameter named {name!r}") from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._parameters)

    def __len__(self) -> int:
        return len(self._parameters)

    def v(self, name: str):
        """Value of a parameter: a float, or a numpy array for a vector."""
        value = self[name].value
        return float(value) if isinstance(value, float) else np.array(value, dtype=float)

    def to_dict(self) -> dict:
        """JSON-friendly ``{name: {"value", "unit", "description"}}``."""
        return {
            name: {"value": list(p.value) if isinstance(p.value, tuple) else p.value,
                   "unit": p.unit, "description": p.description}
            for name, p in self._parameters.items()
        }


def _parse_value(vehicle: str, name: str, raw) -> float | tuple[float, ...]:
    """A finite float or a tuple of finite floats, else ModelError naming the parameter."""
    if isinstance(raw, bool) or not isinstance(raw, (int, float, list, tuple, np.ndarray)):
        raise ModelError(f"{vehicle}: parameter {name!r} must be a number or a list of numbers, got {raw!r}")
    if isinstance(raw, (list, tuple, np.ndarray)):
        values = tuple(_parse_value(vehicle, name, item) for item in raw)
        if any(isinstance(item, tuple) for item in values):
            raise ModelError(f"{vehicle}: parameter {name!r} must be a flat list of numbers")
        return values
    value = float(raw)
    if not math.isfinite(value):
        raise ModelError(f"{vehicle}: parameter {name!r} must be finite, got {value!r}")
    return value


def _check_bounds(vehicle: str, name: str, spec: Mapping, value) -> None:
    """ModelError naming the parameter when a value violates its declared bounds."""
    values = value if isinstance(value, tuple) else (value,)
    unit = spec.get("unit", "")
    if "min" in spec:
        low, inclusive = float(spec["min"]), bool(spec.get("min_inclusive", False))
        for item in values:
            if item < low or (item == low and not inclusive):
                relation = ">=" if inclusive else ">"
                raise ModelError(f"{vehicle}: parameter {name!r} = {item!r} {unit} must be {relation} {low!r}")
    if "max" in spec:
        high, inclusive = float(spec["max"]), bool(spec.get("max_inclusive", False))
        for item in values:
            if item > high or (item == high and not inclusive):
                relation = "<=" if inclusive else "<"
                raise ModelError(f"{vehicle}: parameter {name!r} = {item!r} {unit} must be {relation} {high!r}")


def load_parameters(vehicle: str, paths: list[Path], overrides: Mapping[str, object] | None = None) -> ParameterSet:
    """Read a vehicle's parameter files (in order) and apply overrides, validating every value.

    Raises
    ------
    ModelError
        For an unknown override name, a missing unit, a non-finite value, a value out of its
        declared bounds, or an override whose size differs from the default's.
    """
    table: dict[str, dict] = {}
    origin: dict[str, str] = {}
    for path in paths:
        with open(path, "rb") as handle:
            for name, spec in tomllib.load(handle).items():
                if name in table:
                    raise ModelError(f"{vehicle}: parameter {name!r} is defined in both {origin[name]} and {path.name}")
                table[name], origin[name] = spec, path.name
    overrides = dict(overrides or {})
    unknown = sorted(set(overrides) - set(table))
    if unknown:
        raise ModelError(f"{vehicle}: unknown parameter(s) {unknown}; known: {sorted(table)}")
    parameters = {}
    for name, spec in table.items():
        extra = set(spec) - _KNOWN_KEYS
        if extra or "value" not in spec or "unit" not in spec:
            raise ModelError(f"{vehicle}: parameter {name!r} in {origin[name]} needs 'value' and 'unit' "
                             f"(unexpected keys: {sorted(extra)})")
        default = _parse_value(vehicle, name, spec["value"])
        value = _parse_value(vehicle, name, overrides.get(name, spec["value"]))
        if isinstance(default, tuple) != isinstance(value, tuple) or (
                isinstance(value, tuple) and len(value) != len(default)):
            size = len(default) if isinstance(default, tuple) else 1
            raise ModelError(f"{vehicle}: parameter {name!r} must have {size} entr{'y' if size == 1 else 'ies'}, "
                             f"got {overrides[name]!r}")
        _check_bounds(vehicle, name, spec, value)
        parameters[name] = Parameter(name, value, spec["unit"], spec.get("description", ""))
    return ParameterSet(vehicle, parameters)
