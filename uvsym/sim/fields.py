"""Typed access to one table of a TOML file: every read names its field (``faults[2].kind``) in
the :class:`~uvsym.errors.ScenarioError` it raises, and keys nobody read are refused."""

from __future__ import annotations

import math

import numpy as np

from uvsym.errors import ScenarioError

__all__ = ["Fields"]


class Fields:
    """Typed access to one TOML table that remembers its path and rejects unknown keys."""

    def __init__(self, data, path: str):
        if not isinstance(data, dict):
            raise ScenarioError(f"{path or 'scenario'}: expected a table, got {type(data).__name__}")
        self.data, self.path, self.used = data, path, set()

    def _name(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default=None):
        self.used.add(key)
        return self.data.get(key, default)

    def number(self, key: str, default=None, *, positive: bool = False, minimum: float | None = None) -> float:
        value = self.raw(key, default)
        if value is None:
            raise ScenarioError(f"{self._name(key)}: required number is missing")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ScenarioError(f"{self._name(key)}: expected a finite number, got {value!r}")
        if positive and not value > 0:
            raise ScenarioError(f"{self._name(key)}: must be positive, got {value}")
        if minimum is not None and value < minimum:
            raise ScenarioError(f"{self._name(key)}: must be >= {minimum}, got {value}")
        return float(value)

    def text(self, key: str, default=None, choices: tuple[str, ...] | None = None) -> str:
        value = self.raw(key, default)
        if not isinstance(value, str):
            raise ScenarioError(f"{self._name(key)}: expected a string, got {value!r}")
        if choices is not None and value not in choices:
            raise ScenarioError(f"{self._name(key)}: unknown value {value!r}; known: {', '.join(choices)}")
        return value

    def vector(self, key: str, size: int, default=None) -> np.ndarray | None:
        value = self.raw(key, default)
        if value is None:
            return None
        array = np.asarray(value, dtype=object)
        if array.shape != (size,) or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            raise ScenarioError(f"{self._name(key)}: expected a list of {size} numbers, got {value!r}")
        result = np.asarray(value, dtype=float)
        if not np.all(np.isfinite(result)):
            raise ScenarioError(f"{self._name(key)}: entries must be finite, got {value!r}")
        return result

    def table(self, key: str) -> Fields | None:
        value = self.raw(key)
        return None if value is None else Fields(value, self._name(key))

    def tables(self, key: str) -> list[Fields]:
        value = self.raw(key, [])
        if not isinstance(value, list):
            raise ScenarioError(f"{self._name(key)}: expected an array of tables ([[{key}]])")
        return [Fields(item, f"{self._name(key)}[{i}]") for i, item in enumerate(value)]

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise ScenarioError(f"{self._name(unknown[0])}: unknown field; known here: {', '.join(sorted(self.used))}")
