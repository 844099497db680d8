"""The gallery's hooks: each example gets an output folder as its first argument, and the figures
it writes there (SVG, as :meth:`uvsym.sim.SimResult.plot` saves them) are shown under the code that
wrote them. Named in ``sphinx_gallery_conf`` of conf.py."""

import os
import shutil
from pathlib import Path

from sphinx_gallery.scrapers import figure_rst


def _folder(src_file, gallery_conf) -> Path:
    return Path(gallery_conf["src_dir"]) / "gallery" / "written" / Path(src_file).stem


def output_folder(gallery_conf, script_vars) -> list[str]:
    """sys.argv[1:] of an example: an empty folder of its own, relative to the example's folder
    (where sphinx-gallery runs it), so that what it prints names no absolute path."""
    folder = _folder(script_vars["src_file"], gallery_conf)
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    return [os.path.relpath(folder, Path(script_vars["src_file"]).parent)]


def written_figures(block, block_vars, gallery_conf) -> str:
    """reST showing the SVG figures the block wrote into the example's folder (moved into the gallery's images)."""
    folder = _folder(block_vars["src_file"], gallery_conf)
    shown = []
    for svg, image in zip(sorted(folder.glob("*.svg")), block_vars["image_path_iterator"]):
        target = Path(image).with_suffix(".svg")
        shutil.move(svg, target)
        shown.append(str(target))
    return figure_rst(shown, gallery_conf["src_dir"])
