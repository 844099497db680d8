"""The vehicle library: names -> builders, and ``vehicle(name)`` returning a frozen Model."""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from uvsym.errors import UnknownNameError
from uvsym.models.model import Model
from uvsym.models.vehicles import docking_auv, otter, otter3dof, remus100, torpedo

__all__ = ["VEHICLES", "vehicle", "vehicle_names"]

VEHICLES: dict[str, tuple[str, Callable[..., Model]]] = {
    module.NAME: (module.DESCRIPTION, module.build)
    for module in (remus100, torpedo, docking_auv, otter, otter3dof)
}


def vehicle_names() -> list[str]:
    """Names of every vehicle in the library, in the library's order."""
    return list(VEHICLES)


@functools.lru_cache(maxsize=32)
def _build_cached(name: str, overrides: tuple) -> Model:
    return VEHICLES[name][1](**{key: (list(value) if isinstance(value, tuple) else value) for key, value in overrides})


def vehicle(name: str, **overrides) -> Model:
    """The frozen Model of a library vehicle; keyword arguments override its parameters.

    Raises
    ------
    UnknownNameError
        For a name not in the library (the message lists the known names).
    ModelError
        For an override that is unknown, of the wrong size, non-finite or out of bounds,
        or that makes the mass matrix indefinite.
    """
    if name not in VEHICLES:
        raise UnknownNameError(f"unknown vehicle {name!r}; known vehicles: {', '.join(VEHICLES)}")
    frozen = tuple(sorted((key, tuple(np.asarray(value, dtype=float).ravel().tolist())
                           if isinstance(value, (list, tuple, np.ndarray)) else value)
                          for key, value in overrides.items()))
    return _build_cached(name, frozen)
