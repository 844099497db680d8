"""Cost of one step of the LMS-FIR compass monitor (M = 70), generated C versus padasip's LMS filter.

Run ``python benchmarks/lms.py`` (padasip from the ``bench`` extra); writes
``benchmarks/results/lms.json``. The C steps come from the package of ``uvsym codegen
sensor-fdi-lms``, each timed in a C loop (best of five batches). ``padasip_ns_per_sample``: padasip's
``FilterLMS.run`` (the common Python LMS) on the same data, the same order and the same step
(padasip's ``mu`` is the paper's ``2 mu``), timed in the same run; the two give the same weights
(``max_weight_difference``, against uvsym's own Python evaluation). ``c_ns_per_step`` and
``speedup_vs_padasip`` compare like with like: the package's bare LMS step
(``uvsym.observers.lms.lms_step``: prediction, error, update, input shift) as generated, called
directly (padasip checks nothing either). ``c_checked_ns_per_step``: the same step through the
package's documented wrapper, which checks every input and output for finiteness.
``c_monitor_ns_per_step``: the whole monitor step through its wrapper (the LMS step plus both
criteria, the freeze and the double criterion).
Compare as ratios within one run: the machine is shared.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from c_timing import c_loop_ns  # noqa: E402
from common import finish  # noqa: E402

from uvsym.codegen import find_compiler  # noqa: E402
from uvsym.derivation import observer_set  # noqa: E402
from uvsym.observers.lms import lms_monitor  # noqa: E402
from uvsym.systems.signals import signals  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "lms.json"
ORDER, MU, SAMPLES = 70, 0.002, 20_000


def data(seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """u (N,) white in [-1, 1], the regression rows X (N, M) = [u_{k-1} ... u_{k-M}], y (N,) = X w + noise."""
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1.0, 1.0, SAMPLES)
    padded = np.concatenate([np.zeros(ORDER), u])
    X = np.lib.stride_tricks.sliding_window_view(padded, ORDER)[:SAMPLES, ::-1].copy()
    y = X @ (0.3 * rng.standard_normal(ORDER) * np.exp(-np.arange(ORDER) / 10.0)) + 0.01 * rng.standard_normal(SAMPLES)
    return u, X, y


def padasip_run(X: np.ndarray, y: np.ndarray) -> tuple[float, np.ndarray]:
    """(ns per sample, final weights) of padasip's FilterLMS over the data, best of three runs."""
    import padasip

    best, weights = float("inf"), None
    for _ in range(3):
        lms = padasip.filters.FilterLMS(n=ORDER, mu=2 * MU, w="zeros")
        started = time.perf_counter()
        _, _, history = lms.run(y, X)
        best = min(best, (time.perf_counter() - started) / len(y))
        weights = lms.w.copy()
    del history
    return best * 1e9, weights


def main() -> dict:
    u, X, y = data()
    monitor = lms_monitor(signals(("y", "-", "")), signals(("u", "-", "")), order=ORDER, mu=MU, eps0=1e300, r0=1e300,
                          dt=0.2)
    S, _ = monitor.run(y[:, None], u[:, None])
    padasip_ns, padasip_weights = padasip_run(X, y)
    observers = observer_set("sensor-fdi-lms")
    name = observers.package_name
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        observers.write(folder)
        sources = [folder / "src" / f"{name}_casadi.c", folder / "src" / f"{name}.c"]
        real = f"{name}_real"
        monitor_setup = f"""
  static {real} s[2][{monitor.state.size}], y[1] = {{0.1}}, u[2] = {{0.5, 2.6}}, p[3] = {{{MU}, 1e-3, 9.0}};
  static {real} out[10];"""
        monitor_ns = c_loop_ns(sources, folder / "include", f"{name}.h", monitor_setup,
                               f"{name}_lms_step(s[i & 1], y, u, p, s[(i + 1) & 1], out)", "y[0]", 0.1, "out[2]")
        bare_setup = f"""
  static {real} C[2][{ORDER}], U[2][{ORDER}], target[1] = {{0.1}}, u[1] = {{0.5}}, mu[1] = {{{MU}}}, d[1], e[1];"""
        bare_ns = c_loop_ns(sources, folder / "include", f"{name}.h", bare_setup,
                            f"{name}_lms_fir_step(C[i & 1], U[i & 1], target, u, mu, C[(i + 1) & 1], U[(i + 1) & 1], "
                            "d, e)", "target[0]", 0.1, "e[0]")
        raw = f"{name}_casadi_lms_fir_step"
        raw_setup = bare_setup.replace(real, "casadi_real") + f"""
  static casadi_int iw[{raw}_SZ_IW + 1];
  static casadi_real w[{raw}_SZ_W + 1];
  const casadi_real* arg[{raw}_SZ_ARG + 1];
  casadi_real* res[{raw}_SZ_RES + 1];"""
        raw_ns = c_loop_ns(sources, folder / "include", f"{name}_casadi.h", raw_setup,
                           "arg[0] = C[i & 1], arg[1] = U[i & 1], arg[2] = target, arg[3] = u, arg[4] = mu, "
                           "res[0] = C[(i + 1) & 1], res[1] = U[(i + 1) & 1], res[2] = d, res[3] = e, "
                           f"{raw}(arg, res, iw, w, 0)", "target[0]", 0.1, "e[0]")
    return {"order": ORDER, "mu": MU, "samples": SAMPLES, "c_ns_per_step": raw_ns, "c_checked_ns_per_step": bare_ns,
            "c_monitor_ns_per_step": monitor_ns, "padasip_ns_per_sample": padasip_ns,
            "speedup_vs_padasip": padasip_ns / raw_ns, "checked_speedup_vs_padasip": padasip_ns / bare_ns,
            "monitor_speedup_vs_padasip": padasip_ns / monitor_ns,
            "max_weight_difference": float(np.abs(S[-1, :ORDER] - padasip_weights).max())}


if __name__ == "__main__":
    if find_compiler() is None:
        sys.exit("no C compiler: nothing to measure")
    finish(main(), {"speedup_vs_padasip_min": 40.0, "max_weight_difference_max": 1e-9}, RESULTS)
