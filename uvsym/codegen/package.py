"""A self-contained C99 package of observers: CasADi sources, a wrapper API, build files, manifest.

``write_package(out_dir, functions, name, precision)`` writes::

    include/<name>_casadi.h, src/<name>_casadi.c   CasADi's generated code (its standard API,
                                                   <name>_casadi_<function>, so casadi.external
                                                   can load the library)
    include/<name>.h, src/<name>.c                 one documented wrapper per function:
                                                   <name>_<function>(inputs..., outputs...),
                                                   return codes <NAME>_OK, ... (ERROR_CODES)
    main.c, harness.c                              an example call on experiment data; a
                                                   stdin/stdout harness (uvsym.codegen.programs)
    Makefile, CMakeLists.txt                       libraries, example, harness; CMake installs
                                                   and exports a package config
    README.md                                      API, sizes and units, build, threads, codes
    manifest.json                                  functions, arguments with sizes and a unit
                                                   per entry, precision, citation, SHA-256 of
                                                   each serialised Function and of each file
                                                   written (``files``, see uvsym.paths)

Files an earlier package in ``out_dir`` listed in its manifest and this one does not write are
removed when unchanged (:func:`uvsym.paths.remove_stale`); nothing else there is touched.

Every external C name starts with the package name (CasADi's internals with ``<name>_casadi__``,
the real type is ``<name>_real``, macros with ``<NAME>_``), so that packages link into one
program. ``<name>.h`` stands alone (it does not include CasADi's header, whose ``casadi_real``
macro would leak): headers of packages of either precision go into one source file. Work
buffers are static (sized by CasADi's ``*_SZ_*`` macros): nothing is allocated at run time, and
the wrappers are not reentrant. With ``finite_check`` (the default) a wrapper refuses a NaN or infinite input entry
(``<NAME>_NONFINITE_INPUT``, outputs untouched) and reports a non-finite output entry
(``<NAME>_NONFINITE_OUTPUT``). A function publishing ``pd_margin`` (a Gaussian filter, a bank)
returns ``<NAME>_UNHEALTHY`` when it is not positive, the case in which the Python run raises
CovarianceError. The same functions and options give byte-identical files.
A double build matches the Python evaluation to 1e-12 relative; a float build (C only: it
cannot be loaded through casadi.external) to 1e-5 of each call's largest output (tested). A float
build computes in float throughout: CasADi's double literals and math calls are rewritten
(:func:`_single_precision`), so that a single-precision FPU runs it without soft-float double.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path

import casadi as ca

from uvsym.codegen.arguments import Entries
from uvsym.codegen.build_files import cmake_lists, makefile
from uvsym.codegen.example import Example
from uvsym.codegen.programs import example_program, harness_program
from uvsym.codegen.readme import package_readme
from uvsym.errors import CodegenError
from uvsym.paths import output_folder, recorded_files, remove_stale, write_files

__all__ = ["ERROR_CODES", "Exported", "PRECISIONS", "casadi_name", "write_package"]

PRECISIONS = ("double", "float")
# return codes of every wrapper: suffix of the <NAME>_ macro, value, meaning
ERROR_CODES = (("OK", 0, "success: every output written"),
               ("EVAL_FAILED", 1, "CasADi's evaluation reported a failure"),
               ("NONFINITE_INPUT", 2, "an input entry is NaN or infinite (finite check on): nothing computed, "
                                      "outputs untouched"),
               ("NONFINITE_OUTPUT", 3, "an output entry is NaN or infinite (finite check on): outputs written"),
               ("UNHEALTHY", 4, "an estimator's pd_margin output is not positive: a covariance it factorised is no "
                                "longer positive definite (the Python run raises CovarianceError there); outputs "
                                "written, not to be trusted"))
HEALTH = "pd_margin"  # an output entry of this name must be > 0 (a Gaussian filter's or bank's health)


@dataclass(frozen=True)
class Exported:
    """A Function to export, documented per input and output, with a one-line description.

    input_units, output_units: one per argument, an :class:`~uvsym.codegen.arguments.Entries`
    (what it is, each entry's name and unit: listed in the header and the manifest) or a plain
    line of text (kept as given; the manifest then has no per-entry units).
    """

    function: ca.Function
    input_units: tuple[str | Entries, ...]
    output_units: tuple[str | Entries, ...]
    description: str

    def __post_init__(self):
        f = self.function
        if len(self.input_units) != f.n_in() or len(self.output_units) != f.n_out():
            raise CodegenError(f"{f.name()}: give one unit per input ({f.n_in()}) and output ({f.n_out()})")
        for i in range(f.n_in()):
            if not f.sparsity_in(i).is_dense() or f.size2_in(i) != 1:
                raise CodegenError(f"{f.name()}: input {f.name_in(i)} must be a dense column vector")
        for docs, name, size in ((self.input_units, f.name_in, f.nnz_in), (self.output_units, f.name_out, f.nnz_out)):
            for i, doc in enumerate(docs):
                if isinstance(doc, Entries) and len(doc.units) != size(i):
                    raise CodegenError(f"{f.name()}: argument {name(i)} has {size(i)} entries, its units "
                                       f"{len(doc.units)}")

    def arguments(self) -> list[tuple[str, str, int, str | Entries]]:
        """("in" or "out", name, size, documentation) of every argument, inputs first."""
        f = self.function
        return ([("in", f.name_in(i), f.nnz_in(i), self.input_units[i]) for i in range(f.n_in())]
                + [("out", f.name_out(i), f.nnz_out(i), self.output_units[i]) for i in range(f.n_out())])


def _silence_unused(source: str) -> str:
    """Mark CasADi's unused work-array parameters used, so that -Wall -Wextra -Werror passes."""
    pattern = re.compile(r"^((?:static|CASADI_SYMBOL_EXPORT) [^\n;]*\(([^()]*)\)\s*\{)$", re.MULTILINE)

    def mark(match: re.Match) -> str:
        names = [p.split()[-1].lstrip("*") for p in match.group(2).split(",") if p.strip() and p.strip() != "void"]
        unused = [n for n in names if n in ("iw", "w", "mem")]
        return match.group(1) + ("\n  " + " ".join(f"(void){n};" for n in unused) if unused else "")

    return pattern.sub(mark, source)


# C99 <math.h> functions of double whose float twin is the name with an f (sqrt -> sqrtf)
MATH_FUNCTIONS = ("acos", "acosh", "asin", "asinh", "atan", "atan2", "atanh", "cbrt", "ceil", "copysign", "cos",
                  "cosh", "erf", "erfc", "exp", "exp2", "expm1", "fabs", "fdim", "floor", "fma", "fmax", "fmin", "fmod",
                  "hypot", "log", "log10", "log1p", "log2", "pow", "remainder", "round", "sin", "sinh", "sqrt", "tan",
                  "tanh", "tgamma", "trunc")
FLOAT_MAX, FLOAT_MIN = "3.40282347e+38f", "1.17549435e-38f"  # float's largest finite and smallest normal magnitudes
_LITERAL = re.compile(r"(?<![\w.])(\d+\.\d*(?:[eE][-+]?\d+)?|\d+[eE][-+]?\d+)(?![\w.])")
_MATH_CALL = re.compile(r"(?<![\w.])(" + "|".join(MATH_FUNCTIONS) + r")(?=\s*\()")


def _single_precision(source: str) -> str:
    """CasADi's source for ``casadi_real`` float computed in float: every floating literal gets the
    suffix f (a magnitude beyond float's normal range becomes the nearest of FLOAT_MAX and FLOAT_MIN,
    so a bound stays finite and a guard against zero stays positive) and every math call its float
    twin (``sqrtf``), where CasADi writes double ones (soft-float double on a single-precision FPU)."""
    def literal(match: re.Match) -> str:
        magnitude = float(match.group(1))
        if magnitude > float(FLOAT_MAX[:-1]):
            return FLOAT_MAX
        return FLOAT_MIN if 0.0 < magnitude < float(FLOAT_MIN[:-1]) else match.group(1) + "f"

    return _MATH_CALL.sub(r"\1f", _LITERAL.sub(literal, source))


def _c_name(name: str) -> str:
    if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", name):
        raise CodegenError(f"{name!r} is not a C identifier (a letter, then letters, digits and _)")
    return name


def casadi_name(package: str, function: str) -> str:
    """The name of ``function``'s CasADi API in ``package`` (what ``casadi.external`` loads)."""
    return f"{package}_casadi_{function}"


def _renamed(function: ca.Function, name: str) -> ca.Function:
    """``function`` under another name: an SX graph is copied as it is, anything else is called."""
    symbols = function.sx_in() if function.is_a("SXFunction") else function.mx_in()
    return ca.Function(name, symbols, function.call(symbols), function.name_in(), function.name_out())


def _doc_lines(direction: str, name: str, size: int, doc) -> list[str]:
    """Header comment lines of one argument: what it is, then its entries with units in brackets."""
    if not isinstance(doc, Entries):
        return [f" * {direction:<3} {name}[{size}]: {doc}"]
    lines = [f" * {direction:<3} {name}[{size}]: {doc.what}"]
    lines += [f" *       [{i}] {entry} [{unit}]" for i, (entry, unit) in enumerate(zip(doc.names, doc.units))]
    return lines


def _wrapper(e: Exported, package: str, finite_check: bool) -> tuple[str, str]:
    """(prototype with its documentation, definition) of <package>_<function>."""
    f = e.function
    name, real, codes = casadi_name(package, f.name()), f"{package}_real", package.upper()
    # an empty argument (no entries) is a pointer, which may be NULL: ISO C has no zero-size arrays
    args = [f"const {real} {f.name_in(i)}[{f.nnz_in(i)}]" if f.nnz_in(i) else f"const {real}* {f.name_in(i)}"
            for i in range(f.n_in())]
    args += [f"{real} {f.name_out(i)}[{f.nnz_out(i)}]" if f.nnz_out(i) else f"{real}* {f.name_out(i)}"
             for i in range(f.n_out())]
    doc = [f"/* {e.description}", " *"]
    doc += [line for argument in e.arguments() for line in _doc_lines(*argument)]
    health = _health_entries(e)
    returned = [f"{codes}_OK", f"{codes}_EVAL_FAILED"] + ([f"{codes}_NONFINITE_INPUT", f"{codes}_NONFINITE_OUTPUT"]
                                                          if finite_check else []) + ([f"{codes}_UNHEALTHY"] if health
                                                                                      else [])
    returns = ", ".join(returned[:-1]) + f" or {returned[-1]}"
    doc += [f" * Returns {returns}.", " * Uses static work buffers: not reentrant. */"]
    prototype = "\n".join(doc) + f"\nint {package}_{f.name()}({', '.join(args)});\n"
    inputs = ", ".join(f.name_in(i) for i in range(f.n_in()))
    outputs = ", ".join(f.name_out(i) for i in range(f.n_out()))
    check_in = "".join(f"\n  if (!{package}_all_finite({f.name_in(i)}, {f.nnz_in(i)})) return {codes}_NONFINITE_INPUT;"
                       for i in range(f.n_in()) if finite_check and f.nnz_in(i))
    check_out = "".join(f"\n  if (!{package}_all_finite({f.name_out(i)}, {f.nnz_out(i)})) "
                        f"return {codes}_NONFINITE_OUTPUT;" for i in range(f.n_out()) if finite_check and f.nnz_out(i))
    check_health = "".join(f"\n  if (!({f.name_out(i)}[{j}] > 0)) return {codes}_UNHEALTHY;  /* {HEALTH} */"
                           for i, j in health)
    body = f"""int {package}_{f.name()}({', '.join(args)}) {{
  static casadi_int iw[{name}_SZ_IW > 0 ? {name}_SZ_IW : 1];
  static casadi_real w[{name}_SZ_W > 0 ? {name}_SZ_W : 1];
  const casadi_real* arg[{name}_SZ_ARG > 0 ? {name}_SZ_ARG : 1] = {{{inputs}}};
  casadi_real* res[{name}_SZ_RES > 0 ? {name}_SZ_RES : 1] = {{{outputs}}};{check_in}
  if ({name}(arg, res, iw, w, 0)) return {codes}_EVAL_FAILED;{check_out}{check_health}
  return {codes}_OK;
}}
"""
    return prototype, body


def _health_entries(e: Exported) -> list[tuple[int, int]]:
    """(output, entry) of each output entry named ``HEALTH`` (documented entry by entry)."""
    return [(i, j) for i, doc in enumerate(e.output_units) if isinstance(doc, Entries)
            for j, entry in enumerate(doc.names) if entry == HEALTH]


_ALL_FINITE = """/* 1 when the n entries of v are all finite (not NaN, not infinite), else 0 */
static int {package}_all_finite(const {package}_real* v, int n) {{
  int i;
  for (i = 0; i < n; ++i) if (!isfinite(v[i])) return 0;
  return 1;
}}
"""


def _header(name: str, description: str, citation: str, precision: str, wrappers) -> str:
    guard = name.upper() + "_H"
    cited = f"\n   Implements: {citation}" if citation else ""
    codes = "".join(f"#define {name.upper()}_{suffix} {value} /* {meaning} */\n"
                    for suffix, value, meaning in ERROR_CODES)
    return (f"/* {description or name}: wrapper API generated by uvsym. Precision: {precision}.{cited}\n"
            f"   Units in brackets; README.md describes the API. */\n"
            f"#ifndef {guard}\n#define {guard}\n\ntypedef {precision} {name}_real;\n\n"
            f"/* return codes of every function below */\n{codes}\n"
            + "\n".join(p for p, _ in wrappers) + f"\n#endif /* {guard} */\n")


def _argument_entry(name: str, size: int, doc) -> dict:
    """An argument in the manifest: name, size, what it is, unit (its whole line of text), entries and
    units (lists, one per entry, or None for an argument documented by text only)."""
    entries = doc if isinstance(doc, Entries) else None
    return {"name": name, "size": size, "what": entries.what if entries else str(doc), "unit": str(doc),
            "entries": list(entries.names) if entries else None, "units": list(entries.units) if entries else None}


def write_package(out_dir, functions: list[Exported], name: str, precision: str = "double",
                  description: str = "", *, citation: str = "", example: Example | None = None,
                  finite_check: bool = True, extra: dict | None = None, target=None,
                  target_output: str | None = None) -> dict:
    """Write the package (module docstring) into ``out_dir``; returns the manifest.

    citation: the reference of the method implemented (header, README, manifest); example: data
    for ``main.c`` (:class:`~uvsym.codegen.example.Example`), else it calls on zeros;
    finite_check: wrappers check inputs and outputs for NaN and infinity; extra: more manifest keys;
    target: a :class:`~uvsym.codegen.targets.Target` whose build files and harness go into ``target/``
    (:func:`uvsym.codegen.targets.target_files`); target_output: what its harness printed when built
    and run for it (``target/harness.out``).
    """
    if precision not in PRECISIONS:
        raise CodegenError(f"unknown precision {precision!r}; known: {', '.join(PRECISIONS)}")
    name = _c_name(name)
    names = [_c_name(e.function.name()) for e in functions]
    if len(set(names)) < len(names):
        raise CodegenError(f"package {name}: function names must differ; given {', '.join(names)}")
    if example is not None:
        if example.function not in names:
            raise CodegenError(f"package {name}: the example calls {example.function}, not one of {', '.join(names)}")
        example.check_against(functions[names.index(example.function)].function)
    out = output_folder(out_dir, "the package", CodegenError)
    previous = recorded_files(out, "package") or {}
    # CasADi's internal symbols get the prefix <name>_casadi__, so they cannot meet an API name
    generator = ca.CodeGenerator(f"{name}_casadi", {"with_header": True, "casadi_real": precision,
                                                    "prefix": f"{name}_casadi_"})
    for e in functions:
        generator.add(_renamed(e.function, casadi_name(name, e.function.name())))
    with tempfile.TemporaryDirectory() as scratch:
        generator.generate(f"{scratch}{os.sep}")
        source = _silence_unused((Path(scratch) / f"{name}_casadi.c").read_text())
        source = _single_precision(source) if precision == "float" else source
        header = (Path(scratch) / f"{name}_casadi.h").read_text()
    wrappers = [_wrapper(e, name, finite_check) for e in functions]
    checked = finite_check and any(d for e in functions for _, _, d, _ in e.arguments())  # an entry to check
    all_finite = _ALL_FINITE.format(package=name) + "\n" if checked else ""
    includes = f'#include <math.h>\n#include "{name}_casadi.h"\n#include "{name}.h"\n\n'
    texts = {f"src/{name}_casadi.c": source, f"include/{name}_casadi.h": header,
             f"include/{name}.h": _header(name, description, citation, precision, wrappers),
             f"src/{name}.c": includes + all_finite + "\n".join(b for _, b in wrappers),
             "main.c": example_program(functions, name, example), "harness.c": harness_program(functions, name),
             "Makefile": makefile(name, target), "CMakeLists.txt": cmake_lists(name)}
    if target is not None:
        from uvsym.codegen.targets import target_files, target_vectors

        texts |= target_files(functions, name, precision, target, target_vectors(functions, example))
        if target_output is not None:
            texts["target/harness.out"] = target_output
    manifest = {
        "package": name, "description": description, "citation": citation, "precision": precision,
        "casadi": ca.__version__, "finite_check": finite_check,
        "return_codes": {f"{name.upper()}_{suffix}": {"value": value, "meaning": meaning}
                         for suffix, value, meaning in ERROR_CODES
                         if (finite_check or "NONFINITE" not in suffix)
                         and (suffix != "UNHEALTHY" or any(_health_entries(e) for e in functions))},
        "example": None if example is None else {"function": f"{name}_{example.function}", "source": example.source},
        "functions": [{
            "name": e.function.name(), "c_function": f"{name}_{e.function.name()}",
            "casadi_function": casadi_name(name, e.function.name()), "description": e.description,
            "inputs": [_argument_entry(n, size, doc) for d, n, size, doc in e.arguments() if d == "in"],
            "outputs": [_argument_entry(n, size, doc) for d, n, size, doc in e.arguments() if d == "out"],
            "sha256": hashlib.sha256(e.function.serialize().encode()).hexdigest(),
        } for e in functions],
    } | (extra or {})
    texts["README.md"] = package_readme(manifest)
    manifest["files"] = write_files(out, texts)
    remove_stale(out, previous, manifest["files"])
    (out / "manifest.json").write_text(json.dumps(manifest, indent=2, sort_keys=True) + "\n")
    return manifest
