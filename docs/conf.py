"""Sphinx configuration of uvsym's documentation (``sphinx-build -W -b html docs OUT``).

The API reference is generated from the package (one page per module, autosummary), the gallery
from ``examples/*.py`` (sphinx-gallery, each script run by the build)."""

import shutil
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path[:0] = [str(DOCS.parent), str(DOCS)]  # uvsym, and gallery_figures for the gallery's hooks
for generated in ("api", "gallery"):  # written afresh by every build: a page of a removed module or example
    shutil.rmtree(DOCS / generated, ignore_errors=True)  # left behind would be a page in no toctree (-W)

project = "uvsym"
author = "The uvsym developers"
copyright = "2026, The uvsym developers"  # noqa: A001 (Sphinx's name)
extensions = ["sphinx.ext.autodoc", "sphinx.ext.autosummary", "sphinx.ext.napoleon", "myst_parser",
              "sphinx_gallery.gen_gallery"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
master_doc = "index"
exclude_patterns = ["_build"]
templates_path = ["_templates"]
myst_enable_extensions = ["dollarmath", "deflist"]
myst_heading_anchors = 3

autosummary_generate = True  # api/uvsym.*.rst, one page per module, rewritten by every build
autodoc_member_order = "bysource"
autodoc_typehints = "none"
autodoc_default_options = {"members": True, "undoc-members": True}  # the names of each module's __all__


def _constants() -> dict[str, list[tuple[str, bool]]]:
    """Per module, the names of its ``__all__`` that are not classes, functions or modules, each with
    whether its value is too long to print (repr over 120 characters): autodoc documents module
    data only with a doc comment, so the module template lists these by autodata."""
    import importlib
    import inspect
    import pkgutil

    import uvsym

    found = {}
    for info in pkgutil.walk_packages(uvsym.__path__, "uvsym."):
        module = importlib.import_module(info.name)
        found[info.name] = [(name, len(repr(obj)) > 120) for name in getattr(module, "__all__", ()) if not (
            inspect.isclass(obj := getattr(module, name)) or callable(obj) or inspect.ismodule(obj))]
    return found


autosummary_context = {"constants": _constants()}
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_param = True  # one field per parameter: "name (type) -- description"
napoleon_use_rtype = False  # a Returns section's text stays one paragraph

sphinx_gallery_conf = {
    "examples_dirs": str(DOCS.parent / "examples"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"\.py$",  # every script is run, and its output shown
    "run_stale_examples": True,  # run by every build, never an earlier build's output
    "reset_argv": "gallery_figures.output_folder",
    "image_scrapers": ("gallery_figures.written_figures", "matplotlib"),
    "download_all_examples": False,
    "write_computation_times": False,
    "capture_repr": (),  # the printed output only, not the value of a script's last line
    "remove_config_comments": True,
}

html_theme = "alabaster"


def _drop_type_docstrings(app, what, name, obj, options, lines):
    """A constant without a doc comment gets its type's docstring (dict's, str's) from autodata: none."""
    import inspect

    if what == "data" and lines and "\n".join(lines).strip() == (inspect.getdoc(type(obj)) or "").strip():
        lines.clear()


def setup(app):
    app.connect("autodoc-process-docstring", _drop_type_docstrings)
