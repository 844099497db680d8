"""``report.md`` of the study: paper versus reproduction, set-up, derived equations, claims, C, figures."""

from __future__ import annotations

import casadi as ca

from derivations.actuator_observers.paper import DOCK_RADIUS_M, PAPER, ROUNDING_SHOWN_AS_ZERO, TARGETS
from derivations.papers import paper
from uvsym.report import markdown_table
from uvsym.report.sections import c_section, claims_table, counterexamples
from uvsym.sim.scenario import Scenario
from uvsym.sim.simulation import scenario_observers
from uvsym.sympy_bridge import latex

__all__ = ["report"]

LIU = paper("liu2014")


def _fmt(value, digits: int = 6) -> str:
    return f"{value:.{digits}g}" if isinstance(value, float) else str(value)


def _derived_gains(scenario: Scenario) -> str:
    """LaTeX of L = dR/dnu of each observer in the loop, as CasADi derives it."""
    n = scenario.model.dof
    nu, tau_d, K = ca.SX.sym("nu", n), ca.SX.sym("tau_d", n), ca.SX.sym("K", n)
    parts = []
    for kind, (observer, _) in scenario_observers(scenario.model, scenario.observers).items():
        R = latex(observer.R(nu, tau_d, K)[0], 4)
        parts.append(f"- {kind} ({observer.form} form), first entry of R: $R_1 = {R}$; "
                     f"$L = \\partial R / \\partial \\nu$:\n\n$$L_{{{kind[0]}}} = "
                     f"{latex(observer.L(nu, tau_d, K), 4)}$$\n\n  and the error dynamics $\\dot e = A e$ "
                     f"derived along the faulty plant (constant $\\tau_d$):\n\n$$A_{{{kind[0]}}} = "
                     f"{latex(observer.error_matrix(tau_d, K), 4, zero_below=ROUNDING_SHOWN_AS_ZERO)}$$")
    return "\n\n".join(parts)


def report(scenario: Scenario, r: dict, checks: dict) -> str:
    """The Markdown of the report on the docking ``scenario`` from its results ``r`` and target ``checks``."""
    def versus(key: str, digits: int) -> list[str]:
        """reproduced, paper, reproduced - paper (or whether the two agree, for a decision)."""
        ours, paper = r[key], PAPER[key]
        if isinstance(paper, str):
            return [ours, paper, "same" if ours == paper else "**differs**"]
        return [_fmt(ours, digits), _fmt(paper), f"{ours - paper:+.{max(digits - 3, 2)}g}"]

    rows = [
        ["isolation time (s)", *versus("isolation_time_s", 4), f"<= {TARGETS['isolation_time_s']:g}"],
        ["thruster fault type", *versus("thruster_fault_type", 0), "bias"],
        ["f_bar_a, thruster bias (N)", *versus("f_bar_a", 7), f"13 +- {TARGETS['f_bar_a']}"],
        ["rudder fault type", *versus("rudder_fault_type", 0), "proportional"],
        ["f_bar_p, rudder factor (-)", *versus("f_bar_p", 7), f"0.8 +- {TARGETS['f_bar_p']}"],
        ["cross-track RMS without / with correction (m)",
         f"{_fmt(r['cross_track_rms_m_without_ftc'], 4)} / {_fmt(r['cross_track_rms_m_with_ftc'], 4)} "
         f"(ratio {_fmt(r['cross_track_ratio'], 3)})", "not given (Figs. 4, 7)", "-",
         f"ratio >= {TARGETS['cross_track_ratio']:g}"],
        ["miss at the dock without / with correction (m)",
         f"{_fmt(r['dock_miss_m_without_ftc'], 3)} / {_fmt(r['dock_miss_m_with_ftc'], 3)}",
         "misses / docks", "-", f"dock radius {DOCK_RADIUS_M}"],
    ]
    decisions = [[c, d["kind"], _fmt(d["time_s"], 4), _fmt(d["f_bar"], 7), _fmt(d["variance"], 3)]
                 for c, d in r["channel_decisions"].items()]
    second = r["remus100"]
    second_rows = [[label, v["kind"], _fmt(v["value"], 6), second["true_faults"].get(label, {}).get("kind", "none"),
                    _fmt(second["true_faults"].get(label, {}).get("value", float("nan")), 6), _fmt(v["time_s"], 4)]
                   for label, v in second["identified"].items()]
    stiff = r["stiffer_heading_loop"]
    stiff_text = (
        f"Cross-track RMS and miss are taken from the start until the vehicle reaches the dock's entrance plane. "
        f"Without faults the same path is flown with a cross-track RMS of "
        f"{_fmt(r['cross_track_rms_m_without_faults'], 3)} m and a miss of "
        f"{_fmt(r['dock_miss_m_without_faults'], 3)} m. How much correction gains depends on how much the "
        f"controller's own feedback already rejects the faults: with a stiffer heading loop (kp "
        f"{_fmt(stiff['heading_kp'], 3)}, kd {_fmt(stiff['heading_kd'], 3)}) the cross-track RMS is "
        f"{_fmt(stiff['cross_track_rms_m_without_ftc'], 3)} m without and "
        f"{_fmt(stiff['cross_track_rms_m_with_ftc'], 3)} m with correction (ratio "
        f"{_fmt(stiff['cross_track_ratio'], 3)}).")
    status = "\n".join(f"- {'met' if ok else '**not met**'}: {name}" for name, ok in checks.items())
    dropped = ", ".join(f"{k} {_fmt(v, 3)}" for k, v in r["error_dynamics"]["dropped_term_rms"].items())
    fault_lines = "\n".join(f"    - {scenario.model.input_labels[f.actuator]}: {f.kind} {f.value:g} from t = "
                            f"{f.profile.onset:g} s" for f in scenario.actuator_faults)
    return f"""# Actuator-fault diagnosis and fault-tolerant control ({LIU.short})

Paper: {LIU.reference()}

Reproduction of the docking experiment of its section 4: the docking AUV (`{scenario.model.name}`) follows a
planned path into a dock with a thruster bias and a rudder proportional fault present from the start;
proportional and bias observers run together, and isolation, identification and correction act in the
loop. Every number below is computed by `uvsym report actuator-observers`.

## Paper versus reproduction

{markdown_table(["quantity", "reproduced", "paper", "reproduced - paper", "target"], rows)}

{status}

{stiff_text}

## Set-up (uvsym's choices where the paper gives none)

- Scenario `{scenario.name}` (shipped with uvsym, `uvsym simulate {scenario.name}`): {scenario.description}.
  {scenario.duration:g} s at a {scenario.step:g} s sample period; current none.
- Path: waypoints {[list(p) for p in scenario.controller.path.waypoints]} (north, east in m) with corners
  rounded to {scenario.controller.path.turn_radius:g} m arcs; the dock sits at the last waypoint, facing
  along the final leg, with an entrance radius of {DOCK_RADIUS_M} m.
- Controller: line-of-sight course guidance (lookahead {scenario.controller.path.lookahead:g} m, sideslip
  compensated, path yaw rate fed forward) and a model-based speed and yaw loop without integral action
  (the desired surge and yaw forces `M a + h(eta, nu)` are inverted through the actuation model); depth
  held at {scenario.controller.depth.reference:g} m with the elevator. Faults the controller is not told
  about leave steady errors, which the correction removes.
- Faults:
{fault_lines}
- Observers: proportional and bias, in the momentum form (`R_p = -K T_d M nu`, `R_a = -K M nu`) because
  this vehicle's mass matrix is not diagonal (CG below the CO); the paper's form is the same observer
  when M is diagonal. Gains give a {scenario.observers[0].time_constant:g} s time constant. They run as a
  sampled-data observer (trapezoidal, which also absorbs the `dR/dtau_d tau_d'` term the paper's proof
  drops), on `tau_d = tau(y, u_expected)`: the action healthy actuators deliver for the commands sent.
- Isolation: the paper's variance criterion (threshold 1e-4) on the predicted fault `f_bar`, over a
  1 s window; `f_bar` comes from a least-squares fit of the paper's eq. 19 (the closed form behind
  eqs. 22-24). Identification: `u = u_e + B^+ (tau_hat - tau_d)` on the decided channels.
  Correction: `u* = u_d / f_bar_p` for the rudders, `u* = u_d - f_bar_a` for the thruster.

## Derived by CasADi (not typed)

The numbers are entries of M (kg, kg m, kg m^2), shown to 4 digits (the code keeps every bit);
$k_i$ are the gains, $\\tau_{{d,i}}$ the desired forces. In $A$, coefficients below
{ROUNDING_SHOWN_AS_ZERO:g} (residues of $M M^{{-1}}$ in double precision) are shown as 0 and those
within it of 1 as 1:

{_derived_gains(scenario)}

## Machine-checked claims (`uvsym verify actuator-observers`)

Error dynamics derived by differentiating `e = f - f_hat` along the faulty plant, compared with the
paper's closed forms; convergence over sets of desired actions by LMI, re-checked in exact rational
arithmetic; the fault-tolerant loop of section 3.2 (uvsym's concrete loop: the 3-DOF Otter under
`u_d = -k B' nu`, with the experiment's two faults) by interval branch-and-bound over the CasADi
graph. Negative controls are expected to be refuted; a refuted claim's counterexample is in
`proofs.json` (`uvsym verify actuator-observers --json`).

{claims_table(r["claims"])}

Counterexamples of the refuted claims (the test suite substitutes each one back and checks that it
violates its claim):

{counterexamples(r["claims"])}

## Generated C

{c_section(r["c"], f"The observers of this experiment ({r['c']['vehicle']}, {r['c']['form']} form)")}

## Isolation per channel (run with correction)

{markdown_table(["channel", "decision", "time (s)", "f_bar", "variance"], decisions)}

### Figures (the paper's Figs. 4-8)

![Fig. 4](fig4_without_ftc.svg)

Fig. 4: the docking path with the faults and without correction.

![Fig. 5](fig5_actuation_without_ftc.svg)

Fig. 5: actuation without correction.

![Fig. 6](fig6_estimates.svg)

Fig. 6: the observers' fault estimates.

![Fig. 7](fig7_with_ftc.svg)

Fig. 7: the docking path with correction.

![Fig. 8](fig8_actuation_with_ftc.svg)

Fig. 8: actuation with correction.

## Error dynamics when tau_d varies

The exact error dynamics of the proportional observer, derived symbolically, equal
`e' = A e + (dR/dtau_d) tau_d'` (largest relative residual over 20 random points:
{_fmt(r['error_dynamics']['max_relative_residual'], 3)}); the paper keeps only `A e`. Along the corrected
docking run the dropped term has the RMS (1/s, per channel) {dropped} -- not small next to the
rates of {_fmt(1 / scenario.observers[0].time_constant, 3)} 1/s the gains were designed for, which is why uvsym's
sampled-data observer absorbs it instead of dropping it.

## Second case: {second['vehicle']}, 6 DOF

Scenario `{second['scenario']}`: a stern-plane bias while the vehicle dives and turns. Isolation done at
{_fmt(second['isolation_time_s'], 4)} s; healthy actuators: {', '.join(second['healthy'])}; depth error at the
end with correction: {_fmt(second['final_depth_error_m_with_ftc'], 3)} m.

{markdown_table(["actuator", "identified", "value", "true kind", "true value", "time (s)"], second_rows)}
"""
