"""Experiment data to call an exported step with: the package's ``main.c`` and its float check.

An :class:`Example` holds, for one exported Function, samples of each input taken from an
experiment (rows: samples, columns: the input's entries; a step's state as the experiment
logged it) and says where they come from. Row 0 is the call the generated ``main.c`` makes
(written into it as constants); every row is a call a float build is measured on
(:func:`uvsym.codegen.precision.measure_float`), each from the logged state, so that an
unstable recursion cannot hide or fake a rounding problem.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvsym.errors import CodegenError

__all__ = ["Example", "evaluate_rows"]


@dataclass(frozen=True)
class Example:
    """function: the exported Function's name; inputs: one (samples, size) array per input; source: one line."""

    function: str
    inputs: tuple[np.ndarray, ...]
    source: str

    def __post_init__(self):
        arrays = tuple(np.array(np.atleast_2d(np.asarray(a, dtype=float)), copy=True) for a in self.inputs)
        for array in arrays:
            array.setflags(write=False)
        object.__setattr__(self, "inputs", arrays)
        rows = {a.shape[0] for a in arrays}
        if len(rows) != 1 or 0 in rows:
            raise CodegenError(f"example of {self.function}: every input needs the same number (>= 1) of rows, "
                               f"got {[a.shape[0] for a in arrays]}")
        for index, array in enumerate(arrays):
            if array.ndim != 2 or not np.all(np.isfinite(array)):
                raise CodegenError(f"example of {self.function}: input {index} must be a finite (samples, size) "
                                   f"array")

    @property
    def samples(self) -> int:
        return self.inputs[0].shape[0]

    def first_call(self) -> list[np.ndarray]:
        """Row 0 of every input: the call ``main.c`` makes."""
        return [a[0] for a in self.inputs]

    def check_against(self, function) -> None:
        """CodegenError unless the arrays fit ``function`` (a casadi.Function): count and size of its inputs."""
        if function.name() != self.function or function.n_in() != len(self.inputs):
            raise CodegenError(f"example of {self.function}: needs {function.n_in()} inputs of "
                               f"{function.name()}, got {len(self.inputs)}")
        for i, array in enumerate(self.inputs):
            if array.shape[1] != function.nnz_in(i):
                raise CodegenError(f"example of {self.function}: input {function.name_in(i)} has "
                                   f"{function.nnz_in(i)} entries, the example's rows {array.shape[1]}")


def evaluate_rows(function, example: Example) -> np.ndarray:
    """CasADi's double evaluation of ``function`` on every row of ``example``: (samples, all outputs),
    each output flattened column by column as C sees it."""
    example.check_against(function)
    n = example.samples
    outputs = function.map(n)(*[a.T for a in example.inputs])
    outputs = outputs if isinstance(outputs, (list, tuple)) else [outputs]
    blocks = [np.asarray(o, dtype=float).reshape(function.size1_out(i), n, function.size2_out(i)).transpose(1, 2, 0)
              .reshape(n, -1) for i, o in enumerate(outputs)]
    return np.hstack(blocks) if blocks else np.empty((n, 0))
