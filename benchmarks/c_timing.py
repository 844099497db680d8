"""Time one C call in a tight C loop: best of five batches, in ns per call.

Shared by the benchmarks; the call's inputs are set up by the caller's C snippet, one input is
nudged every iteration so that the compiler cannot hoist the call out of the loop.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

TEMPLATE = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <time.h>
#include "{header}"
int main(void) {{
{setup}
  const long n = {calls};
  double best = 1e30, sink = 0.0;
  int rep;
  for (rep = 0; rep < 5; ++rep) {{
    struct timespec t0, t1;
    long i;
    double ns;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (i = 0; i < n; ++i) {{
      {vary} = {vary_base} + 1e-9 * (double)(i & 1023);  /* defeat hoisting */
      {call};
      sink += {observe};
    }}
    clock_gettime(CLOCK_MONOTONIC, &t1);
    ns = ((t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec)) / (double)n;
    if (ns < best) best = ns;
  }}
  printf("%.3f %.17g\n", best, sink);
  return 0;
}}
"""


def c_loop_ns(sources: list[Path], include: Path, header: str, setup: str, call: str, vary: str,
              vary_base: float, observe: str, calls: int = 1_000_000) -> float | None:
    """ns per ``call`` (C statement) compiled with -O3 -march=native with ``sources``; None without gcc."""
    compiler = shutil.which("gcc") or shutil.which("cc")
    if compiler is None:
        return None
    with tempfile.TemporaryDirectory() as scratch:
        main = Path(scratch) / "timing.c"
        main.write_text(TEMPLATE.format(header=header, setup=setup, calls=calls, vary=vary, vary_base=vary_base,
                                        call=call, observe=observe))
        exe = Path(scratch) / "timing"
        subprocess.run([compiler, "-std=c99", "-O3", "-march=native", "-I", str(include), str(main),
                        *map(str, sources), "-o", str(exe), "-lm"], check=True)
        return float(subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.split()[0])
