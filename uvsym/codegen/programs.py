"""The programs shipped in a C package: ``main.c`` (an example call) and ``harness.c`` (C vs Python).

``example_program`` calls one function on an :class:`~uvsym.codegen.example.Example`'s row 0
(constants written into the source) and prints each output on its own line as
``<output name> v0 v1 ...`` (``%.17g``), so its output can be compared with Python. Without
example data it calls the package's last function on zeros and says so.
``harness_program`` reads records ``index inputs...`` from stdin and prints, per record, the
wrapper's return code then the outputs.
"""

from __future__ import annotations

import textwrap

from uvsym.codegen.example import Example

__all__ = ["c_array", "example_program", "harness_program"]


def c_array(values) -> str:
    """``{v0, v1, ...}``: values as C literals that read back as the same doubles (wrapped lines)."""
    body = ", ".join(repr(float(v)) for v in values)
    return "{" + "\n    ".join(textwrap.wrap(body, 96)) + "}"


def _declarations(f, name: str, values) -> tuple[list[str], list[str]]:
    """(declarations of the inputs (constants or zeros) and outputs, argument names in call order)."""
    real, lines = f"{name}_real", []
    for i in range(f.n_in()):
        if f.nnz_in(i) == 0:
            lines.append(f"  const {real}* {f.name_in(i)} = NULL;")
        else:
            data = c_array(values[i]) if values is not None else "{0}"
            lines.append(f"  static const {real} {f.name_in(i)}[{f.nnz_in(i)}] = {data};")
    for i in range(f.n_out()):
        lines.append(f"  {real}* {f.name_out(i)} = NULL;" if f.nnz_out(i) == 0 else
                     f"  {real} {f.name_out(i)}[{f.nnz_out(i)}];")
    return lines, [f.name_in(i) for i in range(f.n_in())] + [f.name_out(i) for i in range(f.n_out())]


def example_program(functions, name: str, example: Example | None) -> str:
    """Source of ``main.c`` (module docstring); ``functions``: the package's Exported, in order."""
    by_name = {e.function.name(): e.function for e in functions}
    f = by_name[example.function] if example is not None else functions[-1].function
    lines, call = _declarations(f, name, example.first_call() if example is not None else None)
    where = (f"on data from {example.source} (row 0 of the package's example)" if example is not None else
             "on zero inputs (the observer set gives no example data: put yours here)")
    prints = "\n".join(f'  printf("{f.name_out(i)}");\n  for (i = 0; i < {f.nnz_out(i)}; ++i) '
                       f'printf(" %.17g", (double){f.name_out(i)}[i]);\n  printf("\\n");' for i in range(f.n_out()))
    return f"""/* Example: one call of {name}_{f.name()} {where}.
   Prints each output on one line: its name, then its entries (units: README.md, manifest.json). */
#include <stdio.h>
#include "{name}.h"

int main(void) {{
  int i, rc;
{chr(10).join(lines)}
  rc = {name}_{f.name()}({', '.join(call)});
  if (rc != {name.upper()}_OK) {{
    fprintf(stderr, "{name}_{f.name()} returned %d\\n", rc);
    return 1;
  }}
{prints}
  return 0;
}}
"""


def harness_program(functions, name: str) -> str:
    """Source of ``harness.c`` (module docstring)."""
    cases = []
    for index, e in enumerate(functions):
        f = e.function
        reads = "\n".join(f"      for (i = 0; i < {f.nnz_in(k)}; ++i) if (scanf(\"%lf\", &v) != 1) return 1; "
                          f"else in{k}[i] = ({name}_real)v;" for k in range(f.n_in()))
        declare = " ".join(f"{name}_real in{k}[{max(1, f.nnz_in(k))}];" for k in range(f.n_in()))
        declare += " " + " ".join(f"{name}_real out{k}[{max(1, f.nnz_out(k))}];" for k in range(f.n_out()))
        call = ", ".join([f"in{k}" for k in range(f.n_in())] + [f"out{k}" for k in range(f.n_out())])
        prints = "\n".join(f"      for (i = 0; i < {f.nnz_out(k)}; ++i) printf(\" %.17g\", (double)out{k}[i]);"
                           for k in range(f.n_out()))
        cases.append(f"""    case {index}: {{
      {declare}
{reads}
      printf("%d", {name}_{f.name()}({call}));
{prints}
      break;
    }}""")
    return f"""/* Test harness: each record on stdin is a function index then its inputs, all as text;
   prints that function's return code, then its outputs, on one line. Used to compare C with Python. */
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
