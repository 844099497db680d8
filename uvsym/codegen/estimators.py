"""Any :class:`~uvsym.observers.base.Observer` as a Function to export to C, with its units.

``exported_observer(obs)`` gives the observer's step ``<name>_step(s, y, u, p) -> (s_next, out)``
as an :class:`~uvsym.codegen.package.Exported` whose argument documentation lists every signal
with its unit, so the generated header says what each array entry is.
"""

from __future__ import annotations

from uvsym.codegen.package import Exported
from uvsym.systems.signals import Signals

__all__ = ["exported_observer", "signal_units"]


def signal_units(what: str, group: Signals) -> str:
    """``"what: name (unit), ..."``: one line documenting an argument entry by entry."""
    entries = ", ".join(f"{name} ({unit})" for name, unit in zip(group.names, group.units))
    return f"{what}: {entries}" if group.size else f"{what}: none"


def exported_observer(obs) -> Exported:
    """The observer's step, documented signal by signal (state, measurements, inputs, parameters)."""
    return Exported(obs.step,
                    (signal_units("observer state", obs.state), signal_units("measurements", obs.reads_y),
                     signal_units("inputs", obs.reads_u), signal_units("parameters", obs.params)),
                    (signal_units("next observer state", obs.state), signal_units("published", obs.publishes)),
                    obs.description or f"{obs.name}: one step of {obs.dt:g} s")
