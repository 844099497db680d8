"""Markdown pieces for reports (GitHub-flavoured, math between ``$$`` delimiters) and deterministic JSON."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from uvsym.errors import FileFormatError

__all__ = ["markdown_table", "latex_matrix", "write_json", "limits_block", "LIMITS_MARKERS"]

LIMITS_MARKERS = ("<!-- limits -->", "<!-- /limits -->")  # a doc page includes the text between them


def markdown_table(header: list[str], rows: list[list]) -> str:
    """A GitHub Markdown table; cells are converted with ``str`` and '|' escaped."""
    def cell(value) -> str:
        return str(value).replace("|", "\\|")
    lines = ["| " + " | ".join(cell(h) for h in header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def limits_block(body: str) -> str:
    """A study's measured limits (Markdown without links or images: a doc page includes it from the report,
    between the two LIMITS_MARKERS, with MyST's ``{include}``)."""
    if "](" in body:
        raise FileFormatError("a limits block holds no links or images: the doc page that includes it resolves "
                              "them from its own folder")
    return f"{LIMITS_MARKERS[0]}\n\n{body.strip()}\n\n{LIMITS_MARKERS[1]}"


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
    """Write JSON with sorted keys and a trailing newline, so equal data give equal bytes; FileFormatError
    naming the entry, before anything is written, for a NaN or infinity (JSON has none: a missing figure is None)."""
    try:
        text = json.dumps(data, indent=2, sort_keys=True, allow_nan=False)
    except ValueError:
        where = _non_finite(data, "")
        if where is None:  # another ValueError (a circular reference): json's own message
            raise
        raise FileFormatError(f"cannot write {path}: {where[0] or 'the value'} is {where[1]}, which JSON cannot "
                              "hold (a figure without a value, e.g. of no finished run, is None: null)") from None
    Path(path).write_text(text + "\n")


def _non_finite(data, where: str) -> tuple[str, float] | None:
    """(path, value) of the first NaN or infinity in ``data`` (dicts by key, lists by index), or None."""
    if isinstance(data, float):
        return None if np.isfinite(data) else (where, data)
    items = data.items() if isinstance(data, dict) else enumerate(data) if isinstance(data, (list, tuple)) else ()
    for key, value in items:
        found = _non_finite(value, f"{where}[{key}]" if isinstance(key, int) else f"{where}.{key}" if where else
                            str(key))
        if found is not None:
            return found
    return None
