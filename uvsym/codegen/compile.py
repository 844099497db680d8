"""Compile CasADi Functions to shared libraries with the system C compiler and load them back.

``compile_function``: ``casadi.external`` evaluates the compiled code with the same calling
convention as the original Function, so it is a drop-in replacement. ``compile_roll``: a plain
C loop over a step Function ``(z, w) -> (z_next, out)``, called once per chunk of steps through
ctypes -- the fast path of the simulations (see ``benchmarks/sim.py``); a step that is straight-line
code runs as such, on restrict pointers without CasADi's calling convention (faster, results within
1e-10 relative). ``compile_lanes``: the same loop over L independent trajectories side by side, the
step's body run as a loop over lanes that the compiler vectorises (see ``benchmarks/campaign.py``).
Libraries are kept in the compile cache (:mod:`uvsym.codegen.cache`), so the same Function is
compiled once per machine.
"""

from __future__ import annotations

import atexit
import ctypes
import functools
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import casadi as ca
import numpy as np

from uvsym.codegen.cache import cached_library, library_key, memoized
from uvsym.errors import CodegenError

__all__ = ["DEFAULT_FLAGS", "FAST_FLAGS", "find_compiler", "compile_function", "compile_roll", "compile_lanes",
           "vector_doubles"]

# No -ffast-math: a shared library built with it switches the whole process to flush-to-zero
# on load (crtfastmath), which silently changes every other float computation in Python.
DEFAULT_FLAGS = ("-O3", "-march=native", "-fno-math-errno", "-fPIC", "-shared")
# The simulation loops: CasADi's helpers (fmin, fmax, sq) called directly rather than through the
# PLT, and no IEEE special cases the loops do not need; results stay within 1e-10 relative of
# DEFAULT_FLAGS and a loop that produces NaN is still reported (tests/test_compile_cache.py).
FAST_FLAGS = DEFAULT_FLAGS + ("-fno-semantic-interposition", "-ffinite-math-only", "-fno-signed-zeros",
                              "-fno-trapping-math")
_BUILD_DIR: Path | None = None


def find_compiler() -> str | None:
    """Path of the C compiler named by $CC, else gcc or cc on PATH, else None."""
    for candidate in (os.environ.get("CC"), "gcc", "cc"):
        if candidate and shutil.which(candidate):
            return shutil.which(candidate)
    return None


@functools.cache
def vector_doubles() -> int:
    """Doubles in one vector register of the processor the compiler builds for with ``-march=native``:
    8 with AVX-512F, 4 with AVX, else 2 (asked of the compiler's predefined macros, once per process;
    2 without a compiler)."""
    compiler = find_compiler()
    if compiler is None:
        return 2
    done = subprocess.run([compiler, "-march=native", "-dM", "-E", "-x", "c", os.devnull], capture_output=True,
                          text=True)
    macros = set(re.findall(r"#define (\w+)", done.stdout)) if done.returncode == 0 else set()
    return 8 if "__AVX512F__" in macros else 4 if "__AVX__" in macros else 2


def _build_dir() -> Path:
    """This process's scratch folder for generated sources (and libraries the cache cannot hold), removed at exit."""
    global _BUILD_DIR
    if _BUILD_DIR is None:
        _BUILD_DIR = Path(tempfile.mkdtemp(prefix="uvsym-build-"))
        atexit.register(shutil.rmtree, _BUILD_DIR, ignore_errors=True)
    return _BUILD_DIR


def _build(f: ca.Function, extra_source: str, flags: tuple[str, ...], libraries: tuple[str, ...] = ("-lm",),
           generated=None) -> Path:
    """Shared library of ``f`` generated as C (with a header) plus ``extra_source``, from the compile cache
    (compiled into it first when missing). ``generated() -> str``: C to compile instead of CasADi's code
    for ``f`` and ``extra_source``, called only on a cache miss (``extra_source`` must then name all it depends
    on besides ``f``)."""
    compiler = find_compiler()
    if compiler is None:
        raise CodegenError("no C compiler found (set $CC or install gcc)")
    key = library_key(f, extra_source, flags + libraries, compiler)

    def compile_into(library: Path) -> None:
        directory = _build_dir()
        stem = f"{f.name()}_{key[:16]}"
        sources = []
        if generated is None:
            generator = ca.CodeGenerator(stem, {"with_header": True})
            generator.add(f)
            generator.generate(f"{directory}{os.sep}")
            sources.append(directory / f"{stem}.c")
        if extra_source or generated is not None:
            sources.append(directory / f"{stem}_driver.c")
            sources[-1].write_text(generated() if generated is not None else f'#include "{stem}.h"\n' + extra_source)
        command = [compiler, *flags, *map(str, sources), "-o", str(library), *libraries]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            raise CodegenError(f"compiling {f.name()} failed: {' '.join(command)}\n{done.stderr.strip()}")

    return cached_library(key, compile_into, _build_dir())


def compile_function(f: ca.Function, flags: tuple[str, ...] = DEFAULT_FLAGS) -> ca.Function:
    """``f`` generated as C, compiled to a shared library (or taken from the compile cache) and
    loaded with ``casadi.external``.

    Raises
    ------
    CodegenError
        When no C compiler is found or compilation fails (with the compiler's message).
    """
    return ca.external(f.name(), str(_build(f, "", flags)))


_ROLL = """
#include <string.h>
int {name}_roll(const casadi_real* z0, const casadi_real* W, casadi_real* z_end, casadi_real* O, long N) {{
  static casadi_real w[{name}_SZ_W > 0 ? {name}_SZ_W : 1];
  static casadi_int iw[{name}_SZ_IW > 0 ? {name}_SZ_IW : 1];
  casadi_real a[{n_z}], b[{n_z}];
  casadi_real *z = a, *z_next = b, *swap;
  const casadi_real* arg[{name}_SZ_ARG];
  casadi_real* res[{name}_SZ_RES];
  memcpy(z, z0, sizeof a);
  for (long k = 0; k < N; ++k) {{
    arg[0] = z;
    arg[1] = W + k * {n_w};
    res[0] = z_next;
    res[1] = O + k * {n_out};
    if ({name}(arg, res, iw, w, 0)) return 1;
    swap = z; z = z_next; z_next = swap;  /* the next state becomes the state: no copy */
  }}
  memcpy(z_end, z, sizeof a);
  return 0;
}}
"""

_POINTER = ctypes.POINTER(ctypes.c_double)


def _roller(step: ca.Function, library: Path, symbol: str, lanes: tuple[int, ...]):
    """roll(z0, W, out) -> z_end calling ``symbol`` of ``library``; ``lanes``: () or (L,), the trailing axis."""
    n_z, n_w, n_out = step.nnz_in(0), step.nnz_in(1), step.nnz_out(1)
    function = getattr(ctypes.CDLL(str(library)), symbol)  # roll.library below: its path
    function.argtypes = [_POINTER, _POINTER, _POINTER, _POINTER, ctypes.c_long]

    def roll(z0: np.ndarray, W: np.ndarray, out: np.ndarray) -> np.ndarray:
        z0 = np.ascontiguousarray(z0, dtype=float)
        if z0.shape != (n_z, *lanes) or W.shape[1:] != (n_w, *lanes) or out.shape != (W.shape[0], n_out, *lanes) \
                or not (W.flags.c_contiguous and out.flags.c_contiguous):
            shape = "".join(f", {size}" for size in lanes)
            raise CodegenError(f"roll needs z0 ({n_z}{shape}) and C-contiguous W (k, {n_w}{shape}) and "
                               f"out (k, {n_out}{shape})")
        z_end = np.empty_like(z0)
        if function(z0.ctypes.data_as(_POINTER), W.ctypes.data_as(_POINTER), z_end.ctypes.data_as(_POINTER),
                    out.ctypes.data_as(_POINTER), W.shape[0]):
            raise CodegenError(f"{step.name()} failed inside the compiled loop")
        return z_end

    roll.library = library
    return roll


def _runs_roller(step: ca.Function, library: Path, symbol: str, lanes: int):
    """runs(z0, Ws, outs) -> z_end calling ``symbol`` of ``library``: the lanes over each run's own arrays."""
    n_z, n_w, n_out = step.nnz_in(0), step.nnz_in(1), step.nnz_out(1)
    pointers, counts = ctypes.c_void_p * lanes, ctypes.c_long * lanes
    function = getattr(ctypes.CDLL(str(library)), symbol)
    function.argtypes = [_POINTER, pointers, pointers, counts, pointers, _POINTER, pointers, ctypes.c_long,
                         ctypes.c_long, _POINTER, ctypes.POINTER(ctypes.c_long)]
    every_column, unused = np.arange(n_w, dtype=np.int_), np.zeros(n_w)  # a dense W: every column varies

    def runs(z0: np.ndarray, Ws: list, outs: list[np.ndarray], z_max: np.ndarray | None = None,
             first_bad: np.ndarray | None = None) -> np.ndarray:
        """k steps of every lane: lane l reads the rows of Ws[l] (k, n_w: a C-contiguous float64 array, or
        compact inputs with ``constant`` (n_w,), ``columns`` (n_var,) and ``rows`` (k, n_var) as
        :class:`~uvsym.sim.inputs.CompactInputs` holds them) and writes outs[l] (k, n_out) (lanes may share
        an array, a padding lane its run's); z0, z_end (n_z, L). Updated in place where given: z_max (n_max, L)
        float64 (n_max <= n_z), the largest ``abs(z)`` of each of the first n_max entries from z0 on, and first_bad
        (L,) np.int_, each lane's first step (of this call) whose output row is not finite where it holds -1."""
        z0 = np.ascontiguousarray(z0, dtype=float)
        z_max = np.zeros((0, lanes)) if z_max is None else z_max
        first_bad = np.full(lanes, -1, dtype=np.int_) if first_bad is None else first_bad
        if not (z_max.ndim == 2 and z_max.shape[0] <= n_z and z_max.shape[1] == lanes and z_max.dtype == np.float64
                and z_max.flags.c_contiguous
                and first_bad.shape == (lanes,) and first_bad.dtype == np.int_ and first_bad.flags.c_contiguous):
            raise CodegenError(f"the lanes' runs need z_max (at most {n_z}, {lanes}) float64 and first_bad ({lanes},) "
                               "of np.int_, C-contiguous")
        k = Ws[0].shape[0] if len(Ws) else 0
        parts = [(unused, every_column, W) if isinstance(W, np.ndarray) else (W.constant, W.columns, W.rows)
                 for W in Ws]

        def fit(a, width: int, writes: bool) -> bool:
            return (a.shape == (k, width) and a.dtype == np.float64 and a.flags.c_contiguous
                    and (a.flags.writeable or not writes))

        if z0.shape != (n_z, lanes) or len(Ws) != lanes or len(outs) != lanes or not (
                all(fit(rows, columns.size, False) and constant.shape == (n_w,) and constant.dtype == np.float64
                    and columns.dtype == np.int_ and columns.flags.c_contiguous for constant, columns, rows in parts)
                and all(fit(out, n_out, True) for out in outs)):
            raise CodegenError(f"the lanes' runs need z0 ({n_z}, {lanes}) and {lanes} C-contiguous float64 W (k, "
                               f"{n_w}) (or compact inputs of that shape) and out (k, {n_out}) of one k")
        z_end = np.empty_like(z0)
        if function(z0.ctypes.data_as(_POINTER), pointers(*(c.ctypes.data for c, _, _ in parts)),
                    pointers(*(j.ctypes.data for _, j, _ in parts)), counts(*(j.size for _, j, _ in parts)),
                    pointers(*(r.ctypes.data for _, _, r in parts)), z_end.ctypes.data_as(_POINTER),
                    pointers(*(out.ctypes.data for out in outs)), k, z_max.shape[0], z_max.ctypes.data_as(_POINTER),
                    first_bad.ctypes.data_as(ctypes.POINTER(ctypes.c_long))):
            raise CodegenError(f"{step.name()} failed inside the compiled loop")
        return z_end

    return runs


_STRAIGHT = """
__attribute__((noinline)) static void {name}_body(const double* restrict in0, const double* restrict in1,
                                                  double* restrict out0, double* restrict out1) {{
  const long l = 0;
{body}
}}
int {name}_roll(const double* z0, const double* W, double* z_end, double* O, long N) {{
  double a[{n_z}], b[{n_z}];
  double *z = a, *z_next = b, *swap;
  memcpy(z, z0, sizeof a);
  for (long k = 0; k < N; ++k) {{
    {name}_body(z, W + k * {n_w}, z_next, O + k * {n_out});
    swap = z; z = z_next; z_next = swap;  /* the next state becomes the state: no copy */
  }}
  memcpy(z_end, z, sizeof a);
  return 0;
}}
"""


@memoized(16)
def compile_roll(step: ca.Function, flags: tuple[str, ...] = FAST_FLAGS):
    """A C loop over ``step(z, w) -> (z_next, out)`` (dense vectors), compiled and loaded.

    Returns ``roll(z0 (n_z,), W (k, n_w), out (k, n_out)) -> z_end``: k steps, one row of W per
    step, writing each step's ``out`` into the rows of ``out`` (C-contiguous float64 arrays). No
    state history is kept and nothing is allocated per step. A step of straight-line scalar code
    (as :func:`compile_lanes` needs) is compiled as such into the loop, else CasADi's code is called
    per step. Memoized in-process by the step object and the flags: a rerun of one loop loads nothing again.

    Raises CodegenError when there is no compiler or compilation fails.
    """
    n_z, n_w, n_out = step.nnz_in(0), step.nnz_in(1), step.nnz_out(1)
    sizes = {"name": step.name(), "n_z": n_z, "n_w": n_w, "n_out": n_out}

    def straight() -> str:
        """The step's body as straight-line code in the loop (one lane of :func:`_lane_body`)."""
        return _LANE_HELPERS + "#define L 1\n" + _STRAIGHT.format(**sizes, body=_lane_body(step))

    try:
        library = _build(step, "\0".join((_LANE_HELPERS, _STRAIGHT)), flags, generated=straight)
    except CodegenError:  # not straight-line code: CasADi's Function called per step
        library = _build(step, _ROLL.format(**sizes), flags)
    return _roller(step, library, f"{step.name()}_roll", ())


# Math functions with a vector variant in glibc's libmvec (x86-64; sin, cos, exp, log, pow 2.22, the rest
# 2.35): declared SIMD-callable so the lane loop vectorises through them (glibc declares them so only under
# -ffast-math). A libmvec without one fails the link (-z defs), and the lanes fall back to scalar runs.
_VECTOR_MATH = ("sin", "cos", "exp", "log", "pow", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh",
                "hypot", "expm1", "log1p", "cbrt", "erf")
_TWO_ARGUMENTS = {"pow", "atan2", "hypot"}
_SCALAR_OK = {"sqrt", "fabs", "floor", "ceil", "fmin", "fmax", "copysign", "trunc", "round"}
_LANE_HELPERS = """#include <math.h>
#include <string.h>
#define casadi_real double
static inline double casadi_sq(double x) { return x * x; }
static inline double casadi_fmin(double x, double y) { return (y != y || x < y) ? x : y; }
static inline double casadi_fmax(double x, double y) { return (y != y || x > y) ? x : y; }
static inline double casadi_sign(double x) { return x < 0 ? -1. : x > 0 ? 1. : x; }
static inline double casadi_fabs(double x) { return fabs(x); }
"""
_LANES = """
__attribute__((noinline)) static void {name}_lanes_step(const double* restrict in0, const double* restrict in1,
                                                        double* restrict out0, double* restrict out1) {{
  #pragma omp simd
  for (long l = 0; l < {L}; ++l) {{
{body}
  }}
}}
int {name}_lanes_roll(const double* z0, const double* W, double* z_end, double* O, long N) {{
  double a[{n_z} * {L}], b[{n_z} * {L}];
  double *z = a, *zn = b, *swap;
  memcpy(z, z0, sizeof a);
  for (long k = 0; k < N; ++k) {{
    {name}_lanes_step(z, W + k * {n_w} * {L}, zn, O + k * {n_out} * {L});
    swap = z; z = zn; zn = swap;  /* the next state becomes the state: no copy */
  }}
  memcpy(z_end, z, sizeof a);
  return 0;
}}
/* the same roll over each lane's own row-major arrays, gathered into and scattered from the structure of
   arrays one step at a time (in the cache: no pass over the runs' memory). Lane l's inputs: the constant
   row C_l (n_w) and the nJ_l columns J_l that vary, their rows W_l (N, nJ_l); its outputs O_l (N, n_out).
   On the way, what a pass over the outputs would otherwise find: z_max (n_max, L) the largest |z| of each of
   the first n_max state entries from z0 on (kept from the caller's values), and first_bad (L) the first step
   whose output row holds an infinity or a NaN (told by the exponent bits, which -ffinite-math-only leaves
   alone; kept where the caller's value is not -1), counted from 0 in this call. */
static inline long {name}_not_finite(double v) {{
  unsigned long long bits;
  memcpy(&bits, &v, sizeof bits);
  return (bits & 0x7ff0000000000000ULL) == 0x7ff0000000000000ULL;
}}
int {name}_lanes_runs(const double* z0, const double* const* C, const long* const* J, const long* nJ,
                      const double* const* W, double* z_end, double* const* O, long N, long n_max, double* z_max,
                      long* first_bad) {{
  double a[{n_z} * {L}], b[{n_z} * {L}], w[{n_w} * {L}], o[{n_out} * {L}];
  double *z = a, *zn = b, *swap;
  for (long l = 0; l < {L}; ++l)
    for (long j = 0; j < {n_w}; ++j) w[j * {L} + l] = C[l][j];
  memcpy(z, z0, sizeof a);
  for (long i = 0; i < n_max * {L}; ++i) z_max[i] = fmax(z_max[i], fabs(z[i]));
  for (long k = 0; k < N; ++k) {{
    for (long l = 0; l < {L}; ++l) {{
      const long n = nJ[l], *Jl = J[l];
      const double* row = W[l] + k * n;
      for (long i = 0; i < n; ++i) w[Jl[i] * {L} + l] = row[i];
    }}
    {name}_lanes_step(z, w, zn, o);
    for (long l = 0; l < {L}; ++l) {{
      long bad = 0;
      for (long j = 0; j < {n_out}; ++j) {{
        const double v = o[j * {L} + l];
        O[l][k * {n_out} + j] = v;
        bad |= {name}_not_finite(v);
      }}
      if (bad && first_bad[l] < 0) first_bad[l] = k;
    }}
    for (long i = 0; i < n_max * {L}; ++i) z_max[i] = fmax(z_max[i], fabs(zn[i]));
    swap = z; z = zn; zn = swap;
  }}
  memcpy(z_end, z, sizeof a);
  return 0;
}}
"""


def _lane_body(step: ca.Function) -> str:
    """The body of CasADi's C for ``step`` rewritten for lane ``l`` of structure-of-arrays buffers (entry j of
    lane l at ``j * L + l``); CodegenError when it holds anything but straight-line scalar code."""
    bodies = re.findall(r"\nstatic int casadi_f\d+\([^)]*\) \{\n(.*?)\n  return 0;\n\}", _generated(step), re.S)
    if len(bodies) != 1:
        raise CodegenError(f"{step.name()}: expected one generated function body, found {len(bodies)}")
    body = re.sub(r"arg\[([01])\]\? arg\[\1\]\[(\d+)\] : 0", r"in\1[\2 * L + l]", bodies[0])
    body = re.sub(r"if \(res\[([01])\]!=0\) res\[\1\]\[(\d+)\]=", r"out\1[\2 * L + l]=", body)
    calls = set(re.findall(r"([A-Za-z_]\w*)\(", body)) - set(_VECTOR_MATH) - _SCALAR_OK
    calls -= {"casadi_sq", "casadi_fmin", "casadi_fmax", "casadi_sign", "casadi_fabs"}
    if calls or re.search(r"\b(arg|res|iw|w|for|while)\b", body):
        raise CodegenError(f"{step.name()}: its generated code is not straight-line scalar code the lanes can run "
                           f"(calls {sorted(calls)})")
    return body


def _generated(step: ca.Function) -> str:
    """CasADi's C for ``step`` as text."""
    generator = ca.CodeGenerator(f"{step.name()}_lanes")
    generator.add(step)
    return generator.dump()


@memoized(16)
def compile_lanes(step: ca.Function, lanes: int, flags: tuple[str, ...] = FAST_FLAGS):
    """``step(z, w) -> (z_next, out)`` run for ``lanes`` trajectories at once, in a C loop over lanes that
    gcc vectorises (through glibc's vector math library, libmvec, for sin, cos, atan2, exp, ...).

    Returns ``roll(z0 (n_z, L), W (k, n_w, L), out (k, n_out, L)) -> z_end (n_z, L)``: k steps of every
    lane, lane l reading ``W[:, :, l]`` (C-contiguous float64 arrays, structure of arrays); and
    ``roll.runs(z0, Ws, outs) -> z_end``, the same over L runs' own arrays ``Ws[l]`` (k, n_w) and
    ``outs[l]`` (k, n_out), as the scalar roll takes them (no stacking or transposing of whole runs);
    a run's W may be compact (its varying columns and one constant row), read n_var columns per step.
    Memoized in-process as :func:`compile_roll` is.

    Raises CodegenError when there is no compiler, the step is not straight-line scalar code, or
    compilation (or linking with libmvec) fails.
    """
    if not (isinstance(lanes, int) and lanes >= 1):
        raise CodegenError(f"lanes must be a positive integer, got {lanes!r}")
    n_z, n_w, n_out = step.nnz_in(0), step.nnz_in(1), step.nnz_out(1)
    # what the source depends on besides the step: the key is known without generating it
    recipe = "\0".join((_LANE_HELPERS, _LANES, *_VECTOR_MATH, str(lanes)))

    def source() -> str:
        body = _lane_body(step)
        used = [name for name in _VECTOR_MATH if re.search(rf"\b{name}\(", body)]
        declarations = "".join(f'double {name}(double{", double" * (name in _TWO_ARGUMENTS)}) '
                               f'__attribute__((simd("notinbranch"), const, nothrow));\n' for name in used)
        return (_LANE_HELPERS + declarations + f"#define L {lanes}\n"
                + _LANES.format(name=step.name(), L=lanes, n_z=n_z, n_w=n_w, n_out=n_out, body=body))

    # not builtins: gcc would otherwise fuse sin and cos of one angle into a sincos it cannot vectorise
    not_builtin = tuple(f"-fno-builtin-{name}" for name in _VECTOR_MATH)
    # gcc prefers 256-bit vectors on AVX-512 processors: lanes that fill a 512-bit register ask for it
    wide = ("-mprefer-vector-width=512",) if vector_doubles() == 8 and lanes % 8 == 0 else ()
    # gcc 12's partial redundancy elimination folds CasADi's ``c ? b : 0`` of comparisons into selects of
    # boolean masks of two widths its vectoriser cannot take: the lane loop then runs one lane at a time
    library = _build(step, recipe, (*flags, *not_builtin, *wide, "-fno-tree-pre", "-fopenmp-simd", "-Wl,-z,defs"),
                     ("-lmvec", "-lm"), generated=source)
    roll = _roller(step, library, f"{step.name()}_lanes_roll", (lanes,))
    roll.runs = _runs_roller(step, library, f"{step.name()}_lanes_runs", lanes)
    return roll
