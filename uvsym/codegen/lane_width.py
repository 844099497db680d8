"""How many trajectories one compiled lanes step should hold on this machine: measured once, cached.

A processor with 512-bit vectors (8 doubles) does not always run 8 lanes faster than 4: some execute
512-bit arithmetic at half the rate of 256-bit (one fused port, not two), and a wider step streams twice
the inputs and outputs per step. :func:`measured_lanes` times a calibration loop of the shape of the
vehicle loops (a state of ``N_Z`` entries, ``N_W`` inputs and ``N_OUT`` logged outputs per step, with sin,
cos, exp and atan2, on fresh output rows as a simulation writes them) at 4 and 8 lanes, and keeps 8 only
where it is at least ``WIDER_GAIN`` times faster per trajectory-step. The choice is written to
``lanes.json`` in the compile cache folder (:func:`~uvsym.codegen.cache.cache_dir`), keyed by the compiler
and the processor, so it is measured once per machine; deleting the file measures again.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import statistics
import time
from pathlib import Path

import casadi as ca
import numpy as np

from uvsym.codegen.cache import cache_dir, machine_identity
from uvsym.codegen.compile import compile_lanes, find_compiler, vector_doubles
from uvsym.errors import CodegenError

__all__ = ["CANDIDATES", "WIDER_GAIN", "calibration_step", "lane_timings", "measured_lanes"]

CANDIDATES = (4, 8)  # the lane counts compared on a processor of 8 doubles per vector
WIDER_GAIN = 1.15  # 8 lanes are kept when their time per trajectory-step is at most 1 / 1.15 of 4 lanes'
N_Z, N_W, N_OUT, STEPS, CALLS = 96, 56, 80, 2000, 5
_FILE = "lanes.json"


def calibration_step() -> ca.Function:
    """``step(z (N_Z,), w (N_W,)) -> (z_next (N_Z,), out (N_OUT,))``: a stable, bounded nonlinear map of the
    vehicle loops' size and mix of operations (products, sin, cos, exp, atan2)."""
    z, w = ca.SX.sym("z", N_Z), ca.SX.sym("w", N_W)
    rates = [ca.sin(z[i - 1] + w[i % N_W]) * ca.cos(z[(i + 1) % N_Z]) - 0.5 * z[i] * ca.exp(-z[i] * z[i])
             for i in range(N_Z)]
    z_next = ca.vertcat(*[0.9 * z[i] + 0.05 * rates[i] for i in range(N_Z)])
    out = ca.vertcat(*[ca.atan2(z_next[i % N_Z], 1.0 + w[i % N_W] * w[i % N_W]) for i in range(N_OUT)])
    return ca.Function("lane_calibration", [z, w], [z_next, out])


def lane_timings(candidates=CANDIDATES, steps: int = STEPS, calls: int = CALLS) -> dict[int, float]:
    """lanes -> median ns per trajectory-step of the calibration loop over ``steps`` steps, on fresh output rows
    per call (the candidates taking turns call by call). CodegenError where a width cannot be compiled."""
    step = calibration_step()
    rng = np.random.default_rng(0)
    setups = {}
    for lanes in candidates:
        roll = compile_lanes(step, lanes)
        z0 = rng.uniform(-1.0, 1.0, (N_Z, lanes))
        Ws = [np.ascontiguousarray(rng.uniform(-1.0, 1.0, (steps, N_W))) for _ in range(lanes)]
        setups[lanes] = (roll, z0, Ws)
    times: dict[int, list[float]] = {lanes: [] for lanes in candidates}
    for call in range(calls + 1):
        for lanes, (roll, z0, Ws) in setups.items():
            outs = [np.empty((steps, N_OUT)) for _ in range(lanes)]
            started = time.perf_counter()
            roll.runs(z0, Ws, outs)
            if call:  # the first call of each loads its library and touches its code: not timed
                times[lanes].append(time.perf_counter() - started)
    return {lanes: 1e9 * statistics.median(t) / (steps * lanes) for lanes, t in times.items()}


def _machine_key() -> str:
    """This machine's entry in lanes.json: a hash of :func:`~uvsym.codegen.cache.machine_identity`."""
    return hashlib.sha256("\0".join(machine_identity(find_compiler() or "")).encode()).hexdigest()[:24]


def _read(path: Path) -> dict:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def measured_lanes() -> int:
    """The lanes per compiled step for this machine: ``min(vector_doubles(), 4)`` below 8 doubles per vector;
    with 8, 4 or 8 as measured by :func:`lane_timings` (module docstring), read from the cache file when this
    machine was measured before (once per process and cache folder). 4 where the measurement cannot run (no
    compiler, a width that fails to build)."""
    doubles = vector_doubles()
    return min(doubles, 4) if doubles < 8 else _measured(cache_dir())


@functools.lru_cache(maxsize=None)
def _measured(folder: Path) -> int:
    """measured_lanes on a processor of 8 doubles per vector, with its choice kept in ``folder``."""
    path, key = folder / _FILE, _machine_key()
    known = _read(path).get(key)
    if isinstance(known, dict) and known.get("lanes") in CANDIDATES:
        return int(known["lanes"])
    try:
        timings = lane_timings()
    except CodegenError:
        return 4
    lanes = 8 if timings[8] * WIDER_GAIN <= timings[4] else 4
    entry = {"lanes": lanes, "ns_per_trajectory_step": {str(k): v for k, v in timings.items()},
             "wider_gain_needed": WIDER_GAIN}
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_name(f"{_FILE}.{os.getpid()}.part")
        partial.write_text(json.dumps(_read(path) | {key: entry}, indent=1))
        os.replace(partial, path)
    except OSError:  # an unwritable cache: measured again by the next process
        pass
    return lanes
