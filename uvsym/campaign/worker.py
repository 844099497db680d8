"""What a campaign worker does with a run: parse its scenario, simulate it, measure it; one row per run.

A run that raises gives a row with ``status = "error"`` and ``error = "Type: message"``; it never
ends the campaign. The functions here run in worker processes (local or Dask), so they take
only picklable arguments. :func:`execute_many` runs a batch: the runs that can share a compiled
step (method ``fast``, no supervisor or correcting diagnosis) go through
:func:`uvsym.sim.batch.simulate_batch`, in lanes of one loop built and compiled once per worker
for every fault size, current, initial state and seed; a batch in which a run fails is run again
one run at a time, so that each failure is its own row.
"""

from __future__ import annotations

import importlib
import signal
import sys
import time

from uvsym.campaign.metrics import METRIC_COLUMNS, run_metrics, truth
from uvsym.campaign.spec import Run, Settings, storable
from uvsym.errors import CampaignError

__all__ = ["LOST_WORKER", "load_hook", "execute", "execute_many", "failure_row", "lost_worker", "run_chunk",
           "serve"]

_SCALARS = (bool, int, float, str, type(None))


def load_hook(settings: Settings):
    """The metrics hook ``module:function`` (searched also in the campaign file's folder), or None;
    CampaignError naming ``metrics`` when it cannot be imported or is not callable."""
    if settings.metrics is None:
        return None
    module_name, _, function = settings.metrics.partition(":")
    if settings.root not in sys.path:
        sys.path.append(settings.root)
    try:
        hook = getattr(importlib.import_module(module_name), function)
    except (ImportError, AttributeError) as exc:
        raise CampaignError(f"metrics: cannot load {settings.metrics!r}: {exc}") from None
    if not callable(hook):
        raise CampaignError(f"metrics: {settings.metrics!r} is not callable")
    return hook


def _base(run: Run) -> dict:
    return {"run_id": run.id, "case": run.case, "draw": run.draw, **run.fields}


LOST_WORKER = ("WorkerDied", "KilledWorker")  # errors that say the run's process was lost, not the run


def lost_worker(error) -> bool:
    """Whether an error row's message says the run's worker process was lost (killed, crashed under it)."""
    return isinstance(error, str) and error.startswith(LOST_WORKER)


def failure_row(run: Run, message: str) -> dict:
    """The error row of a run that gave no row of its own (e.g. its worker process died)."""
    from uvsym.sim.system_scenario import parse_any_scenario

    return _base(run) | truth(parse_any_scenario(run.scenario)) | {"status": "error", "error": message}


def execute(run: Run, settings: Settings, hook=None) -> dict:
    """Simulate ``run`` and return its row: run_id, case, draw, its fields, status, error, the
    metrics of :func:`uvsym.campaign.metrics.run_metrics`, the hook's columns and wall_s (s)."""
    from uvsym.sim.system_scenario import parse_any_scenario, simulate_any_scenario

    started = time.perf_counter()
    row = _base(run)
    try:
        scenario = parse_any_scenario(run.scenario)
        row |= truth(scenario)
        result = simulate_any_scenario(scenario, **(dict(settings.simulation) | dict(run.simulation)))
        _measure(row, scenario, result, settings, hook)
    except Exception as exc:  # a run that fails is a row, not the end of the campaign
        row |= {"status": "error", "error": f"{type(exc).__name__}: {exc}"}
    row["wall_s"] = time.perf_counter() - started
    return row


def _measure(row: dict, scenario, result, settings: Settings, hook) -> None:
    """Add a finished run's metrics, the hook's columns and status "ok" to ``row`` (its base and truth)."""
    events = list(getattr(result, "events", None) or [])
    row |= run_metrics(scenario, result, events)
    if hook is not None:
        row |= _hook_columns(hook(scenario, result, events), settings.metrics, row)
    row |= {"status": "ok", "error": None}


def _lane_ready(scenario, options: dict) -> bool:
    """Whether simulate_batch runs ``scenario`` as simulate_any_scenario would with ``options``."""
    from uvsym.sim.system_scenario import SystemScenario

    if options.get("method", "fast") != "fast" or set(options) - {"method", "compiled", "substeps"}:
        return False
    if isinstance(scenario, SystemScenario):
        return scenario.supervisor is None
    return scenario.diagnosis is None or not scenario.diagnosis.correct


def execute_many(runs: list[Run], settings: Settings, hook=None) -> list[dict]:
    """The rows of ``runs`` (in order), as :func:`execute` gives them; those that share a loop and its
    options run in lanes (module docstring). Each lane row's ``wall_s`` is its share of its batch's time."""
    from uvsym.sim.batch import simulate_batch
    from uvsym.sim.system_scenario import parse_any_scenario

    rows: dict[int, dict] = {}
    batches: dict[tuple, list[tuple[int, object]]] = {}
    for i, run in enumerate(runs):
        options = dict(settings.simulation) | dict(run.simulation)
        try:
            scenario = parse_any_scenario(run.scenario)
        except Exception:  # its error row comes from execute, which parses it again
            rows[i] = execute(run, settings, hook)
            continue
        if _lane_ready(scenario, options):
            batches.setdefault(tuple(sorted(options.items())), []).append((i, scenario))
        else:
            rows[i] = execute(run, settings, hook)
    for key, members in batches.items():
        options = dict(key)
        started = time.perf_counter()
        try:
            results = simulate_batch([scenario for _, scenario in members], compiled=options.get("compiled", True),
                                     substeps=options.get("substeps", 1), current_in_step=False)
            batch = []
            for (i, scenario), result in zip(members, results):
                row = _base(runs[i]) | truth(scenario)
                _measure(row, scenario, result, settings, hook)
                batch.append((i, row))
        except Exception:  # one run's failure: each run alone, for its own row
            for i, _ in members:
                rows[i] = execute(runs[i], settings, hook)
            continue
        share = (time.perf_counter() - started) / len(members)
        rows.update((i, row | {"wall_s": share}) for i, row in batch)
    return [rows[i] for i in range(len(runs))]


def _hook_columns(columns, name: str, row: dict) -> dict:
    """The hook's columns, checked: new names (not a metric, a field or another column of ``row``),
    scalar values a results table can hold."""
    if not isinstance(columns, dict):
        raise CampaignError(f"metrics: {name} returned {type(columns).__name__}, not a dict of columns")
    for key, value in columns.items():
        if not isinstance(key, str) or key in METRIC_COLUMNS or key in row:
            raise CampaignError(f"metrics: {name} returned the column {key!r}, which is not a new column name "
                                "(a metric, a field or another column of the run has it)")
        if not isinstance(value, _SCALARS) or not storable(value):
            raise CampaignError(f"metrics: {name} column {key!r}: expected a number (an integer within 64 bits), "
                                f"string, bool or None, got {value!r:.60}")
    return columns


def run_chunk(runs: list[Run], settings: Settings) -> list[dict]:
    """The rows of ``runs``, in order (a Dask task), by :func:`execute_many`."""
    return execute_many(runs, settings, load_hook(settings))


def serve(conn, settings: Settings) -> None:
    """A local worker process: receive batches of runs (lists) on ``conn``, send back their rows (a list,
    by :func:`execute_many`), until None or the driver goes. Ctrl-C is the driver's to handle (it stops
    the workers)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    hook = load_hook(settings)
    while True:
        try:
            runs = conn.recv()
            if runs is None:
                return
            conn.send(execute_many(runs, settings, hook))
        except (EOFError, OSError):  # the driver has gone: nothing to report to
            return
