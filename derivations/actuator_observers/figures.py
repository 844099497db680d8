"""The paper's Figs. 4-8 of the docking runs (path into the dock, actuation, fault estimates) and the
fault campaign's confusion matrix and delays."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from derivations.actuator_observers.dock import arrival, dock_miss
from derivations.actuator_observers.paper import DOCK_RADIUS_M
from uvsym.observers.supervisor import FaultDiagnosis
from uvsym.report import save_svg
from uvsym.report.style import confusion_matrix, delay_histograms
from uvsym.sim.scenario import Scenario

__all__ = ["actuation_figure", "campaign_confusion_figure", "campaign_delay_figure", "estimates_figure",
           "path_figure"]


def path_figure(scenario: Scenario, result, title: str, path: Path) -> None:
    """Planned path, the vehicle's track until 2 s past the dock, and the dock's entrance (Figs. 4, 7)."""
    points = np.asarray(scenario.controller.path.waypoints)
    fig, ax = plt.subplots(figsize=(7, 5.5))
    segments = scenario.controller.path.segments()
    for seg in segments:
        if seg["kind"] == "line":
            start = np.asarray(seg["start"])
            end = start + seg["length"] * np.array([np.cos(seg["angle"]), np.sin(seg["angle"])])
            ax.plot([start[1], end[1]], [start[0], end[0]], "k--", lw=1)
        else:
            phi = seg["phi0"] + seg["sign"] * np.linspace(0, seg["length"] / seg["radius"], 50)
            c = seg["center"]
            ax.plot(c[1] + seg["radius"] * np.sin(phi), c[0] + seg["radius"] * np.cos(phi), "k--", lw=1)
    ax.plot([], [], "k--", lw=1, label="planned path")
    end = min(len(result.t), arrival(result, scenario)[0] + 200)  # until 2 s past the dock
    ax.plot(result["x"]["y"][:end], result["x"]["x"][:end], "C0", lw=1.5, label="vehicle")
    dock = points[-1]
    ax.plot([dock[1], dock[1]], [dock[0] - DOCK_RADIUS_M, dock[0] + DOCK_RADIUS_M], "C3", lw=4,
            label=f"dock entrance ({2 * DOCK_RADIUS_M:g} m)")
    ax.text(dock[1], dock[0] + 3, f"miss {dock_miss(result, scenario):.2f} m", ha="center", fontsize=8)
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.legend()
    save_svg(fig, path)


def actuation_figure(result, title: str, path: Path, t_max: float = 30.0) -> None:
    """Desired and delivered thrust and upper rudder over the first ``t_max`` seconds (Figs. 5, 8)."""
    keep = result.t <= t_max
    fig, axes = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    for ax, label, scale, unit in ((axes[0], "X", 1.0, "N"), (axes[1], "delta_ru", 180 / np.pi, "deg")):
        ax.plot(result.t[keep], scale * result["u_desired"][label][keep], "k--", lw=1, label="desired (controller)")
        ax.plot(result.t[keep], scale * result["u_actual"][label][keep], "C0", lw=1.2, label="actual (delivered)")
        ax.set_ylabel(f"{'thrust X' if label == 'X' else 'upper rudder'} ({unit})")
        ax.legend()
    axes[-1].set_xlabel("t (s)")
    axes[0].set_title(title)
    save_svg(fig, path)


def estimates_figure(result, diagnosis: FaultDiagnosis, path: Path, t_max: float = 10.0) -> None:
    """Fault estimates, predicted faults and isolation times of thruster and rudder (Fig. 6)."""
    iso = diagnosis.isolator.result
    keep, keep_iso = result.t <= t_max, iso.t <= t_max
    fig, axes = plt.subplots(2, 2, figsize=(11, 6), sharex=True)
    panels = (("X", "proportional", "thruster: proportional factor (-)"), ("X", "bias", "thruster: bias (N)"),
              ("N", "proportional", "rudder: proportional factor (-)"), ("N", "bias", "rudder: bias (N m)"))
    for ax, (channel, kind, title) in zip(axes.ravel(), panels):
        i = iso.labels.index(channel)
        ax.plot(result.t[keep], result[f"f_hat/{kind}"][channel][keep], "C0", lw=1.2, label="estimate f_hat")
        ax.plot(iso.t[keep_iso], iso.f_bar[kind][keep_iso, i], "C1--", lw=1, label="predicted f_bar")
        decision = iso.decisions.get(channel)
        if decision is not None and decision.kind == kind:
            ax.axvline(decision.time_s, color="C3", lw=0.8, label=f"isolated ({decision.time_s:.2f} s)")
        finite = result[f"f_hat/{kind}"][channel][keep]
        low, high = np.nanpercentile(finite, [2, 98])
        ax.set_ylim(low - 0.2 * (high - low + 1e-3), high + 0.2 * (high - low + 1e-3))
        ax.set_title(f"{title} [{channel} channel]")
        ax.set_ylabel(title.split(": ")[1])
        ax.legend()
    for ax in axes[-1]:
        ax.set_xlabel("t (s)")
    save_svg(fig, path)


def campaign_confusion_figure(confusion, path: Path) -> None:
    """Counted runs: true (kind, actuator) against the decision standing at the end of the run."""
    truths = sorted({t for t, _ in confusion})
    decisions = sorted({d for _, d in confusion} | set(truths))
    grid = np.zeros((len(truths), len(decisions)))
    for (t, d), n in confusion.items():
        grid[truths.index(t), decisions.index(d)] = n
    fig, ax = plt.subplots(figsize=(2.8 + 0.45 * len(decisions), 2.0 + 0.3 * len(truths)))
    confusion_matrix(ax, grid, truths, decisions, "true (injected fault)", "decided (standing at the end of the run)")
    ax.set_title("Campaign: identifiable, excited runs")
    save_svg(fig, path)


def campaign_delay_figure(counted: list[dict], path: Path, target_s: float = 5.0) -> None:
    """Detection and isolation delays (s after the onset) of the counted runs, side by side, and the
    median target."""
    fig, ax = plt.subplots(figsize=(7, 3.4))
    delay_histograms(ax, {what: [r[key] for r in counted] for key, what in
                          (("detection_delay_s", "detection"), ("isolation_delay_s", "isolation"))},
                     bin_width=0.25, unit="s", what="delay after the onset")
    ax.axvline(target_s, color="k", ls=":", lw=1, label=f"median target {target_s:g} s")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    save_svg(fig, path)
