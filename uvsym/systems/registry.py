"""The plant library: plants beyond the marine vehicles, and every marine vehicle as a System.

``plant(name)`` builds (and caches) a plant of :data:`PLANTS` or, for a vehicle name,
``uvsym.vehicle(name).as_system()`` (``plant("otter3dof")`` is Li et al. 2025's
Otter). The vehicle library is imported when first needed: it builds on this package.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

from uvsym.errors import UnknownNameError
from uvsym.systems.plants import induction_motor, quadrotor, rov_yaw
from uvsym.systems.system import System

__all__ = ["PLANTS", "plant", "plant_names"]

PLANTS: dict[str, tuple[str, Callable[..., System]]] = {
    module.NAME: (module.DESCRIPTION, module.build) for module in (induction_motor, quadrotor, rov_yaw)
}


def _vehicle_names() -> list[str]:
    from uvsym.models.registry import vehicle_names

    return vehicle_names()


def plant_names() -> list[str]:
    """Names of every plant: the plants of :data:`PLANTS`, then the marine vehicles."""
    return list(PLANTS) + _vehicle_names()


@functools.lru_cache(maxsize=32)
def _build_cached(name: str, overrides: tuple) -> System:
    options = {key: (list(value) if isinstance(value, tuple) else value) for key, value in overrides}
    if name in PLANTS:
        return PLANTS[name][1](**options)
    from uvsym.models.registry import vehicle

    return vehicle(name, **options).as_system()


def plant(name: str, **overrides) -> System:
    """The System of a plant or marine vehicle; keyword arguments override its parameters (and
    build options such as the induction motor's ``printed_typo``).

    Raises
    ------
    UnknownNameError
        For a name that is neither a plant nor a vehicle (the message lists the known names).
    ModelError
        For an override that is unknown, of the wrong size, non-finite or out of bounds.
    """
    if name not in PLANTS and name not in _vehicle_names():
        raise UnknownNameError(f"unknown plant {name!r}; known plants: {', '.join(plant_names())}")
    from uvsym.models.registry import built_with

    return built_with(_build_cached, name, "plant", overrides)
