"""Package names imported from their submodules on first use (PEP 562), so that importing one submodule
does not import its siblings' dependencies (scipy.signal, sympy, matplotlib)."""

from __future__ import annotations

import pkgutil
import sys
from collections.abc import Callable, Mapping
from importlib import import_module


def lazy_exports(package: str, exports: Mapping[str, str]) -> tuple[Callable[[str], object], Callable[[], list]]:
    """The ``(__getattr__, __dir__)`` of ``package`` whose name -> submodule ``exports`` are imported on first use
    (then kept in the package's namespace); an unknown name raises AttributeError as usual. A name can not be a
    submodule's: importing that submodule binds the package's name to the module (import such a name eagerly,
    after the submodule)."""
    submodules = {info.name for info in pkgutil.iter_modules(sys.modules[package].__path__)}
    clashes = sorted(set(exports) & submodules)
    if clashes:
        raise ValueError(f"{package}: {', '.join(clashes)} named as a submodule: import it eagerly instead")

    def __getattr__(name: str):
        if name not in exports:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(import_module(f"{package}.{exports[name]}"), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(exports))

    return __getattr__, __dir__
