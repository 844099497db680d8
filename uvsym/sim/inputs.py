"""A run's per-sample input table W held as its varying columns, every other column one constant.

Most of a loop's inputs hold still over a run (the docking loop's correction, current and the
fault columns of healthy actuators: 49 of its 59). :class:`CompactInputs` keeps W (k, n_w) as the
varying columns' rows (k, n_var) and one constant row (n_w,), so that building a run's inputs and
the lanes reading them (:func:`uvsym.codegen.compile.compile_lanes`'s ``runs``) touch n_var
columns per sample rather than n_w.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvsym.errors import SimulationError

__all__ = ["CompactInputs", "compact", "input_column", "input_rows"]


@dataclass(frozen=True)
class CompactInputs:
    """W (k, n_w) with ``W[:, columns] = rows`` and ``W[:, j] = constant[j]`` for every other column j.

    constant: (n_w,) float64 (its entries at ``columns`` unused); columns: (n_var,) ascending column
    indices (intp); rows: (k, n_var) C-contiguous float64.
    """

    constant: np.ndarray
    columns: np.ndarray
    rows: np.ndarray

    def __post_init__(self):
        n_w = self.constant.shape[0] if self.constant.ndim == 1 else -1
        if self.rows.ndim != 2 or self.rows.shape[1] != self.columns.size or not (
                self.columns.size == 0 or (0 <= self.columns[0] and self.columns[-1] < n_w
                                           and np.all(np.diff(self.columns) > 0))):
            raise SimulationError(f"compact inputs need a constant row (n_w,), ascending columns within it and rows "
                                  f"(k, {self.columns.size}); got {self.constant.shape}, {self.columns.tolist()} and "
                                  f"{self.rows.shape}")

    @property
    def shape(self) -> tuple[int, int]:
        """(k, n_w): the shape of the dense table."""
        return self.rows.shape[0], self.constant.shape[0]

    def __len__(self) -> int:
        return self.rows.shape[0]

    def __getitem__(self, samples: slice) -> CompactInputs:
        """The samples ``samples`` (a slice; a view of the rows)."""
        if not isinstance(samples, slice):
            raise TypeError("compact inputs are sliced by samples; dense rows come from dense()")
        return CompactInputs(self.constant, self.columns, self.rows[samples])

    def column(self, j: int) -> np.ndarray:
        """(k,) the values of column j."""
        where = np.searchsorted(self.columns, j)
        if where < self.columns.size and self.columns[where] == j:
            return self.rows[:, where]
        return np.full(len(self), self.constant[j])

    def dense(self, samples=slice(None)) -> np.ndarray:
        """W[samples] (k', n_w) dense, for an index numpy takes on the first axis (int, slice, int array)."""
        picked = self.rows[samples]
        table = np.empty((*picked.shape[:-1], self.constant.shape[0]))
        table[...] = self.constant
        table[..., self.columns] = picked
        return table


def compact(W: np.ndarray) -> CompactInputs:
    """W (k, n_w) as its varying columns (those not equal to their first row's entry in every row)."""
    W = np.asarray(W, dtype=float)
    if W.ndim != 2 or not len(W):
        raise SimulationError(f"inputs to compact must be a table (k >= 1, n_w), got shape {W.shape}")
    columns = np.flatnonzero(~np.all(W == W[0], axis=0))
    return CompactInputs(W[0].copy(), columns, np.ascontiguousarray(W[:, columns]))


def input_rows(W, samples) -> np.ndarray:
    """The dense rows ``W[samples]`` of a table W, dense (ndarray) or compact."""
    return W.dense(samples) if isinstance(W, CompactInputs) else W[samples]


def input_column(W, j: int) -> np.ndarray:
    """(k,) column j of a table W, dense (a view) or compact."""
    return W.column(j) if isinstance(W, CompactInputs) else W[:, j]
