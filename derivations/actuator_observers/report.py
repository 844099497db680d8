"""``report.md`` of the study: paper versus reproduction, set-up, derived equations, claims, C, figures."""

from __future__ import annotations

import casadi as ca

from derivations.actuator_observers.paper import DOCK_RADIUS_M, PAPER, ROUNDING_SHOWN_AS_ZERO, TARGETS
from derivations.papers import paper
from uvsym.campaign.limits import false_alarm_table, limits_table
from uvsym.report import limits_block, markdown_table
from uvsym.report.sections import c_section, claims_table, counterexamples
from uvsym.sim.scenario import Scenario
from uvsym.sim.simulation import scenario_observers
from uvsym.sympy_bridge import latex

__all__ = ["report", "continuous_section"]

LIU = paper("liu2014")


def _fmt(value, digits: int = 6) -> str:
    return "-" if value is None else f"{value:.{digits}g}" if isinstance(value, float) else str(value)


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

{continuous_section(r["continuous"])}

## Second case: {second['vehicle']}, 6 DOF

Scenario `{second['scenario']}`: a stern-plane bias while the vehicle dives and turns. Isolation done at
{_fmt(second['isolation_time_s'], 4)} s; healthy actuators: {', '.join(second['healthy'])}; depth error at the
end with correction: {_fmt(second['final_depth_error_m_with_ftc'], 3)} m.

{markdown_table(["actuator", "identified", "value", "true kind", "true value", "time (s)"], second_rows)}
"""


def limits_section(f: dict) -> str:
    """The diagnosis's limits read off the campaign: smallest fault seen per actuator, false alarms per hour."""
    tables = "\n\n".join(f"{vehicle}:\n\n" + markdown_table(
        ["actuator", "fault kind", "sizes tried: detected / runs", "detected in every run from", "missed at",
         "median delay (s)"], limits_table(limits)) for vehicle, limits in f["limits"].items())
    healthy = f["fault_free"]
    long_enough = [r for r in healthy if r["hours"] >= 10.0]
    short = [r for r in healthy if r["hours"] < 10.0]
    designed = f["designed_false_alarms_per_hour"]
    above = [r for r in long_enough if r["per_hour"] is not None and r["per_hour"] > designed]
    measured = "; ".join(f"{r['noise']}: {r['false_alarms']} in {r['hours']:.3g} h" for r in long_enough)
    verdict = (f"above the designed rate at {', '.join(str(r['noise']) for r in above)}" if above else
               "none above the designed rate")
    return "### Limits (from the campaign)\n\n" + limits_block(f"""
Fault sizes are a proportional fault's distance from a factor of 1 and a bias's magnitude (N, rpm or rad);
a stuck actuator's value is no size (what it hides depends on the commands), so stuck faults are left
out here. Each size was tried in a handful of runs (two onsets, with and without noise), so "detected in
every run from" brackets the smallest detectable fault between the sizes tried; the campaign does not
search below them.

{tables}

False alarms of fault-free runs (velocity noise told to the diagnosis, or none):

{markdown_table(["velocity noise", "fault-free hours", "false alarms", "per hour"], false_alarm_table(healthy))}

The designed rate: each decision (every {f["decision_period_s"]:g} s) alarms on a healthy window with
probability at most {f["window_false_alarm_rate"]:g} under white Gaussian noise of the levels told (split
over the hypotheses), and a confirmed alarm needs at least one such window, so at most
{designed:.3g} false alarms per hour. Measured over the settings of at least 10 fault-free hours
(docking AUV): {measured or "none"}; {verdict}. {_short_settings(short)}
({f["campaign_false_alarms_before_onset"]} false alarms before the onsets of the faulty runs besides.)

What the diagnosis cannot see, by construction: a fault of an actuator
whose command stays put after the onset (proportional, bias and stuck faults then act alike: the
unexcited runs above), a proportional fault while its command is near zero, and a fault on an actuator
whose column of B is parallel to another's (no measurement tells the two apart: ambiguous).""")


def _short_settings(short: list[dict]) -> str:
    """What the settings of fewer than 10 fault-free hours can say."""
    if not short:
        return ""
    names = ", ".join(f"{r['noise']} ({r['hours']:.2g} h)" for r in short)
    return (f"The other settings ran too few fault-free hours to confirm that rate ({names}); without noise a "
            "run is deterministic, one trajectory however often it is run.")


def continuous_section(c: dict) -> str:
    """The section on uvsym's continuous diagnosis: the fault campaign and the corrected docking run."""
    f, d = c["campaign"], c["docking"]
    target_rows = [
        ["correct fraction (identifiable, excited runs)", _fmt(f["campaign_correct_fraction"], 4), ">= 0.95"],
        ["false alarms in fault-free runs", f["campaign_false_alarms_no_fault"], "0"],
        ["median / max isolation delay (s)", f"{_fmt(f['campaign_median_isolation_delay_s'], 3)} / "
         f"{_fmt(f['campaign_max_isolation_delay_s'], 3)}", "<= 5 / <= 10"],
        ["runs ending in an exception", f["campaign_crashes"], "0"],
    ]
    met = [[name, "met" if ok else "**missed**"] for name, ok in f["targets"].items()]
    kinds = [[k, v["runs"], v["correct"], _fmt(v["median_size_error_rel"], 3), _fmt(v["max_size_error_rel"], 3)]
             for k, v in f["by_kind"].items()]
    wrong = [[w["case"], f"{w['true_kind']} {w['true_actuator']} {_fmt(w['true_value'], 3)}", _fmt(w["onset_s"], 3),
              "nothing isolated" if w["isolated_target"] is None else f"{w['isolated_kind']} {w['isolated_target']}",
              _fmt(w["identified_value"], 4),
              _fmt(w["size_error_rel"], 3)] for w in f["wrong"]]
    excluded = [[e["vehicle"], e["actuator"], e["kind"], e["runs"]] for e in f["excluded"]]
    intervals = [[i["case"], i["runs"], i["within_tolerance"], f"{i['within_2_std']} of {i['with_std']}",
                  _fmt(i["max_error_std"], 3)] for i in f["size_intervals"]]
    events = [[_fmt(e["t"], 4), e["event"], e["target"], e["kind"] or "",
               _fmt(e["value"], 5) if e["value"] is not None else "",
               _fmt(e["std"], 2) if e.get("std") is not None else ""] for e in d["events"]]
    return f"""## Continuous diagnosis (uvsym, beyond the paper)

The paper's isolation decides each force channel once, from the variance of predicted faults
(reproduced above). `uvsym.diagnosis` instead watches every *actuator* for the whole mission:
every 0.1 s it fits, on the last 2 s of the bias observer's estimate, each hypothesis "actuator a
has a fault of kind k" (a regression on the actuator's column of B, the observer's filter and the
decided faults through the vehicle's exact force model) and logs a state change when a generalised
likelihood ratio clears a threshold set by a stated false-alarm rate in 3 decisions running:
detected, isolated, identified, cleared (a fault that went away), ambiguous (actuators the data
cannot tell apart) or unexcited (a command too steady to tell a fault's kind: Remark 2).

### The fault campaign ([campaign.toml](../../derivations/actuator_observers/campaign.toml))

{f["campaign_runs"]} runs: each fault kind on each actuator of the docking AUV and the REMUS 100, two
sizes, onsets 8 s and 18 s, without and with velocity-sensor noise (0.01 m/s, 0.001 rad/s), and
fault-free runs; `uvsym campaign derivations/actuator_observers/campaign.toml` runs the same file.
A run counts when its fault is identifiable (its actuator's column of B is not parallel to
another's) and excited (after the onset the command varies by at least 1 % of the actuator's
range and the fault's effect is at least 2 % of it), both judged from the geometry and the
simulated commands, not from the diagnosis; {f["campaign_counted_runs"]} of {f["campaign_fault_runs"]} faulty runs
count.
Over all faulty runs {_fmt(f["campaign_correct_fraction_all_faults"], 3)} are decided correctly.
Every per-run row is in [campaign_results.csv](campaign_results.csv).

{markdown_table(["figure", "campaign", "target"], target_rows)}

{markdown_table(["target", ""], met)}

{markdown_table(["fault kind", "counted runs", "correct", "median size error (rel.)", "max size error (rel.)"], kinds)}

Each identified size carries its standard deviation under the noise the diagnosis is told (the
joint fit's inverse information, `std` in the decision log); over the counted runs decided right:

{markdown_table(["case", "runs", "within 2 %", "within 2 std", "largest error (std)"], intervals)}

![confusion](campaign_confusion.svg)

![delays](campaign_delays.svg)

Counted runs not decided correctly:

{markdown_table(["case", "injected", "onset (s)", "decided", "identified", "size error"], wrong) if wrong else "none."}

Runs left out as not excited (the fault classes undecidable there, and why: a command that stays
put makes proportional, bias and stuck faults act alike, and a command near zero hides a
proportional fault):

{markdown_table(["vehicle", "actuator", "fault kind", "runs"], excluded) if excluded else "none."}

{limits_section(f)}

### The docking run with the continuous diagnosis correcting it (`uvsym simulate docking_diagnosis`)

Every fault isolated by {_fmt(d["isolation_time_s"], 3)} s; cross-track RMS {_fmt(d["cross_track_rms_m"], 3)} m,
miss at the dock {_fmt(d["dock_miss_m"], 3)} m. Its decision log (`--events events.json` writes it):

{markdown_table(["t (s)", "event", "target", "kind", "value", "std"], events)}
"""
