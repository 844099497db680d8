"""Build a package for its target, run its harness, and measure it: the figures of ``manifest.json``.

``run_target(package_dir, functions, name, precision, target)`` compiles the package written with
that target (:mod:`uvsym.codegen.targets`) with ``-Wall -Wextra -Werror``, then computes:

- flash (``text`` + ``rodata``) and RAM (``data`` + ``bss``: the static work arrays) of the
  package's own objects, from ``size -A``;
- per exported function, the worst-case stack of its own code: its frame plus the deepest callee
  in gcc's call graph (``-fstack-usage -fcallgraph-info=su``); a dynamic frame or recursion makes
  it unbounded (None, the reason given); calls into the C library (libm, libgcc's soft float)
  are listed, their frames are not in the bound but are in the measured high-water mark
  (stack painted before each call of the harness);
- instructions per call, the largest over the test vectors: qemu's ``-icount`` advances the
  virtual clock by a fixed time per instruction, the harness reads the board's timer around each
  call and calibrates ticks per instruction on a loop of known length (bare metal only);
- the C library symbols the package objects need (``nm -u``), refused when one allocates or
  does I/O (``FORBIDDEN``), and the findings of ``cppcheck`` (default checks, one preprocessor
  configuration; its information messages left out; stopped after ``CPPCHECK_SECONDS``) when installed,
  with the count per rule of its MISRA C:2012 addon's findings (rule numbers only: the addon ships
  without the rules' texts), or the reason the addon did not run;
- each call's outputs, decoded from their bits, with their return codes, and how far they are
  from CasADi's evaluation of the same vectors (:func:`differences`): a double build in units
  of the last place (2^-52) of each output's scale ``max(1, max|Python|)``, a float build relative
  to it (as :mod:`uvsym.codegen.precision` measures).

``check_budget`` refuses figures beyond a budget with BudgetError naming the figure.
"""

from __future__ import annotations

import hashlib
import re
import shutil
import struct
import subprocess
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from uvsym.codegen.targets import LIBRARIES, LINK_FLAGS, Target, qemu_command, target_cflags
from uvsym.errors import CodegenError

__all__ = ["BUDGET_KEYS", "FORBIDDEN", "BudgetError", "TargetRun", "check_budget", "differences", "missing_tools",
           "parse_budget", "run_target"]

FORBIDDEN = ("malloc", "calloc", "realloc", "free", "_sbrk", "sbrk", "printf", "fprintf", "sprintf", "snprintf",
             "vprintf", "puts", "fputs", "putchar", "fopen", "fwrite", "fread", "write", "_write", "scanf")
BUDGET_KEYS = ("flash", "ram", "stack", "instructions")
CPPCHECK_SECONDS = 30  # cppcheck's time limit per package (its result then says it timed out)


class BudgetError(CodegenError):
    """A package figure (flash, RAM, stack, instructions per call) exceeds the budget given."""


@dataclass(frozen=True)
class TargetRun:
    """figures: what goes into the manifest (module docstring); outputs: per function, a (rows, outputs)
    array of the harness's results; codes: per function, the return code of each row; printed: the
    harness's output, line by line (``target/harness.out`` of the package)."""

    figures: dict
    outputs: dict[str, np.ndarray]
    codes: dict[str, np.ndarray]
    printed: str


def _tools(chosen: Target) -> dict[str, str]:
    if chosen.bare_metal:
        return {k: f"{chosen.prefix}{k}" for k in ("gcc", "size", "nm")} | {"qemu": "qemu-system-arm"}
    from uvsym.codegen.compile import find_compiler

    return {"gcc": find_compiler() or "cc", "size": "size", "nm": "nm"}


def missing_tools(chosen: Target) -> list[str]:
    """The programs building and running ``chosen`` needs that are not on PATH."""
    return [tool for tool in _tools(chosen).values() if shutil.which(tool) is None]


def _run(command: list[str], cwd: Path, what: str, timeout: float = 600, both: bool = False) -> str:
    """stdout of ``command`` (with its stderr after it when ``both``: qemu writes semihosting output there)."""
    done = subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0:
        tail = "\n".join((done.stderr or done.stdout).strip().splitlines()[-30:])
        raise CodegenError(f"{what} failed: {' '.join(command)}\n{tail}")
    return done.stdout + (done.stderr if both else "")


def _sizes(size: str, objects: list[Path], cwd: Path) -> tuple[int, int]:
    """(flash, ram) in bytes of the objects' allocated sections."""
    flash = ram = 0
    for line in _run([size, "-A", *map(str, objects)], cwd, "size").splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[1].isdigit():
            section, bytes_ = parts[0], int(parts[1])
            if section.startswith((".text", ".rodata")):
                flash += bytes_
            elif section.startswith(".data"):
                flash, ram = flash + bytes_, ram + bytes_  # initial values stored in flash
            elif section.startswith(".bss") or section == "COMMON":
                ram += bytes_
    return flash, ram


def _call_graph(ci_files: list[Path]) -> tuple[dict[str, tuple[int | None, str]], dict[str, set[str]]]:
    """(frames: function -> (bytes or None for external/dynamic, qualifier), edges) of gcc's .ci files."""
    frames, edges = {}, {}
    for ci in ci_files:
        text = ci.read_text()
        for title, label in re.findall(r'node: \{ title: "([^"]+)" label: "([^"]*)"', text):
            found = re.search(r"\\n(\d+) bytes \((\w+)\)", label)
            if found:
                frames[title] = (int(found.group(1)), found.group(2))
            else:
                frames.setdefault(title, (None, "external"))
        for source, destination in re.findall(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"', text):
            edges.setdefault(source, set()).add(destination)
    return frames, edges


def _stack_bound(function: str, frames, edges) -> tuple[int | None, str, list[str]]:
    """(worst-case bytes of the package's own code or None, why unbounded or '', external callees)."""
    external: set[str] = set()

    def deepest(f: str, path: tuple[str, ...]) -> int:
        if f in path:
            raise CodegenError(f"recursion through {' -> '.join((*path, f))}")
        size, qualifier = frames.get(f, (None, "external"))
        if size is None:
            external.add(f)
            return 0
        if qualifier not in ("static", "bounded"):
            raise CodegenError(f"{f} has a {qualifier} frame")
        return size + max((deepest(g, (*path, f)) for g in edges.get(f, ())), default=0)

    try:
        return deepest(function, ()), "", sorted(external)
    except CodegenError as why:
        return None, str(why), sorted(external)


_CPPCHECKED: dict[tuple, dict] = {}  # (sources' digest, time limit) -> result: one analysis per source, any target


def _cppcheck(package_dir: Path, name: str, seconds: float) -> dict | None:
    """cppcheck's default checks on the package sources within ``seconds``: its version and findings
    (None: not installed)."""
    if shutil.which("cppcheck") is None:
        return None
    sources = [f"src/{name}_casadi.c", f"src/{name}.c"]
    key = (hashlib.sha256(b"".join((package_dir / s).read_bytes() for s in sources)).digest(), seconds)
    if key not in _CPPCHECKED:
        _CPPCHECKED[key] = _run_cppcheck(package_dir, sources, seconds)
    return dict(_CPPCHECKED[key])


def _run_cppcheck(package_dir: Path, sources: list[str], seconds: float) -> dict:
    version = subprocess.run(["cppcheck", "--version"], capture_output=True, text=True).stdout.strip()
    try:
        done = subprocess.run(["cppcheck", "--std=c99", "--quiet", "--max-configs=1", "--addon=misra",
                               "--template={file}:{line}: {severity}: {message} [{id}]", "-Iinclude",
                               *sources], cwd=package_dir,
                              capture_output=True, text=True, timeout=seconds)
    except subprocess.TimeoutExpired:  # its value-flow analysis of a large generated source can take many minutes
        return {"version": version, "findings": [], "misra": None, "timed_out_s": seconds}
    lines = [line for line in done.stderr.splitlines() if re.match(r".+:\d+: (?!information)\w+: ", line)]
    rules = Counter(m.group(1) for m in (re.search(r"\[misra-c2012-([\d.]+)\]$", line) for line in lines) if m)
    failed = re.search(r"Failed to execute [^\n]*", done.stderr)
    misra = ({"error": failed.group(0)} if failed else
             {"findings": sum(rules.values()), "rules": dict(sorted(rules.items(), key=lambda r: _rule_key(r[0])))})
    return {"version": version, "findings": [line for line in lines if "[misra-" not in line], "misra": misra,
            "timed_out_s": None}


def _rule_key(rule: str) -> tuple[int, ...]:
    """"10.3" -> (10, 3): MISRA rules in their document's order."""
    return tuple(int(part) for part in rule.split("."))


def _decode(hexes: list[str], precision: str) -> np.ndarray:
    code = "<d" if precision == "double" else "<f"
    width = 8 if precision == "double" else 4
    return np.array([struct.unpack(code, int(h, 16).to_bytes(width, "little"))[0] for h in hexes], dtype=float)


def run_target(package_dir, functions, name: str, precision: str, chosen: Target,
               analysis_seconds: float | None = None) -> TargetRun:
    """Build, check and run the target harness of the package in ``package_dir`` (module docstring);
    ``analysis_seconds``: cppcheck's time limit (s; None: ``CPPCHECK_SECONDS``).

    Raises CodegenError when a tool is missing, the package does not compile cleanly, it needs an
    allocating or I/O symbol of the C library, or the harness fails."""
    missing = missing_tools(chosen)
    if missing:
        raise CodegenError(f"target {chosen.name}: {', '.join(missing)} not found "
                           f"(scripts/install-arm-toolchain.sh installs Debian's)")
    package_dir, tools = Path(package_dir), _tools(chosen)
    build = package_dir / "target" / "build"
    build.mkdir(exist_ok=True)
    flags = [*target_cflags(chosen), "-Werror", "-Iinclude", "-Itarget"]
    objects = []
    for source in (f"src/{name}_casadi.c", f"src/{name}.c"):
        objects.append(build / (Path(source).stem + ".o"))
        _run([tools["gcc"], *flags, "-fstack-usage", "-fcallgraph-info=su", "-c", source, "-o", str(objects[-1])],
             package_dir, f"compiling {source} for {chosen.name}")
    flash, ram = _sizes(tools["size"], objects, package_dir)
    needed = sorted({line.split()[-1] for o in objects
                     for line in _run([tools["nm"], "-u", str(o)], package_dir, "nm").splitlines()
                     if line.strip() and not line.split()[-1].startswith(name)})
    forbidden = [s for s in needed if s in FORBIDDEN]
    if forbidden:
        raise CodegenError(f"package {name} on {chosen.name} calls {', '.join(forbidden)}: "
                           "no allocation or I/O allowed")
    elf = build / "harness.elf"
    link = [f"-T{package_dir / 'target' / 'link.ld'}", *LINK_FLAGS[:1], *LINK_FLAGS[2:]] if chosen.bare_metal else []
    _run([tools["gcc"], *flags, *link, "-o", str(elf), *map(str, objects), "target/board.c", "target/harness.c",
          *(LIBRARIES if chosen.bare_metal else ("-lm",))], package_dir, f"linking the {chosen.name} harness")
    command = qemu_command(chosen, str(elf)) if chosen.bare_metal else [str(elf)]
    lines = _run(command, package_dir, f"running the {chosen.name} harness", both=True).splitlines()
    if not lines or lines[-1].strip() != "end" or not lines[0].startswith("cal "):
        raise CodegenError(f"the {chosen.name} harness stopped early: {lines[-3:]}")
    empty, loop, count = map(int, lines[0].split()[1:])
    per_instruction = (loop - empty) / count if chosen.bare_metal else None
    frames, edges = _call_graph(sorted(build.glob("*.ci")))
    rows: dict[int, list] = {}
    for line in lines[1:-1]:
        parts = line.split()
        rows.setdefault(int(parts[1]), []).append(parts[2:])
    described, outputs, codes = {}, {}, {}
    for k, e in enumerate(functions):
        f = e.function.name()
        got = rows.get(k, [])
        bound, why, external = _stack_bound(f"{name}_{f}", frames, edges)
        instructions = (max(round((int(r[2]) - empty) / per_instruction) for r in got)
                        if per_instruction and got else None)
        described[f] = {"stack_bound": bound, "stack_unbounded_reason": why, "library_calls": external,
                        "stack_measured": max(int(r[3]) for r in got) if chosen.bare_metal and got else None,
                        "instructions": instructions, "vectors": len(got)}
        outputs[f] = np.array([_decode(r[4:], precision) for r in got])
        codes[f] = np.array([int(r[1]) for r in got])
    version = _run([tools["gcc"], "--version"], package_dir, "gcc --version").splitlines()[0]
    seconds = CPPCHECK_SECONDS if analysis_seconds is None else analysis_seconds
    figures = {"target": chosen.name, "description": chosen.description, "compiler": version,
               "flags": list(target_cflags(chosen)), "qemu_machine": chosen.machine, "clock_mhz": chosen.clock_mhz,
               "precision": precision, "flash": flash, "ram": ram, "library_symbols": needed,
               "functions": described, "cppcheck": _cppcheck(package_dir, name, seconds)}
    shutil.rmtree(build, ignore_errors=True)
    return TargetRun(figures, outputs, codes, "\n".join(lines) + "\n")


def differences(functions, vectors, run: TargetRun, precision: str) -> dict[str, float]:
    """Per function, the largest over its vectors and outputs of ``|C - Python| / max(1, max|Python|)``
    (each output against its own largest entry), in ulps (2^-52) for a double build; NaN where Python
    has NaN must be NaN in C too (else infinite)."""
    from uvsym.codegen.example import evaluate_rows

    worst = {}
    for e, v in zip(functions, vectors):
        f = e.function
        expected, got = evaluate_rows(f, v), run.outputs[f.name()]
        edges = np.cumsum([0] + [f.nnz_out(i) for i in range(f.n_out())])
        largest = 0.0
        with np.errstate(all="ignore"):
            for start, end in zip(edges[:-1], edges[1:]):
                p, c = expected[:, start:end], got[:, start:end]
                d = np.where(np.isnan(p) & np.isnan(c), 0.0, np.abs(c - p))
                d = np.where(np.isfinite(d), d, np.inf)
                scale = np.maximum(1.0, np.where(np.isfinite(p), np.abs(p), 0).max(axis=1, initial=0.0))
                largest = max(largest, float((d.max(axis=1, initial=0.0) / scale).max(initial=0.0)))
        worst[f.name()] = largest / 2.0**-52 if precision == "double" else largest
    return worst


def parse_budget(text: str) -> dict[str, int]:
    """``"flash=65536,stack=5120"`` -> ``{"flash": 65536, "stack": 5120}`` (bytes, instructions per call)."""
    budget = {}
    for item in filter(None, (p.strip() for p in text.split(","))):
        key, _, value = item.partition("=")
        if key not in BUDGET_KEYS or not value.strip().isdigit():
            raise BudgetError(f"--budget {item!r}: give KEY=INTEGER with KEY one of {', '.join(BUDGET_KEYS)}")
        budget[key] = int(value)
    return budget


def check_budget(figures: dict, budget: dict[str, int]) -> None:
    """BudgetError naming the first figure of ``figures`` (run_target's) beyond ``budget``; the stack
    figure of a function is the larger of its bound and its measured high-water mark, and a function
    whose stack cannot be bounded exceeds any stack budget."""
    where = f"on {figures['target']} ({figures['precision']})"
    for key in ("flash", "ram"):
        if key in budget and figures[key] > budget[key]:
            raise BudgetError(f"{key} {figures[key]} bytes {where} exceeds the budget of {budget[key]} bytes")
    for function, f in figures["functions"].items():
        if "stack" in budget:
            if f["stack_bound"] is None:
                raise BudgetError(f"stack of {function} {where} cannot be bounded ({f['stack_unbounded_reason']})")
            stack = max(f["stack_bound"], f["stack_measured"] or 0)
            if stack > budget["stack"]:
                raise BudgetError(f"stack of {function} {where} is {stack} bytes, over the budget of "
                                  f"{budget['stack']} bytes")
        if "instructions" in budget and f["instructions"] is not None and f["instructions"] > budget["instructions"]:
            raise BudgetError(f"instructions per call of {function} {where} are {f['instructions']}, over the budget "
                              f"of {budget['instructions']}")
