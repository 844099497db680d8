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

Times are medians of repeated batches within this one run (the machine may be shared).
"""

from __future__ import annotations

import sys
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


def median_us(call, repeat: int = 7, number: int = 200) -> float:
    """Median microseconds per call (:func:`rhs.median_time`)."""
    return median_time(call, repeat, number) * 1e6


def pypolycontain_us(center: np.ndarray, G: np.ndarray) -> dict | None:
    """pypolycontain's boxing and PCA reductions of the same zonotope, or None when it is not installed."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import pypolycontain as pp
    except ImportError:
        return None
    z = pp.zonotope(x=center.reshape(-1, 1), G=G)
    reduced = pp.operations.boxing_order_reduction(z, GENERATORS_OUT / DIMENSION)
    if reduced.G.shape[1] != GENERATORS_OUT:
        raise RuntimeError(f"pypolycontain kept {reduced.G.shape[1]} generators, not {GENERATORS_OUT}")
    order = GENERATORS_OUT / DIMENSION
    return {"boxing": median_us(lambda: pp.operations.boxing_order_reduction(z, order)),
            "pca": median_us(lambda: pp.operations.pca_order_reduction(z, order))}


def main() -> dict:
    rng = np.random.default_rng(0)
    center, G = rng.normal(size=DIMENSION), rng.normal(size=(DIMENSION, GENERATORS_IN))
    Z = Zonotope(center, G)
    reduce(Z, GENERATORS_OUT)  # builds the compiled kernel once
    # as the README calls it, then with the map
    reduce_us = {method: median_us(lambda m=method: reduce(Z, GENERATORS_OUT, m)) for method in METHODS}
    reduce_us |= {f"{method}_with_map": median_us(lambda m=method: reduce(Z, GENERATORS_OUT, m, coefficients=True))
                  for method in METHODS}
    theirs = pypolycontain_us(center, G)
    baseline = None if theirs is None else theirs["boxing"]
    reduce_us |= {f"pypolycontain_{k}": v for k, v in (theirs or {}).items()}
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
