"""The study's figures: the paper's Fig. 3 (eps^2 and R), Figs. 4a/4b (heading), ROC and delays."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from derivations.sensor_fdi_lms.design import EPS0_DEG2, FAULT_SAMPLE, R0, SET_POINT_DEG
from uvsym.report import save_svg

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
        ax.legend(fontsize=8, loc="upper left")
    top.set_title(f"Compass fault of +{outcome.spec.size_deg:g} deg at sample {FAULT_SAMPLE}: both criteria",
                  fontsize=9)
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
    ax.legend(fontsize=7, loc="lower left")
    ax.set_title(title, fontsize=9)
    save_svg(fig, path)


def roc_figure(roc: dict, path: Path) -> None:
    """Detection probability against false-alarm rate of the three detectors over their thresholds."""
    fig, ax = plt.subplots(figsize=(5, 4.5))
    for (name, curve), style in zip(roc.items(), ("C0o-", "C3s-", "C2^-")):
        ax.plot(curve["false_alarm_rate"], curve["detection_probability"], style, ms=3, lw=1, label=name)
    ax.plot([0, 1], [0, 1], color="grey", lw=0.6, ls=":")
    ax.set_xlabel("false-alarm rate (one-sample disturbance runs)")
    ax.set_ylabel("detection probability (10 deg fault runs)")
    ax.set_xlim(-0.02, 1.02)
    ax.set_ylim(-0.02, 1.02)
    ax.legend(fontsize=8, loc="lower right")
    save_svg(fig, path)


def delay_figure(delays: dict, path: Path) -> None:
    """Histogram of the detection delay (samples after the onset) of each detector at its nominal thresholds."""
    fig, ax = plt.subplots(figsize=(6, 3.5))
    top = max([max(v["delays"], default=0) for v in delays.values()] + [1])
    bins = np.arange(-0.5, top + 1.5)
    for (name, value), colour in zip(delays.items(), ("C0", "C3", "C2")):
        ax.hist(value["delays"], bins=bins, histtype="step", color=colour, lw=1.4, label=name)
    ax.set_xlabel("detection delay (samples of 0.2 s after the onset)")
    ax.set_ylabel("runs")
    ax.legend(fontsize=8)
    save_svg(fig, path)
