"""``run_campaign``: run a loaded campaign's unfinished runs, then merge, summarize and report."""

from __future__ import annotations

import importlib
import threading
from pathlib import Path

import pyarrow as pa

from uvsym.campaign.executors import make_executor
from uvsym.campaign.spec import Campaign
from uvsym.campaign.store import ResultStore, column_kind
from uvsym.campaign.summary import summarize, write_report
from uvsym.campaign.worker import load_hook
from uvsym.errors import CampaignError

__all__ = ["run_campaign", "default_out", "executor_options"]


def default_out(campaign: Campaign) -> Path:
    """Where a campaign writes when no folder is given: ./campaigns/<name>."""
    return Path("campaigns") / campaign.name


def executor_options(campaign: Campaign, executor=None, workers: int | None = None, scheduler: str | None = None,
                     chunk_size: int | None = None) -> dict:
    """The campaign's [executor] with the given overrides; CampaignError naming workers or chunk_size below 1."""
    options = dict(campaign.executor)
    if executor == "local" and scheduler is None:  # asked for by name: the file's scheduler does not apply
        options["scheduler"] = None
    options.update({k: v for k, v in (("workers", workers), ("scheduler", scheduler), ("chunk_size", chunk_size))
                    if v is not None})
    for key in ("workers", "chunk_size"):
        if options[key] is not None and (isinstance(options[key], bool) or not isinstance(options[key], int)
                                         or options[key] < 1):
            raise CampaignError(f"{key}: expected an integer >= 1, got {options[key]!r}")
    return options


def run_campaign(campaign: Campaign, out_dir=None, *, executor=None, workers: int | None = None,
                 scheduler: str | None = None, chunk_size: int | None = None, progress=None,
                 force: bool = False, log=None) -> pa.Table:
    """Run every run of ``campaign`` not already in a whole chunk of ``out_dir`` (default
    :func:`default_out`), then write results.parquet, results.csv, summary.json and the report.

    executor: None (the campaign's [executor]), "local", "dask", or an object with start, run and
    close (:mod:`uvsym.campaign.executors`); workers, scheduler and chunk_size override the
    campaign's. progress: called with the fraction (0..1) of this call's runs finished (its ``total``, where it
    has one, as a :class:`~uvsym.progress.ProgressBar` has, set to their number first); log: called
    with one line of text per step. Returns the results table (pyarrow; one row per finished run,
    in the campaign's order; ``table.to_pylist()`` gives dicts). Every check (folder, metrics hook,
    scheduler) happens before the first run.
    """
    say = log or (lambda line: None)
    store = ResultStore(default_out(campaign) if out_dir is None else out_dir, campaign.name, force)
    load_hook(campaign.settings)
    options = executor_options(campaign, executor, workers, scheduler, chunk_size)
    if isinstance(executor, str) or executor is None:
        executor = make_executor(executor or options["kind"], workers=options["workers"],
                                 scheduler=options["scheduler"], timeout_s=options["timeout_s"])
    done = store.finished()
    todo = [run for run in campaign.runs if run.id not in done]
    if hasattr(progress, "total"):  # a ProgressBar shows counts of the runs to run
        progress.total = len(todo)
    size = options["chunk_size"]
    chunks = [todo[i:i + size] for i in range(0, len(todo), size)]
    say(f"{campaign.name}: {len(campaign.runs)} runs, {len(campaign.runs) - len(todo)} finished before, "
        f"{len(todo)} to run in {len(chunks)} chunks on {type(executor).__name__}; writing {store.folder}")
    if chunks:
        # the report's plotting library loads while the workers run (the driver waits on them meanwhile)
        threading.Thread(target=importlib.import_module, args=("uvsym.report.figures",), daemon=True).start()
        executor.start()
        store.create()
        kinds = {c: column_kind([run.fields.get(c) for run in campaign.runs]) for c in campaign.columns}
        finished = [0]

        def on_chunk(index: int, rows: list[dict]) -> None:
            store.write_chunk(rows, kinds)
            finished[0] += len(rows)
            if progress is not None:
                progress(finished[0] / len(todo))

        try:
            executor.run(chunks, campaign.settings, on_chunk)
        finally:
            executor.close()
    else:
        store.create()
    table = store.results([run.id for run in campaign.runs])
    store.write_results(table)
    rows = table.to_pylist()
    summary = summarize(rows, campaign.name, len(campaign.runs), campaign.roc_by)
    write_report(store.folder, summary, rows, campaign.description)
    store.seal()
    say(f"{campaign.name}: {summary['ok']} ok, {summary['errors']} with an error; wrote {store.folder}")
    return table
