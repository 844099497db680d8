"""Checked calls of the Functions of a Model, System or Observer.

A :class:`CheckedFunction` *is* a ``casadi.Function`` (``isinstance`` holds, ``mapaccum``,
``map``, code generation and symbolic calls work unchanged); only a call with numbers is
checked before CasADi sees it:

- arguments given all by position (as many as the Function takes) or all by name (known names);
- each argument of the Function's size (a scalar broadcasts, as in CasADi, but a one-entry list
  for a vector does not; an empty value for a
  non-empty argument is refused instead of read as zeros);
- every entry finite, and every output finite at finite inputs (a ``guard`` may refuse points
  outside the Function's domain, e.g. a kinematic singularity, before evaluating).

Failures are :class:`~uvsym.errors.ArgumentError` naming the Function, the argument and, with
``labels``, the entry (``otter.f: argument x entry theta is nan``). ``.raw`` is the unchecked
Function, for loops where the checks would cost.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

import casadi as ca
import numpy as np

from uvsym.errors import ArgumentError

__all__ = ["CheckedFunction", "checked"]


class CheckedFunction(ca.Function):
    """``raw`` with checked numeric calls (module docstring); ``owner`` prefixes messages.

    labels: argument or output name -> names of its entries; guard(values) raises a typed error
    for points outside the domain, values: argument name -> (n,) float array.
    """

    def __init__(self, raw: ca.Function, owner: str, labels: Mapping[str, tuple[str, ...]] | None = None,
                 guard: Callable[[dict], None] | None = None):
        raw = raw.raw if isinstance(raw, CheckedFunction) else raw
        ca.Function.__init__(self, raw)
        self._raw, self._owner, self._labels, self._guard = raw, owner, dict(labels or {}), guard
        self._names = list(raw.name_in())
        self._outputs = list(raw.name_out())
        self._shapes = {name: (raw.size1_in(i), raw.size2_in(i)) for i, name in enumerate(self._names)}

    @property
    def raw(self) -> ca.Function:
        """The unchecked ``casadi.Function``."""
        return self._raw

    def __copy__(self) -> CheckedFunction:
        return self  # immutable, like the Function it wraps

    def __deepcopy__(self, memo) -> CheckedFunction:
        return self

    def __reduce__(self):
        return CheckedFunction, (self._raw, self._owner, self._labels, self._guard)

    def _where(self) -> str:
        return f"{self._owner}.{self._raw.name()}"

    def __call__(self, *args, **kwargs):
        names = self._names
        if args and kwargs:
            raise ArgumentError(f"{self._where()}: give the arguments all by position or all by name "
                                f"({', '.join(names)})")
        if kwargs:
            unknown = sorted(set(kwargs) - set(names))
            if unknown:
                raise ArgumentError(f"{self._where()}: unknown argument {unknown[0]!r}; its arguments are "
                                    f"{', '.join(names)}")
            given = dict(kwargs)
        else:
            if len(args) != len(names):
                raise ArgumentError(f"{self._where()}: takes {len(names)} arguments ({', '.join(names)}), "
                                    f"got {len(args)}")
            given = dict(zip(names, args))
        values = {name: _numbers(value) for name, value in given.items()}
        for name, value in given.items():
            if values[name] is None and not _symbolic(value):
                raise ArgumentError(f"{self._where()}: argument {name} must be real numbers or a CasADi expression, "
                                    f"got {type(value).__name__} {value!r:.60}")
        numeric = all(v is not None for v in values.values())
        for name, value in values.items():
            if value is not None:
                self._check_argument(name, value)
        if numeric and self._guard is not None:
            self._guard({name: value.ravel() for name, value in values.items()})
        try:
            result = ca.Function.__call__(self, *args, **kwargs)
        except RuntimeError as exc:
            raise ArgumentError(f"{self._where()}: {_casadi_reason(exc)}") from None
        if numeric:
            self._check_outputs(result, values)
        return result

    def _check_argument(self, name: str, value: np.ndarray) -> None:
        shape = self._shapes[name]
        expected = shape[0] * shape[1]
        vector = 1 in shape
        fits = value.size == 1 or (value.ndim <= 1 and vector) or value.shape in ((shape, shape[::-1]) if vector else
                                                                              (shape,))
        one_entry_list = value.ndim == 1 and value.size == 1 and expected > 1  # [x] for a vector: a mistake
        if value.size not in (expected, 1) or (value.size == 1 and expected == 0) or not fits or one_entry_list:
            raise ArgumentError(f"{self._where()}: argument {name} has {value.size} entries (shape "
                                f"{value.shape}), expected {expected} (shape {shape})")
        if not np.isfinite(value).all():
            flat = value.ravel(order="F")
            first = int(np.flatnonzero(~np.isfinite(flat))[0])
            raise ArgumentError(f"{self._where()}: argument {name} {self._entry(name, first, expected)} is "
                                f"{flat[first]}; every entry must be finite")

    def _check_outputs(self, result, values: dict) -> None:
        outputs = result if isinstance(result, dict) else dict(
            zip(self._outputs, result if isinstance(result, tuple) else (result,)))
        for name, value in outputs.items():
            if all(map(math.isfinite, value.nonzeros())):  # structural zeros are finite
                continue
            array = value.full().ravel(order="F")
            first = int(np.flatnonzero(~np.isfinite(array))[0])
            at = "; ".join(f"{n} = {np.array2string(v.ravel(), precision=6, separator=', ', max_line_width=10**9)}"
                           for n, v in values.items() if v.size)
            raise ArgumentError(f"{self._where()}: output {name} {self._entry(name, first, array.size)} is "
                                f"{array[first]} at finite arguments ({at}); the point is outside the equations' "
                                "domain or overflows double precision")

    def _entry(self, name: str, index: int, size: int) -> str:
        labels = self._labels.get(name, ())
        return f"entry {labels[index]}" if len(labels) == size else f"entry {index}"


def checked(function: ca.Function, owner: str, labels: Mapping[str, tuple[str, ...]] | None = None,
            guard: Callable[[dict], None] | None = None) -> CheckedFunction:
    """``function`` behind the checked-call layer (its ``.raw`` when it already is one)."""
    return CheckedFunction(function, owner, labels, guard)


def _numbers(value) -> np.ndarray | None:
    """A float array of a numeric argument; None for a symbolic one (SX, MX or lists of them) and for what is not
    real numbers (None, complex, text: the caller names it)."""
    if value is None or isinstance(value, (ca.SX, ca.MX)):
        return None
    if isinstance(value, ca.DM):
        return np.asarray(value.full(), dtype=float)
    try:
        array = np.asarray(value)  # converted once: complex is refused, not cut to its real part
        return None if np.iscomplexobj(array) else np.asarray(array, dtype=float)
    except (TypeError, ValueError):
        return None


def _symbolic(value) -> bool:
    """True for a CasADi SX or MX expression, or a list or tuple holding one."""
    if isinstance(value, (ca.SX, ca.MX)):
        return True
    return isinstance(value, (list, tuple)) and any(_symbolic(v) for v in value)


def _casadi_reason(exc: RuntimeError) -> str:
    """The last line of a CasADi error, without its source location."""
    line = (str(exc).strip().splitlines() or ["evaluation failed"])[-1]
    return line.split(": ", 1)[1] if ".hpp:" in line or ".cpp:" in line else line
