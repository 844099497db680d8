"""The Markdown of the LMS-FIR study's report, from its ``results.json`` data."""

from __future__ import annotations

import numpy as np

from derivations.sensor_fdi_lms import design as D
from uvsym.report import limits_block, markdown_table
from uvsym.report.sections import c_section, claims_table

__all__ = ["report_text", "limits_section"]


def _met(ok: bool) -> str:
    return "met" if ok else "**missed**"


def _targets(r: dict) -> list[list[str]]:
    p = r["paper"]
    rows = [["first eps^2 alarm (sample)", str(r["eps2_first_alarm_sample"]), str(p["eps2_first_alarm_sample"]),
             "= 70", _met(r["eps2_first_alarm_sample"] == 70)],
            ["first R alarm (sample)", str(r["R_first_alarm_sample"]), str(p["R_first_alarm_sample"]), "in [71, 80]",
             _met(r["R_first_alarm_sample"] is not None and 71 <= r["R_first_alarm_sample"] <= 80)]]
    for size, value in r["heading_without_ftc_deg"].items():
        paper_value = p["heading_without_ftc_deg"][size]
        rows.append([f"settled true heading without FTC, +{size} deg fault (deg)", f"{value:.2f}", f"{paper_value:g}",
                     f"{paper_value:g} +- 2", _met(abs(value - paper_value) <= 2)])
    for size, value in r["max_abs_heading_error_with_ftc_deg"].items():
        rows.append([f"max abs heading error with FTC, +{size} deg, 60 s after the fault (deg)", f"{value:.2f}",
                     "within [-3, 3]", "<= 3", _met(value <= 3)])
    rows.append(["one-sample disturbance classified as", r["spike_classified_as"], p["spike_classified_as"],
                 "disturbance, no substitution",
                 _met(r["spike_classified_as"] == "disturbance" and not r["spike_substituted"])])
    return rows


def _runs_table(r: dict) -> str:
    rows = []
    for size in ("30", "20", "10"):
        for label, name in (("no_ftc", "no FTC"), ("ftc", "FTC, substitute once confirmed"),
                            ("ftc_on_alarm", "FTC, substitute from the eps^2 alarm (Sec. 4.3)")):
            s = r["runs"][size][label]
            rows.append([f"+{size} deg", name, s["eps2_first_alarm_sample"], s["R_first_alarm_sample"],
                         "-" if s["substituted_from_sample"] is None else s["substituted_from_sample"],
                         f"{s['max_abs_heading_error_deg']:.2f}", f"{s['settled_heading_deg']:.2f}"])
    for label, name in (("spike", "one-sample +10 deg, substitute once confirmed"),
                        ("spike_on_alarm", "one-sample +10 deg, substitute from the alarm")):
        s = r["runs"][label]
        rows.append(["spike", name, s["eps2_first_alarm_sample"], s["R_first_alarm_sample"] or "-",
                     "-" if s["substituted_from_sample"] is None else s["substituted_from_sample"],
                     f"{s['max_abs_heading_error_deg']:.2f}", f"{s['settled_heading_deg']:.2f}"])
    return markdown_table(["fault", "run", "eps^2 alarm", "R alarm", "substituted from", "max abs error (deg)",
                           "settled heading (deg)"], rows)


def _by_size(errors: dict) -> str:
    """``+30 deg: 1.23 deg, ...`` of errors per fault size (deg)."""
    return ", ".join(f"+{size} deg: {value:.2f} deg" for size, value in errors.items())


def _miss(r: dict) -> str:
    """Why the FTC errors are what they are: the faulty samples the loop acts on, the turn they start, the drift."""
    missed = {size: v for size, v in r["max_abs_heading_error_with_ftc_deg"].items() if v > 3.0}
    verdict = ("Missed: " + ", ".join(f"+{size} deg by {v - 3.0:.2f} deg ({v:.2f} deg)" for size, v in missed.items())
               + "." if missed else "Every FTC row is within 3 deg.")
    t30, plant, run30 = r["transient"]["30"], r["plant"], r["runs"]["30"]["ftc"]
    rows = []
    for size, t in r["transient"].items():
        run = r["runs"][size]["ftc"]
        rows.append([f"+{size} deg", t["faulty_samples"], f"{t['command']:.4f}", f"{t['steady_turn_deg_s']:.2f}",
                     f"{t['peak_yaw_rate_deg_s']:.2f}", f"{t['error_at_switch_deg']:.2f}",
                     f"{t['error_after_transient_deg']:.2f}",
                     f"{run['max_abs_heading_error_deg']:.2f} ({run['max_abs_heading_error_sample']})"])
    table = markdown_table(["fault", "faulty samples acted on", "command u", "steady turn at u (deg/s)",
                            "peak yaw rate (deg/s)", "error at the switch (deg)", "error 2 s later (deg)",
                            "max abs error (deg) (at sample)"], rows)
    last = D.FAULT_SAMPLE + t30["faulty_samples"] - 1
    return f"""{verdict} The heading law still acts on the faulty reading for {t30['faulty_samples']} samples
({D.FAULT_SAMPLE}-{last}): $R$ first exceeds $r_0$ at {run30['R_first_above_sample']} and its alarm needs {D.HOLD}
samples in a row, so the fault is confirmed, and the substitute read, from {run30['substituted_from_sample']}
(a switch from the next sample would add one more). On those samples the controller commands $k_p$
times the fault, and the proxy turns fast (a steady {plant['full_thrust_turn_deg_s']:.0f} deg/s at full thrust,
yaw time constant {plant['yaw_time_constant_s']:.2f} s): within {t30['faulty_samples'] * D.DT:g} s it nearly reaches
the steady turn of that command. After the switch the substitute is the set-point (the filter has
not learned, see Set-up), so the controller commands nothing and the vehicle coasts until its
damping stops it. The rest of the error is the drift the yaw torque causes while the heading is
not measured: the paper's rule, whose controller never reads the faulty compass, shows that drift
alone. Seed 0:

{table}

The plant, the controller gain, the thresholds, the confirmation rule and the noise are those of the
rest of this report, not tuned to meet the target."""


def _nominal(r: dict) -> str:
    rows = []
    for name, v in r["study"]["nominal"].items():
        delays = v["delays"]
        rows.append([name, f"{v['detection_probability']:.2f}", f"{v['false_alarm_rate']:.2f}",
                     f"{min(delays)} / {sorted(delays)[len(delays) // 2]} / {max(delays)}" if delays else "-"])
    return markdown_table(["detector", "detection probability", "false-alarm rate", "delay min / median / max"],
                          rows)


def _robustness(r: dict) -> str:
    rob = r["robustness"]
    rows = []
    for size, modes in rob["over_seeds"].items():
        for mode, name in (("fault", "once confirmed"), ("alarm", "from the eps^2 alarm")):
            errors = sorted(modes[mode]["max_abs_error_deg"])
            rows.append([f"+{size} deg", name, f"{errors[0]:.2f}", f"{errors[len(errors) // 2]:.2f}",
                         f"{errors[-1]:.2f}", f"{modes[mode]['within_3_deg']} of {len(errors)}",
                         f"{modes[mode]['confirmed']} of {len(errors)}"])
    seeds = markdown_table(["fault", "substitution", "min", "median", "max", "runs within 3 deg",
                            "runs where R confirmed"], rows)
    on_alarm = [modes["alarm"]["confirmed"] for modes in rob["over_seeds"].values()]
    confirmed = ("$R$ confirmed the fault in every run" if min(on_alarm) == len(rob["seeds"]) else
                 f"$R$ confirmed the fault in {' / '.join(map(str, on_alarm))} of {len(rob['seeds'])} runs "
                 f"(+{' / +'.join(rob['over_seeds'])} deg)")
    laws = markdown_table(["heading law", "max abs error (deg), +30 deg, substitution once confirmed"],
                          [[law, f"{value:.2f}"] for law, value in rob["heading_laws"].items()])
    return f"""Largest heading error in the 60 s after the fault over noise seeds {rob['seeds'][0]}-{rob['seeds'][-1]}
(compass noise and yaw torque), in deg:

{seeds}

Substituting from the $\\varepsilon^2$ alarm in the same sample, the controller never reads the
faulty compass: where $R$ confirms, its error is the drift of the unmeasured heading under the yaw
torque, the same for every fault size. {confirmed} (the weights drift with $e_k U_k$, the large error
times the past commands, whether or not the loop reacts); an unconfirmed freeze is released after
{D.CONFIRM} samples and the faulty sensor switched back in. Substituting once confirmed lets the loop act on
the fault for {r['runs']['30']['ftc']['substituted_from_sample'] - D.FAULT_SAMPLE} samples.

And under other heading laws (seed 0): the error grows with the law's gain, which acts on the
faulty reading until the substitution; an integral term, wound up on those samples, keeps
turning the vehicle once the sensor is replaced by a prediction that does not see the heading:

{laws}"""


def _steps(r: dict) -> str:
    rows = [[f"{row['mu']:g}", f"{r['learning']['input_power'] * row['mu'] * D.ORDER:.3g}",
             f"{row['rms_prediction_error_deg']:.3f}" if "diverged" not in row else "-",
             f"{row['max_abs_heading_error_deg']:.2f}" if "diverged" not in row else row["diverged"]]
            for row in r["steps"]]
    return markdown_table(["mu", "mu M P_u (healthy P_u)", "RMS prediction error before the fault (deg)",
                           "max abs heading error with FTC, +30 deg (deg)"], rows)


DETECTOR_NAMES = {"double_criterion": "double criterion (the paper's)", "error_threshold": "error threshold alone",
                  "step_test": "sensor-step monitor (calibrated)"}
ISOLATES = {"double_criterion": True, "error_threshold": False, "step_test": True}  # the threshold detects only


def _shown(value, digits: int = 3) -> str:
    return "-" if value is None else f"{value:.{digits}g}" if isinstance(value, float) else str(value)


def _detector_table(figures: dict) -> str:
    rows = [[DETECTOR_NAMES[d], f["fault_runs"], _shown(f["detection_probability"]), f["missed_detections"],
             _shown(f["median_detection_delay_s"]),
             _shown(f["correct_isolation"]) if ISOLATES[d] else "- (detects only)", f["false_alarms"],
             _shown(f["healthy_hours"]), _shown(f["false_alarms_per_hour"])] for d, f in figures.items()]
    return markdown_table(["detector", "fault runs", "detection probability", "missed", "median delay (s)",
                           "correct isolation", "false alarms", "healthy hours", "false alarms per hour"], rows)


def _case_table(cases: dict) -> str:
    rows = [[case, DETECTOR_NAMES[d], f["runs"], _shown(f["detection_probability"]), f["missed_detections"],
             _shown(f["median_detection_delay_s"]), f["false_alarms"], _shown(f["false_alarms_per_hour"])]
            for case, figures in cases.items() for d, f in figures.items()]
    return markdown_table(["case", "detector", "runs", "detection probability", "missed", "median delay (s)",
                           "false alarms", "false alarms per hour"], rows)


def _size_table(groups: list[dict]) -> str:
    rows = [[f"{g['size_deg']:g}", f"{g['noise_deg']:g}", g["runs"],
             *(f"{g[d]['detected']} / {g[d]['false_alarms']}" for d in DETECTOR_NAMES)] for g in groups]
    return markdown_table(["bias (deg)", "compass noise (deg)", "runs",
                           *(f"{name}: detected / false alarms before the onset" for name in DETECTOR_NAMES.values())],
                          rows)


def _healthy_table(groups: list[dict], designed: dict) -> str:
    """False alarms in the healthy hours, and per hour, per compass noise and detector; the designed rates below."""
    rows = [[f"{g['noise_deg']:g}", g["double_criterion"]["runs"],
             *(f"{g[d]['false_alarms']} in {_shown(g[d]['healthy_hours'])} h: {_shown(g[d]['false_alarms_per_hour'])}"
               for d in DETECTOR_NAMES)] for g in groups]
    rows.append(["designed", "", *(_shown(designed[d]) for d in DETECTOR_NAMES)])
    return markdown_table(["compass noise (deg)", "runs", *DETECTOR_NAMES.values()], rows)


def _limits_table(groups: list[dict]) -> str:
    """Per compass noise and detector, the smallest bias step detected in every run from it up, and the median delay."""
    def cell(item: dict) -> str:
        seen = (f"{item['seen_from']:g} deg" if item["seen_from"] is not None else
                f"none (missed at {item['missed_up_to']:g} deg)")
        return seen + ("" if item["median_delay_s"] is None else f"; {item['median_delay_s']:.3g} s")

    rows = [[f"{g['noise_deg']:g}", channels[0]["channel"], *map(cell, channels)]
            for g in groups for channels in zip(*(g[d] for d in DETECTOR_NAMES))]
    return markdown_table(["compass noise (deg)", "sensor", *DETECTOR_NAMES.values()], rows)


def _pulse_table(pulses: list[dict]) -> str:
    return markdown_table(["bias pulse of +20 deg (samples)", "runs",
                           *(f"{name}: confirmed" for name in DETECTOR_NAMES.values())],
                          [[p["samples"], p["runs"], *(p[d] for d in DETECTOR_NAMES)] for p in pulses])


def _campaign(k: dict) -> str:
    """The campaign section: per detector overall, per case, the bias steps by size and noise, the failures."""
    healthy, setpoints = k["cases"]["no fault"], k["cases"]["set-point changes, no fault"]
    errors = ", ".join(f"{e['case']}: {e['error']}" for e in k["errors"]) or "none"
    return f"""## Campaign: the faults, noise and set-points a user meets

[campaign.toml](../../derivations/sensor_fdi_lms/campaign.toml) runs the shipped scenario `compass_20deg`
(heading hold at 150 deg, fault-tolerant control, the 100 s warm-up that trains the filter, then the
record) {k['runs']} times, {k['simulated_hours']:.3g} simulated hours; `uvsym campaign
derivations/sensor_fdi_lms/campaign.toml` runs the same file (one line per run in
[campaign_results.csv](campaign_results.csv)). Runs that ended in an error: {errors}. Three detectors watch
the same runs: the paper's double criterion (`[[detectors]] type = "lms"`), its error criterion alone
as a residual threshold (`type = "threshold"` on `lms.e_psi`, sigma from the 0.5 deg compass noise
through the loop, designed for 1 false alarm per hour, 3 samples to confirm) and the calibrated
sensor-step monitor (`type = "sensor_step"`, the section after this one; it only decides here, the
substitution follows the double criterion). The first two are not retuned when the campaign raises
the noise; the step monitor is told it. The compass is the only sensor the method
covers. Delays count from the onset (s); a false alarm is an alarm outside a fault's window (one per
decision: a detection and an isolation at one sample count once). Healthy hours include the warm-up
and the time before every onset. The double criterion latches a confirmed fault, so a run holds at
most one of its false alarms.

Overall (every case):

{_detector_table(k["detectors"])}

Long healthy runs at a constant set-point ({healthy['double_criterion']['runs']} half-hour runs at 0.5, 1 and
1.5 deg compass noise): the double criterion raises {healthy['double_criterion']['false_alarms']} false alarms
({_shown(healthy['double_criterion']['false_alarms_per_hour'])} per hour), the error threshold
{healthy['error_threshold']['false_alarms']} ({_shown(healthy['error_threshold']['false_alarms_per_hour'])} per
hour). Heading set-point changes (150 deg to 140, 153.5, 155, 170, 210, 320 or 30 deg, no fault): the double criterion
raises {setpoints['double_criterion']['false_alarms']} false alarms in {setpoints['double_criterion']['runs']} runs,
the error threshold {setpoints['error_threshold']['false_alarms']}. The long healthy runs by compass noise, beside
the designed rates, are under Limits below.

Per case:

{_case_table(k["cases"])}

Bias steps by size and compass noise (onsets drawn in [110, 150] s):

{_size_table(k["bias_by_size"])}

Where the method fails, and why, is stated under Limits below.
"""


def _size(cal: dict, level: str) -> str:
    """The smallest step of the power table reaching detection probability ``level``, in std and deg."""
    size = cal["power"]["smallest_size_reaching"][level]
    return (f"more than {max(cal['power']['sizes']):g} noise std" if size is None
            else f"{size:g} noise std ({size * D.COMPASS_NOISE_DEG:g} deg)")


def _calibrated(r: dict) -> str:
    """The calibrated sensor-step monitor: its rule and design, and the campaign's figures beside them."""
    cal, k = r["calibrated"], r["campaign"]
    healthy = {g["noise_deg"]: g["step_test"] for g in k["healthy_by_noise"]}
    designed = cal["false_alarms_per_hour"]
    rates = markdown_table(
        ["compass noise (deg, told to the monitor)", "healthy hours", "false confirmations", "per hour, measured",
         "per hour, designed bound", "per test, designed bound"],
        [[f"{noise:g}", _shown(f["healthy_hours"]), f["false_alarms"], _shown(f["false_alarms_per_hour"]),
          f"{designed:g}", f"{cal['per_test_probability']:.3g}"] for noise, f in healthy.items()])
    setpoints = k["cases"]["set-point changes, no fault"]["step_test"]
    errors = cal["max_abs_heading_error_deg"]
    worst = {size: max(e) for size, e in errors.items()}
    ftc = markdown_table(["fault", "seeds", "max abs heading error, worst seed (deg)", "median (deg)", "within 3 deg"],
                         [[f"{float(size):+g} deg", len(e), f"{max(e):.2f}", f"{float(np.median(e)):.2f}",
                           f"{sum(v <= 3.0 for v in e)} of {len(e)}"] for size, e in errors.items()])
    power = markdown_table(["step (noise std)", "step (deg)", "detection probability"],
                           [[f"{size:g}", f"{size * D.COMPASS_NOISE_DEG:g}", f"{p:.2f}"]
                            for size, p in zip(cal["power"]["sizes"], cal["power"]["probability"])])
    return f"""## Calibrated decisions (beyond the paper)

The double criterion's thresholds are choices that fit the paper's runs; its false alarms are not
designed. The **sensor-step monitor** (`uvsym.observers.step_monitor`, block `sensor_step`, switched in
with `decision = "calibrated"`; scenario `compass_calibrated`) decides from a stated noise model
instead: the heading of a vehicle is continuous, so a compass bias is a *step* in the measured
heading, while a set-point change only bends it (a kink in the heading, through the commands) and a
glitch comes back. On a window of {cal['window'][0]} samples before a candidate step and
{cal['window'][1]} after, the step model is tested against every healthy model (a quadratic trend,
the trend with a kink anywhere, the trend with a glitch of up to 3 samples anywhere); under white
Gaussian compass noise of the told standard
deviation the statistic of a healthy window is bounded by a chi-square with 2 degrees of freedom,
so the threshold h = -2 ln(F dt / 3600) = {cal['threshold']:.4g} bounds the false confirmations by
F = {designed:g} per hour ({cal['per_test_probability']:.3g} per test). The substitute is the compass
minus the confirmed offset, from the first alarm; a confirmed offset that steps back clears the
fault and ends the substitution.

Designed and measured false confirmations (the campaign's long healthy runs; the monitor is told the
noise of each row, the double criterion and the error threshold are not):

{rates}

Set-point changes (150 deg to 140, 153.5, 155, 170, 210, 320 or 30 deg, {setpoints['runs']} runs):
{setpoints['false_alarms']} confirmed as a compass fault (the double criterion:
{k['cases']['set-point changes, no fault']['double_criterion']['false_alarms']}). Pulses of +20 deg:

{_pulse_table(k["pulses"])}

With the monitor switching the substitute (the paper's three faults and -30 deg, {len(next(iter(errors.values())))}
noise seeds), the largest heading error in the 60 s after the onset -- worst
{max(worst.values()):.2f} deg against the paper's +-3 deg (the double criterion once confirmed:
{r['max_abs_heading_error_with_ftc_deg']['30']:.2f} deg at +30 deg, seed 0):

{ftc}

What it cannot see (by construction): a drift or a ramp (a kink, what a turn looks like), a compass
stuck where the heading stays anyway, and small steps: a step is told from a fast turn only by the
trend before and after it, so the window ({cal['window'][0]} samples before, {cal['window'][1]} after: the
decision comes {cal['window'][1] * D.DT:g} s after the step) sets the smallest step it confirms. Its detection
probability per step size, by Monte Carlo of the monitor itself on flat records of white noise
({cal['power']['edges']} steps per size; numerical evidence, and a turning heading makes it harder; sizes in
noise standard deviations, and in deg at the study's {D.COMPASS_NOISE_DEG:g} deg):

{power}

At least half the steps of {_size(cal, "0.5")} are confirmed, nine in ten of {_size(cal, "0.9")} (the smallest
sizes tried that reach it; the campaign's bias table shows them in the loop).
"""


def _detected(k: dict, case: str) -> str:
    """``detected/runs`` of the campaign's ``case`` per detector, in the order of DETECTOR_NAMES."""
    figures = k["cases"][case]
    return ", ".join(f"{figures[d]['fault_runs'] - figures[d]['missed_detections']}/{figures[d]['fault_runs']}"
                     for d in DETECTOR_NAMES)


def limits_section(r: dict) -> str:
    """The measured limits, the report's one limits block (a doc page includes it): the smallest compass fault
    and its delay, false alarms per hour beside the designed rates, set-point changes and glitches, and what the
    detectors cannot see."""
    k, cal = r["campaign"], r["calibrated"]
    healthy, setpoints = k["healthy_by_noise"], k["cases"]["set-point changes, no fault"]
    multiples = " and ".join(f"{g['noise_deg'] / D.COMPASS_NOISE_DEG:g}" for g in healthy
                             if g["noise_deg"] != D.COMPASS_NOISE_DEG)
    latched = [f"{g['noise_deg']:g}" for g in healthy
               if g["double_criterion"]["false_alarms"] >= g["double_criterion"]["runs"] > 0]
    bound = (f"at {' and '.join(latched)} deg every run alarmed, so the rate there is a lower bound" if latched else
             "no noise level had every run alarm, so no rate is cut short by it")
    sizes = sorted({size for g in k["bias_limits"] for item in g["double_criterion"] for size, _, _ in item["sizes"]})
    runs = sorted({n for g in k["bias_limits"] for item in g["double_criterion"] for _, n, _ in item["sizes"]})
    before, after, glitch = cal["window"]
    confirm = r["R_first_alarm_sample"] - D.FAULT_SAMPLE
    return "## Limits (measured by this report's campaign)\n\n" + limits_block(f"""
The compass is the only sensor the method covers. Three detectors watch the same {k['runs']} runs of the
campaign: the paper's double criterion, its error criterion alone as a threshold, and the calibrated
sensor-step monitor.

**Smallest compass fault and delay.** Bias steps of {", ".join(f"{s:g}" for s in sizes)} deg,
{" to ".join(map(str, runs))} runs per size and compass noise: the smallest size detected in every run of
it and of every larger size, and the median delay of the detected runs (s after the onset):

{_limits_table(k["bias_limits"])}

In the paper's +30 deg run the double criterion confirms the fault {confirm} samples
({confirm * D.DT:g} s) after the onset ($R$ must stay above $r_0$ on {D.HOLD} samples in a row); the step
monitor decides on {after} samples after a candidate step and, on flat records of white noise,
confirms half the steps of {_size(cal, "0.5")} and nine in ten of {_size(cal, "0.9")}.

**False alarms per hour** on the long healthy runs at a constant set-point, at the study's compass noise
of {D.COMPASS_NOISE_DEG:g} deg and {multiples} times it ("false alarms in healthy hours: per hour"),
and the rate each detector is designed for: the double criterion's thresholds are chosen, not designed;
the error threshold is designed for {D.COMPASS_NOISE_DEG:g} deg and kept when the noise rises; the step
monitor's rate is a bound at the noise it is told:

{_healthy_table(healthy, k["designed_per_hour"])}

A run of the double criterion holds one false alarm at most (a confirmed fault latches): {bound}.

**Set-point changes and glitches.** Heading set-point changes without a fault ({setpoints['double_criterion']['runs']}
runs) raise these false alarms: {", ".join(f"{name}: {setpoints[d]['false_alarms']}" for d, name in
                                          DETECTOR_NAMES.items())}. Bias pulses, the shortest of them glitches:

{_pulse_table(k["pulses"])}

**What it cannot see, and why** (detected / runs of the double criterion, the error threshold and the
step monitor):

- **Set-point changes**, to the double criterion: the filter predicts the deviation $y - r$
  from past commands; a set-point step is a step of $y - r$ that no past command explains, which is what
  a compass bias looks like, and the weights drift while the vehicle turns, so $R$ confirms it. With
  fault-tolerant control the loop then reads the frozen filter instead of a healthy compass.
- **Small steps.** Biases of the order of $\\sqrt{{\\varepsilon_0}}$ = {D.EPS0_DEG2 ** 0.5:g} deg are seen by the
  error criterion by chance or not at all; the step monitor tells a step from a fast turn only by the trend
  before and after it, so its window ({before} samples before, {after} after) sets the smallest step it confirms.
- **Slow faults**: ramps ({_detected(k, "ramp")}), incipient faults ({_detected(k, "incipient")}) and drifts
  ({_detected(k, "drift")}). The slower ones stay under $\\varepsilon_0$ sample by sample while the loop follows
  them; to the step monitor a slow fault is a kink, which is what a turn looks like.
- **A stuck compass** ({_detected(k, "stuck")}): near the set-point the frozen reading is what the filter
  predicts, so $e$ stays small while the true heading wanders under the yaw torque; it holds no step.
- **Noise above the design.** At {multiples} times the compass noise the error criterion fires on noise
  and freezes the filter often; a confirmation window that starts from a noise alarm can let a fault
  pass, or confirm noise as a fault. The threshold and the double criterion are not retuned for it.
- **Glitches** are released by design: by the double criterion as disturbances (the paper's one-sample
  spike), by the step monitor up to {glitch} samples; to the campaign's metrics a glitch unconfirmed is a
  missed fault.""")


def report_text(r: dict, source, step_lines: list[str]) -> str:
    """The report (Markdown) from the results ``r``, the paper ``source`` (derivations.papers.Paper)
    and the LaTeX lines of the bare LMS step of a small order."""
    c, learning, study = r["choices"], r["learning"], r["study"]
    negative = next(row for row in r["claims"] if row["expected"] == "refuted")
    return f"""# Sensor-fault diagnosis with an adaptive LMS-FIR filter, and fault-tolerant heading hold

Reproduction of {source.short}: {source.reference()}

An adaptive FIR filter (order M = {D.ORDER}, LMS step mu = {D.MU:g}) learns the compass from the thrust
command in heading hold at {D.SET_POINT_DEG:g} deg; two criteria watch it, the error criterion
$\\varepsilon^2(k)$ (fast, fooled by disturbances) and the weight-drift statistic $R(k)$ (robust, lagging);
on the first $\\varepsilon^2$ alarm the filter is frozen, and if $R$ also fires the frozen filter's
prediction replaces the compass in the heading loop. The estimator is `uvsym.observers.lms.lms_monitor`,
one CasADi step (simulated, exported as C below); the decision is
`uvsym.observers.lms_supervisor`, and the switch to the substitute the block `uvsym.sim.blocks.select`.
Every number below is computed by the run that wrote this report.

## Paper versus reproduction

{markdown_table(["quantity", "reproduced", "paper", "target", "status"], _targets(r))}

$R$ first exceeds $r_0$ at sample {r['R_first_above_threshold_sample']}, the first sample whose window holds
the filter updated on the faulty sample; its alarm needs {D.HOLD} samples in a row above $r_0$ (see
Method), so {r['R_first_above_threshold_sample'] + D.HOLD - 1} is the earliest it can come (the paper does not say
what sets its own lag of 5 samples).

The FTC rows use the rule of the issue this study answers: substitute once the double criterion
confirms the fault (so that a disturbance never switches the sensor). The switch is made inside the
loop, in the same sample: a block (`uvsym.sim.blocks.select`) publishes
$\\psi_{{sel}}$ = `fault_psi ? psi_sub : psi` and the controller reads it. This is causal: the frozen
filter's prediction for sample k uses the inputs up to k - 1 only, and the fault flag of sample k is
computed from $y_k$ (the monitor's outputs do not depend on the command $u_k$ it reads, so no algebraic
loop), so the controller acts on the substitute from the very sample $R$ confirms the fault
({r['runs']['30']['ftc']['confirmed_sample']}), not the one after. The paper's own experiment (Sec. 4.3, L625-630)
substitutes from the first $\\varepsilon^2$ alarm (`frozen_psi ? psi_sub : psi`); with that rule the
largest errors are {_by_size(r["max_abs_heading_error_with_ftc_on_alarm_deg"])},
but a one-sample disturbance then switches the sensor out for {r['runs']['spike_on_alarm']['substituted_samples']}
samples.

{_miss(r)}

Every run (recorded samples from the start of the record, the fault at {D.FAULT_SAMPLE}):

{_runs_table(r)}

## Method (paper eqs. 3-12, with the choices where it is silent or garbled)

$$ U_k = [u_{{k-1}}, \\dots, u_{{k-M}}]^T,\\quad d_k = C_k^T U_k,\\quad e_k = d_k - (y_k - r_k),\\quad
C_{{k+1}} = C_k - 2 \\mu e_k U_k $$

$$ \\varepsilon^2(k) = e_k^2 > \\varepsilon_0,\\qquad S_k = \\textstyle\\sum_i C_{{i,k}},\\quad
R(k) = \\frac{{(S_k - \\bar S)^2}}{{\\operatorname{{var}} S}} \\text{{ over }} S_{{k-n+1}}, \\dots, S_k,\\quad R > r_0
\\text{{ on }} h \\text{{ samples in a row}} $$

The step as uvsym builds it (`uvsym.observers.lms.lms_step`), rendered from its CasADi graph for
M = 3 (y stands for $y - r$; $^+$ marks the next sample's value):

{chr(10).join(f"$$ {line} $$" for line in step_lines)}

- **Sign of the update.** The paper prints $C_{{k+1}} = C_k + 2\\mu e(k) u(k)$ with $e = d - y$ (L137, L141),
  which climbs the squared error; the step here descends it.
- **Regression vector.** The paper's $u(k+1-i)$ starts at $u(k)$; in the sampled loop $u_k$ is computed from
  $y_k$, so a substitute built from it would feed back on itself within the sample. $U_k$ starts at $u_{{k-1}}$.
- **Offset.** A filter fed by a heading-hold command cannot output 150 deg: it regresses the deviation
  $y - r$ from the set-point $r$, and its substitute is $r + d$.
- **R.** As printed (L398-419) $V$ is already standardised, so $R = (V - \\bar V)^2 / \\operatorname{{std}}(V)^2$ is
  the squared z-score of the newest weight-sum drift in its window; the offset $C_0$ cancels. Window
  n = {c['window']} samples, population variance, $C_k$ the filter in use at sample k (trained on the samples
  before it, as in eq. 5), so $R$ sees the fault one sample after $\\varepsilon^2$.
- **Persistence of R (finding).** A single large error moves the weight sum once; the newest sum's squared
  z-score is then exactly $n - 1$ = {c['window'] - 1} whatever the error's size, so $R > r_0$ as printed cannot
  tell a one-sample disturbance from a fault (the paper says it can, L567-574). A fault keeps the weights
  drifting: the R alarm here needs $R > r_0$ on h = {c['hold']} samples in a row.
- **Double criterion.** $R$ has {c['confirm']} samples after the $\\varepsilon^2$ alarm to confirm it; otherwise
  the freeze is released (a disturbance) and the next $\\varepsilon^2$ alarm freezes anew.
- **Thresholds** (not in the paper): $\\varepsilon_0$ = {c['eps0_deg2']:g} deg^2 (3 deg, the paper's FTC tolerance),
  $r_0$ = {c['r0']:g} (a z-score of 3).

## Set-up (the paper's fault and sample period; the rest uvsym's choices)

- **Fault**: the paper's "fixed drift" fault is a constant added to the measured heading from sample
  70 on (L508-521): uvsym's sensor fault kind `bias` with a step profile.
- **Vehicle**: the Outland 1000's parameters are not published; `uvsym.plant("rov_yaw")`, the VideoRay Pro
  III yaw (Wang 2006), thrust command $u \\in [-1, 1]$, sample period {D.DT:g} s (L563).
- **Controller**: the paper's PID (gains not given) as a proportional law $u = k_p (r - y)$,
  $k_p$ = {c['kp_per_deg']:.4g} per deg (natural frequency {c['bandwidth_rad_per_s']:g} rad/s of the linearised loop,
  no overshoot). An integral term winds up on the faulty samples before the fault is confirmed and,
  once the sensor is replaced by a prediction that does not see the heading, turns the vehicle
  open loop; a derivative term kicks at the switch.
- **Excitation and noise**: compass noise {c['compass_noise_deg']:g} deg (standard deviation), white yaw torque
  {c['torque_noise_N_m']:g} N m held over each sample, seeded. The filter starts at zero weights and trains
  for {c['warm_up']} samples before the record of {c['record']} samples starts. The torque is drawn from its own
  seeded stream, independent of the compass noise (`[noise] tau_d` of a scenario file).
- **Scenario files**: the runs of the paper are `scenarios/compass_10deg.toml`, `compass_20deg.toml`,
  `compass_30deg.toml` and `compass_spike.toml` (`uvsym simulate compass_30deg` prints each detector's
  decisions). One `duration` of {(c['warm_up'] + c['record']) * D.DT:g} s holds the warm-up and the record:
  recorded sample k is at t = ({c['warm_up']} + k) {D.DT:g} s, so the fault at sample {D.FAULT_SAMPLE} starts at
  {(c['warm_up'] + D.FAULT_SAMPLE) * D.DT:g} s. They give the runs of this report to 1e-9 (tests).

**How much the filter learns (finding).** In heading hold the command is small: its power in the
record is $P_u$ = {learning['input_power']:.3g}, so $\\mu M P_u$ = {learning['mu_M_P_u']:.3g} and the LMS adaptation
time $1 / (2 \\mu P_u)$ is {learning['adaptation_samples']:.3g} samples. With the paper's $\\mu$ the filter stays
at its initial weights: its prediction error before the fault, {learning['rms_prediction_error_deg']:.3g} deg RMS,
equals the measured deviation from the set-point, {learning['rms_measured_deviation_deg']:.3g} deg RMS. The
frozen filter's substitute is then the set-point itself: after the switch the controller sees no
error and commands nothing, and the heading error is the transient before the switch plus the
drift the yaw torque causes while the heading is not measured. The $\\varepsilon^2$ and $R$ criteria do
not need a trained filter (a step in the measurement is a step in $e$).

A larger step lets the filter learn, but there is little to learn: in heading hold the past
commands predict the heading no better than the set-point does, and a filter trained on the loop's
noise predicts worse. After the fault the controller's reaction raises the command's power, so a
step below the healthy run's bound can be beyond the faulty run's (the last row):

{_steps(r)}

### Fault-tolerant control: noise seeds and heading laws

{_robustness(r)}

![criteria](fig3_criteria.svg)

![heading without FTC](fig4a_heading_without_ftc.svg)

![heading with FTC](fig4b_heading_with_ftc.svg)

## Beyond the paper: detection over thresholds and noise seeds

{study['seeds']} runs with a +{study['size_deg']:g} deg compass fault at sample {D.FAULT_SAMPLE} and
{study['seeds']} runs with a one-sample +{study['size_deg']:g} deg disturbance there, each with its own noise
seed, without FTC. A fault run is detected when the detector fires within {study['within_samples']} samples of
the onset; a disturbance run with any firing in its record is a false alarm. Thresholds:
$\\varepsilon_0$ from 0.25 to 400 deg^2 ($\\varepsilon^2$ alone), $r_0$ from {study['r0_grid'][0]:g} to
{study['r0_grid'][-1]:g} ($R$ alone, and the double criterion at $\\varepsilon_0$ = {c['eps0_deg2']:g} deg^2).

![ROC](roc.svg)

At the nominal thresholds:

{_nominal(r)}

![detection delay](detection_delay.svg)

{_campaign(r["campaign"])}

{_calibrated(r)}

{limits_section(r)}

## Machine-checked claims

{claims_table(r["claims"])}

The step-size claim takes $P_u$ as the mean square of the healthy run's recorded command and decides
$\\mu M P_u < 1$ in exact rational arithmetic on the samples' binary values (the mean-square bound of
independence theory, Widrow & Stearns 1985, $\\operatorname{{tr}} R_{{UU}} = M P_u$). The negative control
$\\mu$ = {r['negative_factor']:g} / (M P_u) is refuted as it must be: exact $\\mu M P_u$ =
{1 - negative['margin']:g} (margin {negative['margin']:g}).
`uvsym simulate` warns (`StepSizeWarning`, with the bound) when a scenario's $\\mu$ is at or beyond the
bound of its own run's input power (the `lms` detector checks it on the record).

## Generated C

{c_section(r["c"], "The monitor's step (the LMS update, both criteria, the freeze and the double criterion) "
                   "and the bare LMS step it is built on")}
"""
