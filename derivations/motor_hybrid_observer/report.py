"""``report.md``, ``results.json`` and the figures (the paper's Figs. 1-6 and one more) of the study."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from derivations.motor_hybrid_observer.analysis import corrected_model, estimate, estimator_model, step_limit
from derivations.motor_hybrid_observer.campaign import campaign_results, torque_balance_healthy
from derivations.motor_hybrid_observer.claims import hybrid_claims
from derivations.motor_hybrid_observer.design import design
from derivations.motor_hybrid_observer.experiment import CASES, DURATION, run_cases
from derivations.motor_hybrid_observer.identifiability import indistinguishable_offsets
from derivations.motor_hybrid_observer.observer_sets import motor_hybrid
from derivations.motor_hybrid_observer.text import report_text
from derivations.motor_hybrid_observer.torque_balance import loaded_results
from uvsym.report import save_svg, write_json
from uvsym.report.sections import c_package, claim_rows

__all__ = ["build"]

PAPER_ESTIMATES = {"case a (incipient)": 0.996, "case b (step)": 0.997}  # rad/s, the paper's Figs. 5-6 (L296)
FINAL_WINDOW = 1.0  # s: final estimates are means over the run's last second (the estimate is noisy)
UNKNOWN_START = "fault-free, observers start at the operating point"
STRIDE = 50  # every 50th sample (5 ms) in the figures
ERROR_ZOOM = (-0.01, 0.01)  # rad/s: the estimation-error panels show the settled error, not the onset's jump


def _final(run: dict, key: str) -> float:
    return float(np.mean(run[key][run["t"] >= DURATION - FINAL_WINDOW]))


def _ratio(run: dict) -> float:
    """The hybrid estimator's final estimate over the true fault (means over the last second)."""
    return _final(run, "estimator_f_s_hat") / _final(run, "f_s")


def _analytic_final(model, case: str, t: np.ndarray) -> float:
    window = t[t >= DURATION - FINAL_WINDOW][::100]
    return float(np.mean(estimate(model, case, window)))


def _estimates(runs: dict) -> dict:
    """Simulated and analytic final estimates (rad/s) of the hybrid estimator and the corrected design."""
    hybrid, corrected = estimator_model(), corrected_model()
    out = {}
    kinds = (("case a (incipient)", "incipient"), ("case b (step)", "step"), (UNKNOWN_START, "initial error"))
    for case, kind in kinds:
        r = runs[case]
        true = _final(r, "f_s")
        out[case] = {"true": true, "estimator": _final(r, "estimator_f_s_hat"),
                     "estimator_analytic": _analytic_final(hybrid, kind, r["t"]),
                     "corrected": _final(r, "corrected_f_s_hat"),
                     "corrected_analytic": _analytic_final(corrected, kind, r["t"])}
    return out


def _mean(t: np.ndarray, values: np.ndarray, window: int = 1000) -> tuple[np.ndarray, np.ndarray]:
    """(times, centred means over ``window`` samples (0.1 s)) every STRIDE samples, where the window is
    full: the estimates carry the sensor noise."""
    means = np.convolve(values, np.ones(window) / window, mode="valid")
    return t[window // 2: window // 2 + means.size][::STRIDE], means[::STRIDE]


def _coarse(model, case: str, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(times, analytic estimate) every 20 ms (one matrix exponential per point)."""
    times = t[::20 * STRIDE // 5]
    return times, estimate(model, case, times)


def _figure(path: Path, t, panels: list[tuple], title: str, threshold: float | None = None) -> None:
    """One panel per (curves, ylabel[, y limits]); a curve is (values on t, or (times, values)), style,
    label; the threshold (dashed, +-) goes on the first panel."""
    fig, axes = plt.subplots(len(panels), 1, figsize=(7, 3.2 * len(panels)), sharex=True, squeeze=False)
    for ax, (curves, ylabel, *limits) in zip(axes[:, 0], panels):
        if limits:
            ax.set_ylim(*limits[0])
        for values, style, label in curves:
            times, values = values if isinstance(values, tuple) else (t[::STRIDE], values[::STRIDE])
            ax.plot(times, values, style, lw=1, label=label)
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=7, loc="upper right")
    if threshold is not None:
        for sign in (-1, 1):
            axes[0, 0].axhline(sign * threshold, color="grey", ls="--", lw=1, label="threshold" if sign > 0 else None)
        axes[0, 0].legend(fontsize=7, loc="upper right")
    axes[-1, 0].set_xlabel("time (s)")
    axes[0, 0].set_title(title, fontsize=9)
    save_svg(fig, path)


def _figures(cases: dict, out_dir: Path) -> list[tuple[str, str]]:
    runs, thresholds = cases["runs"], cases["thresholds"]
    free = runs["fault-free"]
    files = []
    for number, (detector, case) in enumerate((("detection", "case a (incipient)"), ("detection", "case b (step)"),
                                               ("baseline", "case a (incipient)"), ("baseline", "case b (step)")), 1):
        r = runs[case]
        who = "hybrid detection observer (eq. 6)" if detector == "detection" else "baseline UIO [11]"
        name = f"fig{number}_{detector}_{case.split()[1]}.svg"
        _figure(out_dir / name, r["t"], [([(free[f"{detector}_r_omega_m"], "0.7", "fault-free"),
                                           (r[f"{detector}_r_omega_m"], "C3", case)], "r_omega_m (rad/s)")],
                f"Fig. {number}: speed residual of the {who}, {case}", thresholds[detector])
        files.append((name, f"Fig. {number}: {who}, {case}"))
    for number, case, kind in ((5, "case a (incipient)", "incipient"), (6, "case b (step)", "step")):
        r = runs[case]
        name = f"fig{number}_estimate_{case.split()[1]}.svg"
        times, analytic = _coarse(estimator_model(), kind, r["t"])
        fault = np.interp(times, r["t"], r["f_s"])
        estimates = [(r["f_s"], "k", "fault f_s"), (r["estimator_f_s_hat"], "C0", "hybrid estimator (eq. 18)"),
                     ((times, analytic), "C0--", "its analytic value"),
                     (r["corrected_f_s_hat"], "C2", "corrected design")]
        errors = [(_mean(r["t"], r["f_s"] - r["estimator_f_s_hat"]), "C0", "hybrid estimator (0.1 s means)"),
                  ((times, fault - analytic), "C0--", "its analytic value"),
                  (_mean(r["t"], r["f_s"] - r["corrected_f_s_hat"]), "C2", "corrected design (0.1 s means)")]
        _figure(out_dir / name, r["t"], [(estimates, "f_s (rad/s)"), (errors, "f_s - f_hat (rad/s)", ERROR_ZOOM)],
                f"Fig. {number}: speed-sensor fault and its estimates, {case}")
        files.append((name, f"Fig. {number}: fault and estimates, {case}"))
    r = runs[UNKNOWN_START]
    _figure(out_dir / "fig7_unknown_start.svg", r["t"], [([(r["estimator_f_s_hat"], "C0", "hybrid estimator"),
                                                           (r["corrected_f_s_hat"], "C2", "corrected design")],
                                                          "f_hat (rad/s)")],
            "Fig. 7 (not in the paper): no fault, observers started at the operating point")
    files.append(("fig7_unknown_start.svg", "Fig. 7 (not in the paper): fault-free, observers start at the operating "
                                            "point"))
    return files


def _results(cases: dict) -> dict:
    d = design()
    detections = cases["detection_time_s"]
    estimates = _estimates(cases["runs"])
    a, b = estimates["case a (incipient)"], estimates["case b (step)"]
    split = d.split
    beta = d.plant.extras["coefficients"]["beta"]
    H_printed = np.array([[1, 0], [0, 1], [-1 / beta, 0], [0, -1 / beta]])
    return {
        "case_a_detected": detections["detection"]["case a (incipient)"] is not None,
        "case_b_detected": detections["detection"]["case b (step)"] is not None,
        "case_a_detection_time_s": detections["detection"]["case a (incipient)"],
        "case_b_detection_time_s": detections["detection"]["case b (step)"],
        "false_alarm_fault_free": detections["detection"]["fault-free"] is not None,
        "baseline_detects_incipient": detections["baseline"]["case a (incipient)"] is not None,
        "baseline_detects_step": detections["baseline"]["case b (step)"] is not None,
        "baseline_detection_time_s": detections["baseline"],
        "thresholds_rad_per_s": cases["thresholds"],
        "case_a_final_estimate": a["estimator"], "case_b_final_estimate": b["estimator"],
        "case_a_final_estimate_ratio": a["estimator"] / a["true"],
        "case_b_final_estimate_ratio": b["estimator"] / b["true"],
        "case_a_final_estimate_ratio_noise_free": _ratio(cases["runs"]["case a (incipient), noise-free"]),
        "case_b_final_estimate_ratio_noise_free": _ratio(cases["runs"]["case b (step), noise-free"]),
        "case_a_final_estimate_analytic": a["estimator_analytic"],
        "case_b_final_estimate_analytic": b["estimator_analytic"],
        "step_estimate_limit_closed_form": step_limit(),
        "case_a_true_fault_final": a["true"], "case_b_true_fault_final": b["true"],
        "corrected_case_a_final_error": a["true"] - a["corrected"],
        "corrected_case_b_final_error": b["true"] - b["corrected"],
        "corrected_case_a_final_error_analytic": a["true"] - a["corrected_analytic"],
        "corrected_case_b_final_error_analytic": b["true"] - b["corrected_analytic"],
        "unknown_start_estimate": estimates[UNKNOWN_START],
        "estimator_fault_free_final": _final(cases["runs"]["fault-free"], "estimator_f_s_hat"),
        "estimator_fault_free_final_other_noise": cases["fault_free_final_estimates"],
        "paper_estimates": PAPER_ESTIMATES,
        "ranks": split.ranks,
        "H_minus_printed_max": float(np.max(np.abs(split.H - H_printed))),
        "Tu_E1_relative": float(np.max(np.abs(split.Tu @ split.E1)) / np.max(np.abs(split.E1))),
        "Tu_A12_relative": float(np.max(np.abs(split.omega["Omega2"])) / np.max(np.abs(d.lin.A[list(split.iz1), 4]))),
        "Omega1_eigenvalues": _pairs(np.linalg.eigvals(split.omega["Omega1"])),
        "subsystem1_undetectable": _pairs(split.undetectable),
        "estimator_error_eigenvalues": _pairs(np.linalg.eigvals(estimator_model().A)),
        "corrected_error_eigenvalues": _pairs(np.linalg.eigvals(corrected_model().A)),
        "corrected_gain": d.corrected.K[0].tolist(),
        "baseline_gain": d.baseline.K[0].tolist(),
        "subsystem1_gain": d.K1.tolist(),
    }


def _pairs(values) -> list[list[float]]:
    return [[float(v.real), float(v.imag)] for v in sorted(values, key=lambda v: (v.real, v.imag))]


def build(out_dir: Path, progress) -> None:
    """Design, verify, simulate and write the report into ``out_dir``."""
    progress("design: decoupling, block LMIs, gains")
    design()
    progress("machine-checked claims")
    claims = hybrid_claims()
    progress(f"closed loops: {len(CASES) + 1} runs and fault-free calibration runs of {DURATION:g} s")
    cases = run_cases()
    progress("figures")
    figures = _figures(cases, out_dir)
    progress("C package of the four observers: write, compile, compare")
    c = c_package(motor_hybrid(), out_dir / "c")
    campaign = campaign_results(progress)
    progress("loaded operating point: equilibria with the rotor resistance raised")
    progress("loaded operating point: the torque-balance estimator's variants")
    results = _results(cases) | {"loaded_identifiability": indistinguishable_offsets(),
                                 "torque_balance": loaded_results() | {
                                     "long_healthy": torque_balance_healthy(progress)}, "c": c,
                                 "claims": claim_rows(claims),
                                 "claim_evidence": [c.counterexample for c in claims], "campaign": campaign}
    write_json(out_dir / "results.json", results)
    (out_dir / "report.md").write_text(report_text(results, figures))
