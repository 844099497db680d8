"""Report sections every derivation shares: machine-checked claims and the generated C package.

``claim_rows`` turns certificates into the rows a report and its ``results.json`` keep;
``claims_table`` and ``counterexamples`` render them. ``c_package`` writes an observer set as a
C package, compiles it with strict warnings and compares it with Python
(:func:`uvsym.codegen.check.check_package`); ``c_section`` says what came of it.
"""

from __future__ import annotations

from pathlib import Path

from uvsym.codegen.check import check_package
from uvsym.codegen.observer_sets import ObserverSet
from uvsym.errors import CodegenError
from uvsym.report.markdown import markdown_table

__all__ = ["claim_rows", "claims_table", "counterexamples", "c_package", "c_section"]


def claim_rows(certificates) -> list[dict]:
    """claim, set, method, status, expected, margin (3 digits) and a one-line counterexample per certificate."""
    return [{key: row[key] for key in ("claim", "set", "method", "status", "expected")}
            | {"margin": None if row["margin"] is None else float(f"{row['margin']:.3g}"),
               "counterexample": certificate.counterexample_summary()}
            for certificate, row in ((c, c.to_dict()) for c in certificates)]


def claims_table(rows: list[dict]) -> str:
    """Markdown table of :func:`claim_rows`: statement, set, method, status, margin; a status other
    than the expected one in bold, with the expected one beside it."""
    def status(row: dict) -> str:
        same = row["status"] == row["expected"]
        return row["status"] if same else f"**{row['status']}** (expected {row['expected']})"
    return markdown_table(["statement", "set", "method", "status", "margin"],
                          [[r["claim"], r["set"], r["method"], status(r),
                            "-" if r["margin"] is None else f"{r['margin']:.3g}"] for r in rows])


def counterexamples(rows: list[dict]) -> str:
    """A Markdown list of the refuted claims' counterexamples ("- none" without any)."""
    return "\n".join(f"- {r['claim']}: {r['counterexample']}" for r in rows if r["counterexample"]) or "- none"


def c_package(observers: ObserverSet, folder: Path) -> dict:
    """Write ``observers`` as a C package into ``folder``, compile it and compare it with Python.

    Returns package, folder, functions and either compiled = True with flags, calls_per_function
    and max_relative_difference, or compiled = False with the reason (e.g. no C compiler).
    """
    manifest = observers.write(folder)
    summary = {"package": observers.package_name, "folder": folder.name,
               "functions": [f["c_function"] for f in manifest["functions"]]}
    try:
        check = check_package(folder, list(observers.exported), observers.package_name)
    except CodegenError as exc:
        return summary | {"compiled": False, "reason": str(exc).splitlines()[0]}
    return summary | {"compiled": True, "flags": " ".join(check.flags), "calls_per_function": check.calls,
                      "max_relative_difference": check.max_relative_difference}


def c_section(c: dict, subject: str) -> str:
    """The report's paragraph on a package from :func:`c_package`; ``subject`` opens it ("The observers ...")."""
    package = c["folder"]
    links = (f"[README](<{package}/README.md>) (API, units, build, return codes), "
             f"[header](<{package}/include/{c['package']}.h>), [sources](<{package}/src/>), "
             f"[Makefile](<{package}/Makefile>), [CMakeLists.txt](<{package}/CMakeLists.txt>), "
             f"[example](<{package}/main.c>), [manifest](<{package}/manifest.json>)")
    if c["compiled"]:
        status = (f"Compiled by the run that wrote this report with `{c['flags']}` (no warnings), loaded back and "
                  f"evaluated beside CasADi's own evaluation on {c['calls_per_function']} random calls per function: "
                  f"largest relative difference {c['max_relative_difference']:.1g}.")
    else:
        status = f"**Not compiled by this run**: {c['reason']}"
    functions = ", ".join(f"`{f}`" for f in c["functions"])
    return (f"{subject} as a C99 package in [`{package}/`](<{package}/>): {links}. Functions: {functions}; static "
            f"work buffers, no allocation; build with `make` or CMake.\n\n{status}")
