"""Arguments of exported Functions documented entry by entry, with units written unambiguously.

An :class:`Entries` says what an argument is and names each entry with its unit, so a header
and a manifest can list them (``eta[6]``: ``[0] x [m]``, ..., ``[5] psi [rad]``) instead of prose;
as one line it reads ``eta: x (m), ..., psi (rad)``.
Units are written with an explicit product sign: ``N*m`` (a moment), ``(N*m)/s`` (its rate),
never ``N m/s``, which reads either way. :func:`unit_symbol` turns a space-separated unit
(``"N m"``) into that form; :func:`per_second` gives the unit of a time derivative.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from uvsym.errors import CodegenError

__all__ = ["Entries", "entries_of", "per_second", "unit_symbol"]

_SIMPLE = re.compile(r"[A-Za-z]+(\^-?[0-9]+)?")


def unit_symbol(unit: str) -> str:
    """``"N m"`` -> ``"N*m"``: factors separated by white space joined with ``*``; ``"-"`` stays."""
    unit = str(unit).strip()
    return "*".join(unit.split()) if unit else "-"


def per_second(unit: str) -> str:
    """The unit of the time derivative of a quantity in ``unit``: ``1/s``, ``N/s``, ``(N*m)/s``."""
    unit = unit_symbol(unit)
    if unit == "-":
        return "1/s"
    return f"{unit}/s" if _SIMPLE.fullmatch(unit) else f"({unit})/s"


@dataclass(frozen=True)
class Entries:
    """One argument: what it is (``"eta"``), each entry's name and unit (one per entry).

    Units go through :func:`unit_symbol` (``"N m"`` is stored as ``"N*m"``).
    """

    what: str
    names: tuple[str, ...]
    units: tuple[str, ...]

    def __post_init__(self):
        names, units = tuple(map(str, self.names)), tuple(unit_symbol(u) for u in self.units)
        if len(names) != len(units):
            raise CodegenError(f"argument {self.what!r}: {len(units)} units for {len(names)} entries")
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "units", units)

    def __str__(self) -> str:
        listed = ", ".join(f"{name} ({unit})" for name, unit in zip(self.names, self.units))
        return f"{self.what}: {listed}" if self.names else f"{self.what}: none"


def entries_of(what: str, group) -> Entries:
    """The entries of a :class:`~uvsym.systems.signals.Signals` group (its names and units)."""
    return Entries(what, group.names, group.units)

