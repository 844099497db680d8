"""The integrator options a run is given (``simulate(..., options=...)``, ``simulate_system``), checked before
the run: a dict for a CasADi integrator method, with finite numbers (SUNDIALS loops forever on a NaN
tolerance). Option names are CasADi's to check: it refuses an unknown one when the integrator is built."""

from __future__ import annotations

import math
from collections.abc import Mapping

from uvsym.errors import SimulationError

__all__ = ["METHODS", "checked_options"]

METHODS = ("fast", "cvodes", "idas", "rk", "collocation")  # the compiled fixed-step RK4, then CasADi's integrators


def checked_options(method: str, options) -> dict:
    """``options`` (None: none) as a dict for ``method``'s CasADi integrator; SimulationError for options given to
    the ``fast`` method, for what is not a mapping with text keys, and for a NaN or infinite number in it."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise SimulationError(f"options must be a dict of CasADi integrator options, got {type(options).__name__} "
                              f"{options!r:.60}")
    if options and method == "fast":
        raise SimulationError(f"options {sorted(map(str, options))} go to a CasADi integrator (cvodes, idas, rk, "
                              "collocation); the fast method takes none (its steps per sample: substeps)")
    options = dict(options)
    _check_entries(options, "options")
    return options


def _check_entries(options: dict, where: str) -> None:
    for key, value in options.items():
        if not isinstance(key, str):
            raise SimulationError(f"{where}: option names are text, got {key!r}")
        if isinstance(value, Mapping):
            _check_entries(dict(value), f"{where}[{key!r}]")
        elif isinstance(value, float) and not math.isfinite(value):
            raise SimulationError(f"{where}[{key!r}] is {value}; an integrator option must be finite")
