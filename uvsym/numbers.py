"""Numbers a user passes to the Python API, checked once: a typed error naming the argument, never a
traceback from numpy or CasADi (``kp="5"``, ``dt=-1``, ``seed=-1``)."""

from __future__ import annotations

import math
from numbers import Integral, Real

from uvsym.errors import UvsymError

__all__ = ["real", "integer"]


def real(value, what: str, error: type[UvsymError], *, positive: bool = False, minimum: float | None = None,
         maximum: float | None = None) -> float:
    """``value`` as a finite float (bounds inclusive), else ``error`` naming ``what``: strings, bools,
    NaN and infinities are refused."""
    if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(float(value)):
        raise error(f"{what} must be a finite number, got {value!r:.60}")
    value = float(value)
    if positive and not value > 0:
        raise error(f"{what} must be positive, got {value!r}")
    if minimum is not None and value < minimum:
        raise error(f"{what} must be >= {minimum:g}, got {value!r}")
    if maximum is not None and value > maximum:
        raise error(f"{what} must be <= {maximum:g}, got {value!r}")
    return value


def integer(value, what: str, error: type[UvsymError], *, minimum: int = 0) -> int:
    """``value`` as an int >= minimum (an integral float is refused too: a count is an integer), else
    ``error`` naming ``what``."""
    if isinstance(value, bool) or not isinstance(value, Integral) or value < minimum:
        raise error(f"{what} must be an integer >= {minimum}, got {value!r:.60}")
    return int(value)
