"""Every public function and class (the ``__all__`` of each uvsym module, where it is defined) has a
docstring, and a NumPy-style Parameters section names exactly the parameters of its signature."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re

import pytest

import uvsym

MODULES = sorted(m.name for m in pkgutil.walk_packages(uvsym.__path__, "uvsym.")
                 if not any(part.startswith("_") for part in m.name.split(".")))


def public_objects():
    """(module.name, object) for each function and class a module's __all__ names and the module defines."""
    for name in MODULES:
        module = importlib.import_module(name)
        for attr in getattr(module, "__all__", ()):
            obj = getattr(module, attr)
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and obj.__module__ == name:
                yield f"{name}.{attr}", obj


def documented_parameters(doc: str) -> list[str] | None:
    """The names a NumPy-style Parameters section lists ("a, b : type" counts both), None without one."""
    section = re.search(r"^Parameters\n-+\n(.*?)(?=^\S[^\n]*\n-+\n|\Z)", doc, re.M | re.S)
    if section is None:
        return None
    entries = re.findall(r"^(\*{0,2}\w+(?:\s*,\s*\*{0,2}\w+)*)\s*(?::|$)", section.group(1), re.M)
    return [name.strip().lstrip("*") for entry in entries for name in entry.split(",")]


def signature_parameters(obj) -> list[str]:
    try:
        parameters = inspect.signature(obj).parameters
    except (TypeError, ValueError):  # a class whose signature Python cannot read
        return []
    return [p for p in parameters if p not in ("self", "cls")]


def test_the_modules_are_found_and_name_their_public_objects():
    objects = dict(public_objects())
    assert len(MODULES) > 100 and len(objects) > 400
    assert "uvsym.sim.system_simulation.simulate_system" in objects


def test_the_section_reader_reads_names_and_stops_at_the_next_section():
    doc = ("Summary.\n\nParameters\n----------\na, b : float\n    Two.\n*args : tuple\n    More.\n\n"
           "Returns\n-------\nc : float\n")
    assert documented_parameters(doc) == ["a", "b", "args"]
    assert documented_parameters("No sections.") is None


@pytest.mark.parametrize("qualname, obj", list(public_objects()), ids=lambda v: v if isinstance(v, str) else "")
def test_every_public_name_is_documented_and_its_parameters_match(qualname, obj):
    doc = inspect.getdoc(obj)
    assert doc and doc.strip(), f"{qualname} has no docstring"
    documented = documented_parameters(doc)
    if documented is None:
        return
    expected = signature_parameters(obj)
    assert sorted(documented) == sorted(expected), (
        f"{qualname}: Parameters section names {sorted(set(documented) - set(expected))} not in the signature, "
        f"misses {sorted(set(expected) - set(documented))}")
