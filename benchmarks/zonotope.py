"""Zonotope order reduction and the UIO bank's set propagation: uvsym against pypolycontain.

Run ``python benchmarks/zonotope.py`` (needs the ``bench`` extra for the pypolycontain baseline);
writes ``benchmarks/results/zonotope.json``:

- ``reduce_us``: microseconds per reduction of a random 6 x 200 zonotope to 30 generators, per
  method (girard, combastel: compiled box kernel; pca: numpy), called as the README does
  (``reduce(Z, 30, method)``: no coefficient map) and with the map R (``coefficients=True``), and
  pypolycontain's ``boxing_order_reduction`` and ``pca_order_reduction`` (Kopetzki et
  al. 2017, order 5 = 30 generators) on the same zonotope in the same run;
  ``speedup_vs_pypolycontain`` = pypolycontain's boxing time over uvsym's Girard time (both
  returning the reduced zonotope only; target >= 5);
- ``step_us``: microseconds per sample of the quadrotor UIO bank's band propagation (four
  observers, joint (e, v) zonotopes of dimension 16 bounded to 64 generators), from the
  derivation's own design; ``step_with_maps_us`` the same keeping the reductions' coefficient
  maps (what the Monte Carlo enclosure check needs).

The reductions are timed as the median of ``TURNS * BLOCK`` single calls per contender, the
contenders taking turns in blocks of ``BLOCK`` calls (the machine's speed drifts by tens of percent
within a second here; taking turns exposes each contender to the same drift, and the median leaves
out the first calls of a block, cold after another contender's). The band step is the median of three whole runs.
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import finish  # noqa: E402
from rhs import median_time  # noqa: E402

from derivations.uio_zonotope.design import ERROR_BOUND, GENERATORS, REDUCTION, design  # noqa: E402
from uvsym.observers.uio_bank import residual_bands  # noqa: E402
from uvsym.sets import METHODS, Zonotope, reduce  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "zonotope.json"
TARGETS = {"speedup_vs_pypolycontain_min": 5}
DIMENSION, GENERATORS_IN, GENERATORS_OUT = 6, 200, 30
BAND_SAMPLES = 300
TURNS, BLOCK = 100, 100


def median_us(call, repeat: int = 7, number: int = 200) -> float:
    """Median microseconds per call (:func:`rhs.median_time`)."""
    return median_time(call, repeat, number) * 1e6


def turns_us(calls: dict) -> dict:
    """name -> median microseconds of ``TURNS * BLOCK`` single calls of each callable, the callables taking
    turns in blocks of ``BLOCK`` calls (each single call timed)."""
    clock, names = time.perf_counter, list(calls)
    times = np.empty((len(names), TURNS, BLOCK))
    for turn in range(TURNS):
        for k, name in enumerate(names):
            call, row = calls[name], times[k, turn]
            for i in range(BLOCK):
                started = clock()
                call()
                row[i] = clock() - started
    return {name: float(np.median(times[k]) * 1e6) for k, name in enumerate(names)}


def pypolycontain_calls(center: np.ndarray, G: np.ndarray) -> dict:
    """pypolycontain's boxing and PCA reductions of the same zonotope as calls, or {} when it is not installed."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import pypolycontain as pp
    except ImportError:
        return {}
    z = pp.zonotope(x=center.reshape(-1, 1), G=G)
    order = GENERATORS_OUT / DIMENSION
    reduced = pp.operations.boxing_order_reduction(z, order)
    if reduced.G.shape[1] != GENERATORS_OUT:
        raise RuntimeError(f"pypolycontain kept {reduced.G.shape[1]} generators, not {GENERATORS_OUT}")
    return {"pypolycontain_boxing": lambda: pp.operations.boxing_order_reduction(z, order),
            "pypolycontain_pca": lambda: pp.operations.pca_order_reduction(z, order)}


def main() -> dict:
    rng = np.random.default_rng(0)
    center, G = rng.normal(size=DIMENSION), rng.normal(size=(DIMENSION, GENERATORS_IN))
    Z = Zonotope(center, G)
    reduce(Z, GENERATORS_OUT)  # builds the compiled kernel once
    calls = {method: (lambda m=method: reduce(Z, GENERATORS_OUT, m)) for method in METHODS}  # as the README calls it
    calls |= {f"{method}_with_map": (lambda m=method: reduce(Z, GENERATORS_OUT, m, coefficients=True))
              for method in METHODS}
    reduce_us = turns_us(calls | pypolycontain_calls(center, G))
    baseline = reduce_us.get("pypolycontain_boxing")
    d = design()
    n = d.plant.x.size

    def bank_bands(track: bool):
        for item in d.bank.designs:
            residual_bands(item, d.noise_bound, np.full(n, ERROR_BOUND), BAND_SAMPLES, GENERATORS, REDUCTION,
                           track=track)

    step_us = median_us(lambda: bank_bands(False), repeat=3, number=1) / BAND_SAMPLES
    step_tracked_us = median_us(lambda: bank_bands(True), repeat=3, number=1) / BAND_SAMPLES
    speedup = None if baseline is None else baseline / reduce_us["girard"]
    results = {"reduce_us": reduce_us, "reduce_task": f"{DIMENSION} x {GENERATORS_IN} -> {DIMENSION} x "
                                                      f"{GENERATORS_OUT} generators",
               "speedup_vs_pypolycontain": speedup, "step_us": step_us, "step_with_maps_us": step_tracked_us,
               "step_task": f"{len(d.bank.designs)} observers, joint zonotopes of dimension {2 * n} bounded to "
                            f"{GENERATORS} generators ({REDUCTION}), per sample"}
    return finish(results, TARGETS, RESULTS)


if __name__ == "__main__":
    main()
