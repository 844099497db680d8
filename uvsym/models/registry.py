"""The vehicle library: names -> builders, and ``vehicle(name)`` returning a frozen Model."""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from uvsym.errors import ModelError, UnknownNameError, UvsymError
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
    return built_with(_build_cached, name, "model", overrides)


def built_with(build: Callable, name: str, what: str, overrides: dict):
    """``build(name, frozen overrides)`` (each override hashable by :func:`frozen_override`); ModelError
    naming the overrides when the equations cannot take them (a square root of a negative, ...)."""
    frozen = tuple(sorted((key, frozen_override(name, key, value)) for key, value in overrides.items()))
    try:
        return build(name, frozen)
    except UvsymError:
        raise
    except (ArithmeticError, ValueError, TypeError, np.linalg.LinAlgError) as exc:
        shown = ", ".join(f"{key}={value!r}" for key, value in overrides.items())
        raise ModelError(f"{name}: the {what} cannot be built with {shown}: {type(exc).__name__}: {exc}") from None


def frozen_override(owner: str, key: str, value):
    """An override as a hashable number or tuple of numbers; ModelError naming it when it is neither."""
    if isinstance(value, (list, tuple, np.ndarray)):
        try:
            return tuple(np.asarray(value, dtype=float).ravel().tolist())
        except (TypeError, ValueError):
            pass
    elif isinstance(value, (int, float, str, bool)) or value is None:
        return value
    raise ModelError(f"{owner}: parameter {key!r} must be a number or a list of numbers, got {value!r:.60}")
