"""Typed access to one table of a TOML file: every read names its field (``faults[2].kind``) in
the :class:`~uvsym.errors.ScenarioError` it raises, and keys nobody read are refused.

Given a ``schema`` dict, every read also records the field it reads (``faults[].kind``: type,
default, rule), so that the documented schema is what the validator reads and cannot drift.
"""

from __future__ import annotations

import difflib
import math
import re

import numpy as np

from uvsym.errors import ScenarioError

__all__ = ["Fields"]


class Fields:
    """Typed access to one TOML table that remembers its path and rejects unknown keys."""

    def __init__(self, data, path: str, schema: dict | None = None):
        if not isinstance(data, dict):
            raise ScenarioError(f"{path or 'scenario'}: expected a table, got {type(data).__name__}")
        self.data, self.path, self.used, self.schema = data, path, set(), schema

    def _name(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def _record(self, key: str, kind: str, default, rule: str = "", shown: str | None = None) -> None:
        if self.schema is not None:
            field = re.sub(r"\[\d+\]", "[]", self._name(key))
            if shown is None:
                shown = "required" if default is None else (
                    "zeros" if isinstance(default, list) and default and not any(default) else
                    f"{default:g}" if isinstance(default, float) else repr(default))
            self.schema.setdefault(field, {"field": field, "type": kind, "default": shown, "rule": rule})

    def _misspelt(self, key: str) -> str:
        """`` (is 'durration' a misspelt 'duration'?)`` when a key of the table is close to ``key``."""
        near = difflib.get_close_matches(key, [str(k) for k in self.data if k != key], n=1, cutoff=0.75)
        return f" (is {near[0]!r} a misspelt {key!r}?)" if near else ""

    def unread_hint(self) -> str:
        """`` (is 'timesx' a misspelt 'times'?)`` for a key not read so far that is close to one read: added to
        an error raised while the table was being read, whose cause may be the misspelling."""
        for key in sorted(map(str, set(self.data) - self.used)):
            near = difflib.get_close_matches(key, sorted(self.used), n=1, cutoff=0.75)
            if near:
                return f" (is {self._name(key)!r} a misspelt {near[0]!r}?)"
        return ""

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default=None, kind: str = "any", rule: str = "", shown: str | None = None):
        """The value as parsed; ``kind``, ``rule`` and ``shown`` (the default as the schema gives it,
        e.g. ``none`` for an optional field) only describe it for the schema."""
        self._record(key, kind, default, rule, shown)
        self.used.add(key)
        return self.data.get(key, default)

    def describe(self, key: str, kind: str, rule: str, default: str = "required") -> None:
        """Describe, for the schema only, a field read another way (e.g. keys that are data)."""
        self._record(key, kind, None, rule, shown=default)

    def empty(self, key: str) -> Fields:
        """An empty table standing for the optional table ``key`` (its fields' defaults apply)."""
        return Fields({}, self._name(key), self.schema)

    def number(self, key: str, default=None, *, positive: bool = False, minimum: float | None = None) -> float:
        rule = "> 0" if positive else (f">= {minimum:g}" if minimum is not None else "finite")
        value = self.raw(key, default, "number", rule)
        if value is None:
            raise ScenarioError(f"{self._name(key)}: required number is missing{self._misspelt(key)}")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ScenarioError(f"{self._name(key)}: expected a finite number, got {value!r}")
        if positive and not value > 0:
            raise ScenarioError(f"{self._name(key)}: must be positive, got {value}")
        if minimum is not None and value < minimum:
            raise ScenarioError(f"{self._name(key)}: must be >= {minimum}, got {value}")
        return float(value)

    def integer(self, key: str, default=None, *, minimum: int = 0, unit: str = "") -> int:
        """An integer >= minimum (bools refused); ``unit`` only describes it (``samples``)."""
        rule = f">= {minimum}" + (f" ({unit})" if unit else "")
        value = self.raw(key, default, "integer", rule)
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            missing = self._misspelt(key) if value is None else ""
            raise ScenarioError(f"{self._name(key)}: expected an integer {rule}, got {value!r}{missing}")
        return value

    def text(self, key: str, default=None, choices: tuple[str, ...] | None = None) -> str:
        value = self.raw(key, default, "string", "" if choices is None else "one of " + ", ".join(choices))
        if not isinstance(value, str):
            missing = self._misspelt(key) if value is None else ""
            raise ScenarioError(f"{self._name(key)}: expected a string, got {value!r}{missing}")
        if choices is not None and value not in choices:
            near = difflib.get_close_matches(value, list(choices), n=1)
            raise ScenarioError(f"{self._name(key)}: unknown value {value!r}"
                                + (f" (did you mean {near[0]!r}?)" if near else "") + f"; known: {', '.join(choices)}")
        return value

    def label(self, key: str, default=None, *, spaces: bool = False) -> str:
        """A name: a non-empty string, without white space unless ``spaces`` (a scenario's name may have
        them; a detector's names result columns)."""
        value = self.text(key, default)
        if not value.strip() or (not spaces and any(c.isspace() for c in value)):
            rule = "a non-empty string" + ("" if spaces else " without white space")
            raise ScenarioError(f"{self._name(key)}: a name must be {rule}, got {value!r}")
        return value

    def vector(self, key: str, size: int, default=None) -> np.ndarray | None:
        self._record(key, "list of numbers", default, "finite, one per entry", None if default is not None else "none")
        self.used.add(key)
        value = self.data.get(key, default)
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
        self._record(key, "table", None, shown="optional")
        self.used.add(key)
        value = self.data.get(key)
        return None if value is None else Fields(value, self._name(key), self.schema)

    def tables(self, key: str) -> list[Fields]:
        self._record(key, "array of tables", None, f"[[{self._name(key)}]]", shown="none")
        self.used.add(key)
        value = self.data.get(key, [])
        if not isinstance(value, list):
            raise ScenarioError(f"{self._name(key)}: expected an array of tables ([[{key}]])")
        return [Fields(item, f"{self._name(key)}[{i}]", self.schema) for i, item in enumerate(value)]

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            near = difflib.get_close_matches(unknown[0], sorted(self.used), n=1)
            raise ScenarioError(f"{self._name(unknown[0])}: unknown field" + (f" (did you mean {near[0]!r}?)" if near
                                                                                else "")
                                + f"; known here: {', '.join(sorted(self.used))}")
