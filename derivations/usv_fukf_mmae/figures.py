"""Figures equivalent to the paper's Figs. 3-7, UKF and EKF banks side by side."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from derivations.usv_fukf_mmae.scenario import ThrusterFault
from uvsym.report import save_svg
from uvsym.sim.result import SimResult

__all__ = ["FIGURES", "draw_all"]

STRIDE = 4  # every 4th sample (0.2 s at dt = 0.05 s)
BANKS = (("ukf", "UKF bank", "C0"), ("ekf", "EKF bank", "C3"))
FIGURES = {"fig3_thrust.svg": "Fig. 3: thrust commands and delivered thrust",
           "fig4_states.svg": "Fig. 4: path and states, true and estimated",
           "fig5_errors.svg": "Fig. 5: heading and sway-velocity errors of the fused estimate",
           "fig6_efficiency.svg": "Fig. 6: efficiency (fault severity) estimates",
           "fig7_probabilities.svg": "Fig. 7: model probabilities"}


def _windows(ax, faults: tuple[ThrusterFault, ...]) -> None:
    for f in faults:
        ax.axvspan(f.onset, f.end, color="0.9", lw=0)


def _thrust(result: SimResult, faults: tuple[ThrusterFault, ...], path: Path) -> None:
    t = result.t[::STRIDE]
    fig, axes = plt.subplots(2, 1, figsize=(7, 4.5), sharex=True)
    for ax, name in zip(axes, ("T_L", "T_R")):
        _windows(ax, faults)
        ax.plot(t, result["guidance"][name][::STRIDE], "k", lw=0.8, label=f"command {name} (bar)")
        ax.plot(t, result["u"][name][::STRIDE], "C1", lw=0.8, label=f"delivered {name}")
        ax.set_ylabel("thrust (N)")
        ax.legend()
    axes[-1].set_xlabel("time (s)")
    axes[0].set_title("Thrust commands and delivered thrust; fault windows shaded")
    save_svg(fig, path)


def _states(result: SimResult, faults: tuple[ThrusterFault, ...], path: Path, waypoints) -> None:
    fig, axes = plt.subplot_mosaic([["path", "psi"], ["path", "v"]], figsize=(9, 5.5))
    top = axes["path"]
    waypoints = np.asarray(waypoints)
    top.plot(waypoints[:, 1], waypoints[:, 0], "k:", lw=0.8, label="waypoints")
    top.plot(result["x"]["y"][::STRIDE], result["x"]["x"][::STRIDE], "k", lw=1.2, label="true")
    for method, label, colour in BANKS:
        bank = result[method]
        top.plot(bank["y_hat"][::STRIDE], bank["x_hat"][::STRIDE], colour, lw=0.6, ls="--", label=label)
    top.set_xlabel("east (m)")
    top.set_ylabel("north (m)")
    top.set_aspect("equal")
    top.legend()
    t = result.t[::STRIDE]
    for state, unit in (("psi", "rad"), ("v", "m/s")):
        ax = axes[state]
        _windows(ax, faults)
        ax.plot(t, result["x"][state][::STRIDE], "k", lw=1.0, label="true")
        for method, label, colour in BANKS:
            ax.plot(t, result[method][f"{state}_hat"][::STRIDE], colour, lw=0.6, ls="--", label=label)
        ax.set_ylabel(f"{state} ({unit})")
        ax.legend()
    axes["v"].set_xlabel("time (s)")
    save_svg(fig, path)


def _errors(result: SimResult, faults: tuple[ThrusterFault, ...], path: Path) -> None:
    t = result.t[::STRIDE]
    fig, axes = plt.subplots(2, 1, figsize=(7, 4.5), sharex=True)
    for ax, (state, unit) in zip(axes, (("psi", "rad"), ("v", "m/s"))):
        _windows(ax, faults)
        for method, label, colour in BANKS:
            error = result[method][f"{state}_hat"] - result["x"][state]
            ax.plot(t, error[::STRIDE], colour, lw=0.6, label=label)
        ax.set_ylabel(f"{state} error ({unit})")
        ax.legend()
    axes[-1].set_xlabel("time (s)")
    save_svg(fig, path)


def _efficiency(result: SimResult, faults: tuple[ThrusterFault, ...], path: Path) -> None:
    t = result.t
    fig, axes = plt.subplots(2, 1, figsize=(7, 4.5), sharex=True)
    for ax, (thruster, side) in zip(axes, (("T_L", "left"), ("T_R", "right"))):
        true = np.ones_like(t)
        for f in faults:
            if f.thruster == thruster:
                true[(t >= f.onset - 1e-9) & (t < f.end - 1e-9)] = f.efficiency
        ax.plot(t[::STRIDE], true[::STRIDE], "k", lw=1.2, label="true efficiency")
        for method, label, colour in BANKS:
            ax.plot(t[::STRIDE], result[method][f"{side}.alpha_{thruster}_hat"][::STRIDE], colour,
                    lw=0.7, label=f"{label}: {side} model's estimate")
        ax.set_ylabel(f"alpha {thruster} (-)")
        ax.set_ylim(0.0, 2.5)
        ax.legend()
    axes[-1].set_xlabel("time (s)")
    save_svg(fig, path)


def _probabilities(result: SimResult, faults: tuple[ThrusterFault, ...], path: Path) -> None:
    t = result.t[::STRIDE]
    fig, axes = plt.subplots(2, 1, figsize=(7, 4.5), sharex=True)
    for ax, (method, label, _) in zip(axes, BANKS):
        _windows(ax, faults)
        bank = result[method]
        for model, colour in (("nofault", "k"), ("left", "C0"), ("right", "C3")):
            ax.plot(t, bank[f"p_{model}"][::STRIDE], colour, lw=0.8, label=f"p {model}")
        ax.set_ylabel(f"{label}\nprobability")
        ax.legend()
    axes[-1].set_xlabel("time (s)")
    save_svg(fig, path)


def draw_all(result: SimResult, faults: tuple[ThrusterFault, ...], waypoints, folder: Path) -> None:
    """Write every figure of FIGURES into ``folder``; waypoints: (k, 2) north, east (m) of the path."""
    for name, draw in zip(FIGURES, (_thrust, _states, _errors, _efficiency, _probabilities)):
        draw(result, faults, folder / name, *([waypoints] if draw is _states else []))
