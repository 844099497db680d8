"""Report building blocks: Markdown tables and matrices, deterministic JSON and SVG figures in one style.

The names are imported on first use (:mod:`uvsym.lazy`): writing a table or JSON does not import matplotlib.
"""

from uvsym.lazy import lazy_exports

_EXPORTS = {"latex_matrix": "markdown", "markdown_table": "markdown", "write_json": "markdown",
            "limits_block": "markdown", "LIMITS_MARKERS": "markdown", "save_svg": "figures", "figure_style": "style"}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
