"""Cost of one REMUS 100 nu_dot call: CasADi from Python, buffer(), generated C, plain numpy.

Run ``python benchmarks/rhs.py``; writes ``benchmarks/results/rhs.json``. Times are medians of
repeated batches within this one run; compare them as ratios (the machine is shared).
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import casadi as ca
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from c_timing import c_loop_ns  # noqa: E402
from common import finish  # noqa: E402
from remus100_numpy import Remus100Numpy  # noqa: E402

import uvsym  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "rhs.json"
TARGETS = {"c_ns_per_call_max": 500, "speedup_vs_numpy_min": 150}
ETA = np.array([10.0, -5.0, 20.0, 0.1, -0.05, 0.7])
NU = np.array([1.5, 0.1, -0.05, 0.02, -0.03, 0.04])
U = np.array([0.1, -0.05, 1200.0])

def median_time(call, repeat: int = 7, number: int = 2000) -> float:
    """Median seconds per call over ``repeat`` batches of ``number`` calls."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(number):
            call()
        times.append((time.perf_counter() - start) / number)
    return float(np.median(times))


def nu_dot_c_ns(function: ca.Function) -> float | None:
    """ns per call of the generated C of ``function`` (nu_dot) timed in a C loop (None without gcc)."""
    with tempfile.TemporaryDirectory() as tmp:
        generator = ca.CodeGenerator("nu_dot", {"with_header": True})
        generator.add(function)
        generator.generate(str(tmp) + "/")
        setup = """
  static casadi_real eta[6] = {10.0, -5.0, 20.0, 0.1, -0.05, 0.7};
  static casadi_real nu[6] = {1.5, 0.1, -0.05, 0.02, -0.03, 0.04};
  static casadi_real u[3] = {0.1, -0.05, 1200.0};
  static casadi_real V_c = 0.0, beta_c = 0.0, out[6], w[nu_dot_SZ_W];
  static casadi_int iw[nu_dot_SZ_IW];
  const casadi_real *arg[nu_dot_SZ_ARG] = {eta, nu, u, &V_c, &beta_c};
  casadi_real *res[nu_dot_SZ_RES] = {out};"""
        return c_loop_ns([Path(tmp) / "nu_dot.c"], Path(tmp), "nu_dot.h", setup, "nu_dot(arg, res, iw, w, 0)",
                         "nu[0]", 1.5, "out[0]", calls=2_000_000)


def main() -> dict:
    model = uvsym.vehicle("remus100")
    f = model.nu_dot
    baseline = Remus100Numpy(model)
    expected = np.array(f(ETA, NU, U, 0, 0)).ravel()
    np.testing.assert_allclose(baseline.nu_dot(ETA, NU, U), expected, rtol=1e-9, atol=1e-12)

    args_dm = [ca.DM(ETA), ca.DM(NU), ca.DM(U), ca.DM(0), ca.DM(0)]
    numpy_s = median_time(lambda: baseline.nu_dot(ETA, NU, U), number=500)
    python_numpy_args_s = median_time(lambda: f(ETA, NU, U, 0.0, 0.0))
    python_dm_args_s = median_time(lambda: f(*args_dm))

    buffer, trigger = f.buffer()
    inputs = [np.array(a, dtype=float) for a in (ETA, NU, U, [0.0], [0.0])]
    output = np.zeros(6)
    for i, a in enumerate(inputs):
        buffer.set_arg(i, memoryview(a))
    buffer.set_res(0, memoryview(output))
    buffer_s = median_time(trigger, number=20000)
    np.testing.assert_allclose(output, expected, rtol=1e-14)

    c_ns = nu_dot_c_ns(f)
    results = {
        "vehicle": "remus100",
        "function": "nu_dot(eta, nu, u, V_c, beta_c)",
        "sx_instructions": f.n_instructions(),
        "numpy_us_per_call": numpy_s * 1e6,
        "casadi_python_numpy_args_us_per_call": python_numpy_args_s * 1e6,
        "casadi_python_dm_args_us_per_call": python_dm_args_s * 1e6,
        "casadi_buffer_us_per_call": buffer_s * 1e6,
        "c_ns_per_call": c_ns,
        "speedup_vs_numpy": None if c_ns is None else numpy_s * 1e9 / c_ns,
    }
    return finish(results, TARGETS, RESULTS)


if __name__ == "__main__":
    main()
