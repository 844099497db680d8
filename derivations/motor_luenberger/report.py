"""``report.md``, ``results.json`` and figures of the motor observer study."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from derivations.motor_luenberger.claims import SLOW_DT, motor_claims
from derivations.motor_luenberger.design import DECAY, design
from derivations.motor_luenberger.experiment import (
    CALIBRATION_SEEDS,
    CONFIRM,
    CONVERGED_AFTER,
    FAULT_ONSET,
    INCIPIENT_RATE,
    INITIAL_OFFSET,
    NOISE,
    SENSOR_GAIN,
    THRESHOLD_FACTOR,
    run_cases,
)
from derivations.motor_luenberger.observer_sets import motor_luenberger
from derivations.papers import paper
from uvsym.report import latex_matrix, markdown_table, save_svg, write_json
from uvsym.report.equations import observer_equations
from uvsym.report.sections import c_package, c_section, claim_rows, claims_table, counterexamples

__all__ = ["build"]

OBSERVER = "luenberger"
YU = paper("yu2018")


def _estimation_errors(result) -> list[dict]:
    """Per state: RMS of x - xhat over the converged, fault-free part, in the state's unit."""
    d = design()
    window = (result.t >= CONVERGED_AFTER) & (result.t < FAULT_ONSET)
    return [{"state": name, "unit": unit, "rms_error": float(np.sqrt(np.mean(
        (result["x"][name][window] - result[OBSERVER][f"{name}_hat"][window]) ** 2)))}
        for name, unit in zip(d.plant.x.names, d.plant.x.units)]


def _figure(cases: dict, path: Path, stride: int = 20) -> None:
    """Speed estimate and speed residual of the three runs, with the threshold (every ``stride``-th sample)."""
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    for (name, result), colour in zip(cases["results"].items(), ("k", "C3", "C0")):
        t = result.t[::stride]
        top.plot(t, result["y"]["omega_m"][::stride], colour, lw=0.5, alpha=0.4)
        top.plot(t, result[OBSERVER]["omega_m_hat"][::stride], colour, lw=1.2, label=f"{name}: estimate")
        bottom.plot(t, result[OBSERVER]["r_omega_m"][::stride], colour, lw=0.8, label=name)
    for sign in (-1, 1):
        bottom.axhline(sign * cases["threshold"], color="grey", ls="--", lw=1)
    top.plot(t, result["x"]["omega_m"][::stride], "C2", lw=1, label="true speed")
    top.set_ylabel("speed (rad/s)")
    top.legend(fontsize=7, loc="upper left")
    bottom.set_ylabel("residual r (rad/s)")
    bottom.set_xlabel("time (s)")
    bottom.legend(fontsize=7, loc="upper left")
    top.set_title(f"Speed: measured (faint), estimated; residual with threshold (dashed); every {stride}th sample",
                  fontsize=9)
    save_svg(fig, path)


def build(out_dir: Path, progress) -> None:
    """Design, simulate, export, verify and write the report into ``out_dir``."""
    progress("design: linearisation at the operating point, LMI gain")
    d = design()
    progress("closed loop: fault-free, step and incipient speed-sensor faults")
    cases = run_cases()
    progress("C package of the observer: write, compile, compare")
    c = c_package(motor_luenberger(), out_dir / "c")
    progress("machine-checked claims")
    claims = claim_rows(motor_claims())
    progress("figures")
    _figure(cases, out_dir / "speed_residual.svg")
    results = {"decay_per_s": DECAY, "dt_s": d.observer.dt, "L": d.synthesis.L.tolist(),
               "eigenvalues_A_minus_LC": [[float(v.real), float(v.imag)] for v in sorted(
                   np.linalg.eigvals(d.lin.A - d.synthesis.L @ d.lin.C), key=lambda v: (v.real, v.imag))],
               "threshold_rad_per_s": cases["threshold"], "detection_time_s": cases["detection_time_s"],
               "time_above_threshold_s": cases["time_above_threshold_s"],
               "estimation_rms": _estimation_errors(cases["results"]["fault-free"]), "c": c, "claims": claims}
    write_json(out_dir / "results.json", results)
    (out_dir / "report.md").write_text(_report(results))


def _report(r: dict) -> str:
    d = design()
    plant, obs = d.plant, d.observer
    signals_rows = [[group, name, unit, text] for group, g in (("state", plant.x), ("input", plant.u),
                                                               ("output", plant.y))
                    for name, unit, text in zip(g.names, g.units, g.descriptions)]
    equations = "\n".join(f"$$ {line} $$" for line in observer_equations(obs))
    detection = [[name, "-" if t is None else f"{t:.4g}",
                  "-" if t is None or name == "fault-free" else f"{t - FAULT_ONSET:.4g}",
                  f"{r['time_above_threshold_s'][name]:.4g}"] for name, t in r["detection_time_s"].items()]
    errors = [[e["state"], e["unit"], f"{e['rms_error']:.3g}"] for e in r["estimation_rms"]]
    noise = ", ".join(f"{name} {sigma:g}" for name, sigma in NOISE.items())
    modes = r["eigenvalues_A_minus_LC"]
    eigenvalues = ", ".join(f"{re:.4g} {'+' if im >= 0 else '-'} {abs(im):.4g}j" for re, im in modes)
    slowest = abs(max(re for re, _ in modes))  # 1/s, the speed channel's rate
    return f"""# A Luenberger observer of the induction motor, through every stage

Every stage of uvsym on a plant that is not a vehicle: the d-q induction motor of
{YU.short}'s incipient sensor-fault study (eq. 23; {YU.reference()}), `uvsym.plant("induction_motor")`, with
Modelica Standard Library parameters. A Luenberger observer (`uvsym.observers.luenberger`)
with a gain from an LMI, simulated in a loop wired by signal name with a speed-sensor fault,
exported as C and compared with Python, its error dynamics checked by `uvsym verify`. Every
number below is computed by the run that wrote this report.

## Plant and operating point

{markdown_table(["signal", "name", "unit", "meaning"], signals_rows)}

Operating point: {", ".join(f"{n} = {v:.6g} {u}" for n, v, u in zip(plant.x.names, plant.x_op, plant.x.units))};
{", ".join(f"{n} = {v:.6g} {u}" for n, v, u in zip(plant.u.names, plant.u_op, plant.u.units))}. Source: {plant.source}.

## Observer

Gain by the LMI $A^T P + P A - C^T Y^T - Y C + 2 \\alpha' P \\prec 0$, $L = P^{{-1}} Y$, with $A, C$ the
Jacobians at the operating point (by `casadi.jacobian`), solved for $\\alpha'$ = 1 % beyond the rate
$\\alpha$ = {r['decay_per_s']:g} 1/s, then certified at $\\alpha$ without the solver (exact rational LDL^T):

$$ L = {latex_matrix(np.asarray(r['L']), 4)} $$

Eigenvalues of $A - L C$: {eigenvalues} 1/s.
The observer runs on the nonlinear model, sampled every {r['dt_s']:g} s (RK4 prediction plus
$\\Delta t\\, L (y - h(\\hat x))$). The fast current modes ({max(abs(im) for _, im in modes):.4g} rad/s) limit the
sample period: the claims below prove that the sampled error map contracts at {r['dt_s']:g} s and
refute it at {SLOW_DT:g} s. Its continuous form, rendered from the CasADi graph:

{equations}

## Simulation: speed-sensor fault

The motor starts {", ".join(f"{v:+g} {u}" for v, u in zip(INITIAL_OFFSET, plant.x.units))} away from the
operating point (states in order) on constant voltages; the observer starts at the operating
point. Sensor noise (standard deviations, uvsym's choice): {noise}. From t = {FAULT_ONSET:g} s the
speed sensor reads $\\omega_m + F f(t)$, $F$ = {SENSOR_GAIN:g}, with $f$ a unit step (case b) or
$1 - e^{{-0.8 (t - 1)}}$ (case a), as in the paper. Threshold on $|r_{{\\omega_m}}|$:
{THRESHOLD_FACTOR:g} times its largest value after {CONVERGED_AFTER:g} s in {len(CALIBRATION_SEEDS)} fault-free runs
with other noise draws than the runs judged below = {r['threshold_rad_per_s']:.4g} rad/s.

{markdown_table(["run", "alarm (s)", "delay after onset (s)", "time above threshold (s)"], detection)}

The residual of a plain Luenberger observer is transient: the speed is measured and its model
row has no restoring term, so the estimate follows the biased sensor within a few time
constants of the speed channel (about {1 / slowest:.2g} s) and the residual returns below the
threshold. The incipient fault is not detected: its steepest slope,
{SENSOR_GAIN * INCIPIENT_RATE:g} rad/s^2, leaves a tracking residual of about
{SENSOR_GAIN * INCIPIENT_RATE / slowest:.2g} rad/s, below the threshold; an alarm needs {CONFIRM} samples in a row above
it, so a noise excursion of a sample or two is not one. Holding the alarm, or estimating the
fault itself, is what Yu et al. 2018's unknown-input and adaptive observers
add (`reports/motor-hybrid-observer/`).

Estimation error (RMS of $x - \\hat x$, fault-free, {CONVERGED_AFTER:g} s to {FAULT_ONSET:g} s):

{markdown_table(["state", "unit", "RMS error"], errors)}

![speed and residual](speed_residual.svg)

## Machine-checked claims

{claims_table(r["claims"])}

Counterexamples of the refuted claims:

{counterexamples(r["claims"])}

The nonlinear decay of $V = e^T P e$ on a box of errors (`region_decay_claim`) is not claimed:
on this motor the interval branch-and-bound stays inconclusive after two million boxes
($P$'s condition number is about 3500 and the flux-speed products are large).

## Generated C

{c_section(r["c"], "The observer's step")}
"""
