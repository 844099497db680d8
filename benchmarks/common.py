"""What every benchmark records and prints: the machine and its load, and each target met or missed.

Targets are ``{"name_min": bound}`` or ``{"name_max": bound}`` for a result key ``name``;
:func:`finish` adds ``machine`` (with the load average over 1, 5 and 15 minutes, since these
machines are shared) and ``verdicts`` to the results, writes them to ``path`` and prints one
line per target: ``target met: fast_sim_s_per_wall_s = 21,000 >= 20,000``.
"""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path

import casadi as ca
import numpy as np

__all__ = ["finish", "machine", "verdicts"]


def machine() -> dict:
    """Python, CasADi and numpy versions, processor, CPU count and load average (1, 5, 15 min)."""
    return {"python": platform.python_version(), "casadi": ca.__version__, "numpy": np.__version__,
            "processor": platform.machine(), "cpus": os.cpu_count(), "load_average": list(os.getloadavg())}


def verdicts(results: dict, targets: dict[str, float]) -> dict[str, dict]:
    """Each target ``key_min``/``key_max`` against ``results[key]``: value, bound and whether it is met
    (a missing or ``None`` value is not met)."""
    out = {}
    for target, bound in targets.items():
        key, _, side = target.rpartition("_")
        if side not in ("min", "max") or not key:
            raise ValueError(f"target {target!r} must end in _min or _max")
        value = results.get(key)
        met = value is not None and (value >= bound if side == "min" else value <= bound)
        out[key] = {"value": value, "bound": bound, "side": side, "met": bool(met)}
    return out


def finish(results: dict, targets: dict[str, float], path: Path) -> dict:
    """Add targets, verdicts and the machine to ``results``, write them as JSON to ``path``, print the verdicts."""
    results = {**results, "targets": targets, "verdicts": verdicts(results, targets), "machine": machine()}
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(results, indent=2) + "\n")
    for key, v in results["verdicts"].items():
        relation = ">=" if v["side"] == "min" else "<="
        shown = "none" if v["value"] is None else f"{v['value']:,.4g}"
        print(f"target {'met' if v['met'] else 'MISSED'}: {key} = {shown} {relation} {v['bound']:,.4g}")
    print(f"wrote {path} (load average {results['machine']['load_average'][0]:.2f})")
    return results
