"""README.md of a C package, written from its manifest: API, sizes and units, build, threads, codes."""

from __future__ import annotations

__all__ = ["package_readme", "target_lines"]


def _argument_rows(function: dict) -> list[str]:
    rows = []
    for direction, key in (("in", "inputs"), ("out", "outputs")):
        for argument in function[key]:
            if argument["units"] is None:
                entries = "(documented as text only)"
            else:
                entries = ", ".join(f"{entry} [{unit}]" for entry, unit in
                                    zip(argument["entries"], argument["units"])) or "none"
            rows.append(f"| {direction} | `{argument['name']}` | {argument['size']} | {argument['what']} | {entries} |")
    return rows


def _function_section(function: dict, real: str) -> str:
    arguments = [f"const {real} {a['name']}[{a['size']}]" if a["size"] else f"const {real}* {a['name']}"
                 for a in function["inputs"]]
    arguments += [f"{real} {a['name']}[{a['size']}]" if a["size"] else f"{real}* {a['name']}"
                  for a in function["outputs"]]
    table = ["| | argument | size | what | entries [unit] |", "|---|---|---|---|---|", *_argument_rows(function)]
    return (f"### `{function['c_function']}`\n\n{function['description']}.\n\n"
            f"```c\nint {function['c_function']}({', '.join(arguments)});\n```\n\n" + "\n".join(table) + "\n")


def target_lines(figures: dict) -> list[str]:
    """The target figures of a manifest (``target``, see :mod:`uvsym.codegen.target_run`) as text lines."""
    lines = [f"target {figures['target']} ({figures['description']}), {figures['precision']}: "
             f"flash {figures['flash']} B, RAM {figures['ram']} B (package objects; {figures['compiler']})"]
    for name, f in figures["functions"].items():
        bound = (f"{f['stack_bound']} B" if f["stack_bound"] is not None else
                 f"unbounded ({f['stack_unbounded_reason']})")
        measured = f", measured {f['stack_measured']} B" if f["stack_measured"] is not None else ""
        cost = (f", {f['instructions']} instructions per call ({f['instructions'] / figures['clock_mhz']:.1f} us at "
                f"{figures['clock_mhz']:g} MHz, one per cycle)" if f["instructions"] is not None else "")
        lines.append(f"  {name}: stack {bound} own code{measured}{cost}; differs from Python by "
                     f"{f.get('difference', float('nan')):.3g} {figures.get('difference_unit', '')}")
    return lines


def _target_section(manifest: dict) -> str:
    figures = manifest.get("target")
    if not figures:
        return ""
    build = ("`make target` builds `target/harness.elf` with the flags below and `make run-target` runs it under "
             f"`qemu-system-arm -machine {figures['qemu_machine']}`" if figures["qemu_machine"] else
             "`make target` builds `target/harness.elf` and `make run-target` runs it")
    rows = "\n".join(f"| `{name}` | {f['stack_bound']} | {f['stack_measured']} | {f['instructions']} | "
                      f"{f['difference']:.3g} |" for name, f in figures["functions"].items())
    libraries = ", ".join(f"`{s}`" for s in figures["library_symbols"]) or "none"
    check = figures["cppcheck"]
    cppcheck = ("cppcheck was not installed when this package was built." if check is None else
                f"{check['version']} (default checks) stopped after {check['timed_out_s']} s: not analysed."
                if check.get("timed_out_s") else
                f"{check['version']} (default checks): {len(check['findings'])} findings"
                + "".join(f"\n- {line}" for line in check["findings"][:20]) + _misra(check["misra"]))
    return f"""
## Target: {figures['target']}

{figures['description']}. {build}; `cmake -DCMAKE_TOOLCHAIN_FILE=target/toolchain.cmake` uses the
same compiler and flags: `{' '.join(figures['flags'])}`. The harness (`target/harness.c`, with
`target/board.c`: startup, semihosting output, no heap) calls every function on its test vectors
and prints each output's bits; `target/harness.out` is what it printed when this package was
written (`make run-target` prints the same on the same toolchain). Measured then ({figures['compiler']}):
flash {figures['flash']} bytes (text, rodata and data of the package's objects), RAM {figures['ram']}
bytes (data and bss: the static work arrays). Stack: the bound of the package's own code from
`-fstack-usage` and the call graph, and the high-water mark measured under qemu (with the C
library's frames); instructions per call: the largest over the vectors, counted with qemu's
`-icount`. Difference from CasADi's evaluation: {figures['difference_unit']}.

| function | stack bound [B] | stack measured [B] | instructions per call | difference |
|---|---|---|---|---|
{rows}

C library symbols the package needs: {libraries}. {cppcheck}
"""


def _misra(misra: dict) -> str:
    """The README's line on cppcheck's MISRA C:2012 addon (its findings per rule, or why it did not run)."""
    if "error" in misra:
        return f"\n\nIts MISRA C:2012 addon did not run: {misra['error']}"
    rules = ", ".join(f"{rule}: {count}" for rule, count in misra["rules"].items())
    return (f"\n\nIts MISRA C:2012 addon (rule numbers only: cppcheck ships without the rules' texts): "
            f"{misra['findings']} findings" + (f" (per rule: {rules})." if rules else "."))


def package_readme(manifest: dict) -> str:
    """The README text of the package described by ``manifest`` (see :func:`uvsym.codegen.package.write_package`)."""
    name, real = manifest["package"], f"{manifest['package']}_real"
    cited = f"\nIt implements: {manifest['citation']}\n" if manifest["citation"] else ""
    codes = "\n".join(f"| `{macro}` | {code['value']} | {code['meaning']} |"
                      for macro, code in manifest["return_codes"].items())
    check = ("Every function checks its inputs for NaN and infinity before it computes (and returns "
             f"`{name.upper()}_NONFINITE_INPUT` without touching the outputs) and its outputs after (returns "
             f"`{name.upper()}_NONFINITE_OUTPUT`, outputs written). Do not build with `-ffast-math`: it may "
             "remove these checks." if manifest["finite_check"] else
             "Generated without the finite check: NaN or infinite inputs propagate to the outputs unreported.")
    example = manifest["example"]
    example_text = (f"`main.c` calls `{example['function']}` on data from {example['source']} and prints each "
                    "output on one line (its name, then its entries)." if example else
                    "`main.c` calls the last function on zero inputs (the generator was given no example data).")
    functions = "\n".join(_function_section(f, real) for f in manifest["functions"])
    float_check = manifest.get("float_check")
    precision = f"Precision: `{manifest['precision']}` (`{real}` is `{manifest['precision']}`)."
    if float_check:
        precision += (f" The float build was run against the double evaluation on {float_check['source']} "
                      f"({float_check['samples']} samples): largest relative difference "
                      f"{float_check['max_relative_difference']:.2g} (limit {float_check['tolerance']:g}).")
    return f"""# {name}

{manifest['description'] or name}. Generated by uvsym (CasADi {manifest['casadi']}).
{cited}
{precision} Units are SI, written with an explicit product sign (`N*m`, `(N*m)/s`); each
argument is an array whose entries are listed below in order. `manifest.json` holds the same
information for programs (units as lists, one per entry).

## API

Include `{name}.h`. Every function takes its inputs then its outputs as arrays of `{real}` (an
argument of size 0 is a pointer that may be NULL) and returns one of the codes below.

{functions}
## Return codes

| macro | value | meaning |
|---|---|---|
{codes}

{check}

## Build

- `make`: `lib{name}.a`, `lib{name}.so`, `example` (from `main.c`) and `harness`, with
  `-std=c99 -O2 -Wall -Wextra -pedantic`; override with `make CFLAGS=...`.
- CMake (Release by default, same warnings):
  `cmake -S . -B build && cmake --build build && cmake --install build --prefix PREFIX`
  installs the libraries, headers and a package configuration; another project then uses
  `find_package({name} REQUIRED)` and links `{name}::{name}` (static) or `{name}::{name}_shared`.
- Or compile `src/{name}_casadi.c` and `src/{name}.c` with `-Iinclude` into your program and
  link `-lm`.

{example_text}

## Memory and threads

Nothing is allocated at run time: each function keeps its work arrays in static storage. So a
function is not reentrant and not thread-safe: do not call the same function from two threads
at once (serialise the calls, e.g. with a mutex). Different functions have separate work arrays.
All external names start with `{name}` (macros with `{name.upper()}_`), so several uvsym packages
link into one program.
""" + _target_section(manifest)
