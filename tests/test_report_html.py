"""report.html: self-contained, and its equations render in a real headless browser."""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np
import pytest

from uvsym.errors import UvsymError
from uvsym.report.html import markdown_to_html

REPORTS = Path(__file__).resolve().parents[1] / "reports"
HTML_REPORTS = sorted(REPORTS.glob("*/report.html"))


def test_every_report_has_its_html():
    assert sorted(p.parent for p in REPORTS.glob("*/report.md")) == [p.parent for p in HTML_REPORTS]


@pytest.mark.parametrize("page", HTML_REPORTS, ids=lambda p: p.parent.name)
def test_report_html_needs_nothing_from_outside(page):
    text = page.read_text()
    markdown = (page.parent / "report.md").read_text()
    assert "<script" not in text and "<link" not in text
    assert not re.search(r'src="(?!data:)', text), "every image is embedded"
    assert not re.search(r'href="[^"#:]+\.(svg|png)"', text), "figures are shown, not linked (the page works alone)"
    # every formula of the Markdown is MathML in the HTML, none left as TeX
    assert text.count('<math xmlns="http://www.w3.org/1998/Math/MathML" display="block">') == markdown.count("$$") // 2
    assert "$$" not in text and "\\begin{" not in text


def test_markdown_to_html_names_what_it_cannot_render(tmp_path):
    with pytest.raises(UvsymError, match="missing.svg"):
        markdown_to_html("![figure](missing.svg)\n", "t", tmp_path)
    with pytest.raises(UvsymError, match="formula"):
        markdown_to_html("$$\\begin{nonsense} x$$\n", "t", tmp_path)
    page = markdown_to_html("a `$x$` code span and $y$ in text\n", "t", tmp_path)
    assert "<code>$x$</code>" in page and "<mi>y</mi>" in page


def _ink_bands(png: bytes) -> int:
    """Number of separate horizontal bands of dark pixels in a screenshot."""
    from PIL import Image

    dark = np.asarray(Image.open(io.BytesIO(png)).convert("L")) < 128
    rows = dark.any(axis=1).astype(int)
    return int(np.sum(np.diff(np.r_[0, rows]) == 1))


@pytest.mark.parametrize("page", HTML_REPORTS, ids=lambda p: p.parent.name)
def test_report_html_renders_its_equations_in_headless_chromium(browser, page):
    tab = browser.new_page(viewport={"width": 1200, "height": 900})
    outside = []
    tab.route(re.compile(r"^(?!file:|data:).*"), lambda route: (outside.append(route.request.url), route.abort()))
    tab.goto(page.as_uri())
    assert outside == [], f"the page asked the network for {outside}"
    images = tab.evaluate("Array.from(document.images).map(i => i.complete && i.naturalWidth > 0)")
    assert images and all(images), "an embedded figure did not load"
    if "bmatrix" not in (page.parent / "report.md").read_text():
        tab.close()
        return  # no matrix to lay out on this page: the figures and the network are what it shows
    line = float(tab.evaluate("parseFloat(getComputedStyle(document.querySelector('p')).lineHeight)"))
    table = tab.locator("math[display=block] mtable").first
    rows = table.locator("mtr").count()
    box = table.bounding_box()
    # laid out as a matrix: the rows stacked (as plain text they would share one line)
    assert rows >= 3 and box["height"] >= 0.5 * rows * line
    table.scroll_into_view_if_needed()
    box = table.bounding_box()
    inside = {"x": box["x"] + 0.15 * box["width"], "y": box["y"], "width": 0.7 * box["width"], "height": box["height"]}
    assert _ink_bands(tab.screenshot(clip=inside)) >= rows, "the screenshot does not show the matrix's rows"
    tab.close()
