"""The figures of merit of a run: detection delays, efficiency estimates, no-fault probability
outside the fault windows, estimation errors; the paper's targets beside them."""

from __future__ import annotations

import numpy as np

from derivations.usv_fukf_mmae.scenario import ThrusterFault
from uvsym.sim.result import SimResult

__all__ = ["THRESHOLD", "DETECT_WITHIN", "SETTLE", "LAST", "EFFICIENCY_TOLERANCE", "SIDE", "BANKS",
           "figures_of_merit"]

THRESHOLD = 0.9  # probability a model must exceed
DETECT_WITHIN = 5.0  # s after onset (the reproduction notes' T_d; the paper gives none)
SETTLE = 5.0  # s after the start and after each window's end before p_nofault is judged
LAST = 25.0  # s: the efficiency estimate is the mean over the last 25 s of its window
EFFICIENCY_TOLERANCE = 0.05
SIDE = {"T_L": "left", "T_R": "right"}
BANKS = ("ukf", "ekf")  # the banks' block names in the shipped scenario


def _detect_delay(t: np.ndarray, p: np.ndarray, onset: float, end: float) -> float | None:
    """Seconds from onset to the first sample in [onset, end) with p > THRESHOLD, or None."""
    window = np.flatnonzero((t >= onset - 1e-9) & (t < end - 1e-9) & (p > THRESHOLD))
    return None if window.size == 0 else float(t[window[0]] - onset)


def _outside(t: np.ndarray, faults: tuple[ThrusterFault, ...]) -> np.ndarray:
    """Samples judged healthy: SETTLE s after the start and after each window, outside every window."""
    keep = t >= SETTLE
    for f in faults:
        keep &= ~((t >= f.onset - 1e-9) & (t < f.end + SETTLE - 1e-9))
    return keep


def bank_figures(t: np.ndarray, bank, faults: tuple[ThrusterFault, ...]) -> dict:
    """Per bank: p_nofault minimum outside the windows, and per fault its delay and estimate."""
    outside = _outside(t, faults)
    figures = {"p_nofault_min_outside_windows": float(np.min(bank["p_nofault"][outside])), "faults": []}
    for f in faults:
        side = SIDE[f.thruster]
        last = (t >= max(f.onset, f.end - LAST) - 1e-9) & (t < f.end - 1e-9)  # a short window: all of it
        estimate = float(np.mean(bank[f"{side}.alpha_{f.thruster}_hat"][last]))
        figures["faults"].append({"thruster": f.thruster, "model": side, "onset_s": f.onset, "end_s": f.end,
                                  "efficiency": f.efficiency,
                                  "detect_delay_s": _detect_delay(t, bank[f"p_{side}"], f.onset, f.end),
                                  "efficiency_estimate": estimate, "efficiency_error": abs(estimate - f.efficiency)})
    return figures


def _rms(result: SimResult, bank: str, window: np.ndarray) -> dict:
    """RMS of the fused estimate's error per state over ``window``."""
    x = result["x"]
    return {s: float(np.sqrt(np.mean((result[bank][f"{s}_hat"][window] - x[s][window]) ** 2))) for s in x.labels}


def figures_of_merit(result: SimResult, faults: tuple[ThrusterFault, ...]) -> dict:
    """results.json's figures: the UKF bank's without prefix, the EKF bank's with ``ekf_``;
    ``left_*`` and ``right_*`` from the first fault of each thruster."""
    t = result.t
    per_bank = {m: bank_figures(t, result[m], faults) for m in BANKS}
    flat = {}
    for method, prefix in (("ukf", ""), ("ekf", "ekf_")):
        figures = per_bank[method]
        flat[f"{prefix}p_nofault_min_outside_windows"] = figures["p_nofault_min_outside_windows"]
        for fault in reversed(figures["faults"]):  # the first fault of a thruster wins
            flat[f"{prefix}{fault['model']}_detect_delay_s"] = fault["detect_delay_s"]
            flat[f"{prefix}{fault['model']}_efficiency_estimate"] = fault["efficiency_estimate"]
    healthy = _outside(t, faults)
    return {**dict(sorted(flat.items())), "banks": per_bank,
            "rms_error_outside_windows": {m: _rms(result, m, healthy) for m in BANKS}}
