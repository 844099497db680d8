"""Order reduction of zonotopes: at most ``generators`` generators, always enclosing the original.

Each method splits the generators into kept ones ``G_k`` and a group ``G_s`` that it replaces by
a parallelotope ``B = U diag(s)`` with ``s_i = sum_j |(U^T G_s)_{ij}|``:

- ``girard`` (Girard 2005): ``G_s`` the generators with the smallest ``||g||_1 - ||g||_inf``
  (the ones a box over-approximates least), ``U = I``;
- ``combastel`` (Combastel 2003): ``G_s`` the generators with the smallest ``||g||_2``, ``U = I``;
- ``pca`` (Kopetzki, Schuermann & Althoff 2017): Girard's group, ``U`` the left singular vectors
  of ``G_s`` (the box aligned with the group's principal axes).

Enclosure is constructive: ``G = [G_k B] R`` with ``R = [[I, 0], [0, diag(1/s) U^T G_s]]``, and
every row of R has an absolute sum <= 1, so a point ``c + G xi`` with ``||xi||_inf <= 1`` is
``c + [G_k B] (R xi)`` with ``||R xi||_inf <= 1``. :func:`reduce` returns R with the zonotope,
so that a point's coefficients can be carried through every reduction.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np

from uvsym.errors import SetError
from uvsym.sets.kernel import box_reduce
from uvsym.sets.zonotope import Zonotope

__all__ = ["METHODS", "Reduction", "reduce"]

METHODS = ("girard", "combastel", "pca")


@dataclass(frozen=True)
class Reduction:
    """zonotope: the reduced zonotope (n, <= generators); coefficients: R (m_new, m_old) with
    ``G_old = G_new R`` and every row's absolute sum <= 1 (None when not asked for)."""

    zonotope: Zonotope
    coefficients: np.ndarray | None


def reduce(zonotope: Zonotope, generators: int, method: str = "girard", coefficients: bool = False) -> Reduction:
    """The zonotope with at most ``generators`` generators enclosing ``zonotope`` (module docstring);
    with ``coefficients=True`` also the map R (``Reduction.coefficients``; None without it: forming R
    costs more than the reduction, and only carrying a point's coefficients needs it).

    Raises
    ------
    SetError
        For an unknown method, or ``generators`` (the reduction order, as a number of
        generators) not an integer or below the dimension.
    """
    if method not in METHODS:
        raise SetError(f"unknown reduction method {method!r}; known: {', '.join(METHODS)}")
    n, m = zonotope.dimension, zonotope.order
    if type(generators) is not int and (isinstance(generators, bool) or not isinstance(generators, numbers.Integral)) \
            or generators < n:
        raise SetError(f"reduction order: generators must be an integer >= the dimension {n} (a parallelotope), "
                       f"got {generators!r}")
    if m <= generators:
        return _reduction(zonotope, np.eye(m) if coefficients else None)
    G = zonotope.generators
    count = m - generators + n  # replaced by n parallelotope generators
    if method != "pca":
        compiled = box_reduce(G, count, method == "combastel", details=coefficients)
        if compiled is not None:
            new_G, replaced, s = compiled
            reduced = Zonotope.trusted(zonotope.center, new_G)
            return _reduction(reduced, _coefficients(replaced, G, None, s) if coefficients else None)
    if method == "combastel":
        score = np.einsum("ij,ij->j", G, G)
    else:
        magnitude = np.abs(G)
        score = magnitude.sum(axis=0) - magnitude.max(axis=0)
    replaced = np.zeros(m, dtype=bool)
    replaced[np.argsort(score, kind="stable")[:count]] = True  # ties to the lower index, as the C kernel
    G_s = G[:, replaced]
    U = np.linalg.svd(G_s, full_matrices=False)[0] if method == "pca" else None
    rotated = G_s if U is None else U.T @ G_s
    s = np.sum(np.abs(rotated), axis=1)
    axes = np.flatnonzero(s > 0)
    if U is None:
        B = np.zeros((n, axes.size))
        B[axes, np.arange(axes.size)] = s[axes]
    else:
        B = U[:, axes] * s[axes]
    reduced = Zonotope.trusted(zonotope.center, np.hstack([G[:, ~replaced], B]))
    return _reduction(reduced, _coefficients(replaced, G, U, s) if coefficients else None)


def _reduction(zonotope: Zonotope, coefficients: np.ndarray | None) -> Reduction:
    """``Reduction(zonotope, coefficients)`` past the frozen dataclass's ``__init__`` (0.2 of a 3.5 us call)."""
    result = object.__new__(Reduction)
    result.__dict__["zonotope"], result.__dict__["coefficients"] = zonotope, coefficients
    return result


def _coefficients(replaced: np.ndarray, G: np.ndarray, U: np.ndarray | None, s: np.ndarray) -> np.ndarray:
    """R (module docstring) from the replaced mask (m,), the generators, the parallelotope's axes U
    (None: the identity) and the absolute row sums s of ``U^T G_s``."""
    kept, axes = np.flatnonzero(~replaced), np.flatnonzero(s > 0)
    R = np.zeros((kept.size + axes.size, replaced.size))
    R[np.arange(kept.size), kept] = 1.0
    group = G * replaced  # the replaced generators, the kept ones zeroed
    rotated = group[axes] if U is None else U[:, axes].T @ group
    R[kept.size:] = rotated / s[axes, None]
    return R
