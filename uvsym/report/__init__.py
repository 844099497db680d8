"""Report building blocks: Markdown tables and matrices, deterministic JSON and SVG figures."""

from uvsym.report.figures import save_svg
from uvsym.report.markdown import latex_matrix, markdown_table, write_json

__all__ = ["latex_matrix", "markdown_table", "save_svg", "write_json"]
