"""Output folders and files: checked before anything is written into them.

A folder uvsym writes a package or a report into must be new, empty, or uvsym's own: its record
(:data:`RECORDS`: a C package's ``manifest.json``, a report's ``.build.json``) lists the SHA-256 of
every file uvsym wrote there (``files``), and a folder holding any other file, or a listed file
changed since, is refused unless ``force``. A record without ``files`` (older uvsym; committed
reports have no ``.build.json``) is recognised as before: an uvsym manifest, or ``report.md``
beside ``results.json``. An existing result file is not overwritten unless ``overwrite``. Every
refusal is a :class:`~uvsym.errors.PathError` naming the path.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from uvsym.errors import PathError, UvsymError

__all__ = ["output_folder", "claim_folder", "make_folder", "output_file", "OWNERS", "RECORDS", "WRITERS", "file_hashes",
           "recorded_files", "record_of", "write_files", "remove_stale"]


def output_folder(path, what: str, error: type[UvsymError] = UvsymError) -> Path:
    """``path`` as a Path, ``error`` naming it when it, or the nearest existing parent, is a file."""
    folder = Path(path)
    for link in (folder, *folder.parents):
        if link.is_symlink() and not link.exists():
            raise error(f"cannot write {what} into {folder}: {link} is a symbolic link to {os.readlink(link)}, "
                        "which does not exist")
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


# what uvsym writes -> how it recognises a folder of its own without a list of files
OWNERS = {"package": _package_manifest, "report": _report}
# what uvsym writes -> its record in the folder (a JSON object whose "files" maps path -> SHA-256)
RECORDS = {"package": "manifest.json", "report": ".build.json"}


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def file_hashes(folder, skip: str | None = None) -> dict[str, str]:
    """Every file under ``folder`` (its path relative to it, with /) -> SHA-256, except ``skip``."""
    folder = Path(folder)
    return {rel: _sha256(p) for p in sorted(folder.rglob("*"))
            if p.is_file() and (rel := p.relative_to(folder).as_posix()) != skip}


def recorded_files(folder, owner: str) -> dict[str, str] | None:
    """The files ``folder``'s ``owner`` record lists (path -> SHA-256); None when it lists none."""
    try:
        record = json.loads((Path(folder) / RECORDS[owner]).read_text())
    except (OSError, ValueError):
        return None
    files = record.get("files") if isinstance(record, dict) else None
    if not isinstance(files, dict) or not all(isinstance(h, str) for h in files.values()):
        return None
    return files


def write_files(folder, texts: dict[str, str]) -> dict[str, str]:
    """Write ``texts`` (path relative to ``folder`` -> content; folders made); their SHA-256 by path."""
    folder = Path(folder)
    for rel, text in texts.items():
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        (folder / rel).write_text(text)
    return {rel: _sha256(folder / rel) for rel in texts}


def remove_stale(folder, old: dict[str, str], kept) -> list[str]:
    """Remove the files of the ``old`` record not in ``kept`` and unchanged since (uvsym's own), and
    the folders they leave empty; the paths removed."""
    folder, removed = Path(folder), []
    for rel, digest in sorted(old.items()):
        path = folder / rel
        if rel in kept or ".." in Path(rel).parts or not path.is_file() or _sha256(path) != digest:
            continue
        path.unlink()
        removed.append(rel)
        for parent in path.parents:
            if parent == folder or not parent.is_relative_to(folder) or any(parent.iterdir()):
                break
            parent.rmdir()
    return removed


def _listing(names: list[str]) -> str:
    return ", ".join(names[:5]) + (f" and {len(names) - 5} more" if len(names) > 5 else "")


def claim_folder(path, what: str, owner: str, force: bool = False, built: tuple[str, ...] = (),
                 writer: tuple[str, str] | None = None, accepts: tuple[str, ...] = ()) -> Path:
    """The folder ``path`` for ``what`` (not made here); PathError naming the files when it holds
    files that are not uvsym's own ``owner`` output, or that changed since uvsym wrote them (module
    docstring), unless ``force``, or is not a writable folder. ``built``: relative paths that the
    output's own build files write (a C package's ``make`` products), taken as uvsym's.

    writer: (command, name) of what writes the folder, e.g. ``("campaign", "dc-motor")``; a record
    says which command wrote the folder (its key among :data:`WRITERS`), and a folder another command
    wrote (unless its command is in ``accepts``), or another campaign, is refused too."""
    folder = output_folder(path, what, PathError)
    if not folder.is_dir() or force:
        return folder
    if writer is not None:
        _check_writer(folder, owner, what, writer, accepts)
    files = recorded_files(folder, owner)
    if files is None:  # no list of files: today's rule
        others = [] if OWNERS[owner](folder) else sorted(p.name for p in folder.iterdir())
        changed = []
    else:
        present = file_hashes(folder, skip=RECORDS[owner])
        others = [rel for rel in present if rel not in files and rel not in built]
        changed = [rel for rel, digest in present.items() if rel in files and files[rel] != digest]
    problems = ([f"files uvsym did not write ({_listing(others)})"] if others else []) + (
        [f"files changed since uvsym wrote them ({_listing(changed)})"] if changed else [])
    if problems:
        raise PathError(f"{folder} holds {' and '.join(problems)}; refusing to write {what} over them: "
                        "choose a new or empty folder, or pass --force to overwrite")
    return folder


# the key of a folder's record -> the command that wrote the folder (its value: what it wrote)
WRITERS = {"derivation": "uvsym report", "campaign": "uvsym campaign", "verify": "uvsym verify"}


def record_of(folder, owner: str) -> dict | None:
    """The JSON object of ``folder``'s ``owner`` record, or None."""
    try:
        record = json.loads((Path(folder) / RECORDS[owner]).read_text())
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def _check_writer(folder: Path, owner: str, what: str, writer: tuple[str, str], accepts: tuple[str, ...]) -> None:
    """PathError when the folder's record says another command wrote it, or another output of the same name."""
    record = record_of(folder, owner)
    if record is None:
        return
    command, name = writer
    found = [key for key in WRITERS if key in record]
    if found and command not in found and not set(found) & set(accepts):
        key = found[0]
        raise PathError(f"{folder} holds {WRITERS[key]}'s output for {record[key]!r}; refusing to write {what} "
                        "over it: choose another folder, or pass --force to overwrite")
    if command in found and command == "campaign" and record[command] != name:
        raise PathError(f"{folder} holds the campaign {record[command]!r}; refusing to write {what} over it: "
                        "choose another folder, or pass --force to overwrite")


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
        raise PathError(f"{path} exists; refusing to overwrite it (--force; overwrite=True in Python)")
    make_folder(path.parent, what)
    return path
