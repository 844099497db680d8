"""Campaigns: one scenario swept over grids and Monte Carlo draws, run on local processes or Dask,
measured run by run, resumable, summarized in a report (``uvsym campaign FILE.toml``).

``load_campaign(path)`` expands and validates every run (:mod:`.spec`); ``run_campaign(campaign,
out_dir)`` runs the unfinished ones (:mod:`.executors`), writes each chunk of rows as it finishes
(:mod:`.store`) and returns the results as a pyarrow Table; :mod:`.metrics` measures a run from
its event log, :mod:`.summary` writes summary.json and the report. The names below are imported
on first use: reading a campaign file does not import the simulator or pyarrow.
"""

from uvsym.lazy import lazy_exports

_EXPORTS = {  # name -> the submodule that defines it (imported on first use, :mod:`uvsym.lazy`)
    **dict.fromkeys(["LocalExecutor", "DaskExecutor", "make_executor"], "executors"),
    **dict.fromkeys(["event_metrics", "run_metrics", "truth"], "metrics"),
    **dict.fromkeys(["default_out", "run_campaign"], "runner"),
    **dict.fromkeys(["Campaign", "Run", "Settings", "load_campaign", "parse_campaign"], "spec"),
}
__all__ = ["Campaign", "Run", "Settings", "load_campaign", "parse_campaign", "run_campaign", "default_out",
           "LocalExecutor", "DaskExecutor", "make_executor", "truth", "event_metrics", "run_metrics"]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
