"""Named, unit-carrying signal groups: the vocabulary every stage shares.

A :class:`Signals` is an ordered group of scalar signals (a system's states, inputs, an
observer's outputs, ...), each with a name, a unit and a one-line description. Stages address
signals by name, never by position; positions are looked up here, with an error that names the
unknown signal and lists the known ones.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np

from uvsym.errors import ModelError, UnknownNameError

__all__ = ["Signals", "signals"]


@dataclass(frozen=True)
class Signals:
    """An ordered group of named scalar signals.

    names: unique, non-empty, without white space (``"i_sq"``, ``"f_hat.X"``); units: one per
    name (SI, ``"-"`` for dimensionless); descriptions: one per name (empty strings by default);
    group: what the group is, used in error messages (``"state"``, ``"input"``, ...).
    """

    names: tuple[str, ...] = ()
    units: tuple[str, ...] = ()
    descriptions: tuple[str, ...] = ()
    group: str = "signal"

    def __post_init__(self):
        names, units = tuple(self.names), tuple(self.units)
        descriptions = tuple(self.descriptions) or ("",) * len(names)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "units", units)
        object.__setattr__(self, "descriptions", descriptions)
        for name in names:
            if not isinstance(name, str) or not name or any(c.isspace() for c in name):
                raise ModelError(f"{self.group} name {name!r} must be a non-empty string without white space")
        repeated = sorted({name for name in names if names.count(name) > 1})
        if repeated:
            raise ModelError(f"{self.group} names must be unique; repeated: {repeated}")
        for what, seq in (("units", units), ("descriptions", descriptions)):
            if len(seq) != len(names):
                raise ModelError(f"{self.group} signals {list(names)}: {len(seq)} {what} for {len(names)} names")

    @property
    def size(self) -> int:
        """Number of scalar signals."""
        return len(self.names)

    def __len__(self) -> int:
        return len(self.names)

    def __iter__(self) -> Iterator[str]:
        return iter(self.names)

    def __contains__(self, name) -> bool:
        return name in self.names

    def index(self, name: str) -> int:
        """Position of ``name``; UnknownNameError naming it and listing the group's names."""
        try:
            return self.names.index(name)
        except ValueError:
            known = ", ".join(self.names) or "none"
            raise UnknownNameError(f"no {self.group} named {name!r}; known: {known}") from None

    def indices(self, names: Iterable[str]) -> list[int]:
        """Positions of several names, in the order given."""
        return [self.index(name) for name in names]

    def unit(self, name: str) -> str:
        """Unit of one signal."""
        return self.units[self.index(name)]

    def select(self, names: Iterable[str]) -> Signals:
        """The sub-group of the given names, in the order given."""
        picked = self.indices(names)
        return Signals(tuple(self.names[i] for i in picked), tuple(self.units[i] for i in picked),
                       tuple(self.descriptions[i] for i in picked), self.group)

    def renamed(self, prefix: str = "", suffix: str = "", group: str | None = None) -> Signals:
        """The same signals named ``prefix + name + suffix`` (e.g. ``"f_hat."``, ``"_hat"``)."""
        return Signals(tuple(f"{prefix}{name}{suffix}" for name in self.names), self.units, self.descriptions,
                       group or self.group)

    def __add__(self, other: Signals) -> Signals:
        return Signals(self.names + other.names, self.units + other.units, self.descriptions + other.descriptions,
                       self.group if self.group == other.group else "signal")

    def vector(self, values, what: str | None = None) -> np.ndarray:
        """A finite float vector of this group's size from ``values`` (sequence, array or
        ``{name: value}`` mapping that names every signal); ModelError naming the problem."""
        what = what or self.group
        if isinstance(values, dict):
            unknown = sorted(set(values) - set(self.names))
            if unknown:
                raise UnknownNameError(f"no {self.group} named {unknown}; known: {', '.join(self.names) or 'none'}")
            missing = [name for name in self.names if name not in values]
            if missing:
                raise ModelError(f"{what}: no value for {missing}")
            values = [values[name] for name in self.names]
        try:
            array = np.asarray(values, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise ModelError(f"{what} must be numbers, got {values!r}") from None
        if array.size != self.size:
            raise ModelError(f"{what} must have {self.size} entries ({', '.join(self.names)}), got {array.size}")
        bad = [name for name, value in zip(self.names, array) if not np.isfinite(value)]
        if bad:
            raise ModelError(f"{what}: non-finite value for {bad}")
        return array

    def to_list(self) -> list[dict]:
        """JSON-friendly ``[{"name", "unit", "description"}]``."""
        return [{"name": n, "unit": u, "description": d} for n, u, d in zip(self.names, self.units, self.descriptions)]


def signals(*entries: tuple[str, str] | tuple[str, str, str], group: str = "signal") -> Signals:
    """``signals(("i_sq", "A", "q-axis stator current"), ...)``: a group from (name, unit[, description])."""
    for entry in entries:
        if not isinstance(entry, tuple) or len(entry) not in (2, 3):
            raise ModelError(f"{group} entry {entry!r} must be (name, unit) or (name, unit, description)")
    return Signals(tuple(e[0] for e in entries), tuple(e[1] for e in entries),
                   tuple(e[2] if len(e) == 3 else "" for e in entries), group)
