"""``report.md``, ``results.json`` and figures of the LMS-FIR sensor-fault study."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from derivations.papers import paper
from derivations.sensor_fdi_lms import design as D
from derivations.sensor_fdi_lms.campaign import campaign_results
from derivations.sensor_fdi_lms.claims import NEGATIVE_FACTOR, healthy_input, lms_claims
from derivations.sensor_fdi_lms.experiment import Run, first_sample, run
from derivations.sensor_fdi_lms.figures import criteria_figure, delay_figure, heading_figure, roc_figure
from derivations.sensor_fdi_lms.observer_sets import lms_set
from derivations.sensor_fdi_lms.study import R0_GRID, SIZE_DEG, WITHIN, detection_study
from derivations.sensor_fdi_lms.text import report_text
from uvsym.errors import SimulationError
from uvsym.observers.lms import lms_step, mu_bound
from uvsym.observers.step_monitor import step_power, step_threshold
from uvsym.report import write_json
from uvsym.report.equations import function_equations
from uvsym.report.sections import c_package, claim_rows
from uvsym.systems.signals import Signals

__all__ = ["build", "PAPER", "SETTLED", "FTC_WINDOW"]

PAPER = {"eps2_first_alarm_sample": 70, "R_first_alarm_sample": 75,
         "heading_without_ftc_deg": {"30": 120.0, "20": 130.0, "10": 140.0}, "max_abs_heading_error_with_ftc_deg": 3.0,
         "spike_classified_as": "disturbance"}
SETTLED = 100  # samples (20 s) at the end of the record whose mean heading is the settled heading
FTC_WINDOW = 300  # samples (60 s) after the onset over which the FTC error is taken
TRANSIENT = 10  # samples (2 s) after the switch by which the turn begun on the faulty samples has died out
FTC_SEEDS = tuple(range(8))  # noise seeds of the FTC robustness runs
BANDWIDTHS = (0.35, D.BANDWIDTH, 1.4)  # rad/s, the proportional law's natural frequencies compared
STEPS = (D.MU, 1e3, 1e4, 1e5)  # LMS steps compared (the paper's, and larger ones that let the filter learn)
STEP_POWER_SIZES = (4.0, 6.0, 8.0, 9.0, 10.0, 11.0, 12.0, 14.0, 16.0)  # steps of the power table (noise std)
STEP_POWER_EDGES = 400  # steps per size in the power Monte Carlo (a probability to about +-0.025)
STEP_POWER_LEVELS = (0.5, 0.9)  # detection probabilities whose smallest step the report states


def _summary(outcome) -> dict:
    """Alarm samples, the samples the controller read the substitute, settled heading and the
    largest heading error over FTC_WINDOW after the onset."""
    k, heading = outcome.k, outcome.heading_deg()
    after = (k >= D.FAULT_SAMPLE) & (k < D.FAULT_SAMPLE + FTC_WINDOW)
    confirmed = outcome.supervisor.first("R alarm")
    substituted = outcome.substituted() & (k >= 0)
    largest = int(np.argmax(np.where(after, np.abs(heading - D.SET_POINT_DEG), -1.0)))
    return {"eps2_first_alarm_sample": first_sample(outcome.monitor("alarm_eps2_psi"), k),
            "R_first_alarm_sample": first_sample(outcome.monitor("alarm_R_psi"), k, D.FAULT_SAMPLE),
            "R_first_above_sample": first_sample(outcome.monitor("R_psi") > D.R0, k, D.FAULT_SAMPLE),
            "confirmed_sample": None if confirmed is None else confirmed.sample - outcome.spec.warm_up,
            "substituted_from_sample": first_sample(substituted, k),
            "substituted_samples": int(np.sum(substituted)),
            "settled_heading_deg": float(np.mean(heading[-SETTLED:])),
            "max_abs_heading_error_deg": float(np.abs(heading[largest] - D.SET_POINT_DEG)),
            "max_abs_heading_error_sample": int(k[largest]),
            "events": [[e.sample - outcome.spec.warm_up, e.what] for e in outcome.supervisor.events
                       if e.sample >= outcome.spec.warm_up]}


def _runs(progress) -> tuple[dict, dict]:
    """Every run of the reproduction: the three faults with and without FTC (both substitution
    rules), the one-sample disturbance; (outcomes for the figures, summaries)."""
    outcomes, summaries = {}, {}
    for size in D.FAULT_SIZES_DEG:
        for label, spec in (("ftc", Run(size_deg=size)), ("no_ftc", Run(size_deg=size, ftc=False)),
                            ("ftc_on_alarm", Run(size_deg=size, substitute_on="alarm"))):
            progress(f"run: +{size:g} deg compass fault, {label}")
            outcomes[(size, label)] = run(spec)
            summaries.setdefault(f"{size:g}", {})[label] = _summary(outcomes[(size, label)])
    for label, mode in (("spike", "fault"), ("spike_on_alarm", "alarm")):
        progress(f"run: one-sample disturbance, substitution on {mode}")
        outcomes[label] = run(Run(size_deg=D.FAULT_SIZES_DEG[-1], profile="pulse", length=1, substitute_on=mode))
        summaries[label] = _summary(outcomes[label])
    return outcomes, summaries


def _transient(outcome) -> dict:
    """What the controller did on the faulty samples before the switch: their number, its mean
    command (-), the steady turn rate that command would reach and the peak yaw rate (deg/s), and
    the heading error (deg) at the switch and TRANSIENT samples after it."""
    k, error = outcome.k, outcome.heading_deg() - D.SET_POINT_DEG
    switch = first_sample(outcome.substituted(), k, D.FAULT_SAMPLE)
    acting = (k >= D.FAULT_SAMPLE) & (k < switch)
    turning = (k >= D.FAULT_SAMPLE) & (k < switch + TRANSIENT)
    command = float(np.mean(outcome.result["u"]["u"][acting]))
    return {"faulty_samples": int(np.sum(acting)),
            "command": command, "steady_turn_deg_s": math.degrees(D.turn_rate(D.design().plant, command)),
            "peak_yaw_rate_deg_s": float(np.max(np.abs(np.degrees(outcome.result["x"]["r"][turning])))),
            "error_at_switch_deg": float(error[k == switch][0]),
            "error_after_transient_deg": float(error[k == switch + TRANSIENT][0])}


def _max_error(spec: Run) -> float:
    return _summary(run(spec))["max_abs_heading_error_deg"]


def _ftc_over_seeds(size: float, mode: str) -> dict:
    """Largest FTC error and whether R confirmed the fault, per seed of FTC_SEEDS."""
    summaries = [_summary(run(Run(size_deg=size, substitute_on=mode, seed=seed))) for seed in FTC_SEEDS]
    errors = [s["max_abs_heading_error_deg"] for s in summaries]
    return {"max_abs_error_deg": errors, "within_3_deg": sum(e <= 3.0 for e in errors),
            "confirmed": sum(s["confirmed_sample"] is not None for s in summaries)}


def _calibrated(progress) -> dict:
    """The calibrated sensor-step monitor switching the substitute: the FTC error per fault size and
    seed of FTC_SEEDS, and its designed threshold."""
    errors = {}
    for size in D.FAULT_SIZES_DEG + (-30.0,):
        progress(f"calibrated monitor, FTC over {len(FTC_SEEDS)} noise seeds: {size:+g} deg")
        errors[f"{size:g}"] = [_max_error(Run(size_deg=size, decision="calibrated", seed=seed)) for seed in FTC_SEEDS]
    return {"max_abs_heading_error_deg": errors, "false_alarms_per_hour": D.STEP_FALSE_ALARMS_PER_HOUR,
            "per_test_probability": D.STEP_FALSE_ALARMS_PER_HOUR * D.DT / 3600.0,
            "threshold": step_threshold(D.STEP_FALSE_ALARMS_PER_HOUR, D.DT), "window": list(D.STEP_WINDOW),
            "power": _step_power(progress)}


def _step_power(progress) -> dict:
    """The monitor's detection probability per step size (noise standard deviations; Monte Carlo on flat
    records, :func:`~uvsym.observers.step_monitor.step_power`) and the smallest sizes of STEP_POWER_LEVELS."""
    progress(f"calibrated monitor: detection probability over {STEP_POWER_EDGES} steps per size")
    before, after, glitch = D.STEP_WINDOW
    power = step_power(STEP_POWER_SIZES, dt=D.DT, false_alarms_per_hour=D.STEP_FALSE_ALARMS_PER_HOUR, before=before,
                       after=after, glitch=glitch, edges=STEP_POWER_EDGES)
    reached = {f"{level:g}": next((size for size, p in zip(power["sizes"], power["probability"]) if p >= level), None)
               for level in STEP_POWER_LEVELS}
    return {**power, "smallest_size_reaching": reached}


def _robustness(progress) -> dict:
    """The FTC error over noise seeds (both substitution rules) and over heading laws (+30 deg, seed 0)."""
    seeds = {}
    for size in D.FAULT_SIZES_DEG:
        progress(f"FTC over {len(FTC_SEEDS)} noise seeds: +{size:g} deg")
        for mode in ("fault", "alarm"):
            seeds.setdefault(f"{size:g}", {})[mode] = _ftc_over_seeds(size, mode)
    progress("FTC under other heading laws")
    laws = {f"P, {b:g} rad/s": _max_error(Run(size_deg=30.0, bandwidth=b)) for b in BANDWIDTHS}
    laws["PI, triple pole at -1/(3T)"] = _max_error(Run(size_deg=30.0, integral=True))
    return {"seeds": list(FTC_SEEDS), "over_seeds": seeds, "heading_laws": laws}


def _steps(progress) -> list[dict]:
    """Per mu of STEPS (+30 deg, FTC once confirmed, seed 0): prediction error before the fault and
    the FTC error, or the time the loop diverged."""
    rows = []
    for mu in STEPS:
        progress(f"LMS step mu = {mu:g}")
        try:
            outcome = run(Run(size_deg=30.0, mu=mu))
        except SimulationError as exc:
            rows.append({"mu": mu, "diverged": str(exc).split(";")[0]})
            continue
        k = outcome.k
        before = (k >= 0) & (k < D.FAULT_SAMPLE)
        error = np.degrees(outcome.monitor("e_psi")[before])
        rows.append({"mu": mu, "rms_prediction_error_deg": float(np.sqrt(np.mean(error ** 2))),
                     "max_abs_heading_error_deg": _summary(outcome)["max_abs_heading_error_deg"]})
    return rows


def _learning(u: np.ndarray, outcome) -> dict:
    """How much the filter learns: input power, mu M P_u, adaptation time, prediction error before the fault."""
    k = outcome.k
    before = (k >= 0) & (k < D.FAULT_SAMPLE)
    deviation = np.degrees(outcome.result["y"]["psi"][before]) - D.SET_POINT_DEG
    error = np.degrees(outcome.monitor("e_psi")[before])
    power = float(np.mean(u ** 2))
    return {"input_power": power, "mu_M_P_u": D.MU * D.ORDER * power, "mu_bound": mu_bound(D.ORDER, power),
            "adaptation_samples": 1.0 / (2.0 * D.MU * power),
            "rms_measured_deviation_deg": float(np.sqrt(np.mean(deviation ** 2))),
            "rms_prediction_error_deg": float(np.sqrt(np.mean(error ** 2)))}


def build(out_dir: Path, progress) -> None:
    """Run the reproduction, the detection study and the campaign, export C, check the claims, write the report."""
    outcomes, summaries = _runs(progress)
    robustness = _robustness(progress)
    steps = _steps(progress)
    progress(f"detection study: {2 * 100} runs over noise seeds, ROC over thresholds")
    study = detection_study()
    campaign = campaign_results(out_dir, progress)
    progress("C package of the monitor: write, compile, compare")
    c = c_package(lms_set(), out_dir / "c")
    progress("machine-checked claims")
    claims = claim_rows(lms_claims())
    progress("figures")
    criteria_figure(outcomes[(30.0, "ftc")], out_dir / "fig3_criteria.svg")
    heading_figure({f"+{s:g} deg": outcomes[(s, "no_ftc")] for s in D.FAULT_SIZES_DEG},
                   out_dir / "fig4a_heading_without_ftc.svg", "Without fault-tolerant control", substitute=False)
    heading_figure({f"+{s:g} deg": outcomes[(s, "ftc")] for s in D.FAULT_SIZES_DEG},
                   out_dir / "fig4b_heading_with_ftc.svg",
                   "With fault-tolerant control (substitute read from the sample the fault is confirmed)",
                   substitute=True)
    roc_figure(study.roc, out_dir / "roc.svg")
    delay_figure(study.delays, out_dir / "detection_delay.svg")
    paper_run = summaries["30"]["ftc"]
    ftc = {size: summaries[size]["ftc"]["max_abs_heading_error_deg"] for size in ("30", "20", "10")}
    results = {
        "eps2_first_alarm_sample": paper_run["eps2_first_alarm_sample"],
        "R_first_alarm_sample": paper_run["R_first_alarm_sample"],
        "R_first_above_threshold_sample": paper_run["R_first_above_sample"],
        "heading_without_ftc_deg": {size: summaries[size]["no_ftc"]["settled_heading_deg"] for size in ftc},
        "max_abs_heading_error_with_ftc_deg": ftc,
        "max_abs_heading_error_with_ftc_on_alarm_deg": {size: summaries[size]["ftc_on_alarm"][
            "max_abs_heading_error_deg"] for size in ftc},
        "spike_classified_as": _classified(summaries["spike"]),
        "spike_substituted": summaries["spike"]["substituted_from_sample"] is not None,
        "transient": {size: _transient(outcomes[(float(size), "ftc")]) for size in ftc},
        "plant": {"yaw_time_constant_s": D.yaw_model(D.design().plant)[0],
                  "full_thrust_turn_deg_s": math.degrees(D.turn_rate(D.design().plant, 1.0))},
        "runs": summaries, "robustness": robustness, "steps": steps, "calibrated": _calibrated(progress),
        "learning": _learning(healthy_input(), outcomes[(30.0, "ftc")]),
        "study": {"seeds": study.seeds, "size_deg": SIZE_DEG, "within_samples": WITHIN, "roc": study.roc,
                  "nominal": study.delays, "r0_grid": list(R0_GRID)},
        "campaign": campaign, "paper": PAPER, "c": c, "claims": claims, "negative_factor": NEGATIVE_FACTOR,
        "choices": {"eps0_deg2": D.EPS0_DEG2, "r0": D.R0, "window": D.WINDOW, "hold": D.HOLD, "confirm": D.CONFIRM,
                    "bandwidth_rad_per_s": D.BANDWIDTH, "compass_noise_deg": D.COMPASS_NOISE_DEG,
                    "torque_noise_N_m": D.TORQUE_NOISE, "warm_up": D.WARM_UP, "record": D.RECORD,
                    "kp_per_rad": D.design().kp, "kp_per_deg": D.design().kp * math.pi / 180.0},
    }
    write_json(out_dir / "results.json", results)
    (out_dir / "report.md").write_text(report_text(results, paper("zhu-lms"), _rendered_step()))


def _rendered_step(order: int = 3) -> list[str]:
    """LaTeX lines of the bare LMS step of a small order, rendered from its CasADi graph."""
    def named(*entries) -> Signals:
        return Signals(tuple(entries), ("",) * len(entries))

    weights, inputs = (named(*(f"{b}_{i}" for i in range(1, order + 1))) for b in ("C", "U"))
    return function_equations(lms_step(order), [weights, inputs, named("y"), named("u"), named("mu")],
                              [(weights, "next"), (inputs, "next"), (named("d"), ""), (named("e"), "")])


def _classified(summary: dict) -> str:
    """"fault" when the spike run confirmed a fault, "disturbance" when it released the freeze, else "none"."""
    whats = [what for _, what in summary["events"]]
    if any(w.startswith("R alarm") for w in whats):
        return "fault"
    return "disturbance" if any(w.startswith("no R alarm") for w in whats) else "none"
