"""Check a written C package: compile it with strict warnings, load it, compare with Python.

``check_package`` compiles the package's two sources (``src/NAME_casadi.c``, ``src/NAME.c``)
with ``STRICT_FLAGS`` into a shared library in a scratch folder (the package folder is left as it was), loads every
function through ``casadi.external`` and evaluates it and the Python Function on the same
random inputs. The result says how far apart they are, relative to each call's largest output.
"""

from __future__ import annotations

import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import casadi as ca
import numpy as np

from uvsym.codegen.compile import find_compiler
from uvsym.codegen.package import Exported, casadi_name
from uvsym.errors import CodegenError

__all__ = ["STRICT_FLAGS", "PackageCheck", "check_package"]

STRICT_FLAGS = ("-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic", "-fPIC", "-shared")


@dataclass(frozen=True)
class PackageCheck:
    """flags used; calls compared (per function); the largest ``max|C - Python| / max(1, max|Python|)``."""

    flags: tuple[str, ...]
    calls: int
    max_relative_difference: float


def check_package(package_dir, functions: list[Exported], name: str, calls: int = 20, seed: int = 0) -> PackageCheck:
    """Compile, load and compare the package written by ``write_package(package_dir, functions, name)``.

    Raises CodegenError when there is no compiler or the sources do not compile cleanly
    (the compiler's message included).
    """
    compiler = find_compiler()
    if compiler is None:
        raise CodegenError("no C compiler found (set $CC or install gcc)")
    package_dir = Path(package_dir)
    sources = [str(package_dir / "src" / f"{name}_casadi.c"), str(package_dir / "src" / f"{name}.c")]
    rng = np.random.default_rng(seed)
    worst = 0.0
    with tempfile.TemporaryDirectory(prefix="uvsym-check-") as scratch:
        library = Path(scratch) / f"lib{name}.so"
        command = [compiler, *STRICT_FLAGS, "-I", str(package_dir / "include"), *sources, "-o", str(library), "-lm"]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            tail = "\n".join(done.stderr.strip().splitlines()[-30:])
            raise CodegenError(f"the package does not compile cleanly: {' '.join(command)}\n{tail}")
        for exported in functions:
            python = exported.function
            compiled = ca.external(casadi_name(name, python.name()), str(library))
            for _ in range(calls):
                args = [rng.normal(size=python.nnz_in(i)) for i in range(python.n_in())]
                expected = np.concatenate([np.asarray(r, dtype=float).ravel() for r in python(*args)])
                got = np.concatenate([np.asarray(r, dtype=float).ravel() for r in compiled(*args)])
                scale = max(1.0, float(np.max(np.abs(expected))))
                worst = max(worst, float(np.max(np.abs(got - expected))) / scale)
    return PackageCheck(STRICT_FLAGS, calls, worst)
