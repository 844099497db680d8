"""Output folders: checked before anything is written into them."""

from __future__ import annotations

from pathlib import Path

from uvsym.errors import UvsymError

__all__ = ["output_folder"]


def output_folder(path, what: str, error: type[UvsymError] = UvsymError) -> Path:
    """``path`` as a Path, ``error`` naming it when it, or the nearest existing parent, is a file."""
    folder = Path(path)
    existing = next((q for q in (folder, *folder.parents) if q.exists()), None)
    if existing is not None and not existing.is_dir():
        raise error(f"cannot write {what} into {folder}: {existing} is a file, not a folder")
    return folder
