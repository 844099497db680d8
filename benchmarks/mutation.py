"""Mutation testing of uvsym's core with mutmut (on demand, never in CI): kill rate per module and every survivor.

Run ``python benchmarks/mutation.py [--modules GLOB ...] [--max-children 1]`` (needs ``pip install -e .[mutation]``).
The ``[tool.mutmut]`` section of pyproject.toml says what is mutated (``only_mutate``) and by which tests; this
script copies the working tree (tracked and new files, not ignored ones) to a scratch folder, narrows
``only_mutate`` to ``--modules`` (globs or paths under ``uvsym/``; default every configured module), runs
``nice -n 15 mutmut run --max-children N`` there and writes ``benchmarks/results/mutation.json``:

- ``modules``: per file, mutants ``total``, ``killed`` (failed a test, timed out or crashed), ``survived``,
  ``equivalent`` (survivors listed in ``tests/mutation_equivalents.toml`` with a reason), ``no_tests`` (no
  selected test reaches the code) and ``kill_rate`` = killed / (total - equivalent);
- ``survivors``: name and diff of every survivor not justified as equivalent; ``stale_equivalents``: entries of
  the equivalents file whose mutant no longer exists or no longer shows the recorded change;
  ``renumbered_equivalents``: entry -> the survivor it excused under another number (same function, and the
  line the mutant adds is the entry's change: an edit above it renumbered the function's mutants);
- ``started``, ``seconds``, ``modules_requested``, the mutmut version (``--merge`` keeps the other modules of
  the last results, each with the ``started`` of its own run).

``--results PATH`` writes (and merges into) another file than the committed results.

``--sample N`` tests N mutants of each module drawn at random (seeded by the module's path; ``--seed TEXT`` draws
another sample), an estimate (``sample`` in each module's record; the others count as not checked).
``--keep FOLDER`` keeps the copy; ``--again FOLDER`` brings the current tests and [tool.mutmut] (its
``only_mutate`` kept) there and tests again only the mutants that were not killed. The tests kept there only add
kills, so the result is that of a full run with the current tests on the source copied then: a kill that mutmut
drops unchecked because the test selection changed is put back. The other modules' current sources come too
(a fix elsewhere reaches the tests); a mutated module that changed is left out (measure it afresh). ``--suspect FILE``
also tests again the kills that may owe to a test listed there failing for another reason.
``--before --tests-at COMMIT`` records a baseline with an earlier commit's tests under the key ``before``.
"""

from __future__ import annotations

import argparse
import fnmatch
import importlib.metadata
import io
import json
import os
import random
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
import time
import tomllib
from datetime import datetime, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import finish  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results" / "mutation.json"
EQUIVALENTS = ROOT / "tests" / "mutation_equivalents.toml"
KILLED = {"killed", "timeout", "segfault", "caught by type check"}
TARGET_KILL_RATE = 0.85


def _config() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["mutmut"]


def configured_modules(config: dict) -> list[str]:
    """Every file that ``only_mutate`` names and ``do_not_mutate`` does not, as paths relative to the root."""
    files = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "uvsym").rglob("*.py"))
    return [f for f in files if any(fnmatch.fnmatch(f, p) for p in config["only_mutate"])
            and not any(fnmatch.fnmatch(f, p) for p in config.get("do_not_mutate", []))]


def _toml_value(value) -> str:
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return json.dumps(value)


def _copy_tests(destination: Path, without: list[str], tests_at: str | None) -> None:
    """tests/ of the working tree (tracked and untracked, ignored ones and ``without`` left out), or of commit
    ``tests_at``, into ``destination``/tests."""
    if tests_at:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", tests_at, "tests"], capture_output=True,
                                 check=True).stdout
        with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
            tar.extractall(destination, filter="data")
        return
    _copy_listed(destination, ["tests"], without)


def _copy_listed(destination: Path, folders: list[str], without: list[str]) -> None:
    listed = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-co", "--exclude-standard", *folders],
                            capture_output=True, text=True, check=True).stdout.split()
    for name in listed:
        if (ROOT / name).is_file() and name not in without:
            (destination / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, destination / name)


def _copy_tree(scratch: Path, config: dict, modules: list[str], without: list[str], tests_at: str | None) -> None:
    """The working tree's uvsym/, derivations/ and pyproject.toml in ``scratch``, its tests (or those of
    ``tests_at``), ``only_mutate`` narrowed to ``modules``."""
    _copy_listed(scratch, ["uvsym", "derivations", "pyproject.toml"], [])
    _copy_tests(scratch, without, tests_at)
    _write_config(scratch, config, modules)


def _write_config(scratch: Path, config: dict, modules: list[str]) -> None:
    """``scratch``'s [tool.mutmut] set to ``config`` with ``only_mutate`` = ``modules``; a selected test file that
    is missing there becomes an empty one (mutmut's pytest would stop on a missing path)."""
    for folder in (scratch, scratch / "mutants"):
        for name in config["pytest_add_cli_args_test_selection"]:
            if folder.is_dir() and not (folder / name).exists():
                (folder / name).write_text('"""Not in the tests measured (benchmarks/mutation.py)."""\n')
    section = "[tool.mutmut]\n" + "".join(f"{k} = {_toml_value(v)}\n" for k, v in {**config,
                                                                                     "only_mutate": modules}.items())
    text = (scratch / "pyproject.toml").read_text()
    text = re.sub(r"(?ms)^\[tool\.mutmut\]\n.*?(?=^\[)", lambda _: section + "\n", text)
    (scratch / "pyproject.toml").write_text(text)


def _current_sources(scratch: Path, modules: list[str]) -> list[str]:
    """The working tree's uvsym/ into the kept ``scratch`` and its mutants/ (a fix elsewhere reaches the tests), the
    mutated ``modules`` left as mutmut made them; those that changed since the kept run come unmutated, as they are
    now, and are not measured (measure them afresh). Returns the modules still measured."""
    changed = [m for m in modules if (scratch / m).read_bytes() != (ROOT / m).read_bytes()]
    if changed:
        print(f"--again: {', '.join(changed)} changed since the kept run, not measured here: measure afresh")
    measured = [m for m in modules if m not in changed]
    for destination in (scratch, scratch / "mutants"):
        _copy_listed(destination, ["uvsym"], measured if destination.name == "mutants" else [])
    return measured


def _suspect_kills(scratch: Path, modules: list[str], tests: set[str]) -> list[str]:
    """Killed mutants of ``modules`` whose function any of ``tests`` (pytest node ids) ran, by the kept run's
    statistics: a kill that may be those tests failing for another reason."""
    from mutmut.stats import status_by_exit_code

    ran = json.loads((scratch / "mutants" / "mutmut-stats.json").read_text())["tests_by_mangled_function_name"]
    return sorted(name for codes in _exit_codes(scratch, modules).values() for name, code in codes.items()
                  if status_by_exit_code[code] in KILLED and tests & set(ran.get(name.rsplit("__mutmut_", 1)[0], ())))


def _exit_codes(scratch: Path, modules: list[str]) -> dict[str, dict[str, int | None]]:
    """module -> mutant name -> mutmut's exit code (None: not checked), from the .meta files in ``scratch``."""
    out = {}
    for module in modules:
        meta = scratch / "mutants" / f"{module}.meta"
        out[module] = json.loads(meta.read_text())["exit_code_by_key"] if meta.exists() else {}
    return out


def _keep_kills(scratch: Path, kept: dict[str, dict[str, int | None]]) -> None:
    """Put back the kills of the kept run that mutmut dropped, unchecked, when the test selection changed: the
    tests kept there are still selected, so they still kill those mutants (the source has not changed)."""
    from mutmut.stats import status_by_exit_code

    for module, codes in kept.items():
        meta = scratch / "mutants" / f"{module}.meta"
        data = json.loads(meta.read_text())
        now = data["exit_code_by_key"]
        for name, code in codes.items():
            if now.get(name) is None and status_by_exit_code[code] in KILLED:
                now[name] = code
        meta.write_text(json.dumps(data, indent=4))


def _equivalents() -> list[dict]:
    if not EQUIVALENTS.exists():
        return []
    return tomllib.loads(EQUIVALENTS.read_text()).get("equivalent", [])


def _outcomes(scratch: Path, modules: list[str]) -> dict[str, dict[str, str]]:
    """module -> mutant name -> status, from the .meta files mutmut wrote in ``scratch/mutants``."""
    from mutmut.stats import status_by_exit_code

    return {module: {name: status_by_exit_code[code] for name, code in codes.items()}
            for module, codes in _exit_codes(scratch, modules).items()}


_DIFFS = """
import json, sys
from pathlib import Path
from mutmut.mutation.diff_apply import get_diff_for_mutant
names = json.loads(sys.stdin.read())
print(json.dumps({n: get_diff_for_mutant(n, path=Path(n.rsplit(".", 1)[0].replace(".", "/") + ".py")) for n in names}))
"""


def _diffs(scratch: Path, names: list[str]) -> dict[str, str]:
    """The changed lines of each mutant (mutmut's diff without its headers), read in one process in ``scratch``."""
    if not names:
        return {}
    shown = subprocess.run([sys.executable, "-c", _DIFFS], cwd=scratch, input=json.dumps(names), capture_output=True,
                           text=True, check=True)
    return {name: "\n".join(line for line in diff.splitlines() if line.startswith(("+", "-"))
                             and not line.startswith(("+++", "---")))
            for name, diff in json.loads(shown.stdout).items()}


def _dotted(module: str) -> str:
    """uvsym/verify/lyapunov.py -> "uvsym.verify.lyapunov." (how mutmut's mutant names start)."""
    return module[:-3].replace("/", ".") + "."


def _function_of(mutant: str) -> str:
    """uvsym.verify.exact.x_f__mutmut_12 -> uvsym.verify.exact.x_f (mutmut numbers mutants within a function)."""
    return mutant.rsplit("__mutmut_", 1)[0]


def _justifying(name: str, diff: str, equivalents: dict[str, dict]) -> str | None:
    """The equivalents entry that excuses survivor ``name``: its own entry if the diff still shows the recorded
    change, else an entry of the same function whose change is exactly the line the mutant adds (an edit above it
    renumbers a function's mutants, not what they change)."""
    entry = equivalents.get(name)
    if entry and entry["change"].strip() in diff:
        return name
    added = {line[1:].strip() for line in diff.splitlines() if line.startswith("+")}
    return next((e["mutant"] for e in equivalents.values()
                 if _function_of(e["mutant"]) == _function_of(name) and e["change"].strip() in added), None)


def _tally(scratch: Path, module: str, statuses: dict[str, str], equivalents: dict[str, dict],
           started: str) -> tuple[dict, list[dict], dict[str, str]]:
    """(counts of one module, its unjustified survivors with their diffs, survivor -> the entry that excused it)."""
    survivors, excused = [], {}
    for name, diff in _diffs(scratch, [n for n, s in statuses.items() if s in ("survived", "no tests")]).items():
        if entry := _justifying(name, diff, equivalents):
            excused[name] = entry
        else:
            survivors.append({"mutant": name, "module": module, "status": statuses[name], "diff": diff})
    count = {status: sum(s == status for s in statuses.values()) for status in set(statuses.values())}
    killed = sum(n for status, n in count.items() if status in KILLED)
    judged = killed + len(survivors) + count.get("suspicious", 0)  # not checked (an interrupted run) left out
    return ({"started": started, "total": len(statuses), "killed": killed, "survived": len(survivors),
             "equivalent": len(excused), "not_checked": count.get("not checked", 0),
             "suspicious": count.get("suspicious", 0), "kill_rate": killed / judged if judged else None},
            survivors, excused)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--modules", nargs="+", help="globs or paths of modules to mutate (default: all configured; "
                                                      "with --again: those of the kept run)")
    parser.add_argument("--max-children", type=int, default=1, help="mutants tested at once (default 1: shared cores)")
    parser.add_argument("--results", type=Path, default=RESULTS,
                        help="the results file to write (and to merge into); default benchmarks/results/mutation.json")
    parser.add_argument("--keep", type=Path, help="run in this folder and keep it (default: a temporary one)")
    parser.add_argument("--without", nargs="+", default=[],
                        help="test files to leave out (to measure what the other tests kill)")
    parser.add_argument("--tests-at", metavar="COMMIT",
                        help="take tests/ from this commit (to measure what the tests of an earlier commit kill)")
    parser.add_argument("--merge", action="store_true",
                        help="keep the modules and survivors of the last results that this run does not measure")
    parser.add_argument("--again", type=Path, metavar="FOLDER",
                        help="in a folder an earlier run kept (--keep), bring the current tests and test again only "
                             "the mutants that were not killed (tests kept there only add kills); with --sample, "
                             "only those of the sample tested there")
    parser.add_argument("--suspect", type=Path, metavar="FILE",
                        help="with --again: also test again the killed mutants whose function a test listed in FILE "
                             "(pytest node ids, one per line) ran: kills that test may owe to another failure")
    parser.add_argument("--sample", type=int, metavar="N",
                        help="test N mutants of each module drawn at random (seeded by its path): an estimate, "
                             "not a full run")
    parser.add_argument("--seed", help="with --sample: draw another sample (seeded by this text and the module's "
                                           "path), e.g. one no test was written against, for an unbiased estimate")
    parser.add_argument("--before", action="store_true",
                        help="record this run as the baseline (key 'before') and leave the last results as they are")
    args = parser.parse_args(argv)
    for name in ("max_children", "sample"):
        if getattr(args, name) is not None and getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} must be at least 1, got {getattr(args, name)}")
    if args.again and not (args.again / "pyproject.toml").is_file():
        parser.error(f"--again {args.again}: not a folder an earlier run kept with --keep (no pyproject.toml there)")
    if args.suspect and not args.again:
        parser.error("--suspect re-tests kills of a kept run: give --again FOLDER with it")
    if args.suspect and not args.suspect.is_file():
        parser.error(f"--suspect {args.suspect}: no such file")
    config = _config()
    available = configured_modules(config)
    if args.again:
        kept = tomllib.loads((args.again / "pyproject.toml").read_text())["tool"]["mutmut"]["only_mutate"]
        modules = [m for m in available if m in kept and (not args.modules or any(
            fnmatch.fnmatch(m, p) or m == p for p in args.modules))]
    else:
        modules = available if not args.modules else [m for m in available if any(
            fnmatch.fnmatch(m, p) or m == p for p in args.modules)]
    if not modules and args.again:
        parser.error(f"--modules matches none of the modules whose mutants {args.again} holds (its last run mutated "
                     f"{', '.join(kept)}): run the module afresh with --keep")
    if not modules:
        parser.error(f"--modules matches none of the configured modules: {', '.join(available)}")
    started, clock = datetime.now(timezone.utc).isoformat(timespec="seconds"), time.perf_counter()
    scratch = args.again or args.keep or Path(tempfile.mkdtemp(prefix="uvsym-mutation-"))
    try:
        scratch.mkdir(parents=True, exist_ok=True)
        names = []
        if args.again:
            for destination in (scratch, scratch / "mutants"):
                _copy_tests(destination, args.without, args.tests_at)
            modules = _current_sources(scratch, modules)
            if not modules:
                parser.error(f"--again: every module {args.again} measured changed since; measure them afresh")
            suspect = _suspect_kills(scratch, modules, set(args.suspect.read_text().split())) if args.suspect else []
            kept_codes = _exit_codes(scratch, modules)
            for name in suspect:  # tested again below: its verdict is the new one, not the kept kill
                kept_codes[next(m for m in modules if name.startswith(_dotted(m)))].pop(name)
            _write_config(scratch, config, modules)
            again = {"survived", "no tests", "suspicious", "timeout"} | (set() if args.sample else {"not checked"})
            names = sorted({n for statuses in _outcomes(scratch, modules).values() for n, s in statuses.items()
                            if s in again} | set(suspect))
        else:
            _copy_tree(scratch, config, modules, args.without, args.tests_at)
        mutmut = str(Path(sys.executable).parent / "mutmut")
        env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
        if args.sample and not args.again:  # generate the mutants and test statistics, test none, draw the sample
            subprocess.run(["nice", "-n", "15", mutmut, "run", "no-mutant-is-named-so*"], cwd=scratch, env=env,
                           capture_output=True, text=True)
            for module, statuses in _outcomes(scratch, modules).items():
                pending = sorted(n for n, s in statuses.items() if s not in KILLED | {"survived"})
                # the same draw whatever other modules the run takes; --seed draws another, unseen sample
                draw = random.Random(module if args.seed is None else f"{args.seed}:{module}")
                names += sorted(draw.sample(pending, min(args.sample, len(pending))))
        run = subprocess.run(["nice", "-n", "15", mutmut, "run", "--max-children", str(args.max_children), *names],
                             cwd=scratch, env=env, capture_output=True, text=True)
        (scratch / "mutmut-run.log").write_text(run.stdout + run.stderr)
        if args.again:
            _keep_kills(scratch, kept_codes)
        seconds = time.perf_counter() - clock
        equivalents = {e["mutant"]: e for e in _equivalents()}
        per_module, survivors, justified = {}, [], {}
        outcomes = _outcomes(scratch, modules)
        for module, statuses in outcomes.items():
            per_module[module], left, excused = _tally(scratch, module, statuses, equivalents, started)
            per_module[module].update(sample=args.sample, sample_seed=args.seed, run_seconds=seconds,
                                      tests_at=args.tests_at, tests_left_out=args.without,
                                      retested=sum(n.startswith(_dotted(module)) for n in names))
            survivors += left
            justified.update(excused)
    finally:
        if args.keep is None and args.again is None:
            shutil.rmtree(scratch, ignore_errors=True)
    measured = {name for statuses in outcomes.values() for name in statuses}
    prefixes = tuple(_dotted(m) for m in modules)
    stale = sorted(n for n in equivalents if n.startswith(prefixes) and n not in justified.values())
    renumbered = {entry: name for name, entry in sorted(justified.items()) if entry != name}
    saved = json.loads(args.results.read_text()) if args.results.exists() else {}
    previous = saved.get("before") if args.before else saved
    if args.merge and previous and "modules" in previous:
        per_module = {**{k: v for k, v in previous["modules"].items() if k not in per_module}, **per_module}
        survivors = [s for s in previous["survivors"] if s["module"] not in outcomes] + survivors
        stale = sorted(set(stale) | {n for n in previous.get("stale_equivalents", []) if not n.startswith(prefixes)})
    rates = [m["kill_rate"] for m in per_module.values() if m["kill_rate"] is not None]
    results = {"started": started, "seconds": seconds, "mutmut": importlib.metadata.version("mutmut"),
               "max_children": args.max_children, "modules_requested": args.modules or modules,
               "tests_left_out": args.without, "tests_at": args.tests_at, "mutmut_exit_code": run.returncode,
               "mutants_measured": len(measured),
               "modules": per_module, "lowest_kill_rate": min(rates) if rates else None, "survivors": survivors,
               "stale_equivalents": stale, "renumbered_equivalents": renumbered}
    for module, m in per_module.items():
        rate = "-" if m["kill_rate"] is None else f"{100 * m['kill_rate']:.1f} %"
        print(f"{module:<40} {m['killed']:>4} of {m['total']:<4} killed ({rate}), {m['survived']} survived, "
              f"{m['equivalent']} equivalent, {m['not_checked']} not checked")
    if args.before:
        args.results.parent.mkdir(parents=True, exist_ok=True)
        args.results.write_text(json.dumps({**saved, "before": results}, indent=2) + "\n")
        print(f"wrote the baseline into {args.results}")
    else:
        finish({**results, "before": saved.get("before")}, {"lowest_kill_rate_min": TARGET_KILL_RATE}, args.results)
    return 0 if run.returncode == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
