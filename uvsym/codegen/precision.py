"""How far a single-precision build strays from double precision on an experiment's data.

``measure_float(exported, example)`` writes the function alone as a float package in a scratch
folder, compiles its harness, calls it on every row of the
:class:`~uvsym.codegen.example.Example` and compares every output with CasADi's double
evaluation of the same rows (:func:`~uvsym.codegen.example.evaluate_rows`). The figure is the
largest, over the rows and the outputs, of ``max|float - double| / max(1, max|double|)``
(each output against its own largest entry). A float step can be
far from a double one that is fine: when the gains are stiff for the step (``K tau_d^2 dt >> 1``),
its result is a small difference of large terms (``f_hat = x - R(nu)``) that float cannot resolve.
"""

from __future__ import annotations

import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from uvsym.codegen.compile import find_compiler
from uvsym.codegen.example import Example, evaluate_rows
from uvsym.errors import CodegenError, PrecisionError

__all__ = ["FLOAT_TOLERANCE", "FloatCheck", "checked_float", "measure_float"]

FLOAT_TOLERANCE = 1e-3  # largest accepted relative difference of a float build along its example


@dataclass(frozen=True)
class FloatCheck:
    """rows compared; the largest relative difference (module docstring); where the data comes from."""

    samples: int
    max_relative_difference: float
    source: str

    def to_dict(self, tolerance: float = FLOAT_TOLERANCE) -> dict:
        return {"samples": self.samples, "max_relative_difference": float(f"{self.max_relative_difference:.3g}"),
                "tolerance": tolerance, "source": self.source}


def _records(example: Example) -> str:
    """The example's rows as harness records (function index 0, then the inputs)."""
    return "".join("0 " + " ".join(repr(float(v)) for a in example.inputs for v in a[k]) + "\n"
                   for k in range(example.samples))


def measure_float(exported, example: Example) -> FloatCheck:
    """Run ``exported`` (an :class:`~uvsym.codegen.package.Exported`) in float along ``example``.

    Raises CodegenError when no C compiler is found or the float build does not compile."""
    from uvsym.codegen.package import write_package

    f = exported.function
    example.check_against(f)
    compiler = find_compiler()
    if compiler is None:
        raise CodegenError("cannot measure the float build's error: no C compiler found (set $CC or install gcc)")
    name = "uvsym_float_check"
    with tempfile.TemporaryDirectory(prefix="uvsym-float-") as scratch:
        package = Path(scratch)
        write_package(package, [exported], name, "float", finite_check=False)
        exe = package / "harness"
        command = [compiler, "-std=c99", "-O2", "-I", str(package / "include"), str(package / "harness.c"),
                   str(package / "src" / f"{name}_casadi.c"), str(package / "src" / f"{name}.c"), "-o", str(exe), "-lm"]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            raise CodegenError(f"the float build does not compile: {' '.join(command)}\n{done.stderr.strip()}")
        ran = subprocess.run([str(exe)], input=_records(example), capture_output=True, text=True, timeout=600)
    if ran.returncode != 0:
        raise CodegenError(f"the float check program failed (exit code {ran.returncode}): {ran.stderr.strip()}")
    got = np.array([[float(v) for v in line.split()] for line in ran.stdout.strip().splitlines()])
    expected = evaluate_rows(f, example)
    worst = np.inf if np.any(got[:, 0] != 0) else 0.0
    edges = np.cumsum([0] + [f.nnz_out(i) for i in range(f.n_out())])
    with np.errstate(all="ignore"):
        for start, end in zip(edges[:-1], edges[1:]):  # each output relative to its own largest entry
            difference = np.abs(got[:, 1 + start:1 + end] - expected[:, start:end])
            difference = np.where(np.isfinite(difference), difference, np.inf).max(axis=1, initial=0.0)
            worst = max(worst, float(np.max(difference / np.maximum(1.0, np.abs(expected[:, start:end]).max(
                axis=1, initial=0.0)), initial=0.0)))
    return FloatCheck(example.samples, worst, example.source)


def checked_float(exported, example: Example, tolerance: float = FLOAT_TOLERANCE) -> FloatCheck:
    """:func:`measure_float`, refused with PrecisionError (the figure in the message) above ``tolerance``."""
    check = measure_float(exported, example)
    if not check.max_relative_difference <= tolerance:
        raise PrecisionError(
            f"{exported.function.name()}: the float build strays {check.max_relative_difference:.3g} (relative) from "
            f"the double one on {check.samples} samples of {check.source}, more than {tolerance:g}: single precision "
            f"is not enough for this step and these gains (stiff gains, K tau_d^2 dt >> 1, or cancellation); "
            f"export in double precision, or use a smaller step or gain")
    return check
