"""Campaigns: one scenario swept over grids and Monte Carlo draws, run on local processes or Dask,
measured run by run, resumable, summarized in a report (``uvsym campaign FILE.toml``).

``load_campaign(path)`` expands and validates every run (:mod:`.spec`); ``run_campaign(campaign,
out_dir)`` runs the unfinished ones (:mod:`.executors`), writes each chunk of rows as it finishes
(:mod:`.store`) and returns the results as a pyarrow Table; :mod:`.metrics` measures a run from
its event log, :mod:`.summary` writes summary.json and the report.
"""

from uvsym.campaign.executors import DaskExecutor, LocalExecutor, make_executor
from uvsym.campaign.metrics import event_metrics, run_metrics, truth
from uvsym.campaign.runner import default_out, run_campaign
from uvsym.campaign.spec import Campaign, Run, Settings, load_campaign, parse_campaign

__all__ = ["Campaign", "Run", "Settings", "load_campaign", "parse_campaign", "run_campaign", "default_out",
           "LocalExecutor", "DaskExecutor", "make_executor", "truth", "event_metrics", "run_metrics"]
