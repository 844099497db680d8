"""The docking experiment of Liu et al. 2014 (section 4) and its second case, run and written.

Runs the docking experiment (scenario ``docking_faults``) without and with correction, and a
second case on the 6-DOF REMUS 100 (scenario ``remus100_stern_plane_bias``). Writes
``report.md``, ``results.json`` and the paper's Figs. 4-8 as SVG into the given folder, and the
observers as a C package into ``c/``; every number is computed by this run. The closed loops run
on CasADi's virtual machine (not the compiled fast path) so that the numbers do not depend on the
machine's compiler flags.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import casadi as ca
import numpy as np

from derivations.actuator_observers.claims import core_paper_claims
from derivations.actuator_observers.continuous import campaign_results, corrected_docking
from derivations.actuator_observers.dock import cross_track_rms, dock_miss
from derivations.actuator_observers.figures import actuation_figure, estimates_figure, path_figure
from derivations.actuator_observers.observer_sets import actuator_observers
from derivations.actuator_observers.paper import DOCK_RADIUS_M, DOCKING, PAPER, SECOND, TARGETS, TRUE
from derivations.actuator_observers.report import report
from uvsym.observers.isolation import IsolationSettings
from uvsym.observers.supervisor import FaultDiagnosis
from uvsym.report import write_json
from uvsym.report.sections import c_package, claim_rows
from uvsym.sim.scenario import Scenario, load_scenario
from uvsym.sim.simulation import scenario_observers, simulate_scenario

__all__ = ["build"]


def _run(scenario: Scenario, correct: bool):
    """Simulate with the diagnosis in the loop; returns (SimResult, FaultDiagnosis)."""
    diagnosis = FaultDiagnosis(scenario.model, scenario_observers(scenario.model, scenario.observers),
                               IsolationSettings(), correct=correct)
    return simulate_scenario(scenario, supervisor=diagnosis, compiled=False), diagnosis


def _error_dynamics_check(scenario: Scenario, result) -> dict:
    """Exact error dynamics of the proportional observer vs e' = A e, and the size of the dropped term."""
    observers = scenario_observers(scenario.model, scenario.observers)
    observer, K = observers["proportional"]
    n = scenario.model.dof
    rng = np.random.default_rng(0)
    residual = 0.0
    tau_d_sym, nu_sym = ca.SX.sym("tau_d", n), ca.SX.sym("nu", n)
    dR_dtau = ca.Function("dR_dtau", [nu_sym, tau_d_sym],
                          [ca.jacobian(observer.R(nu_sym, tau_d_sym, K), tau_d_sym)])
    for _ in range(20):
        e, f, eta, nu = (rng.standard_normal(n) for _ in range(4))
        tau_d, tau_d_dot = 5 * rng.standard_normal(n), rng.standard_normal(n)
        exact = np.asarray(observer.error_dynamics(e, f, eta, nu, tau_d, tau_d_dot, K)).ravel()
        predicted = np.asarray(observer.error_matrix(tau_d, K)) @ e + np.asarray(dR_dtau(nu, tau_d)) @ tau_d_dot
        residual = max(residual, float(np.max(np.abs(exact - predicted)) / max(1.0, np.max(np.abs(exact)))))
    tau_d = result["tau_desired"].values
    nu = result["x"].values[:, n:]
    dt = float(result.t[1] - result.t[0])
    tau_d_dot = np.gradient(tau_d, dt, axis=0)
    dropped = np.array([np.asarray(dR_dtau(nu[k], tau_d[k])) @ tau_d_dot[k] for k in range(len(result.t))])
    return {"max_relative_residual": residual,
            "dropped_term_rms": {label: float(v) for label, v in
                                 zip(result["tau_desired"].labels, np.sqrt(np.mean(dropped**2, axis=0)))}}


def _round(value, digits: int = 9):
    """Floats rounded to ``digits`` significant digits (stable JSON across platforms), recursively."""
    if isinstance(value, float):
        return float(f"{value:.{digits}g}")
    if isinstance(value, dict):
        return {k: _round(v, digits) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_round(v, digits) for v in value]
    return value


def _stiffer(scenario: Scenario) -> dict:
    """The cross-track ratio when the heading loop is stiffer (gains x 5/3 and x 2): faults then leave less."""
    heading = replace(scenario.controller.heading, kp=scenario.controller.heading.kp * 5 / 3,
                      kd=scenario.controller.heading.kd * 2)
    stiff = replace(scenario, controller=replace(scenario.controller, heading=heading))
    without, _ = _run(stiff, correct=False)
    with_ftc, _ = _run(stiff, correct=True)
    rms_without, rms_with = cross_track_rms(without, scenario), cross_track_rms(with_ftc, scenario)
    return {"heading_kp": heading.kp, "heading_kd": heading.kd, "cross_track_rms_m_without_ftc": rms_without,
            "cross_track_rms_m_with_ftc": rms_with, "cross_track_ratio": rms_without / rms_with}


def _second_case(progress) -> dict:
    """The 6-DOF REMUS 100 with a stern-plane bias, corrected: what was identified, and when."""
    scenario = load_scenario(SECOND)
    progress(f"second case: {scenario.description}")
    result, diagnosis = _run(scenario, correct=True)
    truth = {scenario.model.input_labels[f.actuator]: {"kind": f.kind, "value": f.value}
             for f in scenario.actuator_faults}
    identified = {label: {"kind": est.kind, "value": est.value, "time_s": est.time_s}
                  for label, est in diagnosis.identified.items()}
    depth_error = float(abs(result["x"]["z"][-1] - scenario.controller.depth.reference))
    return {"scenario": scenario.name, "vehicle": scenario.model.name, "true_faults": truth,
            "identified": identified, "healthy": sorted(diagnosis.healthy),
            "isolation_time_s": diagnosis.isolation_time_s, "final_depth_error_m_with_ftc": depth_error,
            "decisions": {c: {"kind": d.kind, "time_s": d.time_s, "f_bar": d.f_bar}
                          for c, d in diagnosis.isolator.result.decisions.items()}}


def _generated_c(scenario: Scenario, folder: Path) -> dict:
    """The experiment's observers as a checked C package in ``folder`` (:func:`uvsym.report.sections.c_package`)."""
    form = scenario.observers[0].form
    c = c_package(actuator_observers(vehicle=scenario.model.name, form=form), folder)
    return {"package": c.pop("package"), "folder": c.pop("folder"), "vehicle": scenario.model.name, "form": form} | c


def build(out_dir: Path, progress) -> None:
    """Run the experiments and write the report, results and figures into ``out_dir``."""
    out_dir = Path(out_dir)
    scenario = load_scenario(DOCKING)
    progress("docking without correction (diagnosis runs, commands unchanged)")
    without, _ = _run(scenario, correct=False)
    progress("docking with correction")
    with_ftc, diagnosis = _run(scenario, correct=True)
    progress("docking without faults (reference)")
    healthy = simulate_scenario(replace(scenario, actuator_faults=()), compiled=False)

    thruster, rudder = diagnosis.identified.get("X"), diagnosis.identified.get("delta_ru")
    rms_without, rms_with = cross_track_rms(without, scenario), cross_track_rms(with_ftc, scenario)
    results = {
        "isolation_time_s": diagnosis.isolation_time_s,
        "thruster_fault_type": thruster.kind if thruster else "not identified",
        "f_bar_a": thruster.value if thruster else float("nan"),
        "rudder_fault_type": rudder.kind if rudder else "not identified",
        "f_bar_p": rudder.value if rudder else float("nan"),
        "f_bar_p_lower_rudder": diagnosis.identified["delta_rd"].value if "delta_rd" in diagnosis.identified else None,
        "cross_track_rms_m_without_ftc": rms_without,
        "cross_track_rms_m_with_ftc": rms_with,
        "cross_track_rms_m_without_faults": cross_track_rms(healthy, scenario),
        "cross_track_ratio": rms_without / rms_with,
        "dock_miss_m_without_ftc": dock_miss(without, scenario),
        "dock_miss_m_with_ftc": dock_miss(with_ftc, scenario),
        "dock_miss_m_without_faults": dock_miss(healthy, scenario),
        "dock_radius_m": DOCK_RADIUS_M,
        "channel_decisions": {c: {"kind": d.kind, "time_s": d.time_s, "f_bar": d.f_bar, "variance": d.variance}
                              for c, d in diagnosis.isolator.result.decisions.items()},
        "error_dynamics": _error_dynamics_check(scenario, with_ftc),
        "paper": PAPER,
    }
    checks = {
        "thruster isolated as bias": results["thruster_fault_type"] == "bias",
        "rudder isolated as proportional": results["rudder_fault_type"] == "proportional",
        f"|f_bar_a - 13| <= {TARGETS['f_bar_a']}": abs(results["f_bar_a"] - TRUE["f_a"]) <= TARGETS["f_bar_a"],
        f"|f_bar_p - 0.8| <= {TARGETS['f_bar_p']}": abs(results["f_bar_p"] - TRUE["f_p"]) <= TARGETS["f_bar_p"],
        f"isolation within {TARGETS['isolation_time_s']:g} s":
            results["isolation_time_s"] <= TARGETS["isolation_time_s"],
        f"cross-track RMS at least {TARGETS['cross_track_ratio']:g}x smaller with correction":
            results["cross_track_ratio"] >= TARGETS["cross_track_ratio"],
        "docks with correction": results["dock_miss_m_with_ftc"] <= DOCK_RADIUS_M,
        "misses the dock without correction": results["dock_miss_m_without_ftc"] > DOCK_RADIUS_M,
    }
    results["targets"] = {name: bool(ok) for name, ok in checks.items()}
    progress("sensitivity: a stiffer heading loop")
    results["stiffer_heading_loop"] = _stiffer(scenario)
    results["remus100"] = _second_case(progress)
    progress("C sources of the observers: write, compile, compare")
    results["c"] = _generated_c(scenario, out_dir / "c")
    results["continuous"] = {"campaign": campaign_results(out_dir, progress), "docking": corrected_docking(progress)}
    progress("machine-checked claims")
    results["claims"] = claim_rows(core_paper_claims())
    write_json(out_dir / "results.json", _round(results))

    progress("figures")
    path_figure(scenario, without, "Fig. 4: docking without fault-tolerant correction",
                 out_dir / "fig4_without_ftc.svg")
    actuation_figure(without, "Fig. 5: desired and delivered actuation without correction",
                      out_dir / "fig5_actuation_without_ftc.svg")
    estimates_figure(with_ftc, diagnosis, out_dir / "fig6_estimates.svg")
    path_figure(scenario, with_ftc, "Fig. 7: docking with fault-tolerant correction", out_dir / "fig7_with_ftc.svg")
    actuation_figure(with_ftc, "Fig. 8: desired and delivered actuation with correction",
                      out_dir / "fig8_actuation_with_ftc.svg")
    (out_dir / "report.md").write_text(report(scenario, results, checks))
