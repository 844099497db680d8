"""Deterministic SVG figures: the same data give byte-identical files."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

__all__ = ["save_svg"]


def save_svg(fig, path: Path) -> None:
    """Save a matplotlib figure as SVG without date or random ids, then close it."""
    with matplotlib.rc_context({"svg.hashsalt": "uvsym", "svg.fonttype": "path"}):
        fig.savefig(path, format="svg", metadata={"Date": None, "Creator": None})
    plt.close(fig)
