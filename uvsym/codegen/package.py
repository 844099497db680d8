"""A self-contained C99 package of observers: CasADi sources, a wrapper API, build files, manifest.

``write_package(out_dir, functions, name, precision)`` writes::

    include/<name>_casadi.h, src/<name>_casadi.c   CasADi's generated code (its standard API,
                                                   <name>_casadi_<function>, so casadi.external
                                                   can load the library)
    include/<name>.h, src/<name>.c                 one documented wrapper per function:
                                                   <name>_<function>(inputs..., outputs...)
    main.c, harness.c                              an example program; a stdin/stdout harness
    Makefile, CMakeLists.txt                       static and shared library, example, harness
    manifest.json                                  functions, argument names, sizes, units,
                                                   precision, SHA-256 of each serialised Function

Every external C name starts with the package name (CasADi's internals with ``<name>_casadi__``,
the real type is ``<name>_real``), so that packages of the same precision link into one program
and their headers go into one source file. Work buffers are static (sized by CasADi's ``*_SZ_*``
macros): nothing is allocated at run time, and the wrappers are not reentrant. The same
functions and options give byte-identical files.
A double build matches the Python evaluation to 1e-12 relative; a float build (C only: it
cannot be loaded through casadi.external) to 1e-5 of each call's largest output (tested).
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

from uvsym.errors import CodegenError
from uvsym.paths import output_folder

__all__ = ["Exported", "PRECISIONS", "casadi_name", "write_package"]

PRECISIONS = ("double", "float")


@dataclass(frozen=True)
class Exported:
    """A Function to export, with one unit string per input and output and a one-line description."""

    function: ca.Function
    input_units: tuple[str, ...]
    output_units: tuple[str, ...]
    description: str

    def __post_init__(self):
        f = self.function
        if len(self.input_units) != f.n_in() or len(self.output_units) != f.n_out():
            raise CodegenError(f"{f.name()}: give one unit per input ({f.n_in()}) and output ({f.n_out()})")
        for i in range(f.n_in()):
            if not f.sparsity_in(i).is_dense() or f.size2_in(i) != 1:
                raise CodegenError(f"{f.name()}: input {f.name_in(i)} must be a dense column vector")


def _silence_unused(source: str) -> str:
    """Mark CasADi's unused work-array parameters used, so that -Wall -Wextra -Werror passes."""
    pattern = re.compile(r"^((?:static|CASADI_SYMBOL_EXPORT) [^\n;]*\(([^()]*)\)\s*\{)$", re.MULTILINE)

    def mark(match: re.Match) -> str:
        names = [p.split()[-1].lstrip("*") for p in match.group(2).split(",") if p.strip() and p.strip() != "void"]
        unused = [n for n in names if n in ("iw", "w", "mem")]
        return match.group(1) + ("\n  " + " ".join(f"(void){n};" for n in unused) if unused else "")

    return pattern.sub(mark, source)


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


def _wrapper(e: Exported, package: str) -> tuple[str, str]:
    """(prototype with its documentation, definition) of <package>_<function>."""
    f = e.function
    name, real = casadi_name(package, f.name()), f"{package}_real"
    # an empty argument (no entries) is a pointer, which may be NULL: ISO C has no zero-size arrays
    args = [f"const {real} {f.name_in(i)}[{f.nnz_in(i)}]" if f.nnz_in(i) else f"const {real}* {f.name_in(i)}"
            for i in range(f.n_in())]
    args += [f"{real} {f.name_out(i)}[{f.nnz_out(i)}]" if f.nnz_out(i) else f"{real}* {f.name_out(i)}"
             for i in range(f.n_out())]
    doc = [f"/* {e.description}", " *"]
    doc += [f" * in  {f.name_in(i)}[{f.nnz_in(i)}]: {e.input_units[i]}" for i in range(f.n_in())]
    doc += [f" * out {f.name_out(i)}[{f.nnz_out(i)}]: {e.output_units[i]}" for i in range(f.n_out())]
    doc += [" * Returns 0 on success. Uses static work buffers: not reentrant. */"]
    prototype = "\n".join(doc) + f"\nint {package}_{f.name()}({', '.join(args)});\n"
    inputs = ", ".join(f.name_in(i) for i in range(f.n_in()))
    outputs = ", ".join(f.name_out(i) for i in range(f.n_out()))
    body = f"""int {package}_{f.name()}({', '.join(args)}) {{
  static casadi_int iw[{name}_SZ_IW > 0 ? {name}_SZ_IW : 1];
  static casadi_real w[{name}_SZ_W > 0 ? {name}_SZ_W : 1];
  const casadi_real* arg[{name}_SZ_ARG > 0 ? {name}_SZ_ARG : 1] = {{{inputs}}};
  casadi_real* res[{name}_SZ_RES > 0 ? {name}_SZ_RES : 1] = {{{outputs}}};
  return {name}(arg, res, iw, w, 0);
}}
"""
    return prototype, body


def _harness(functions: list[Exported], name: str) -> str:
    """stdin/stdout harness: reads `index` then the inputs as text, prints the outputs (%.17g)."""
    cases = []
    for index, e in enumerate(functions):
        f = e.function
        reads = "\n".join(f"      for (i = 0; i < {f.nnz_in(k)}; ++i) if (scanf(\"%lf\", &v) != 1) return 1; "
                          f"else in{k}[i] = ({name}_real)v;" for k in range(f.n_in()))
        declare = " ".join(f"{name}_real in{k}[{max(1, f.nnz_in(k))}];" for k in range(f.n_in()))
        declare += " " + " ".join(f"{name}_real out{k}[{max(1, f.nnz_out(k))}];" for k in range(f.n_out()))
        call = ", ".join([f"in{k}" for k in range(f.n_in())] + [f"out{k}" for k in range(f.n_out())])
        prints = "\n".join(f"      for (i = 0; i < {f.nnz_out(k)}; ++i) printf(\"%.17g \", (double)out{k}[i]);"
                           for k in range(f.n_out()))
        cases.append(f"""    case {index}: {{
      {declare}
{reads}
      if ({name}_{f.name()}({call})) return 2;
{prints}
      break;
    }}""")
    return f"""/* Test harness: each record on stdin is a function index then its inputs, all as text;
   prints that function's outputs on one line. Used to compare C with Python. */
#include <stdio.h>
#include "{name}.h"

int main(void) {{
  int index;
  double v;
  int i;
  while (scanf("%d", &index) == 1) {{
    switch (index) {{
{chr(10).join(cases)}
    default:
      return 3;
    }}
    printf("\\n");
  }}
  return 0;
}}
"""


def _example(functions: list[Exported], name: str) -> str:
    f = functions[-1].function
    declare = "\n".join(f"  {name}_real {f.name_in(i)}[{max(1, f.nnz_in(i))}] = {{0}};" for i in range(f.n_in()))
    declare += "\n" + "\n".join(f"  {name}_real {f.name_out(i)}[{max(1, f.nnz_out(i))}];" for i in range(f.n_out()))
    call = ", ".join([f.name_in(i) for i in range(f.n_in())] + [f.name_out(i) for i in range(f.n_out())])
    last = f.name_out(f.n_out() - 1)
    return f"""/* Example: one call of {name}_{f.name()} with zero inputs; prints its last output. */
#include <stdio.h>
#include "{name}.h"

int main(void) {{
  int i;
{declare}
  if ({name}_{f.name()}({call})) return 1;
  for (i = 0; i < {f.nnz_out(f.n_out() - 1)}; ++i) printf("%g ", (double){last}[i]);
  printf("\\n");
  return 0;
}}
"""


def _makefile(name: str) -> str:
    return f"""# Builds lib{name}.a, lib{name}.so, the example and the harness.
# CFLAGS may be overridden freely (e.g. make CFLAGS="-std=c99 -O2 -Wall -Wextra -Werror -fPIC");
# include paths live in CPPFLAGS.
CC ?= cc
CFLAGS ?= -std=c99 -O2 -Wall -Wextra -fPIC
CPPFLAGS += -Iinclude
LDLIBS += -lm
OBJ = src/{name}_casadi.o src/{name}.o

all: lib{name}.a lib{name}.so example harness

lib{name}.a: $(OBJ)
\t$(AR) rcs $@ $(OBJ)

lib{name}.so: $(OBJ)
\t$(CC) $(CFLAGS) -shared -o $@ $(OBJ) $(LDLIBS)

example: main.o lib{name}.a
\t$(CC) $(CFLAGS) -o $@ main.o lib{name}.a $(LDLIBS)

harness: harness.o lib{name}.a
\t$(CC) $(CFLAGS) -o $@ harness.o lib{name}.a $(LDLIBS)

%.o: %.c
\t$(CC) $(CPPFLAGS) $(CFLAGS) -c -o $@ $<

clean:
\trm -f $(OBJ) main.o harness.o lib{name}.a lib{name}.so example harness

.PHONY: all clean
"""


def _cmake(name: str) -> str:
    return f"""cmake_minimum_required(VERSION 3.10)
project({name} C)
set(CMAKE_C_STANDARD 99)
set(CMAKE_C_STANDARD_REQUIRED ON)
set(CMAKE_POSITION_INDEPENDENT_CODE ON)
set(SOURCES src/{name}_casadi.c src/{name}.c)
add_library({name}_static STATIC ${{SOURCES}})
add_library({name}_shared SHARED ${{SOURCES}})
set_target_properties({name}_static {name}_shared PROPERTIES OUTPUT_NAME {name})
foreach(target {name}_static {name}_shared)
  target_include_directories(${{target}} PUBLIC include)
  target_link_libraries(${{target}} PUBLIC m)
endforeach()
add_executable(example main.c)
target_link_libraries(example {name}_static)
add_executable(harness harness.c)
target_link_libraries(harness {name}_static)
"""


def write_package(out_dir, functions: list[Exported], name: str, precision: str = "double",
                  description: str = "") -> dict:
    """Write the package (module docstring) into ``out_dir``; returns the manifest."""
    if precision not in PRECISIONS:
        raise CodegenError(f"unknown precision {precision!r}; known: {', '.join(PRECISIONS)}")
    name = _c_name(name)
    names = [_c_name(e.function.name()) for e in functions]
    if len(set(names)) < len(names):
        raise CodegenError(f"package {name}: function names must differ; given {', '.join(names)}")
    out = output_folder(out_dir, "the package", CodegenError)
    (out / "include").mkdir(parents=True, exist_ok=True)
    (out / "src").mkdir(exist_ok=True)
    # CasADi's internal symbols get the prefix <name>_casadi__, so they cannot meet an API name
    generator = ca.CodeGenerator(f"{name}_casadi", {"with_header": True, "casadi_real": precision,
                                                    "prefix": f"{name}_casadi_"})
    for e in functions:
        generator.add(_renamed(e.function, casadi_name(name, e.function.name())))
    with tempfile.TemporaryDirectory() as scratch:
        generator.generate(f"{scratch}{os.sep}")
        source = _silence_unused((Path(scratch) / f"{name}_casadi.c").read_text())
        header = (Path(scratch) / f"{name}_casadi.h").read_text()
    (out / "src" / f"{name}_casadi.c").write_text(source)
    (out / "include" / f"{name}_casadi.h").write_text(header)
    wrappers = [_wrapper(e, name) for e in functions]
    guard = name.upper() + "_H"
    (out / "include" / f"{name}.h").write_text(
        f"/* {description or name}: wrapper API generated by uvsym. Precision: {precision}. */\n"
        f"#ifndef {guard}\n#define {guard}\n#include \"{name}_casadi.h\"\n\ntypedef casadi_real {name}_real;\n\n"
        + "\n".join(p for p, _ in wrappers) + f"\n#endif /* {guard} */\n")
    (out / "src" / f"{name}.c").write_text(f'#include "{name}.h"\n\n' + "\n".join(b for _, b in wrappers))
    (out / "main.c").write_text(_example(functions, name))
    (out / "harness.c").write_text(_harness(functions, name))
    (out / "Makefile").write_text(_makefile(name))
    (out / "CMakeLists.txt").write_text(_cmake(name))
    manifest = {
        "package": name, "description": description, "precision": precision, "casadi": ca.__version__,
        "functions": [{
            "name": e.function.name(), "c_function": f"{name}_{e.function.name()}",
            "casadi_function": casadi_name(name, e.function.name()), "description": e.description,
            "inputs": [{"name": e.function.name_in(i), "size": e.function.nnz_in(i), "unit": e.input_units[i]}
                       for i in range(e.function.n_in())],
            "outputs": [{"name": e.function.name_out(i), "size": e.function.nnz_out(i), "unit": e.output_units[i]}
                        for i in range(e.function.n_out())],
            "sha256": hashlib.sha256(e.function.serialize().encode()).hexdigest(),
        } for e in functions],
    }
    (out / "manifest.json").write_text(json.dumps(manifest, indent=2, sort_keys=True) + "\n")
    return manifest
