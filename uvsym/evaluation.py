"""CasADi Functions evaluated on numpy arrays in place, through CasADi's buffer interface.

Calling a Function on numpy arrays converts every argument to a ``DM`` and every output back (through
Python lists, casadi/casadi#2951): on a Function mapped over thousands of samples that conversion takes
most of the call (a regressor bank's force model: about 5 of 6 ms). :class:`InPlace` binds numpy memory to
the Function's buffers instead and evaluates there.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from uvsym.errors import ArgumentError

__all__ = ["InPlace"]


class InPlace:
    """``function`` callable on numbers and numpy arrays, evaluated in CasADi's buffers (module docstring).

    ``InPlace(f)(*arguments)`` is the list of f's outputs, each a C-ordered float64 array of the output's
    (rows, cols) shape -- what ``np.asarray(f(*arguments)[i])`` gives, bit for bit, structural zeros
    included; safe to call from several threads at once. An argument is an array of its input's (rows,
    cols) shape (a column input also takes a 1-D array) or a number, which fills the input as a Function
    call broadcasts it.

    Raises
    ------
    ArgumentError
        For a Function with a sparse input (built here), a wrong number of arguments, an argument of
        another shape or not of real numbers (complex, text), or an evaluation that fails (the Function's
        own error code).
    """

    def __init__(self, function: ca.Function):
        self.name = function.name()
        for i in range(function.n_in()):
            if not function.sparsity_in(i).is_dense():
                raise ArgumentError(f"{function.name()}: input {function.name_in(i)} is sparse; InPlace takes dense "
                                 "inputs")
        if not all(function.sparsity_out(i).is_dense() for i in range(function.n_out())):
            # its outputs' structural zeros written out: an MX call of the Function (evaluated as it is), densified
            inputs = function.mx_in()
            function = ca.Function(f"{self.name}_dense", inputs, [ca.densify(v) for v in function.call(inputs)],
                                   function.name_in(), function.name_out())
        self.function = function
        self._inputs = [function.size_in(i) for i in range(function.n_in())]
        self._outputs = [function.size_out(i) for i in range(function.n_out())]

    def __call__(self, *arguments) -> list[np.ndarray]:
        if len(arguments) != len(self._inputs):
            raise ArgumentError(f"{self.name} takes {len(self._inputs)} arguments, got {len(arguments)}")
        buffer, trigger = self.function.buffer()  # one per call (a few us): threads may share an InPlace
        held = []  # the arguments' column-major copies, alive until the evaluation is done
        for i, (argument, (rows, cols)) in enumerate(zip(arguments, self._inputs)):
            value = np.asarray(argument)
            if value.dtype.kind not in "biuf":
                raise ArgumentError(f"{self.name}: argument {self.function.name_in(i)} must be real numbers, got "
                                    f"{value.dtype}")
            value = value.astype(float, copy=False)
            if value.size == 1 and value.shape != (rows, cols):
                value = np.full((rows, cols), value.item())
            elif value.ndim == 1 and cols == 1 and value.size == rows:
                value = value[:, None]
            if value.shape != (rows, cols):
                raise ArgumentError(f"{self.name}: argument {self.function.name_in(i)} must be ({rows}, "
                                 f"{cols}), got {value.shape}")
            held.append(np.ascontiguousarray(value.T))  # CasADi is column-major: the C-ordered transpose
            buffer.set_arg(i, memoryview(held[-1].reshape(-1)))
        outputs = [np.empty((cols, rows)) for rows, cols in self._outputs]  # column-major (rows, cols)
        for i, values in enumerate(outputs):
            buffer.set_res(i, memoryview(values.reshape(-1)))
        trigger()
        if buffer.ret():
            raise ArgumentError(f"{self.name}: the evaluation failed (error {buffer.ret()})")
        return [np.ascontiguousarray(values.T) for values in outputs]
