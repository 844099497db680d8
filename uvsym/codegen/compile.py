"""Compile CasADi Functions to shared libraries with the system C compiler and load them back.

``compile_function``: ``casadi.external`` evaluates the compiled code with the same calling
convention as the original Function, so it is a drop-in replacement. ``compile_roll``: a plain
C loop over a step Function ``(z, w) -> (z_next, out)``, called once per chunk of steps through
ctypes -- the fast path of the simulations (see ``benchmarks/sim.py``).
"""

from __future__ import annotations

import atexit
import ctypes
import itertools
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import casadi as ca
import numpy as np

from uvsym.errors import CodegenError

__all__ = ["DEFAULT_FLAGS", "find_compiler", "compile_function", "compile_roll"]

# No -ffast-math: a shared library built with it switches the whole process to flush-to-zero
# on load (crtfastmath), which silently changes every other float computation in Python.
DEFAULT_FLAGS = ("-O3", "-march=native", "-fno-math-errno", "-fPIC", "-shared")
_BUILD_DIR: Path | None = None
_COUNTER = itertools.count()


def find_compiler() -> str | None:
    """Path of the C compiler named by $CC, else gcc or cc on PATH, else None."""
    for candidate in (os.environ.get("CC"), "gcc", "cc"):
        if candidate and shutil.which(candidate):
            return shutil.which(candidate)
    return None


def _build_dir() -> Path:
    """This process's scratch folder for generated sources and libraries, removed at exit."""
    global _BUILD_DIR
    if _BUILD_DIR is None:
        _BUILD_DIR = Path(tempfile.mkdtemp(prefix="uvsym-build-"))
        atexit.register(shutil.rmtree, _BUILD_DIR, ignore_errors=True)
    return _BUILD_DIR


def _build(f: ca.Function, extra_source: str, flags: tuple[str, ...]) -> Path:
    """Generate ``f`` (with a header) plus ``extra_source``, compile both into a new shared library."""
    compiler = find_compiler()
    if compiler is None:
        raise CodegenError("no C compiler found (set $CC or install gcc)")
    stem = f"{f.name()}_{os.getpid()}_{next(_COUNTER)}"
    directory = _build_dir()
    generator = ca.CodeGenerator(stem, {"with_header": True})
    generator.add(f)
    generator.generate(f"{directory}{os.sep}")
    sources = [directory / f"{stem}.c"]
    if extra_source:
        sources.append(directory / f"{stem}_driver.c")
        sources[-1].write_text(f'#include "{stem}.h"\n' + extra_source)
    library = directory / f"{stem}.so"
    command = [compiler, *flags, *map(str, sources), "-o", str(library), "-lm"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise CodegenError(f"compiling {f.name()} failed: {' '.join(command)}\n{done.stderr.strip()}")
    return library


def compile_function(f: ca.Function, flags: tuple[str, ...] = DEFAULT_FLAGS) -> ca.Function:
    """``f`` generated as C, compiled to a shared library and loaded with ``casadi.external``.

    Every call builds a library with a new file name (the loader caches by path).

    Raises
    ------
    CodegenError
        When no C compiler is found or compilation fails (with the compiler's message).
    """
    return ca.external(f.name(), str(_build(f, "", flags)))


_ROLL = """
#include <string.h>
int {name}_roll(const casadi_real* z0, const casadi_real* W, casadi_real* z_end, casadi_real* O, long N) {{
  static casadi_real w[{name}_SZ_W > 0 ? {name}_SZ_W : 1];
  static casadi_int iw[{name}_SZ_IW > 0 ? {name}_SZ_IW : 1];
  casadi_real z[{n_z}], z_next[{n_z}];
  const casadi_real* arg[{name}_SZ_ARG];
  casadi_real* res[{name}_SZ_RES];
  memcpy(z, z0, sizeof z);
  for (long k = 0; k < N; ++k) {{
    arg[0] = z;
    arg[1] = W + k * {n_w};
    res[0] = z_next;
    res[1] = O + k * {n_out};
    if ({name}(arg, res, iw, w, 0)) return 1;
    memcpy(z, z_next, sizeof z);
  }}
  memcpy(z_end, z, sizeof z);
  return 0;
}}
"""


def compile_roll(step: ca.Function, flags: tuple[str, ...] = DEFAULT_FLAGS):
    """A C loop over ``step(z, w) -> (z_next, out)`` (dense vectors), compiled and loaded.

    Returns ``roll(z0 (n_z,), W (k, n_w), out (k, n_out)) -> z_end``: k steps, one row of W per
    step, writing each step's ``out`` into the rows of ``out`` (C-contiguous float64 arrays). No
    state history is kept and nothing is allocated per step.

    Raises CodegenError when there is no compiler or compilation fails.
    """
    n_z, n_w, n_out = step.nnz_in(0), step.nnz_in(1), step.nnz_out(1)
    library = _build(step, _ROLL.format(name=step.name(), n_z=n_z, n_w=n_w, n_out=n_out), flags)
    function = getattr(ctypes.CDLL(str(library)), f"{step.name()}_roll")
    pointer = ctypes.POINTER(ctypes.c_double)
    function.argtypes = [pointer, pointer, pointer, pointer, ctypes.c_long]

    def roll(z0: np.ndarray, W: np.ndarray, out: np.ndarray) -> np.ndarray:
        z0 = np.ascontiguousarray(z0, dtype=float)
        if W.shape[1:] != (n_w,) or out.shape != (W.shape[0], n_out) or not (W.flags.c_contiguous and
                                                                            out.flags.c_contiguous):
            raise CodegenError(f"roll needs C-contiguous W (k, {n_w}) and out (k, {n_out})")
        z_end = np.empty(n_z)
        if function(z0.ctypes.data_as(pointer), W.ctypes.data_as(pointer), z_end.ctypes.data_as(pointer),
                    out.ctypes.data_as(pointer), W.shape[0]):
            raise CodegenError(f"{step.name()} failed inside the compiled loop")
        return z_end

    return roll
