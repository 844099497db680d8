"""The vehicle library: equations, parameters, agreement with the field's reference simulator.

``uvsym report models`` writes ``report.md``, ``results.json`` and ``step_responses.svg`` into
the given folder. Every number in them is computed by this run. No claims, no observer sets.
"""

from __future__ import annotations

import json
from pathlib import Path

import casadi as ca
import matplotlib.pyplot as plt
import numpy as np

from uvsym import vehicle, vehicle_names
from uvsym.derivation import Derivation
from uvsym.report import latex_matrix, markdown_table, save_svg, write_json

__all__ = ["DERIVATION", "build", "docking_input_matrix", "reference_agreement", "step_response"]

REFERENCE = Path(__file__).with_name("data") / "fossen_pvs_reference.json"
TOLERANCE = 1e-9  # relative agreement required of nu_dot: max |a - b| / max |b|
REFERENCE_VEHICLES = ("remus100", "torpedo", "otter")
# The paper's eq. 27: non-zero pattern of B for u = (X, delta_e, delta_ru, delta_rd).
EQ27_PATTERN = np.array([[1, 0, 0, 0], [0, 0, 1, 1], [0, 1, 0, 0], [0, 0, 1, 1], [0, 1, 0, 0], [0, 0, 1, 1]], bool)
STEP_INPUTS = {  # vehicle -> (actuator values held constant, seconds)
    "remus100": ([np.deg2rad(5.0), np.deg2rad(-5.0), 1525.0], 60.0),
    "otter": ([80.0, 120.0], 60.0),
}


def _relative_error(actual, reference) -> float:
    reference = np.asarray(reference, dtype=float)
    scale = max(float(np.max(np.abs(reference))), 1e-300)
    return float(np.max(np.abs(np.asarray(actual, dtype=float).ravel() - reference)) / scale)


def reference_agreement() -> list[dict]:
    """For every reference case: relative errors of nu_dot, eta_dot and the actuator rates."""
    data = json.loads(REFERENCE.read_text())
    rows = []
    for name in REFERENCE_VEHICLES:
        model = vehicle(name)
        for case in data[name]["cases"]:
            env = dict(V_c=case["V_c"], beta_c=case["beta_c_rad"])
            nu_dot = model.nu_dot(eta=case["eta"], nu=case["nu"], u=case["u_actual"], **env)["nu_dot"]
            x_dot = model.f(x=np.r_[case["eta"], case["nu"]], u=case["u_actual"],
                            p=[case["V_c"], case["beta_c_rad"]])["x_dot"]
            row = {"vehicle": name, "case": case["name"],
                   "nu_dot_rel_error": _relative_error(nu_dot, case["nu_dot"]),
                   "eta_dot_rel_error": _relative_error(np.asarray(x_dot)[:6], case["eta_dot"])}
            if "u_actual_dot" in case:
                rate = model.actuator_rate(u=case["u_actual"], u_cmd=case["u_control"])["u_dot"]
                row["u_dot_rel_error"] = _relative_error(rate, case["u_actual_dot"])
            row["pass"] = all(v <= TOLERANCE for k, v in row.items() if k.endswith("rel_error"))
            rows.append(row)
    return rows


def docking_input_matrix() -> dict:
    """B = d tau / d u of the docking AUV at 1.5 m/s cruise, and its match with eq. 27's pattern."""
    model = vehicle("docking_auv")
    B = np.array(model.B(eta=np.zeros(6), nu=[1.5, 0, 0, 0, 0, 0], u=[20.0, 0, 0, 0], V_c=0, beta_c=0)["B"])
    pattern = np.abs(B) > 1e-12 * np.max(np.abs(B))
    return {"B": B.tolist(), "matches_eq27_pattern": bool(np.array_equal(pattern, EQ27_PATTERN)),
            "Y_row_equal_for_both_rudders": bool(np.isclose(B[1, 2], B[1, 3], rtol=1e-12)),
            "N_row_equal_for_both_rudders": bool(np.isclose(B[5, 2], B[5, 3], rtol=1e-12))}


def step_response(name: str, u, duration: float, step: float = 0.1) -> dict:
    """Constant-input response from rest, integrated by CVODES on a fixed output grid."""
    model = vehicle(name)
    x = ca.SX.sym("x", 2 * model.dof)
    ode = model.f(x, ca.DM(u), ca.DM.zeros(2))
    grid = np.arange(0.0, duration + step / 2, step)
    F = ca.integrator("F", "cvodes", {"x": x, "ode": ode}, 0.0, grid[1:], {"abstol": 1e-10, "reltol": 1e-10})
    X = np.hstack([np.zeros((2 * model.dof, 1)), np.array(F(x0=np.zeros(2 * model.dof))["xf"])])
    return {"t": grid, "x": X, "u": list(u)}


def _figure(responses: dict, path: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for name, r in responses.items():
        axes[0].plot(r["x"][1], r["x"][0], label=name)
        speed = np.hypot(r["x"][6], r["x"][7])
        axes[1].plot(r["t"], speed, label=name)
    axes[0].set(xlabel="East y (m)", ylabel="North x (m)", title="Track, constant inputs from rest")
    axes[0].axis("equal")
    axes[1].set(xlabel="time (s)", ylabel="horizontal speed (m/s)", title="Speed")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend()
    fig.tight_layout()
    save_svg(fig, path)


def _vehicle_section(name: str) -> str:
    model = vehicle(name)
    inputs = markdown_table(["input", "unit", "min", "max"],
                            [[lab, u, f"{lo:.6g}", f"{hi:.6g}"] for lab, u, lo, hi in
                             zip(model.input_labels, model.input_units, model.u_min, model.u_max)])
    params = markdown_table(["parameter", "value", "unit", "meaning"],
                            [[n, _fmt(p.value), p.unit, p.description] for n, p in model.parameters.items()])
    return "\n\n".join([
        f"### `{name}`: {model.description}",
        f"{model.dof} DOF, {model.n_inputs} inputs; `nu_dot` is {model.nu_dot.n_instructions()} SX instructions.",
        "$$M \\left(\\dot\\nu - \\dot\\nu_c\\right) + h(\\eta, \\nu_r) = \\tau(\\eta, \\nu, u), \\quad "
        "h = " + " + ".join("\\mathrm{" + t.replace("_", "\\_") + "}" for t in model.term_names) + "$$",
        "$$M = " + latex_matrix(model.M, 5) + "$$",
        inputs,
        "<details><summary>Parameters</summary>\n\n" + params + "\n\n</details>",
    ])


def _fmt(value) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in value) + "]" if isinstance(value, tuple) else f"{value:.6g}"


def build(out_dir: Path, progress=lambda message: None) -> None:
    """Build the vehicle-library report into ``out_dir``."""
    out_dir = Path(out_dir)
    progress("comparing with the reference simulator")
    agreement = reference_agreement()
    progress("input matrix of the docking AUV")
    docking = docking_input_matrix()
    progress("step responses")
    responses = {name: step_response(name, *STEP_INPUTS[name]) for name in STEP_INPUTS}
    _figure(responses, out_dir / "step_responses.svg")

    worst = max(row["nu_dot_rel_error"] for row in agreement)
    results = {
        "reference_tolerance": TOLERANCE,
        "reference_cases": len(agreement),
        "reference_cases_passed": sum(row["pass"] for row in agreement),
        "reference_worst_nu_dot_rel_error": float(f"{worst:.3e}"),
        "docking_auv_B_matches_eq27": docking["matches_eq27_pattern"],
        "vehicles": {name: {"dof": vehicle(name).dof, "inputs": list(vehicle(name).input_labels),
                            "sx_instructions_nu_dot": vehicle(name).nu_dot.n_instructions()}
                     for name in vehicle_names()},
    }
    write_json(out_dir / "results.json", results)

    agreement_table = markdown_table(
        ["vehicle", "case", "nu_dot rel. error", "eta_dot rel. error", "u_dot rel. error", f"within {TOLERANCE:g}"],
        [[r["vehicle"], r["case"], f"{r['nu_dot_rel_error']:.1e}", f"{r['eta_dot_rel_error']:.1e}",
          f"{r['u_dot_rel_error']:.1e}" if "u_dot_rel_error" in r else "-", "yes" if r["pass"] else "**NO**"]
         for r in agreement])
    B = np.array(docking["B"])
    text = "\n\n".join([
        "# Vehicle library",
        "Every model is built symbolically in CasADi from the parameters listed with it (SI units, "
        "angles in rad). This report is written by `uvsym report models`; every number in it is "
        "computed by the run that wrote it.",
        "## Agreement with the field's reference simulator",
        f"Accelerations of uvsym's symbolic models against Fossen's Python Vehicle Simulator for "
        f"the same states, inputs and currents ({results['reference_cases_passed']} of "
        f"{results['reference_cases']} cases within {TOLERANCE:g}; worst {worst:.1e}). Relative error is "
        "max |uvsym - reference| / max |reference| over the vector.",
        agreement_table,
        "## Input matrix of the docking AUV against the paper's eq. 27",
        "$B = \\partial\\tau / \\partial u$ derived by CasADi at $u = 1.5$ m/s, for "
        "$u = (X, \\delta_e, \\delta_{ru}, \\delta_{rd})$:",
        "$$B = " + latex_matrix(B, 5) + "$$",
        f"Non-zero pattern equal to eq. 27: **{'yes' if docking['matches_eq27_pattern'] else 'no'}**; "
        f"sway and yaw rows equal for both rudders: "
        f"{'yes' if docking['Y_row_equal_for_both_rudders'] and docking['N_row_equal_for_both_rudders'] else 'no'}; "
        "the roll entries of the two rudders are opposite (they sit above and below the axis).",
        "## Step responses",
        "Constant inputs from rest (REMUS 100: rudder 5 deg, stern planes -5 deg, 1525 rpm; Otter: "
        "n = 80 and 120 rad/s), integrated by CVODES.",
        "![step responses](step_responses.svg)",
        "## Vehicles",
        *[_vehicle_section(name) for name in vehicle_names()],
    ]) + "\n"
    (out_dir / "report.md").write_text(text)


DERIVATION = Derivation(name="models", title="Vehicle library", build=build)
