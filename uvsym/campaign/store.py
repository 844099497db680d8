"""A campaign's output folder: one Parquet file per finished chunk, merged into the results table.

``OUT/chunks/chunk-<hash>.parquet`` holds the rows of one chunk. A chunk is written to a
``.part`` file and renamed, after the folder's record (``.build.json``, as for reports: every file
uvsym wrote with its SHA-256, see :mod:`uvsym.paths`) lists it, so a campaign killed at any moment
leaves only whole chunks, which a rerun skips (but the runs whose worker process was lost, which it
runs again); leftover ``.part`` files of a campaign folder are removed. The folder is claimed with
:func:`uvsym.paths.claim_folder`: one holding files uvsym did not write is refused unless ``force``.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
from pathlib import Path

import pyarrow as pa
import pyarrow.csv
import pyarrow.parquet as pq

from uvsym.campaign.metrics import METRIC_COLUMNS
from uvsym.campaign.worker import lost_worker
from uvsym.errors import FileFormatError
from uvsym.paths import RECORDS, claim_folder, file_hashes, make_folder

__all__ = ["ResultStore", "to_table", "column_kind", "merge_tables"]

RECORD = RECORDS["report"]
_TYPES = {"string": pa.string(), "int64": pa.int64(), "float64": pa.float64(), "bool": pa.bool_(),
          "json": pa.string(), "null": pa.null()}


def column_kind(values) -> str:
    """How a column of Python values is stored: null, bool, int64, float64, string, or json (text)."""
    present = [v for v in values if v is not None]
    if not present:
        return "null"
    if all(isinstance(v, bool) for v in present):
        return "bool"
    if all(isinstance(v, int) and not isinstance(v, bool) for v in present):
        return "int64"
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in present):
        return "float64"
    if all(isinstance(v, str) for v in present):
        return "string"
    return "json"


def to_table(rows: list[dict], kinds: dict[str, str]) -> pa.Table:
    """Rows (dicts) as a table: the generic metric columns, then ``kinds``' columns (column -> kind of
    :func:`column_kind`), then any other key, its kind inferred; a missing value is null."""
    names = list(dict.fromkeys([*METRIC_COLUMNS, *kinds, *(key for row in rows for key in row)]))
    arrays = []
    for name in names:
        values = [row.get(name) for row in rows]
        kind = METRIC_COLUMNS.get(name) or kinds.get(name) or column_kind(values)
        if kind == "json":
            values = [None if v is None else json.dumps(v, sort_keys=True) for v in values]
        elif kind == "float64":
            values = [None if v is None else float(v) for v in values]
        arrays.append(pa.array(values, type=_TYPES[kind]))
    return pa.table(arrays, names=names)


def merge_tables(tables: list[pa.Table]) -> pa.Table:
    """One table of several chunks' tables (columns missing in some become null; a column whose
    types differ between chunks, e.g. a hook's int in one and text in another, becomes text)."""
    try:
        return pa.concat_tables(tables, promote_options="permissive")
    except (pa.ArrowInvalid, pa.ArrowTypeError):
        types: dict[str, set] = {}
        for table in tables:
            for field in table.schema:
                types.setdefault(field.name, set()).add(field.type)
        mixed = {name for name, kinds in types.items() if len(kinds - {pa.null()}) > 1}
        return pa.concat_tables([table.cast(pa.schema(
            [pa.field(f.name, pa.string() if f.name in mixed else f.type) for f in table.schema]))
            for table in tables], promote_options="permissive")


class ResultStore:
    """The output folder of the campaign ``name`` (module docstring); checked and made when opened."""

    def __init__(self, folder, name: str, force: bool = False):
        self.folder, self.name = Path(folder), name
        self._drop_partials()
        claim_folder(self.folder, f"the campaign {name}", "report", force, writer=("campaign", name))
        record = self._record()
        self.files = dict(record.get("files") or {}) if isinstance(record, dict) else {}
        self._written: dict[Path, pa.Table] = {}  # the chunks this store wrote: not read back

    def create(self) -> None:
        """Make the folder, its chunks/ and its record (after every check, before the first run: a campaign
        stopped before its first chunk lands resumes, its folder being the campaign's own)."""
        make_folder(self.folder / "chunks", f"the campaign {self.name}")
        self._save_record()

    def _record(self):
        try:
            return json.loads((self.folder / RECORD).read_text())
        except (OSError, ValueError):
            return None

    def _drop_partials(self) -> None:
        """Remove the ``.part`` files a killed campaign left (only in a folder whose record is a campaign's)."""
        record = self._record()
        if isinstance(record, dict) and "campaign" in record:
            for path in self.folder.rglob("*.part"):
                path.unlink()

    def _save_record(self) -> None:
        temporary = self.folder / f"{RECORD}.part"
        temporary.write_text(json.dumps({"campaign": self.name, "files": self.files}, indent=2, sort_keys=True) + "\n")
        os.replace(temporary, self.folder / RECORD)

    def chunk_files(self) -> list[Path]:
        return sorted((self.folder / "chunks").glob("chunk-*.parquet"))

    def finished(self) -> set[str]:
        """The ids of the runs in whole chunk files, but those whose only rows say their worker was lost
        (:data:`~uvsym.campaign.worker.LOST_WORKER`): a rerun runs them again."""
        done, lost = set(), set()
        for path in self.chunk_files():
            try:
                table = pq.read_table(path, columns=["run_id", "error"])
            except (OSError, pa.ArrowException) as exc:
                raise FileFormatError(f"{path}: not a campaign chunk uvsym wrote: {exc}") from None
            for run_id, error in zip(table.column("run_id").to_pylist(), table.column("error").to_pylist()):
                (lost if lost_worker(error) else done).add(run_id)
        return done

    def write_chunk(self, rows: list[dict], kinds: dict[str, str]) -> Path:
        """Write the rows of one finished chunk (recorded first, then written to .part and renamed)."""
        buffer = io.BytesIO()
        table = to_table(rows, kinds)
        pq.write_table(table, buffer)
        data = buffer.getvalue()
        ids = hashlib.sha256("\n".join(row["run_id"] for row in rows).encode()).hexdigest()[:16]
        rel = f"chunks/chunk-{ids}.parquet"
        self.files[rel] = hashlib.sha256(data).hexdigest()
        self._save_record()
        temporary = self.folder / f"{rel}.part"
        temporary.write_bytes(data)
        os.replace(temporary, self.folder / rel)
        self._written[self.folder / rel] = table
        return self.folder / rel

    def results(self, run_ids: list[str]) -> pa.Table:
        """The rows of the runs ``run_ids`` found in the chunk files, in that order (each once)."""
        tables = [self._written[path] if path in self._written else pq.read_table(path) for path in self.chunk_files()]
        if not tables:
            return to_table([], {})
        table = merge_tables(tables)
        where, errors = {}, table.column("error").to_pylist()
        for i, run_id in enumerate(table.column("run_id").to_pylist()):  # a run's row, not its lost worker's
            if run_id not in where or (lost_worker(errors[where[run_id]]) and not lost_worker(errors[i])):
                where[run_id] = i
        return table.take([where[run_id] for run_id in run_ids if run_id in where])

    def write_results(self, table: pa.Table) -> None:
        """results.parquet and results.csv (lists and tables as JSON text)."""
        pq.write_table(table, self.folder / "results.parquet")
        pyarrow.csv.write_csv(table, self.folder / "results.csv")

    def seal(self) -> None:
        """Record every file now in the folder (after the results and the report are written)."""
        self.files = file_hashes(self.folder, skip=RECORD)
        self._save_record()
