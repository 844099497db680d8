"""The estimators as a user calls them: ``Observer.run`` on recorded data, against padasip and filterpy.

Run ``python benchmarks/observer_run.py`` (the ``bench`` extra's padasip and filterpy); writes
``benchmarks/results/observer_run.json``. Every figure is the median of ``REPEATS`` single calls, each
on fresh outputs, the contenders taking turns call by call (the machine is shared; the load is
recorded):

- the LMS-FIR compass monitor (order 70, :mod:`benchmarks.lms`'s data) through ``Observer.run`` against
  padasip's ``FilterLMS.run`` on the same data and step (it computes the LMS filter alone; the monitor
  also runs both criteria), with every state kept (``run_s``: 235 numbers a sample, against padasip's
  70), with the weights' history only (``states=`` the weights ``C_1 .. C_70``, ``run_weights_s``: the
  outputs, prediction error among them, and the weights, what padasip's ``run`` returns) and with the final
  state only (``states="final"``, ``run_final_s``: the outputs);
- the left-thruster UKF of the Otter (7 states, :mod:`benchmarks.ukf`'s data: the shipped scenario's run)
  through ``Observer.run`` against filterpy's ``UnscentedKalmanFilter`` update-then-predict loop;
- linearity: each ``Observer.run`` at N / 10 and N samples, the ratio of the two times over 10, on
  each of its paths (``compiled=True``: the C loop, the default from ``COMPILE_FROM`` samples on;
  ``compiled=False``: CasADi's virtual machine in fixed chunks).

The kernels (one generated C step called in a C loop) are the second figure, in ``lms.json`` and
``ukf.json``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import finish  # noqa: E402
from lms import MU, ORDER, data  # noqa: E402
from ukf import filterpy_filters, numpy_model, shipped_filters  # noqa: E402

from derivations.usv_fukf_mmae.experiment import run  # noqa: E402
from derivations.usv_fukf_mmae.scenario import block_table, parsed, read  # noqa: E402
from uvsym.observers.kalman import filter_observer  # noqa: E402
from uvsym.observers.lms import lms_monitor  # noqa: E402
from uvsym.systems.signals import signals  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "observer_run.json"
REPEATS = 5
TARGETS = {"lms_run_speedup_vs_padasip_min": 10.0, "lms_run_weights_speedup_vs_padasip_min": 10.0,
           "lms_run_final_speedup_vs_padasip_min": 10.0,
           "ukf_run_speedup_vs_filterpy_min": 100.0,
           "lms_run_linearity_max": 1.3, "ukf_run_linearity_max": 1.3, "lms_vm_linearity_max": 1.3,
           "ukf_vm_linearity_max": 1.3}


def _median_s(calls: dict) -> dict:
    """name -> median seconds of REPEATS single calls of each callable, taking turns."""
    times = {name: [] for name in calls}
    for _ in range(REPEATS):
        for name, call in calls.items():
            started = time.perf_counter()
            call()
            times[name].append(time.perf_counter() - started)
    return {name: float(np.median(values)) for name, values in times.items()}


def _paths(estimator, Y, U) -> dict:
    """The calls of the linearity figures: each path at all samples and at a tenth of them."""
    tenth = len(Y) // 10
    return {f"{path}{part}": (lambda n=n, c=c: estimator.run(Y[:n], U[:n], compiled=c))
            for path, c in (("c", True), ("vm", False)) for part, n in (("", len(Y)), ("_tenth", tenth))}


def _linearity(seconds: dict) -> dict:
    return {"c_s": seconds["c"], "vm_s": seconds["vm"], "linearity": seconds["c"] / (10 * seconds["c_tenth"]),
            "vm_linearity": seconds["vm"] / (10 * seconds["vm_tenth"])}


def lms_figures() -> dict:
    import padasip

    u, X, y = data()
    monitor = lms_monitor(signals(("y", "-", "")), signals(("u", "-", "")), order=ORDER, mu=MU, eps0=1e300, r0=1e300,
                          dt=0.2)
    Y, U, N = y[:, None], u[:, None], len(y)
    monitor.run(Y, U, compiled=True), monitor.run(Y[:100], U[:100], compiled=False)  # compiled, mapped once

    def padasip_run():
        padasip.filters.FilterLMS(n=ORDER, mu=2 * MU, w="zeros").run(y, X)

    weights = [f"C_{i}" for i in range(1, ORDER + 1)]
    monitor.run(Y, U, states=weights)  # compiled once
    seconds = _median_s({"run": lambda: monitor.run(Y, U), "run_weights": lambda: monitor.run(Y, U, states=weights),
                         "run_final": lambda: monitor.run(Y, U, states="final"), "padasip": padasip_run,
                         **_paths(monitor, Y, U)})
    return {"samples": N, "run_s": seconds["run"], "run_weights_s": seconds["run_weights"],
            "run_final_s": seconds["run_final"], "padasip_s": seconds["padasip"],
            "speedup_vs_padasip": seconds["padasip"] / seconds["run"],
            "weights_speedup_vs_padasip": seconds["padasip"] / seconds["run_weights"],
            "final_speedup_vs_padasip": seconds["padasip"] / seconds["run_final"], **_linearity(seconds)}


def ukf_figures() -> dict:
    table = read()
    tuning, dt = block_table(table, "ukf"), table["step"]
    result = run(parsed(table))
    Y, U = result["y"].values, result["guidance"].values[:, :2]
    N = (len(Y) // 10) * 10
    Y, U = Y[:N], U[:N]
    left = filter_observer(shipped_filters(tuning, dt)["left"], "left-thruster UKF")
    left.run(Y, U, compiled=True), left.run(Y[:100], U[:100], compiled=False)
    fx = numpy_model()
    tenth = N // 10

    def filterpy_run():  # on a tenth of the samples: filterpy is slow; its time per sample is what is compared
        ukf, which = filterpy_filters(tuning, dt, fx)["left"]
        for y, u in zip(Y[:tenth], U[:tenth]):
            ukf.update(y)
            ukf.predict(u=u, which=which)

    seconds = _median_s({"run": lambda: left.run(Y, U), "filterpy_tenth": filterpy_run, **_paths(left, Y, U)})
    return {"samples": N, "run_s": seconds["run"], "filterpy_s_per_sample": seconds["filterpy_tenth"] / tenth,
            "run_s_per_sample": seconds["run"] / N,
            "speedup_vs_filterpy": (seconds["filterpy_tenth"] / tenth) / (seconds["run"] / N), **_linearity(seconds)}


def main() -> dict:
    lms, ukf = lms_figures(), ukf_figures()
    print(f"LMS monitor Observer.run: {lms['run_s'] * 1e3:.1f} ms for {lms['samples']} samples, padasip "
          f"{lms['padasip_s'] * 1e3:.1f} ms: x{lms['speedup_vs_padasip']:.1f} (the weights' history "
          f"x{lms['weights_speedup_vs_padasip']:.1f}, final state only x{lms['final_speedup_vs_padasip']:.1f}); "
          f"linearity {lms['linearity']:.2f}")
    print(f"UKF Observer.run: {ukf['run_s_per_sample'] * 1e6:.1f} us per sample, filterpy "
          f"{ukf['filterpy_s_per_sample'] * 1e6:.1f} us: x{ukf['speedup_vs_filterpy']:.1f}; "
          f"linearity {ukf['linearity']:.2f}")
    return {"lms": lms, "ukf": ukf, "lms_run_speedup_vs_padasip": lms["speedup_vs_padasip"],
            "lms_run_weights_speedup_vs_padasip": lms["weights_speedup_vs_padasip"],
            "lms_run_final_speedup_vs_padasip": lms["final_speedup_vs_padasip"],
            "ukf_run_speedup_vs_filterpy": ukf["speedup_vs_filterpy"], "lms_run_linearity": lms["linearity"],
            "ukf_run_linearity": ukf["linearity"], "lms_vm_linearity": lms["vm_linearity"],
            "ukf_vm_linearity": ukf["vm_linearity"]}


if __name__ == "__main__":
    finish(main(), TARGETS, RESULTS)
