"""Exhaustive binary16 check of the TwoSum exactness test in ``interval_arithmetic._rounded_sum``.

Knuth's TwoSum splits the rounding error of ``s = x + y`` into two exact parts,
``a = x - (s - (s - x))`` and ``b = y - (s - x)``, with ``a + b`` the error. ``_rounded_sum`` calls the
sum exact where ``a + b == 0``; the mutant ``a - b`` would call it exact where ``a == b``. The two agree
unless ``a == b != 0``: this benchmark counts such pairs over every pair of finite binary16 numbers
(x >= 0: the sign flip of both is a symmetry), and checks ``_rounded_sum`` itself in binary16 against
exact sums (an exact sum left alone, an inexact one moved one step towards the direction). binary16
has the same round-to-nearest-even addition as binary64 at precision 11 (numpy adds in binary32 and
rounds once more, which is innocuous for a sum since 24 >= 2 * 11 + 2).

    python benchmarks/twosum_parts.py   # about 10 minutes on one core; writes benchmarks/results/twosum_parts.json
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from uvsym.verify.interval_arithmetic import _rounded_sum

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import finish  # noqa: E402

RESULTS = Path(__file__).parent / "results" / "twosum_parts.json"


def main() -> dict:
    started = time.perf_counter()
    values = np.arange(2 ** 16, dtype=np.uint16).view(np.float16)
    ys = values[np.isfinite(values)]
    xs = ys[ys >= 0]
    pairs = inexact = equal_parts = misjudged = 0
    with np.errstate(all="ignore"):
        for x in xs:
            total = x + ys
            finite = np.isfinite(total)
            y_part = total - x
            a, b = x - (total - y_part), ys - y_part
            exact = x.astype(np.float64) + ys.astype(np.float64) == total.astype(np.float64)
            equal_parts += int(np.sum(finite & (a == b) & (a != 0)))
            up, down = _rounded_sum(x, ys, np.inf), _rounded_sum(x, ys, -np.inf)
            right = np.where(exact, (up == total) & (down == total),
                             (up == np.nextafter(total, np.float16(np.inf))) &
                             (down == np.nextafter(total, np.float16(-np.inf))))
            misjudged += int(np.sum(finite & ~right))
            pairs += int(np.sum(finite))
            inexact += int(np.sum(finite & ~exact))
    results = {"pairs": pairs, "inexact_pairs": inexact, "pairs_with_equal_nonzero_parts": equal_parts,
               "misjudged_sums": misjudged, "seconds": time.perf_counter() - started}
    return finish(results, {"pairs_with_equal_nonzero_parts_max": 0, "misjudged_sums_max": 0}, RESULTS)


if __name__ == "__main__":
    main()
