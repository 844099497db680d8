"""Sphinx configuration of uvsym's documentation (``sphinx-build -W -b html docs OUT``)."""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

project = "uvsym"
author = "The uvsym developers"
copyright = "2026, The uvsym developers"  # noqa: A001 (Sphinx's name)
extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon", "myst_parser"]  # napoleon reads the NumPy-style sections
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
master_doc = "index"
exclude_patterns = ["_build"]
myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3
autodoc_member_order = "bysource"
autodoc_typehints = "none"
napoleon_google_docstring = False
html_theme = "alabaster"
