"""Any :class:`~uvsym.observers.base.Observer` as a Function to export to C, with its units.

``exported_observer(obs)`` gives the observer's step ``<name>_step(s, y, u, p) -> (s_next, out)``
as an :class:`~uvsym.codegen.package.Exported` whose arguments list every signal with its unit,
so the generated header says what each array entry is. ``observer_example(obs, result, ...)``
takes the data for the package's ``main.c`` and float check from a simulation the observer ran in.
"""

from __future__ import annotations

import numpy as np

from uvsym.codegen.arguments import entries_of
from uvsym.codegen.example import Example
from uvsym.codegen.package import Exported
from uvsym.errors import CodegenError
from uvsym.systems.signals import Signals

__all__ = ["exported_observer", "observer_example", "signal_units"]


def signal_units(what: str, group: Signals) -> str:
    """``"what: name (unit), ..."``: one line documenting an argument entry by entry."""
    return str(entries_of(what, group))


def exported_observer(obs) -> Exported:
    """The observer's step, documented signal by signal (state, measurements, inputs, parameters)."""
    return Exported(obs.step,
                    (entries_of("observer state", obs.state), entries_of("measurements", obs.reads_y),
                     entries_of("inputs", obs.reads_u), entries_of("parameters", obs.params)),
                    (entries_of("next observer state", obs.state), entries_of("published", obs.publishes)),
                    obs.description or f"{obs.name}: one step of {obs.dt:g} s")


def _columns(result, names, what: str, groups: tuple[str, ...]) -> np.ndarray:
    """(samples, len(names)): each named signal from the first of ``groups`` of ``result`` that has it."""
    columns = []
    for name in names:
        found = next((g for g in groups if g in result.signals and name in result.signals[g].labels), None)
        if found is None:
            raise CodegenError(f"observer example: the simulation logged no {what} {name!r} (looked in "
                               f"{', '.join(groups)})")
        columns.append(result[found][name])
    return np.column_stack(columns) if columns else np.empty((len(result.t), 0))


def observer_example(obs, result, start: float, steps: int, source: str) -> Example:
    """``steps`` samples of ``obs``'s step from ``result`` (a SimResult of a loop the observer ran in),
    the first at time ``start`` (s), one every ``obs.dt``: its state (published by the observer), the
    measurements ``y``, the inputs ``u`` and its parameter values. ``source``: one line, where from."""
    t = np.asarray(result.t, dtype=float)
    rows = np.rint((start + obs.dt * np.arange(steps) - t[0]) / (t[1] - t[0])).astype(int)
    if steps < 1 or rows[0] < 0 or rows[-1] >= len(t):
        raise CodegenError(f"observer example: {steps} steps of {obs.dt:g} s from t = {start:g} s do not fit the "
                           f"simulation's {t[0]:g} .. {t[-1]:g} s")
    state = _columns(result, obs.state.names, "observer state", (obs.name,))
    y = _columns(result, obs.reads_y.names, "measurement", ("y",))
    u = _columns(result, obs.reads_u.names, "input", ("u",))
    p = np.tile(np.asarray(obs.p0, dtype=float).ravel(), (len(rows), 1))
    return Example(obs.step.name(), (state[rows], y[rows], u[rows], p), source)
