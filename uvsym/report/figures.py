"""Deterministic figures in uvsym's style (:mod:`uvsym.report.style`): the same data give
byte-identical SVG files, and a PNG beside the SVG where a paper wants a raster."""

from __future__ import annotations

import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from uvsym.report.style import RC, figure_style, finish, text_outside_figure  # noqa: E402

__all__ = ["figure_style", "plt", "save_svg"]


def save_svg(fig, path: Path, png: bool = False) -> None:
    """Lay out ``fig`` in uvsym's style (:func:`~uvsym.report.style.finish`), save it as SVG without
    date or random ids (and, if ``png``, as PNG at ``RC["savefig.dpi"]`` beside it), then close it.
    A text that leaves the figure (a label longer than the figure) is named in a RuntimeWarning."""
    path = Path(path)
    finish(fig)
    clipped = text_outside_figure(fig)
    if clipped:
        warnings.warn(f"{path.name}: text outside the figure: {'; '.join(clipped)}", RuntimeWarning, stacklevel=2)
    fig.set_layout_engine("none")  # keep the layout the check drew: the saves below do not lay it out again
    with matplotlib.rc_context({"svg.hashsalt": RC["svg.hashsalt"], "svg.fonttype": RC["svg.fonttype"]}):
        fig.savefig(path, format="svg", metadata={"Date": None, "Creator": None})
    if png:
        fig.savefig(path.with_suffix(".png"), format="png", dpi=RC["savefig.dpi"], metadata={"Software": None})
    plt.close(fig)
