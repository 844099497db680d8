"""uvsym's one figure style: every report figure and :meth:`SimResult.plot` look the same.

- :data:`PALETTE`: the Okabe-Ito colours (safe for the common colour-vision deficiencies), the
  colour cycle, so ``"C0"``, ``"C1"``, ... name them; :data:`RC` the matplotlib settings,
  applied by :func:`figure_style` to the figures made inside it;
- :func:`finish`, run by :func:`uvsym.report.figures.save_svg` on every figure before it is
  written: constrained layout (no label cut at the figure's edge) and every axes' legend moved
  outside its data, to the right of the axes;
- the campaign plots drawn the same way everywhere: :func:`confusion_matrix` (counts written on
  their cells in a colour that contrasts with the cell), :func:`roc_curves` (labels placed where
  they overlap no other label), :func:`delay_histograms` (several detectors' bars side by side).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager

import matplotlib
import matplotlib.ticker
import numpy as np
from cycler import cycler

__all__ = ["PALETTE", "RC", "confusion_matrix", "delay_histograms", "figure_style", "finish", "legend_outside",
           "roc_curves", "text_outside_figure"]

# Okabe & Ito (2008), "Color universal design": blue, vermillion, bluish green, orange, reddish purple,
# sky blue, yellow, black -- ordered so that the first colours differ most, also in grey
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#E69F00", "#CC79A7", "#56B4E9", "#F0E442", "#000000")

RC = {
    "axes.prop_cycle": cycler(color=PALETTE),
    "axes.grid": True, "grid.alpha": 0.3, "grid.linewidth": 0.6,
    "axes.spines.top": False, "axes.spines.right": False,
    "axes.titlesize": 9, "axes.titlelocation": "left", "axes.labelsize": 9,
    "xtick.labelsize": 8, "ytick.labelsize": 8,
    "legend.fontsize": 7.5, "legend.frameon": False, "legend.borderaxespad": 0.3,
    "font.size": 9, "figure.dpi": 100, "savefig.dpi": 200,
    "image.cmap": "cividis",  # perceptually uniform and colour-blind safe
    "lines.linewidth": 1.2,
    "svg.hashsalt": "uvsym", "svg.fonttype": "path",
}


@contextmanager
def figure_style() -> Iterator[None]:
    """Figures made (and saved) inside this context use :data:`RC` and the Agg backend."""
    matplotlib.use("Agg")
    with matplotlib.rc_context(RC):
        yield


def legend_outside(ax, **options):
    """The axes' legend (its handles and labels as drawn) redrawn outside its data, right of the axes."""
    legend = ax.get_legend()
    if legend is None:
        handles, labels = ax.get_legend_handles_labels()
        if not handles:
            return None
    else:
        handles, labels = legend.legend_handles, [t.get_text() for t in legend.get_texts()]
    options = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "borderaxespad": 0.0,
               "fontsize": matplotlib.rcParams["legend.fontsize"], **options}
    return ax.legend(handles, labels, **options)


def finish(fig) -> None:
    """Constrained layout, every axes' legend outside its data (a legend already placed outside stays)."""
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is not None and legend.get_bbox_to_anchor() is not None and _outside(legend, ax):
            continue
        if legend is not None:
            legend_outside(ax)
    if not _is_constrained(fig):
        fig.set_layout_engine("constrained")


def _is_constrained(fig) -> bool:
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    return isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine)


def _outside(legend, ax) -> bool:
    """Whether the legend is anchored outside the axes (in axes coordinates)."""
    anchor = legend.get_bbox_to_anchor().transformed(ax.transAxes.inverted())
    return anchor.x0 >= 1.0 or anchor.y1 <= 0.0 or anchor.y0 >= 1.0 or anchor.x1 <= 0.0


def text_outside_figure(fig, tolerance_px: float = 0.5) -> list[str]:
    """The visible texts of ``fig`` (labels, titles, tick labels, legends, annotations) whose drawn
    extent leaves the figure, as ``"text" at (x0, y0, x1, y1) px``; lays the figure out by a draw that renders
    no pixels (the text's extents need the layout, not the raster: a fifth of a figure's save)."""
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    bounds, hidden = fig.bbox, _undrawn_texts(fig)
    clipped = []
    for text in fig.findobj(matplotlib.text.Text):
        if not text.get_visible() or not text.get_text().strip() or id(text) in hidden:
            continue
        box = text.get_window_extent(renderer)
        if (box.x0 < bounds.x0 - tolerance_px or box.y0 < bounds.y0 - tolerance_px
                or box.x1 > bounds.x1 + tolerance_px or box.y1 > bounds.y1 + tolerance_px):
            clipped.append(f"{text.get_text()!r} at ({box.x0:.0f}, {box.y0:.0f}, {box.x1:.0f}, {box.y1:.0f}) px")
    return clipped


def _undrawn_texts(fig) -> set[int]:
    """ids of the texts matplotlib does not draw: every text of an invisible axes; the tick labels, label and
    offset text of an axis not drawn (hidden, or its axes ``set_axis_off``); a tick label whose tick lies
    outside the axis' view."""
    hidden = set()
    for ax in fig.axes:
        if not ax.get_visible():
            hidden.update(id(text) for text in ax.findobj(matplotlib.text.Text))
            continue
        for axis in (ax.xaxis, ax.yaxis):
            drawn = ax.axison and axis.get_visible()
            if not drawn:
                hidden.update((id(axis.label), id(axis.offsetText)))
            low, high = sorted(axis.get_view_interval())
            slack = 1e-9 * max(abs(low), abs(high), 1.0)
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                if not drawn or not low - slack <= tick.get_loc() <= high + slack:
                    hidden.update((id(tick.label1), id(tick.label2)))
    return hidden


def confusion_matrix(ax, counts, true_labels: Sequence[str], decided_labels: Sequence[str],
                     true_title: str = "true", decided_title: str = "decided") -> None:
    """Counts (runs) of each true class (rows) against each decision (columns), annotated in a colour
    that contrasts with the cell (white on dark, black on light); zero cells left blank."""
    counts = np.asarray(counts, dtype=float)
    image = ax.imshow(counts, cmap="Blues", vmin=0, vmax=max(counts.max(initial=0.0), 1), aspect="auto")  # none: blank
    size = 8 if max(counts.shape) <= 8 else 7
    for (i, j), count in np.ndenumerate(counts):
        if count:
            red, green, blue, _ = image.cmap(image.norm(count))
            dark = 0.2126 * red + 0.7152 * green + 0.0722 * blue < 0.5
            ax.text(j, i, f"{count:.0f}", ha="center", va="center", fontsize=size,
                    color="white" if dark else "black", fontweight="bold" if dark else "normal")
    ax.set_xticks(range(len(decided_labels)), decided_labels, rotation=40, ha="right", rotation_mode="anchor")
    ax.set_yticks(range(len(true_labels)), true_labels)
    ax.set_xticks(np.arange(-0.5, len(decided_labels)), minor=True)
    ax.set_yticks(np.arange(-0.5, len(true_labels)), minor=True)
    ax.grid(False)
    ax.grid(which="minor", color="white", linewidth=1.0)
    ax.tick_params(which="minor", length=0)
    for spine in ax.spines.values():
        spine.set_visible(False)
    ax.set_xlabel(decided_title)
    ax.set_ylabel(true_title)
    ax.figure.colorbar(image, ax=ax, label="runs", shrink=0.8)


def roc_curves(ax, curves: Mapping[str, tuple[Sequence[float], Sequence[float]]],
               point_labels: Mapping[str, Sequence[str]] | None = None) -> None:
    """Detection probability against false-alarm rate, one curve (colour and marker) per detector,
    the chance diagonal dotted; ``point_labels[name]`` (e.g. the threshold of each point) are written
    beside the points, each where it overlaps no label already placed."""
    markers = "osD^vP*X"
    for (name, (false_alarms, detections)), marker in zip(curves.items(), markers * len(curves)):
        ax.plot(false_alarms, detections, marker=marker, ms=4, lw=1, label=name)
    ax.plot([0, 1], [0, 1], ":", color="0.5", lw=0.8, label="chance")
    ax.set_xlim(-0.03, 1.03)
    ax.set_ylim(-0.03, 1.08)
    ax.set_xlabel("false-alarm rate (fraction of runs)")
    ax.set_ylabel("detection probability (fraction of runs)")
    legend_outside(ax)
    if point_labels:
        _place_labels(ax, [(x, y, label, f"C{k % len(PALETTE)}") for k, name in enumerate(curves)
                           for x, y, label in zip(*curves[name], point_labels.get(name, ()))])


_OFFSETS = [(dx, dy) for r in (5, 11, 18, 26) for dx, dy in ((1, 1), (1, -1), (-1, 1), (-1, -1), (1, 0), (-1, 0),
                                                             (0, 1), (0, -1))
            for dx, dy in [(dx * r, dy * r)]]


def _place_labels(ax, points: list[tuple[float, float, str, str]]) -> None:
    """Annotate each point at the first offset (points, nearest first) whose text overlaps no label
    placed before and stays inside the axes; a label with no free place is left out of the plot."""
    fig = ax.figure
    if not _is_constrained(fig):
        fig.set_layout_engine("constrained")
    fig.canvas.draw()  # the layout as it will be saved, so that the tested extents are the final ones
    renderer, frame, placed = fig.canvas.get_renderer(), ax.get_window_extent(), []
    marks = [ax.transData.transform((x, y)) for x, y, _, _ in points]
    for (x, y, label, colour) in points:
        for dx, dy in _OFFSETS:
            note = ax.annotate(label, (x, y), xytext=(dx, dy), textcoords="offset points", fontsize=7, color=colour,
                               ha="left" if dx > 0 else "right" if dx < 0 else "center",
                               va="bottom" if dy > 0 else "top" if dy < 0 else "center")
            box = note.get_window_extent(renderer).padded(1)
            inside = frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
            free = not any(box.overlaps(other) for other in placed) and not any(
                box.contains(*mark) for mark in marks)
            if inside and free:
                placed.append(box)
                break
            note.remove()


def delay_histograms(ax, delays: Mapping[str, Sequence[float]], bin_width: float, unit: str,
                     what: str = "detection delay after the onset") -> None:
    """Runs per delay bin of several detectors, their bars side by side in each bin (``bin_width`` in
    ``unit``); a detector with no delay is named in the legend with "(none)"."""
    values = {name: np.asarray([v for v in vs if v is not None], dtype=float) for name, vs in delays.items()}
    seen = [v for v in values.values() if v.size]
    low = min([0.0] + [np.floor(v.min() / bin_width) * bin_width for v in seen])
    edges = np.arange(low, max([v.max() for v in seen] + [low]) + 1.5 * bin_width, bin_width)
    width = bin_width / max(len(values), 1)
    for k, (name, v) in enumerate(values.items()):
        counts, _ = np.histogram(v, bins=edges)
        ax.bar(edges[:-1] + (k + 0.5) * width, counts, width=width * 0.92, color=f"C{k % len(PALETTE)}",
               label=f"{name} ({v.size} runs)" if v.size else f"{name} (none)")
    ax.set_xlim(edges[0], edges[-1])
    ax.set_xlabel(f"{what} ({unit})")
    ax.set_ylabel("runs")
    ax.yaxis.set_major_locator(matplotlib.ticker.MaxNLocator(integer=True))
    ax.grid(axis="x", visible=False)
    legend_outside(ax)
