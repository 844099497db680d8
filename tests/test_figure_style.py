"""uvsym's figure style: no text leaves the figure, legends sit outside the data, the campaign
plots (confusion matrix, ROC, delays) are readable."""

import numpy as np
import pytest

from uvsym.report.figures import figure_style, plt, save_svg
from uvsym.report.style import PALETTE, confusion_matrix, delay_histograms, finish, roc_curves, text_outside_figure


def test_a_label_past_the_figure_edge_is_found_and_finish_brings_it_back():
    with figure_style():
        fig, ax = plt.subplots(figsize=(4, 3))
        ax.plot([0, 1], [0, 1e6], label="a long legend entry that needs room")
        ax.set_ylabel("yaw moment on the hull (N m)")
        ax.set_xlabel("t (s)")
        ax.legend()
        fig.subplots_adjust(left=0.0, bottom=0.0)  # what matplotlib's defaults do to long labels
        assert text_outside_figure(fig)
        finish(fig)
        assert text_outside_figure(fig) == []
        legend = ax.get_legend()
        assert legend.get_window_extent().x0 >= ax.get_window_extent().x1  # outside the data, to the right
        plt.close(fig)


def test_the_tick_labels_of_an_axes_set_off_are_not_taken_for_text_outside_the_figure():
    with figure_style():
        fig, ax = plt.subplots(figsize=(2.5, 1.8))
        ax.text(0.5, 0.5, "no run finished", ha="center", va="center", transform=ax.transAxes)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("value")
        fig.subplots_adjust(left=0.0, bottom=0.0)  # its tick and axis labels would lie past the edge, if drawn
        drawn = text_outside_figure(fig)
        assert any("time (s)" in d for d in drawn) and any("'0.0'" in d for d in drawn)
        ax.set_axis_off()
        assert text_outside_figure(fig) == []
        ax.set_axis_on()
        ax.yaxis.set_visible(False)
        ax.xaxis.set_visible(False)
        assert text_outside_figure(fig) == []
        ax.xaxis.set_visible(True)
        assert any("time (s)" in d for d in text_outside_figure(fig))
        ax.set_visible(False)
        assert text_outside_figure(fig) == []
        plt.close(fig)


def test_the_colour_cycle_is_the_colour_blind_safe_palette():
    with figure_style():
        fig, ax = plt.subplots()
        lines = [ax.plot([0, 1], [k, k])[0] for k in range(3)]
        assert [line.get_color().upper() for line in lines] == [c.upper() for c in PALETTE[:3]]
        plt.close(fig)


def test_confusion_counts_contrast_with_their_cells_and_the_axes_are_titled():
    counts = np.array([[40, 0, 1], [2, 35, 0], [0, 0, 12]])
    with figure_style():
        fig, ax = plt.subplots()
        confusion_matrix(ax, counts, ["bias X", "loss N", "none"], ["bias X", "loss N", "none"])
        finish(fig)
        assert text_outside_figure(fig) == []
        shown = {t.get_text(): t.get_color() for t in ax.texts}
        assert set(shown) == {"40", "1", "2", "35", "12"}  # zeros left blank
        assert shown["40"] == "white" and shown["1"] == "black"  # dark cell, light cell
        assert (ax.get_xlabel(), ax.get_ylabel()) == ("decided", "true")
        plt.close(fig)


def test_roc_point_labels_do_not_overlap():
    rates = np.linspace(0, 1, 12)
    curves = {"A": (rates ** 2, rates ** 0.3), "B": (rates ** 2 * 0.9, rates ** 0.3), "C": (rates, rates)}
    labels = {name: [f"threshold {k}" for k in range(12)] for name in curves}
    with figure_style():
        fig, ax = plt.subplots(figsize=(6, 4))
        roc_curves(ax, curves, labels)
        finish(fig)
        assert text_outside_figure(fig) == []
        fig.canvas.draw()
        boxes = [t.get_window_extent() for t in ax.texts]
        assert boxes  # some labels were placed
        assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])
        plt.close(fig)


def test_delay_histograms_show_each_detector_side_by_side():
    delays = {"chi2": [0.2, 0.4, 0.4, 1.1], "cusum": [0.3, 0.5, None], "silent": [None]}
    with figure_style():
        fig, ax = plt.subplots()
        delay_histograms(ax, delays, bin_width=0.25, unit="s")
        finish(fig)
        assert text_outside_figure(fig) == []
        bars = {c.get_label(): c for c in ax.containers}
        assert set(bars) == {"chi2 (4 runs)", "cusum (2 runs)", "silent (none)"}
        first = [container.patches[0].get_x() for container in bars.values()]
        assert len(set(first)) == 3  # the same bin's bars at three positions, not drawn over each other
        assert ax.get_xlabel().endswith("(s)")
        plt.close(fig)


def test_save_writes_a_deterministic_svg_and_a_png_beside_it(tmp_path):
    for name in ("a.svg", "b.svg"):
        with figure_style():
            fig, ax = plt.subplots()
            ax.plot([0, 1], [1, 0], label="x")
            ax.set(xlabel="t (s)", ylabel="x (m)")
            ax.legend()
            save_svg(fig, tmp_path / name, png=True)
    assert (tmp_path / "a.svg").read_bytes() == (tmp_path / "b.svg").read_bytes()
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("names", [None])
def test_the_quick_look_plot_has_no_clipped_text_and_units_on_its_axes(names):
    from uvsym.sim.result import Signal, SimResult

    t = np.linspace(0, 10, 101)
    result = SimResult(t=t, signals={"x": Signal(np.c_[t, 0.1 * t], ("x", "psi"), ("m", "rad"))}, meta={})
    fig = result.plot(names=names)
    assert text_outside_figure(fig) == []
    assert all(ax.get_ylabel().endswith(")") for ax in fig.axes)
    assert fig.axes[-1].get_xlabel() == "t (s)"
    plt.close(fig)


def test_saving_a_figure_whose_text_cannot_fit_names_that_text(tmp_path):
    with figure_style():
        fig, ax = plt.subplots(figsize=(2, 1.5))
        ax.set_ylabel("a label far longer than the figure is tall (N m)")
        with pytest.warns(RuntimeWarning, match="a label far longer"):
            save_svg(fig, tmp_path / "small.svg")
