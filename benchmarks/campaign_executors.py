"""Overhead of the Dask executor: the same small campaign on local processes and on a LocalCluster.

Run ``python benchmarks/campaign_executors.py``; writes ``benchmarks/results/campaign_executors.json``.
16 docking runs of 10 s (``docking_faults`` with its thruster bias at four sizes, in four currents;
the loop compiled per run, as ``uvsym campaign`` does by default), chunks of 2 runs, on the local
executor (2 processes) and on a ``dask.distributed.LocalCluster`` of 2 single-threaded worker
processes started before the clock (a cluster is a standing service that ``--scheduler`` joins).
Each executor first runs a one-run campaign that is not timed (workers import uvsym once), then
the timed one three times, interleaved with the other's, each into a fresh folder; the best of
each counts. Target: ``dask_local_overhead`` = wall Dask / wall local <= 1.2.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import finish  # noqa: E402

from uvsym.campaign import parse_campaign, run_campaign  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "campaign_executors.json"
TARGETS = {"dask_local_overhead_max": 1.2}
WORKERS = 2
REPEATS = 3


def _campaign(currents: list[float], sizes: list[float]):
    return parse_campaign({"name": "executors", "executor": {"chunk_size": 2}, "case": [{
        "name": "docking", "scenario": "docking_faults", "set": {"duration": 10.0},
        "grid": {"current.speed": currents, "faults[0].value": sizes}}]})


def _wall(campaign, folder: Path, **executor) -> tuple[float, float]:
    """Wall time of the campaign (s) and the mean of its runs' own wall times (s)."""
    started = time.perf_counter()
    table = run_campaign(campaign, folder, workers=WORKERS, **executor)
    wall = time.perf_counter() - started
    statuses = set(table.column("status").to_pylist())
    if statuses != {"ok"}:
        raise RuntimeError(f"a benchmark run failed: {table.filter(table['status'] != 'ok')['error'].to_pylist()}")
    runs = table.column("wall_s").to_pylist()
    return wall, sum(runs) / len(runs)


def dask_overhead() -> dict:
    """dask_local_overhead (best wall on the LocalCluster / best wall on local processes), both walls
    (s) and every repeat's, the mean wall time of a run on each (s) and the campaign's size; the
    LocalCluster's start-up is not timed."""
    from distributed import LocalCluster

    warm, timed = _campaign([0.0], [5.0]), _campaign([0.0, 0.05, 0.1, 0.15], [5.0, 10.0, 15.0, 20.0])
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        with LocalCluster(n_workers=WORKERS, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
            dask = {"scheduler": cluster.scheduler_address}
            _wall(warm, root / "local-warm")
            _wall(warm, root / "dask-warm", **dask)
            local, remote = [], []
            for repeat in range(REPEATS):  # interleaved, so that a burst of load on the shared machine hits both
                local.append(_wall(timed, root / f"local-{repeat}"))
                remote.append(_wall(timed, root / f"dask-{repeat}", **dask))
    (wall_local, run_local), (wall_dask, run_dask) = min(local), min(remote)
    return {"dask_local_overhead": wall_dask / wall_local, "wall_local_s": wall_local, "wall_dask_s": wall_dask,
            "run_wall_mean_local_s": run_local, "run_wall_mean_dask_s": run_dask, "runs": len(timed.runs),
            "run_duration_s": 10.0, "workers": WORKERS, "chunk_size": 2, "repeats": REPEATS,
            "walls_local_s": [w for w, _ in local], "walls_dask_s": [w for w, _ in remote]}


if __name__ == "__main__":
    results = dask_overhead()
    print(f"16 runs: local {results['wall_local_s']:.2f} s, Dask LocalCluster {results['wall_dask_s']:.2f} s")
    finish(results, TARGETS, RESULTS)
