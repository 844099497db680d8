"""Campaign files: cases of a scenario swept over a grid and/or Monte Carlo draws, expanded into runs.

A campaign file (TOML) holds ``name``, ``description``, ``max_runs`` (default 1000; more runs need
confirmation), ``metrics`` (``module:function(scenario, result, events) -> dict`` of extra columns:
``scenario`` the run's validated :class:`~uvsym.sim.scenario.Scenario` (its faults as
``actuator_faults`` and ``sensor_faults``), ``result`` its SimResult, ``events`` its decision log),
``roc_by`` (field paths grouping the ROC points), ``[executor]`` (kind, workers, scheduler, chunk_size,
timeout_s: how long to wait for a Dask scheduler to answer, not a limit per run), ``[simulation]``
(method, compiled, substeps: options of :func:`~uvsym.sim.simulation.simulate_scenario`) and one or more
``[[case]]`` tables: ``name``, ``scenario`` (a shipped scenario or a path relative to the campaign
file), ``set`` (dotted path -> value, every run of the case), ``[case.simulation]`` (the options of
``[simulation]`` it gives, for the case's runs: e.g. ``compiled = true`` for long fault-free runs that
share one compiled loop), ``[case.grid]`` (dotted path -> list of values, full product, in file order)
and ``[case.monte_carlo]`` (``runs`` draws per grid point from the master ``seed``, an integer; dotted
path -> ``{uniform = [lo, hi]}``, ``{normal = [mean, std]}``, ``{integers = [lo, hi]}`` (both ends
included) or ``{choice = [...]}``; ``seed = {integers = [lo, hi]}`` draws the scenario's own noise seed,
the master seed then ``master_seed``, default 0). Paths follow :mod:`uvsym.campaign.dotted`.

A case's scenario is a vehicle scenario or a scenario over any plant (``plant = ...``,
:mod:`uvsym.sim.system_scenario`); every run's scenario is parsed when the campaign is loaded, so a
bad field fails before anything runs. A run's id hashes its case name and its whole
scenario table: the key a resumed campaign skips finished runs by.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from uvsym.campaign.dotted import copied, flatten, new_entry, parse_path, set_path
from uvsym.errors import CampaignError, CampaignSizeError, ScenarioError, UvsymError, did_you_mean
from uvsym.sim.fields import Fields
from uvsym.sim.shipped import every_shipped_scenario

__all__ = ["Campaign", "Run", "Settings", "load_campaign", "parse_campaign", "DISTRIBUTIONS", "EXECUTORS", "storable"]

DISTRIBUTIONS = ("uniform", "normal", "integers", "choice")
EXECUTORS = ("local", "dask")
# field paths whose sweep is a setting of the diagnosis rather than of the mission: ROC groups by default
_SETTING_ROOTS = ("diagnosis", "observers", "detectors", "blocks")


@dataclass(frozen=True)
class Run:
    """One run: ``id`` (16 hex digits), its case, Monte Carlo draw (None without), the values of its
    grid and drawn fields (column -> value, tables flattened), its scenario table, and the simulation
    options its case sets over the campaign's (name, value pairs)."""

    id: str
    case: str
    draw: int | None
    fields: dict
    scenario: dict
    simulation: tuple = ()


@dataclass(frozen=True)
class Settings:
    """What a worker needs besides the run: the metrics hook (``module:function`` or None), the
    campaign file's folder (searched for the hook's module) and simulate_scenario's options."""

    metrics: str | None = None
    root: str = "."
    simulation: tuple = ()


@dataclass(frozen=True)
class Campaign:
    """A loaded campaign: every run expanded and its scenario validated. ``executor`` holds kind,
    workers (None: cores), scheduler (None), chunk_size and timeout_s (s); ``columns`` are the field
    columns in order; ``roc_by`` the field columns that group ROC points."""

    name: str
    description: str
    path: Path | None
    max_runs: int
    settings: Settings
    executor: dict
    runs: tuple[Run, ...]
    columns: tuple[str, ...]
    roc_by: tuple[str, ...]


def load_campaign(path, *, confirm: bool = False) -> Campaign:
    """Read, expand and validate the campaign file ``path``; ``confirm`` allows more runs than max_runs."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise CampaignError(f"{path}: not valid TOML: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CampaignError(f"{path}: cannot be read: {exc}") from None
    return parse_campaign(data, root=path.parent, default_name=path.stem, confirm=confirm, path=path)


def parse_campaign(data: dict, root=".", default_name: str = "campaign", *, confirm: bool = False,
                   path: Path | None = None) -> Campaign:
    """A :class:`Campaign` from a parsed campaign table; scenario paths are relative to ``root``."""
    try:
        top = Fields(data, "")
        name = top.text("name", default_name)
        description = top.text("description", "")
        max_runs = _integer(top, "max_runs", 1000, 1)
        metrics = top.raw("metrics", None)
        if metrics is not None and (not isinstance(metrics, str) or metrics.count(":") != 1):
            raise CampaignError(f"metrics: expected 'module:function', got {metrics!r}")
        roc_by = top.raw("roc_by", None)
        executor = _executor(top.table("executor") or top.empty("executor"))
        simulation = _simulation(top.table("simulation") or top.empty("simulation"))
        cases = top.tables("case")
        top.done()
    except CampaignError:
        raise
    except ScenarioError as exc:
        raise CampaignError(str(exc)) from None
    if not cases:
        raise CampaignError("case: a campaign needs at least one [[case]] table")
    specs = [_case(fields, Path(root)) for fields in cases]
    names = [spec["name"] for spec in specs]
    if len(set(names)) != len(names):
        duplicate = next(n for n in names if names.count(n) > 1)
        raise CampaignError(f"case[{names.index(duplicate, names.index(duplicate) + 1)}].name: {duplicate!r} names "
                            "two cases; each case needs its own name")
    total = sum(_count(spec) for spec in specs)
    if total > max_runs and not confirm:
        raise CampaignSizeError(f"max_runs: the campaign has {total} runs, more than max_runs = {max_runs}; "
                                "confirm with --yes (confirm=True) or raise max_runs")
    runs = [run for spec in specs for run in _expand(spec)]
    seen: dict[str, Run] = {}
    for run in runs:
        if run.id in seen:
            raise CampaignError(f"case {run.case!r}: two runs have the same scenario ({_describe(run.fields)}); "
                                "remove the repeated grid value")
        seen[run.id] = run
    from uvsym.sim.system_scenario import is_system_scenario  # the simulator: imported once the file is read

    if any("substeps" in dict(simulation) | dict(run.simulation) and is_system_scenario(run.scenario) for run in runs):
        raise CampaignError("simulation.substeps: a scenario over a plant sets its own substeps (substeps = N in "
                            "the scenario, or a case's set)")
    columns = tuple(dict.fromkeys(column for run in runs for column in run.fields))
    if roc_by is None:
        roc_by = [c for c in columns if parse_path(c)[0] in _SETTING_ROOTS]
    roc_by = [roc_by] if isinstance(roc_by, str) else roc_by
    if not isinstance(roc_by, list) or any(c not in columns for c in roc_by):
        raise CampaignError(f"roc_by: expected field columns of the campaign ({', '.join(columns) or 'none'}), "
                            f"got {roc_by!r}")
    settings = Settings(metrics=metrics, root=str(Path(root).resolve()), simulation=simulation)
    return Campaign(name=name, description=description, path=path, max_runs=max_runs, settings=settings,
                    executor=executor, runs=tuple(runs), columns=columns, roc_by=tuple(roc_by))


def _integer(fields: Fields, key: str, default, minimum: int):
    value = fields.raw(key, default)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise CampaignError(f"{fields._name(key)}: expected an integer >= {minimum}, got {value!r}")
    return value


def _executor(fields: Fields) -> dict:
    kind = fields.text("kind", "local", choices=EXECUTORS)
    scheduler = fields.raw("scheduler", None)
    if scheduler is not None and not isinstance(scheduler, str):
        raise CampaignError(f"executor.scheduler: expected an address such as 'tcp://host:8786', got {scheduler!r}")
    executor = {"kind": "dask" if scheduler else kind, "workers": _integer(fields, "workers", None, 1),
                "scheduler": scheduler, "chunk_size": _integer(fields, "chunk_size", 8, 1),
                "timeout_s": fields.number("timeout_s", 10.0, positive=True)}
    fields.done()
    return executor


def _simulation(fields: Fields, given_only: bool = False) -> tuple:
    """The ``[simulation]`` options as (name, value) pairs; ``given_only``: only those the table gives
    (a case's, over the campaign's)."""
    from uvsym.sim.integrator_options import METHODS

    options = {"method": fields.text("method", "fast", choices=METHODS)}
    compiled = fields.raw("compiled", True)
    if not isinstance(compiled, bool):
        raise CampaignError(f"{fields._name('compiled')}: expected true or false, got {compiled!r}")
    options["compiled"] = compiled
    substeps = _integer(fields, "substeps", 1, 1)
    if substeps != 1 or (given_only and fields.has("substeps")):
        options["substeps"] = substeps
    fields.done()
    return tuple((key, value) for key, value in options.items() if not given_only or fields.has(key))


def _scenario_table(fields: Fields, root: Path) -> tuple[dict, str]:
    from uvsym.sim.scenario import read_scenario_file
    from uvsym.sim.system_scenario import is_system_scenario

    source = fields.text("scenario")
    path = root / source
    if not path.is_file():
        shipped = every_shipped_scenario()
        if source not in shipped:
            raise CampaignError(f"{fields.path}.scenario: no file {path} and no shipped scenario {source!r}"
                                f"{did_you_mean(source, shipped)}; shipped: {', '.join(shipped)}")
        path = shipped[source]
    try:
        table = read_scenario_file(path)
    except ScenarioError as exc:
        raise CampaignError(f"{fields.path}.scenario: {exc}") from None
    if is_system_scenario(table) and ":" in str(table["plant"]):
        table.setdefault("plant_path", str(path.parent.resolve()))  # the plant's module, beside its scenario
    return table, path.stem


def _case(fields: Fields, root: Path) -> dict:
    """name, base (scenario table with ``set`` applied), scenario name, axes [(path, values)] and
    draws (runs, seed, [(path, distribution)]) or None, checked field by field."""
    try:
        name = fields.text("name")
        where = f"case {name!r}"
        base, scenario_name = _scenario_table(fields, root)
        assignments = fields.raw("set", {})
        if not isinstance(assignments, dict):
            raise CampaignError(f"{where}: set: expected a table of path = value, got {assignments!r}")
        for path, value in assignments.items():
            _apply(base, path, value, f"{where}: set")
        grid = fields.raw("grid", None)
        monte_carlo = fields.raw("monte_carlo", None)
        simulation = fields.table("simulation")
        simulation = () if simulation is None else _simulation(simulation, given_only=True)
        fields.done()
    except CampaignError:
        raise
    except ScenarioError as exc:
        raise CampaignError(str(exc)) from None
    axes = []
    if grid is not None:
        if not isinstance(grid, dict) or not grid:
            raise CampaignError(f"{where}: [case.grid] has no axes; leave it out for a single run")
        for path, values in grid.items():
            _checked_path(path, f"{where}: grid axis")
            if not isinstance(values, list):
                raise CampaignError(f"{where}: grid axis {path!r}: expected a list of values, got {values!r}")
            if not values:
                raise CampaignError(f"{where}: grid axis {path!r} is an empty list: the grid has no runs")
            axes.append((path, values))
    draws = None if monte_carlo is None else _monte_carlo(monte_carlo, where)
    return {"name": name, "base": base, "scenario": scenario_name, "axes": axes, "draws": draws,
            "simulation": simulation}


def _monte_carlo(table, where: str):
    if not isinstance(table, dict):
        raise CampaignError(f"{where}: monte_carlo: expected a table")
    table = dict(table)
    # seed = an integer is the draws' master seed (or master_seed, beside seed = a distribution, which
    # draws the scenario's own noise seed: TOML holds one key seed per table)
    master, runs = table.pop("master_seed", None), table.pop("runs", None)
    if isinstance(table.get("seed"), dict):
        seed = 0 if master is None else master
    elif master is not None and "seed" in table:
        raise CampaignError(f"{where}: monte_carlo: give the master seed as seed or as master_seed, not both")
    else:
        seed = table.pop("seed", 0 if master is None else master)
    for key, value, minimum in (("runs", runs, 1), ("seed", seed, 0)):
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            raise CampaignError(f"{where}: monte_carlo.{key}: expected an integer >= {minimum}, got {value!r}")
    if not table:
        raise CampaignError(f"{where}: monte_carlo: no field to draw (path = {{uniform = [lo, hi]}}, ...)")
    fields = []
    for path, spec in table.items():
        _checked_path(path, f"{where}: monte_carlo field")
        if not isinstance(spec, dict) or len(spec) != 1 or next(iter(spec)) not in DISTRIBUTIONS:
            raise CampaignError(f"{where}: monte_carlo field {path!r}: expected one of "
                                f"{', '.join(f'{{{d} = ...}}' for d in DISTRIBUTIONS)}, got {spec!r}")
        kind, args = next(iter(spec.items()))
        _check_distribution(kind, args, f"{where}: monte_carlo field {path!r}: {kind}")
        fields.append((path, kind, args))
    return runs, seed, fields


def _check_distribution(kind: str, args, where: str) -> None:
    if kind == "choice":
        if not isinstance(args, list) or not args:
            raise CampaignError(f"{where}: expected a non-empty list of values, got {args!r}")
        return
    numbers = isinstance(args, list) and len(args) == 2 and all(
        isinstance(a, (int, float)) and not isinstance(a, bool) and math.isfinite(a) for a in args)
    if not numbers:
        raise CampaignError(f"{where}: expected two finite numbers, got {args!r}")
    if kind == "integers" and not all(isinstance(a, int) for a in args):
        raise CampaignError(f"{where}: expected two integers [lo, hi], got {args!r}")
    if kind == "normal" and args[1] < 0:
        raise CampaignError(f"{where}: the standard deviation must be >= 0, got {args[1]!r}")
    if kind != "normal" and args[0] > args[1]:
        raise CampaignError(f"{where}: lo {args[0]!r} > hi {args[1]!r}")


def _draw(rng: np.random.Generator, kind: str, args):
    if kind == "uniform":
        return float(rng.uniform(args[0], args[1]))
    if kind == "normal":
        return float(rng.normal(args[0], args[1]))
    if kind == "integers":
        return int(rng.integers(args[0], args[1], endpoint=True))
    return copied(args[int(rng.integers(len(args)))])


def _count(spec: dict) -> int:
    return math.prod(len(values) for _, values in spec["axes"]) * (spec["draws"][0] if spec["draws"] else 1)


def _checked_path(path: str, where: str) -> None:
    try:
        parse_path(path)
    except CampaignError as exc:
        raise CampaignError(f"{where} {exc}") from None


def _apply(data: dict, path: str, value, where: str) -> None:
    try:
        set_path(data, path, value)
    except CampaignError as exc:
        raise CampaignError(f"{where}: {exc}") from None


def _describe(fields: dict) -> str:
    return ", ".join(f"{k} = {json.dumps(v)}" for k, v in fields.items()) or "no fields"


def _expand(spec: dict) -> list[Run]:
    """The case's runs in order (grid points in product order, draws within each), each parsed."""
    name, where = spec["name"], f"case {spec['name']!r}"
    paths = [path for path, _ in spec["axes"]]
    drawn_paths = [path for path, _, _ in spec["draws"][2]] if spec["draws"] else []
    made = [entry for entry in (new_entry(spec["base"], path) for path in paths + drawn_paths) if entry]
    runs = []
    for point in itertools.product(*(values for _, values in spec["axes"])):
        table = copied(spec["base"])
        fields: dict = {}
        for path, value in zip(paths, point):
            _apply(table, path, value, f"{where}: grid axis {path!r}")
            fields |= flatten(path, value)
        if spec["draws"] is None:
            runs.append(_run(name, None, fields, table, spec["scenario"], made, spec["simulation"]))
            continue
        count, seed, distributions = spec["draws"]
        digest = hashlib.sha256(json.dumps([name, point], sort_keys=True, default=str).encode()).digest()
        for draw in range(count):
            # one generator per (master seed, case, grid point, draw): draws do not move when others are added
            rng = np.random.default_rng([seed, *np.frombuffer(digest[:16], dtype=np.uint32).tolist(), draw])
            drawn, drawn_fields = copied(table), dict(fields)
            for path, kind, args in distributions:
                value = _draw(rng, kind, args)
                _apply(drawn, path, value, f"{where}: monte_carlo field {path!r}")
                drawn_fields |= flatten(path, value)
            runs.append(_run(name, draw, drawn_fields, drawn, spec["scenario"], made, spec["simulation"]))
    return runs


INT64 = (-2 ** 63, 2 ** 63 - 1)  # what a results table's integer column holds


def storable(value) -> bool:
    """Whether a results table can hold ``value`` (every integer in it within 64 bits, recursively)."""
    if isinstance(value, bool) or value is None:
        return True
    if isinstance(value, int):
        return INT64[0] <= value <= INT64[1]
    if isinstance(value, (list, tuple)):
        return all(storable(v) for v in value)
    if isinstance(value, dict):
        return all(storable(v) for v in value.values())
    return True


def _run(case: str, draw: int | None, fields: dict, table: dict, scenario_name: str, made=(),
         simulation: tuple = ()) -> Run:
    """The parsed run; made: list entries (``faults[1]``) the case's paths add to its scenario (named
    in an error that is about one of them); simulation: the case's options."""
    huge = [column for column, value in fields.items() if not storable(value)]
    if huge:
        raise CampaignError(f"case {case!r}, run {_describe(fields)}: {huge[0]} = {fields[huge[0]]!r:.40} holds an "
                            "integer beyond 64 bits, which the results table cannot store")
    from uvsym.sim.system_scenario import parse_any_scenario

    try:
        parse_any_scenario(table, default_name=scenario_name)
    except UvsymError as exc:
        about = [entry for entry in made if str(exc).startswith(entry)]
        hint = (f" ({about[0]} is not in the scenario: the case's paths made it from the fields they set; to add "
                f"an entry set all of it, e.g. set = {{ \"{about[0]}\" = {{ ... }} }}, or index an existing one)"
                if about else "")
        raise CampaignError(f"case {case!r}, run {_describe(fields)}"
                            + ("" if draw is None else f", draw {draw}") + f": {exc}{hint}") from None
    table.setdefault("name", scenario_name)
    key = json.dumps({"case": case, "scenario": table}, sort_keys=True, default=str)
    return Run(id=hashlib.sha256(key.encode()).hexdigest()[:16], case=case, draw=draw, fields=fields,
               scenario=table, simulation=simulation)

