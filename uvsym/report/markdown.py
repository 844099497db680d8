"""Markdown pieces for reports (GitHub-flavoured, math in ``$$ ... $$``) and deterministic JSON."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

__all__ = ["markdown_table", "latex_matrix", "write_json"]


def markdown_table(header: list[str], rows: list[list]) -> str:
    """A GitHub Markdown table; cells are converted with ``str`` and '|' escaped."""
    def cell(value) -> str:
        return str(value).replace("|", "\\|")
    lines = ["| " + " | ".join(cell(h) for h in header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def latex_matrix(matrix, digits: int = 6) -> str:
    """A numeric matrix as a LaTeX ``bmatrix`` with ``digits`` significant digits (exact zeros as 0,
    exponents as ``2.5 \\cdot 10^{-9}``)."""
    array = np.atleast_2d(np.asarray(matrix, dtype=float))
    def fmt(x: float) -> str:
        mantissa, _, exponent = ("0" if x == 0 else f"{x:.{digits}g}").partition("e")
        return f"{mantissa} \\cdot 10^{{{int(exponent)}}}" if exponent else mantissa
    body = r" \\ ".join(" & ".join(fmt(x) for x in row) for row in array)
    return r"\begin{bmatrix} " + body + r" \end{bmatrix}"


def write_json(path: Path, data) -> None:
    """Write JSON with sorted keys and a trailing newline, so equal data give equal bytes."""
    Path(path).write_text(json.dumps(data, indent=2, sort_keys=True, allow_nan=False) + "\n")
