"""The ``uvsym`` command: list and inspect vehicles, simulate, and run derivations (report, verify, codegen).

Derivations and their observer sets come through :mod:`uvsym.derivation`. Each command imports what it
runs, and only once its names are checked: ``--help`` and a misspelt name answer without CasADi or scipy.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from uvsym import __version__
from uvsym.errors import UnknownNameError, UvsymError, did_you_mean
from uvsym.paths import RECORDS, claim_folder, file_hashes, make_folder, output_folder, record_of

if TYPE_CHECKING:
    from uvsym.derivation import Derivation

__all__ = ["BUILD_STAMP", "main"]

BUILD_STAMP = RECORDS["report"]  # in each report folder: its source fingerprint and files (not committed)


def _table(rows: list[list[str]], header: list[str]) -> str:
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    line = lambda r: "  ".join(str(c).ljust(w) for c, w in zip(r, widths)).rstrip()  # noqa: E731
    return "\n".join([line(header), line(["-" * w for w in widths]), *map(line, rows)])


def _cmd_models(args) -> int:
    import numpy as np

    from uvsym.models import VEHICLES, vehicle
    from uvsym.systems.registry import PLANTS, plant, plant_names

    if args.action == "show":
        if not args.name:
            raise UnknownNameError(f"'uvsym models show' needs a name; known: {', '.join(plant_names())}")
        if args.name in PLANTS:
            return _show_plant(plant(args.name), args.json)
        if args.name not in VEHICLES:
            raise UnknownNameError(f"unknown model {args.name!r}; known: {', '.join(plant_names())}")
        model = vehicle(args.name)
        summary = model.summary()
        if args.json:
            print(json.dumps(summary, indent=2))
            return 0
        print(f"{model.name}: {model.description}")
        states = ", ".join(f"{lab} ({unit})" for lab, unit in zip(model.state_labels, model.state_units))
        print(f"{model.dof} DOF; states x = [eta; nu] = {states}")
        print("inputs: " + ", ".join(f"{i['label']} ({i['unit']}, {i['min']:.6g} .. {i['max']:.6g})"
                                     for i in summary["inputs"]))
        print("equations: M (nu_dot - nu_c_dot) + h(eta, nu) = tau(eta, nu, u);  h = " + " + ".join(model.term_names))
        print(f"nu_dot: {model.nu_dot.n_instructions()} SX instructions\n")
        print("M =\n" + np.array2string(model.M, precision=6, suppress_small=True, max_line_width=140) + "\n")
        _parameter_table(model.parameters)
        return 0
    listing = [{"name": name, "kind": "vehicle", "description": description, "dof": vehicle(name).dof,
                "states": list(vehicle(name).state_labels), "inputs": list(vehicle(name).input_labels)}
               for name, (description, _) in VEHICLES.items()]
    listing += [{"name": name, "kind": "plant", "description": description, "dof": None,
                 "states": list(plant(name).x.names), "inputs": list(plant(name).u.names)}
                for name, (description, _) in PLANTS.items()]
    if args.json:
        print(json.dumps(listing, indent=2))
    else:
        print(_table([[v["name"], v["dof"], ", ".join(v["inputs"]), v["description"]] for v in listing
                      if v["kind"] == "vehicle"], ["vehicle", "dof", "inputs", "description"]) + "\n")
        print(_table([[p["name"], _signals_line(plant(p["name"]).x), _signals_line(plant(p["name"]).u),
                       p["description"]]
                      for p in listing if p["kind"] == "plant"], ["plant", "states", "inputs", "description"]))
    return 0


def _signals_line(group) -> str:
    return ", ".join(f"{name} ({unit})" for name, unit in zip(group.names, group.units)) or "none"


def _parameter_table(parameters) -> None:
    rows = [[name, _format_value(p.value), p.unit, p.description] for name, p in parameters.items()]
    print(_table(rows, ["parameter", "value", "unit", "meaning"]))


def _show_plant(system, as_json: bool) -> int:
    """``uvsym models show PLANT``: signals with units, operating point, constants, source."""
    if as_json:
        print(json.dumps(system.summary(), indent=2))
        return 0
    print(f"{system.name}: {system.description}")
    print("continuous time" if system.dt is None else f"discrete time, dt = {system.dt:g} s")
    for label, group in (("states x", system.x), ("inputs u", system.u), ("disturbances d", system.d),
                         ("parameters p", system.p), ("outputs y", system.y)):
        print(f"{label}: {_signals_line(group)}")
    print("operating point: " + ", ".join(f"{n} = {v:.6g}" for n, v in zip(system.x.names, system.x_op))
          + "; " + ", ".join(f"{n} = {v:.6g}" for n, v in zip(system.u.names, system.u_op)))
    print(f"f: {system.f.n_instructions()} SX instructions\nsource: {system.source}\n")
    if system.constants is not None:
        _parameter_table(system.constants)
    return 0


def _format_value(value) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in value) + "]" if isinstance(value, tuple) else f"{value:.6g}"


def _selected(names: list[str]) -> list[Derivation]:
    """The derivations named (each checked before any is loaded), or all installed ones."""
    from uvsym.derivation import derivations, load_derivations

    return derivations(names) if names else list(load_derivations().values())


def _cmd_report(args) -> int:
    selected = _selected(args.names)
    from uvsym.derivation import source_fingerprint
    from uvsym.report.figures import figure_style
    from uvsym.report.html import write_html

    out_root = output_folder(args.out, "reports")
    out_dirs = [claim_folder(out_root / study.name, f"the {study.name} report", "report", args.force,
                             writer=("derivation", study.name), accepts=("verify",))
                for study in selected]  # every folder checked, then made, before any study runs
    for out_dir in out_dirs:
        make_folder(out_dir, "a report")
    for index, (study, out_dir) in enumerate(zip(selected, out_dirs), 1):

        def progress(message: str, _name=study.name, _index=index) -> None:
            print(f"[{_index}/{len(selected)}] {_name}: {message}", file=sys.stderr, flush=True)

        with figure_style():  # every figure of every report in uvsym's one style
            study.build(out_dir, progress)
        progress("report.html")
        write_html(out_dir)
        stamp = {"derivation": study.name, "source_fingerprint": source_fingerprint(study),
                 "files": file_hashes(out_dir, skip=BUILD_STAMP)}  # what claim_folder checks next time
        (out_dir / BUILD_STAMP).write_text(json.dumps(stamp) + "\n")
        print(f"wrote {out_dir}")
    return 0


def _scenario_path(source: str) -> Path:
    """A scenario file, or the file of a shipped scenario (uvsym's, found without importing the
    derivations, else a derivation's) named ``source``."""
    from uvsym.sim.shipped import every_shipped_scenario, shipped_scenarios

    path = Path(source)
    if path.exists():
        return path
    own = {**shipped_scenarios(), **shipped_scenarios("plant")}
    if source in own:
        return own[source]
    shipped = every_shipped_scenario()
    if source not in shipped:
        raise UnknownNameError(f"no scenario file {source!r} and no shipped scenario of that name"
                               f"{did_you_mean(source, shipped)}; shipped: {', '.join(sorted(shipped))}")
    return shipped[source]


def _cmd_simulate(args) -> int:
    from uvsym.derivation import study_scenarios
    from uvsym.sim.shipped import shipped_scenarios

    if args.schema is not False:  # the kind named, else the given file's, else the vehicle format
        from uvsym.sim.scenario import read_scenario_file
        from uvsym.sim.schema import schema_markdown
        from uvsym.sim.system_scenario import is_system_scenario

        kind = args.schema or ("plant" if args.scenario and is_system_scenario(
            read_scenario_file(_scenario_path(args.scenario))) else "vehicle")
        print(schema_markdown(kind))
        return 0
    if args.list or not args.scenario:
        rows = [[name, "", str(path.name)] for name, path in shipped_scenarios().items()]
        rows += [[name, "", f"plants/{path.name}"] for name, path in shipped_scenarios("plant").items()]
        rows += [[name, study, str(path.name)] for name, (study, path) in study_scenarios().items()]
        print(_table(rows, ["shipped scenario", "study", "file"]))
        return 0
    path = _scenario_path(args.scenario)
    from uvsym.campaign.metrics import detector_names
    from uvsym.progress import ProgressBar
    from uvsym.sim.result import SimResult
    from uvsym.sim.scenario import read_scenario_file
    from uvsym.sim.system_scenario import parse_any_scenario, simulate_any_scenario

    if args.compress and not args.out:
        raise UvsymError("--compress: it compresses the --out file; give one (.npz or .mat)")
    if args.out:  # format, folder and an existing file checked before the run
        SimResult.check_path(args.out, overwrite=args.force, compress=args.compress)
    table = read_scenario_file(path)
    scenario = parse_any_scenario(table, default_name=path.stem, root=path.parent)
    if args.events is not None:
        _check_events_path(args.events, scenario, args.force)
    figure = None
    if args.plot is not None:  # the figure checked like the result, before the run
        default = Path(args.out).with_suffix(".svg") if args.out else f"{scenario.name}.svg"
        figure = SimResult.check_plot_path(args.plot or default, overwrite=args.force)
    method = args.method or "fast"
    bar = ProgressBar(f"{scenario.name} ({method})")
    result = simulate_any_scenario(scenario, method=method, progress=bar)
    what = (scenario.plant if hasattr(scenario, "plant") else scenario.model).name
    bar.close()
    wall = result.meta["wall_s"]
    print(f"{scenario.name}: {what}, {scenario.duration:g} s at {scenario.step:g} s, method "
          f"{method}: {wall:.3g} s wall ({scenario.duration / wall:,.0f} simulated s per wall s), "
          f"build {result.meta['build_s']:.2f} s")
    x = result["x"]
    print("final state: " + ", ".join(f"{lab} = {v:.4g} {u}" for lab, v, u in zip(x.labels, x.values[-1], x.units)))
    if args.out:
        print(f"wrote {result.save(args.out, overwrite=args.force, compress=args.compress)}")
    if detector_names(scenario):  # a vehicle's [diagnosis] table, or [[detectors]]
        print(_event_lines(result.events))
    if getattr(scenario, "diagnosis", None) is not None:
        print(_decisions(result.events))
    if args.events:
        from uvsym.diagnosis.events import write_events

        print(f"wrote {write_events(result.events, args.events)} ({len(result.events)} events)")
    if figure is not None:
        result.plot(figure, overwrite=args.force)
        print(f"wrote {figure}")
    return 0


def _decisions(events: list[dict]) -> str:
    """One line on what the diagnosis decided: the faults standing at the end (identified or isolated)."""
    standing = {}
    for e in events:
        if e["event"] in ("isolated", "identified"):
            standing[e["target"]] = e
        elif e["event"] == "cleared":
            standing.pop(e["target"], None)
    faults = ", ".join(f"{a} {e['kind']} {e['value']:.4g}" + (f" +- {2 * e['std']:.2g} (2 std)" if e.get("std") else "")
                       + f" ({e['event']} at {e['t']:g} s)" for a, e in standing.items())
    return f"diagnosis: {len(events)} events; faults standing at the end: {faults or 'none'}"


def _event_lines(events: list[dict]) -> str:
    """Every detector's decisions, one line per event: time, detector, event, target, kind and value."""
    if not events:
        return "decisions: none (no detector logged an event)"
    lines = ["decisions:"]
    for e in events:
        value = "" if e["value"] is None else f" {e['value']:.4g}"
        lines.append(f"  {e['t']:>10.4f} s  {e['detector'] or '-':<16} {e['event']:<11} {e['target'] or '-'}"
                     + (f" {e['kind']}" if e["kind"] else "") + value)
    return "\n".join(lines)


def _check_events_path(path, scenario, force: bool) -> None:
    """UvsymError before the run: --events needs a scenario with detectors (a vehicle's [diagnosis] table
    or [[detectors]]), a .json file whose folder exists, and --force to replace a file."""
    from uvsym.campaign.metrics import detector_names

    target = Path(path)
    if not detector_names(scenario):
        raise UvsymError("--events: the scenario has no detector ([diagnosis] for a vehicle, [[detectors]] for a "
                         "plant), so there is no decision log to write (uvsym simulate --schema lists the fields)")
    if not str(path).strip() or target.suffix != ".json":
        raise UvsymError(f"--events: {path} must end in .json")
    if not target.parent.is_dir():
        raise UvsymError(f"--events: folder {target.parent} does not exist")
    if target.exists() and not force:
        raise UvsymError(f"--events: {path} exists; pass --force to overwrite it")


def _read_system_scenario(source: str, command: str):
    """(scenario, table) of a scenario file over a System, for ``uvsym codegen`` and ``uvsym verify``."""
    from uvsym.errors import ScenarioError
    from uvsym.sim.scenario import read_scenario_file
    from uvsym.sim.system_scenario import is_system_scenario, parse_system_scenario

    path = _scenario_path(source)
    table = read_scenario_file(path)
    if not is_system_scenario(table):
        raise ScenarioError(f"uvsym {command} {source}: a vehicle scenario (no 'plant'); {command} takes scenarios "
                            f"over a plant (the observer sets of vehicles: uvsym {command} --help)")
    return parse_system_scenario(table, default_name=path.stem, root=path.parent), table


def _is_scenario_file(name: str) -> bool:
    """A scenario file, or the name of a shipped scenario (rather than a derivation or an observer set)."""
    from uvsym.sim.shipped import every_shipped_scenario

    return name.endswith(".toml") or Path(name).is_file() or name in every_shipped_scenario()


def _first_sentence(doc: str | None) -> str:
    """A docstring's first sentence as plain text: its first paragraph joined into one line, up to the
    first full stop that ends a sentence, without reStructuredText's backticks."""
    import re

    paragraph = " ".join((doc or "").strip().split("\n\n")[0].split()).replace("``", "").replace("`", "")
    return re.split(r"(?<=[a-z0-9)][.!?])\s+(?=[A-Z(])", paragraph, maxsplit=1)[0]


def _cmd_codegen(args) -> int:
    from uvsym.derivation import observer_set, observer_sets

    if args.list or not args.name:
        from uvsym.codegen.observer_sets import option_flags, options_of

        rows = [[name, study, option_flags(options_of(factory)), _first_sentence(factory.__doc__)]
                for name, (study, factory) in observer_sets().items()]
        print(_table(rows, ["observer set", "derivation", "options", "description"]))
        return 0
    if not args.out:
        raise UvsymError(f"uvsym codegen {args.name}: give the output folder with -o/--out DIR")
    if args.budget and not args.target:
        raise UvsymError(f"uvsym codegen {args.name}: --budget needs --target")
    if args.analysis_seconds is not None and (not args.target or not args.analysis_seconds > 0):
        raise UvsymError(f"uvsym codegen {args.name}: --analysis-seconds needs --target and a positive number of "
                         f"seconds, got {args.analysis_seconds:g}")
    from uvsym.codegen.target_run import parse_budget  # the options checked before anything is built

    budget = parse_budget(args.budget or "")
    if _is_scenario_file(args.name):
        from uvsym.scenario_exports import scenario_package

        if args.set_options or args.vehicle or args.form:
            raise UvsymError(f"uvsym codegen {args.name}: --vehicle, --form and set options are for observer sets; "
                             "a scenario's blocks take their design from the file")
        scenario, _ = _read_system_scenario(args.name, "codegen")
        names = None if args.blocks is None else [n.strip() for n in args.blocks.split(",") if n.strip()]
        observers = scenario_package(scenario, names)
    else:
        factory = observer_sets().get(args.name, (None, None))[1]
        options = {key: value for key, value in (("vehicle", args.vehicle), ("form", args.form)) if value is not None}
        options |= _set_options(args.name, factory, args.set_options)
        observers = observer_set(args.name, **options)
    from uvsym.codegen.build_files import make_products

    make_folder(claim_folder(args.out, "the C package", "package", args.force,
                             built=make_products(observers.package_name)), "the C package")
    manifest = observers.write(args.out, "float" if args.float else "double", finite_check=not args.no_finite_check,
                               target=args.target, budget=budget, analysis_seconds=args.analysis_seconds)
    count = len(manifest["functions"])
    print(f"wrote {args.out}: {observers.package_name}, {count} function{'s' if count != 1 else ''} "
          f"({', '.join(f['c_function'] for f in manifest['functions'])}), {manifest['precision']}; "
          f"build with 'make' or cmake")
    if "float_check" in manifest:
        check = manifest["float_check"]
        print(f"float against double on {check['source']}: largest relative difference "
              f"{check['max_relative_difference']:.2g} (limit {check['tolerance']:g})")
    if "target" in manifest:
        from uvsym.codegen.readme import target_lines

        print("\n".join(target_lines(manifest["target"])))
    return 0


def _set_options(name: str, factory, tokens: list[str]) -> dict:
    """``--key value`` / ``--key=value`` options of an observer set, typed like the factory's defaults."""
    import inspect

    options, tokens = {}, list(tokens)
    while tokens:
        token = tokens.pop(0)
        if not token.startswith("--") or len(token) < 3:
            raise UvsymError(f"uvsym codegen {name}: unexpected argument {token!r}")
        key, _, value = token[2:].partition("=")
        if not _ and not tokens:
            raise UvsymError(f"uvsym codegen {name}: option --{key} needs a value")
        value = value if _ else tokens.pop(0)
        key = key.replace("-", "_")
        parameter = inspect.signature(factory).parameters.get(key) if factory else None
        default = None if parameter is None else parameter.default
        try:
            options[key] = type(default)(value) if isinstance(default, (int, float)) and not isinstance(
                default, bool) else value
        except ValueError:
            raise UvsymError(f"uvsym codegen {name}: option --{key} takes a {type(default).__name__}, "
                             f"got {value!r}") from None
    return options


def _claim_block(row: dict, width: int = 100) -> str:
    """One claim for the terminal, no line wider than ``width``: its status line, then the claim,
    the set and the method wrapped at word boundaries."""
    import textwrap

    mark = "  " if row["status"] == row["expected"] else "!!"
    margin = "" if row["margin"] is None else f", margin {row['margin']:.3g}"
    head = f"{mark} {row['status'].upper()} (expected {row['expected']}{margin}, {row['seconds']:.2f} s)"
    lines = [head]
    for label in ("claim", "set", "method"):
        lines += textwrap.wrap(str(row[label]), width, initial_indent=f"   {label + ':':8}",
                               subsequent_indent=" " * 11, break_on_hyphens=False) or [f"   {label}:"]
    return "\n".join(lines)


def _cmd_verify(args) -> int:
    import time

    scenario_files = [n for n in args.names if _is_scenario_file(n)]
    studies = [n for n in args.names if not _is_scenario_file(n)]
    chosen = [s for s in _selected(studies) if s.claims is not None] if studies or not scenario_files else []
    from uvsym.progress import ProgressBar
    from uvsym.report.markdown import write_json
    from uvsym.verify.certificate import STATUSES

    everything, failures = [], 0

    def claimed(name: str) -> Path:
        """NAME's folder for proofs.json, checked before its claims are computed: new, or uvsym's report or
        proofs of NAME (proofs.json as uvsym wrote it), else PathError unless --force."""
        return claim_folder(output_folder(args.out, "proofs") / name, f"the proofs of {name}", "report", args.force,
                            writer=("verify", name), accepts=("derivation",))

    def record(out_dir: Path, name: str, certificates, seconds: float, notes=()) -> None:
        nonlocal failures
        rows = [c.to_dict() for c in certificates]
        failures += sum(not c.as_expected for c in certificates)
        make_folder(out_dir, f"the proofs of {name}")
        write_json(out_dir / "proofs.json", [{**row, "seconds": round(row["seconds"], 3)} for row in rows])
        folder_record = record_of(out_dir, "report") or {"verify": name}  # proofs.json listed as uvsym's
        folder_record["files"] = {**(folder_record.get("files") or {}), **file_hashes(out_dir, skip=BUILD_STAMP)}
        (out_dir / BUILD_STAMP).write_text(json.dumps(folder_record) + "\n")
        everything.extend({"derivation": name, **row} for row in rows)
        if not args.json:
            print(f"{name}: {len(rows)} claims in {seconds:.1f} s, written to\n  {out_dir / 'proofs.json'}")
            print("\n\n".join(_claim_block(r) for r in rows) + "\n")
            print("".join(f"   {note}\n" for note in notes))

    if chosen:
        folders = [claimed(study.name) for study in chosen]  # every folder checked before any claim runs
        bar = ProgressBar("verify", total=len(chosen), unit="derivations", interval_s=0.0)
        for index, (study, out_dir) in enumerate(zip(chosen, folders)):
            print(f"[{index + 1}/{len(chosen)}] {study.name}: checking its claims", file=sys.stderr, flush=True)
            started = time.perf_counter()
            record(out_dir, study.name, study.claims(), time.perf_counter() - started)
            bar((index + 1) / len(chosen))
            bar.close()  # one line per derivation: its claims print next
    for source in scenario_files:
        from uvsym.scenario_exports import scenario_claims

        started = time.perf_counter()
        scenario, table = _read_system_scenario(source, "verify")
        out_dir = claimed(scenario.name)
        certificates, notes = scenario_claims(scenario, table)
        record(out_dir, scenario.name, certificates, time.perf_counter() - started, notes)
    if args.json:
        print(json.dumps(everything, indent=2))
    else:
        counts = {status: sum(row["status"] == status for row in everything) for status in STATUSES}
        print(f"{counts['proved']} proved (rigorous), {counts['checked']} checked (numerical evidence, not proofs), "
              f"{counts['refuted']} refuted, {counts['inconclusive']} inconclusive")
    if failures and not args.json:
        print(f"{failures} claim(s) differ from their expected status", file=sys.stderr)
    return 1 if failures else 0


def _cmd_campaign(args) -> int:
    from uvsym.campaign.spec import load_campaign

    if Path(args.file).is_file() and not args.dry_run and args.executor in (None, "local") and args.scheduler is None:
        from uvsym.campaign.executors import start_forkserver

        start_forkserver()  # the workers' imports run while the campaign's runs are read and checked
    campaign = load_campaign(args.file, confirm=args.yes)
    from uvsym.campaign.runner import default_out, run_campaign
    from uvsym.progress import ProgressBar

    if args.dry_run:
        from uvsym.campaign.runner import executor_options
        from uvsym.campaign.worker import load_hook

        load_hook(campaign.settings)
        executor_options(campaign, args.executor, args.workers, args.scheduler, args.chunk_size)
        print(f"{campaign.name}: {len(campaign.runs)} runs in {len({r.case for r in campaign.runs})} cases, every "
              f"scenario valid; fields: {', '.join(campaign.columns) or 'none'}")
        return 0
    bar = ProgressBar(campaign.name, unit="runs")  # counts of the runs to run: set by run_campaign

    def log(line: str) -> None:
        bar.close()
        print(line, file=sys.stderr, flush=True)

    out = Path(args.out) if args.out else default_out(campaign)
    try:
        table = run_campaign(campaign, out, executor=args.executor, workers=args.workers, scheduler=args.scheduler,
                             chunk_size=args.chunk_size, progress=bar, force=args.force, log=log)
    except KeyboardInterrupt:
        log(f"interrupted: the finished chunks are kept in {out / 'chunks'}; run the same command to resume")
        return 130
    print(f"wrote {out}: results.parquet, results.csv, summary.json, report.md, report.html")
    errors = [row["error"] for row in table.select(["status", "error"]).to_pylist() if row["status"] != "ok"]
    if errors and len(errors) == table.num_rows:  # nothing to summarize: a setup fault, not the scenarios'
        from collections import Counter

        error, count = Counter(errors).most_common(1)[0]
        print(f"uvsym: error: all {len(errors)} runs of {campaign.name} failed, {count} with: {error} (each run's "
              f"error: the error column of {out / 'results.csv'})", file=sys.stderr)
        return 1
    return 0


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="uvsym", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Vehicle dynamics and fault-diagnosis observers built symbolically in CasADi:\n"
                    "inspect the models, simulate scenarios, build the derivation reports, check their\n"
                    "claims by machine and write observers as C.",
        epilog="examples:\n  uvsym models show remus100\n  uvsym simulate docking_faults --out run.npz --plot\n"
               "  uvsym report actuator-observers\n  uvsym verify --json\n"
               "  uvsym codegen actuator-observers -o c_out --vehicle otter3dof\n"
               "  uvsym codegen examples/dc_motor/speed_sensor_bias.toml -o c_motor --blocks luenberger\n"
               "  uvsym campaign examples/campaign_docking.toml --workers 2\n"
               "'uvsym COMMAND --help' gives each command's options.")
    parser.add_argument("--version", action="version", version=f"uvsym {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    models = sub.add_parser("models", help="list the vehicles and plants, or show one")
    models.add_argument("action", nargs="?", choices=["list", "show"], default="list")
    models.add_argument("name", nargs="?", help="vehicle or plant name (with 'show')")
    models.add_argument("--json", action="store_true", help="machine-readable output")
    models.set_defaults(run=_cmd_models)
    report = sub.add_parser("report", help="build derivation reports (all, or the ones named)")
    report.add_argument("names", nargs="*", help="derivations to build (default: all)")
    report.add_argument("--out", default="reports", help="output folder (default: ./reports)")
    report.add_argument("--force", action="store_true", help="write into folders holding files uvsym did not write")
    report.set_defaults(run=_cmd_report)
    from uvsym.sim.integrator_options import METHODS

    simulate = sub.add_parser("simulate", help="run a scenario (a TOML file or a shipped example's name)")
    simulate.add_argument("scenario", nargs="?", help="scenario file or shipped name (none: list the shipped ones)")
    simulate.add_argument("--method", choices=METHODS, default=None,
                          help="fast (compiled fixed-step RK4, default) or a CasADi integrator")
    simulate.add_argument("--out", help="write the result (.npz, .csv or .mat)")
    simulate.add_argument("--compress", action="store_true", help="compress the --out .npz or .mat file (about "
                                                                 "half the size, far slower to write for a long run)")
    simulate.add_argument("--plot", nargs="?", const="", default=None,
                          help="write a quick-look figure (.svg or .png; default: next to --out)")
    simulate.add_argument("--list", action="store_true", help="list the shipped scenarios")
    simulate.add_argument("--schema", nargs="?", const=None, default=False, choices=["vehicle", "plant"],
                          help="print every field of a vehicle scenario file, or (plant) of a scenario over a "
                               "plant (type, default, rule) as a Markdown table; with a scenario and no kind, "
                               "the fields of its format")
    simulate.add_argument("--events", help="write the diagnosis's decision log (.json; needs a [diagnosis] table)")
    simulate.add_argument("--force", action="store_true", help="overwrite an existing --out, --plot or --events file")
    simulate.set_defaults(run=_cmd_simulate)
    codegen = sub.add_parser("codegen", help="write a C99 package of an observer set (sources, build files, manifest); "
                                             "a set's own options as --name value (uvsym codegen --list)")
    codegen.add_argument("name", nargs="?", help="observer set a derivation declares, or a scenario file over a "
                                                 "plant (FILE.toml: its blocks' steps); none: list the sets")
    codegen.add_argument("--blocks", help="with a scenario file: the blocks to export, comma-separated "
                                          "(default: every block with a state)")
    codegen.add_argument("-o", "--out", help="output folder (needed with a set)")
    codegen.add_argument("--list", action="store_true", help="list the observer sets with their derivation")
    codegen.add_argument("--force", action="store_true", help="write into a folder holding files uvsym did not write")
    codegen.add_argument("--vehicle", help="vehicle of the library, for a set that takes one (default: the set's)")
    codegen.add_argument("--form", help="observer form, for a set that takes one (default: the set's)")
    codegen.add_argument("--float", action="store_true", help="single precision (C only: not loadable by casadi); "
                                                              "refused when it strays from double on the set's example")
    codegen.add_argument("--no-finite-check", action="store_true",
                         help="wrappers without the NaN/infinity check of inputs and outputs (codes 2 and 3)")
    codegen.add_argument("--target", choices=("cortex-m4f", "cortex-m7", "host"),
                         help="also build for this target (target/: Makefile 'target', CMake toolchain, harness), "
                              "run it (qemu for Cortex-M) and record flash, RAM, stack, instructions per call")
    codegen.add_argument("--budget", help="with --target: refuse the package beyond these figures, e.g. "
                                          "flash=65536,ram=16384,stack=5120,instructions=50000")
    codegen.add_argument("--analysis-seconds", type=float, metavar="S",
                         help="with --target: cppcheck's time limit (default 30 s; a large generated step such as "
                              "the UKF bank's needs about 150 s, or its manifest says it was not analysed)")
    codegen.set_defaults(run=_cmd_codegen)
    campaign = sub.add_parser("campaign", help="run a campaign file: scenarios over grids and Monte Carlo draws, "
                                               "on local processes or Dask; results, summary and report; resumable")
    campaign.add_argument("file", help="campaign file (TOML)")
    campaign.add_argument("--out", help="output folder (default: ./campaigns/NAME); rerun to resume")
    campaign.add_argument("--executor", choices=["local", "dask"], help="where runs execute (default: the file's, "
                                                                         "else local processes)")
    campaign.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786 (implies --executor dask)")
    campaign.add_argument("--workers", type=int, help="local processes, or LocalCluster workers (default: cores)")
    campaign.add_argument("--chunk-size", type=int, help="runs per chunk file (default: the file's, else 8)")
    campaign.add_argument("--yes", action="store_true", help="confirm a campaign of more runs than its max_runs")
    campaign.add_argument("--dry-run", action="store_true", help="expand and check every run, run none")
    campaign.add_argument("--force", action="store_true", help="write into a folder holding files uvsym did not write")
    campaign.set_defaults(run=_cmd_campaign)
    verify = sub.add_parser("verify", help="check the derivations' claims by machine; exit 1 if any is unexpected")
    verify.add_argument("names", nargs="*", help="derivations, or scenario files over a plant (FILE.toml: claims "
                                                 "about its estimators); default: every derivation that makes claims")
    verify.add_argument("--json", action="store_true", help="print the claims as a JSON list")
    verify.add_argument("--out", default="reports", help="where proofs.json goes, beside the report (default reports)")
    verify.add_argument("--force", action="store_true", help="write into a folder holding files uvsym did not write")
    verify.set_defaults(run=_cmd_verify)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``uvsym`` console script; returns the exit status."""
    parser = _parser()
    args, extra = parser.parse_known_args(argv)
    if extra and args.command != "codegen":
        parser.error(f"unrecognized arguments: {' '.join(extra)}")
    args.set_options = extra
    try:
        return args.run(args)
    except UvsymError as exc:
        print(f"uvsym: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. head, which stopped reading
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
