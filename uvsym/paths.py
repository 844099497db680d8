"""Output folders and files: checked before anything is written into them.

A folder uvsym writes a package or a report into must be new, empty, or recognisably uvsym's own
(its manifest: a C package's ``manifest.json``, a report's ``report.md`` with ``results.json``);
otherwise the files in it are someone else's and are not overwritten unless ``force``. An
existing result file is not overwritten unless ``overwrite``. Every refusal is a
:class:`~uvsym.errors.PathError` naming the path.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from uvsym.errors import PathError, UvsymError

__all__ = ["output_folder", "claim_folder", "make_folder", "output_file", "OWNERS"]


def output_folder(path, what: str, error: type[UvsymError] = UvsymError) -> Path:
    """``path`` as a Path, ``error`` naming it when it, or the nearest existing parent, is a file."""
    folder = Path(path)
    existing = next((q for q in (folder, *folder.parents) if q.exists()), None)
    if existing is not None and not existing.is_dir():
        raise error(f"cannot write {what} into {folder}: {existing} is a file, not a folder")
    if existing is not None and not os.access(existing, os.W_OK | os.X_OK):
        raise error(f"cannot write {what} into {folder}: {existing} is not writable")
    return folder


def _package_manifest(folder: Path) -> bool:
    """True when ``folder/manifest.json`` is a C package manifest uvsym wrote."""
    try:
        manifest = json.loads((folder / "manifest.json").read_text())
    except (OSError, ValueError):
        return False
    return isinstance(manifest, dict) and {"package", "precision", "functions"} <= set(manifest)


def _report(folder: Path) -> bool:
    """True when ``folder`` holds a derivation report uvsym wrote (report.md beside a JSON results.json)."""
    try:
        json.loads((folder / "results.json").read_text())
        return (folder / "report.md").read_text().startswith("# ")
    except (OSError, ValueError):
        return False


# what uvsym writes -> how it recognises a folder of its own
OWNERS = {"package": _package_manifest, "report": _report}


def claim_folder(path, what: str, owner: str, force: bool = False) -> Path:
    """The folder ``path`` for ``what`` (not made here); PathError when it holds files that are not
    uvsym's own ``owner`` output (see :data:`OWNERS`), unless ``force``, or is not a writable folder."""
    folder = output_folder(path, what, PathError)
    if folder.is_dir() and not force and not OWNERS[owner](folder):
        others = sorted(p.name for p in folder.iterdir())
        if others:
            shown = ", ".join(others[:5]) + (f" and {len(others) - 5} more" if len(others) > 5 else "")
            raise PathError(f"{folder} holds files uvsym did not write ({shown}); refusing to write {what} over "
                            "them: choose a new or empty folder, or pass --force to overwrite")
    return folder


def make_folder(path, what: str) -> Path:
    """The folder ``path``, made with its parents if missing; PathError naming it when it cannot be."""
    folder = output_folder(path, what, PathError)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise PathError(f"cannot make the folder {folder} for {what}: {exc.strerror or exc}") from None
    return folder


def output_file(path, what: str, overwrite: bool = False) -> Path:
    """``path`` checked before any work: not a folder, its folder made if missing (PathError when it
    cannot be), no existing file unless ``overwrite``."""
    path = Path(path)
    if path.is_dir():
        raise PathError(f"cannot write {what} to {path}: it is a folder")
    if path.exists() and not overwrite:
        raise PathError(f"{path} exists; refusing to overwrite it (pass overwrite=True, or --force)")
    make_folder(path.parent, what)
    return path
