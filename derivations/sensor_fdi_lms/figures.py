"""The study's figures: the paper's Fig. 3 (eps^2 and R), Figs. 4a/4b (heading), ROC and delays."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from derivations.sensor_fdi_lms.design import EPS0_DEG2, FAULT_SAMPLE, R0, SET_POINT_DEG
from uvsym.report import save_svg
from uvsym.report.style import delay_histograms, roc_curves

__all__ = ["criteria_figure", "heading_figure", "roc_figure", "delay_figure"]

SHOWN = (0, 160)  # recorded samples shown in the time plots


def _window(outcome) -> np.ndarray:
    k = outcome.k
    return (k >= SHOWN[0]) & (k <= SHOWN[1])


def criteria_figure(outcome, path: Path) -> None:
    """Fig. 3: eps^2 (deg^2, log scale) and R against their thresholds, around the fault."""
    w = _window(outcome)
    k = outcome.k[w]
    eps2 = outcome.monitor("eps2_psi")[w] * (180.0 / math.pi) ** 2
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    top.semilogy(k, eps2, "C0", lw=1, label=r"$\varepsilon^2(k)$")
    top.axhline(EPS0_DEG2, color="grey", ls="--", lw=1, label=r"$\varepsilon_0$")
    top.set_ylabel(r"$\varepsilon^2$ (deg$^2$)")
    bottom.plot(k, outcome.monitor("R_psi")[w], "C3", lw=1, label="R(k)")
    bottom.axhline(R0, color="grey", ls="--", lw=1, label=r"$r_0$")
    bottom.set_ylabel("R (-)")
    bottom.set_xlabel("recorded sample k (0.2 s)")
    for ax in (top, bottom):
        ax.axvline(FAULT_SAMPLE, color="k", lw=0.6, ls=":")
        ax.legend()
    top.set_title(f"Compass fault of +{outcome.spec.size_deg:g} deg at sample {FAULT_SAMPLE}: both criteria",
)
    save_svg(fig, path)


def heading_figure(outcomes: dict, path: Path, title: str, substitute: bool) -> None:
    """Figs. 4a/4b: true (solid) heading per fault; without ``substitute`` the measured one (faint),
    with it the frozen filter's substitute (dashed) of the first run and the paper's +-3 deg band."""
    fig, ax = plt.subplots(figsize=(7, 3.8))
    for (label, outcome), colour in zip(outcomes.items(), ("C3", "C1", "C0")):
        w = _window(outcome)
        k = outcome.k[w]
        if not substitute:
            ax.plot(k, np.degrees(outcome.result["y"]["psi"][w]), colour, lw=0.6, alpha=0.35)
        ax.plot(k, outcome.heading_deg()[w], colour, lw=1.3, label=f"{label}: true heading")
    if substitute:
        outcome = next(iter(outcomes.values()))
        w = _window(outcome)
        ax.plot(outcome.k[w], np.degrees(outcome.monitor("psi_sub")[w]), "k--", lw=1, label="FIR substitute (first)")
        ax.axhspan(SET_POINT_DEG - 3.0, SET_POINT_DEG + 3.0, color="grey", alpha=0.12, lw=0, label="+-3 deg")
    ax.axhline(SET_POINT_DEG, color="grey", lw=0.6)
    ax.axvline(FAULT_SAMPLE, color="k", lw=0.6, ls=":")
    ax.set_xlabel("recorded sample k (0.2 s)")
    ax.set_ylabel("heading (deg)")
    ax.legend()
    ax.set_title(title)
    save_svg(fig, path)


def roc_figure(roc: dict, path: Path) -> None:
    """Detection probability against false-alarm rate of the three detectors over their thresholds."""
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    roc_curves(ax, {name: (curve["false_alarm_rate"], curve["detection_probability"]) for name, curve in roc.items()})
    ax.set_xlabel("false-alarm rate (fraction of one-sample disturbance runs)")
    ax.set_ylabel("detection probability (fraction of 10 deg fault runs)")
    ax.set_title("ROC of the three detectors over their thresholds")
    save_svg(fig, path)


def delay_figure(delays: dict, path: Path) -> None:
    """Runs per detection delay (samples after the onset) of each detector at its nominal thresholds,
    the detectors' bars side by side."""
    fig, ax = plt.subplots(figsize=(7, 3.5))
    delay_histograms(ax, {name: value["delays"] for name, value in delays.items()}, bin_width=1.0,
                     unit="samples of 0.2 s")
    ax.set_title("Detection delay at the nominal thresholds")
    save_svg(fig, path)
