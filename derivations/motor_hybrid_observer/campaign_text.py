"""The fault campaign's section of the report; every number comes from the campaign's rows
(:mod:`derivations.motor_hybrid_observer.campaign`)."""

from __future__ import annotations

from derivations.motor_hybrid_observer.campaign import DETECTORS, STEP_CASE
from uvsym.report import markdown_table

__all__ = ["campaign_section", "designed_against_measured"]

WHO = {"hybrid": "hybrid, z sigma at 1 /h", "hybrid_study": "hybrid, study's threshold",
       "luenberger_fd": "Luenberger, z sigma at 1 /h"}


def _p(value) -> str:
    return "-" if value is None else f"{value:.2f}"


def _ms(value) -> str:
    return "missed" if value is None else f"{1000 * value:.1f}"


def _rate(rates: dict) -> str:
    """False alarms per hour, with the count and the healthy hours it rests on."""
    if not rates["healthy_hours"]:
        return "-"
    return f"{rates['false_alarms_per_hour']:.3g} ({rates['false_alarms']} in {rates['healthy_hours']:.3g} h)"


def _smallest(grid: dict, noise: str, detector: str) -> str:
    sizes = [float(size) for size, row in grid[noise].items() if row[detector] is not None]
    return f"{min(sizes):g}" if sizes else "none"


def designed_against_measured(c: dict) -> str:
    """Each detector's designed false-alarm rate beside what the noise levels of 10 fault-free hours or more
    measured; the shorter levels named as too short to confirm it."""
    long_enough = {noise: r for noise, r in c["healthy_by_noise"].items() if r["hybrid"]["healthy_hours"] >= 10.0}
    short = [f"{noise} rad/s ({r['hybrid']['healthy_hours']:.3g} h)" for noise, r in c["healthy_by_noise"].items()
             if noise not in long_enough]
    parts = []
    for d in DETECTORS:
        designed = c["designed_false_alarms_per_hour"][d]
        measured = "; ".join(f"{noise} rad/s: {_rate(r[d])}" for noise, r in long_enough.items())
        if designed is None:
            parts.append(f"{WHO[d]} (a given threshold: no designed rate): {measured}")
            continue
        above = [noise for noise, r in long_enough.items() if r[d]["false_alarms_per_hour"] > designed]
        verdict = f"above it at {', '.join(above)} rad/s" if above else "none above it"
        parts.append(f"{WHO[d]} (designed for {designed:g} per hour): {measured}; {verdict}")
    return ("Designed and measured false alarms per hour, over the noise levels with at least 10 fault-free "
            "hours: " + ". ".join(parts) + "." + (f" Too few fault-free hours to confirm a rate at "
                                                   f"{', '.join(short)}." if short else ""))


def campaign_section(c: dict) -> str:
    """The section: overall and per-case figures per detector, the step sizes, the other runs."""
    overall = [[WHO[d], _p(r["detection_probability"]), f"{r['missed_detections']} of {r['fault_runs']}",
                _ms(r["median_detection_delay_s"]), _p(r["median_size_error_rel"]), _rate(r)]
               for d, r in c["overall"].items()]
    cases = [[case] + [f"{_p(r[d]['detection_probability'])} / {_ms(r[d]['median_detection_delay_s'])} / "
                       f"{r[d]['false_alarms']}" for d in DETECTORS] for case, r in c["cases"].items()]
    healthy = [[noise] + [_rate(r[d]) for d in DETECTORS] for noise, r in c["healthy_by_noise"].items()]
    grid = c["step_detection_delay_s"]
    steps = [[noise, size] + [_ms(row[d]) for d in DETECTORS] for noise, sizes in grid.items()
             for size, row in sizes.items()]
    others = [[o["case"], o["fault"], f"{o['onset_s']:.2f}" if o["onset_s"] is not None else "-"]
              + [_ms(o[f"{d}:detection_delay_s"]) for d in DETECTORS]
              + ["-" if o["hybrid:identified_value"] is None else f"{o['hybrid:identified_value']:.3f}"]
              for o in c["other_runs"]]
    smallest = "; ".join(f"{noise} rad/s noise: " + ", ".join(f"{WHO[d]} {_smallest(grid, noise, d)}"
                                                              for d in DETECTORS) for noise in grid)
    current = [o for o in c["other_runs"] if o["fault"].startswith(("i_sq", "i_sd"))]
    flagged = sum(o["hybrid:detection_delay_s"] is not None for o in current)
    flagged_d = sum(o["hybrid:detection_delay_s"] is not None for o in current if o["fault"].startswith("i_sd"))
    slow = [o["fault"] for o in c["other_runs"] if o["fault"] != "none" and o["hybrid:detection_delay_s"] is None
            and not o["fault"].startswith(("i_sq", "i_sd")) and "stuck" not in o["fault"]]
    stuck = [o for o in c["other_runs"] if "stuck" in o["fault"]]
    stuck_still = [o for o in stuck if o["case"] != "supply step"]
    stuck_moving = [o["hybrid:detection_delay_s"] for o in stuck if o["case"] == "supply step"]
    noisiest = c["healthy_by_noise"][max(c["healthy_by_noise"], key=float)]
    return f"""## Fault campaign ([campaign.toml](../../derivations/motor_hybrid_observer/campaign.toml))

{c["runs"]} runs ({c["errors"]} ending in an error) of
[campaign_motor.toml](../../derivations/motor_hybrid_observer/campaign_motor.toml): the shipped
scenarios' motor, drift, noise and observers, 6 s per run (the healthy ones 120 s, and 30 s in the
10 fault-free hours per noise level at the study's noise and twice it), onsets drawn in
[1, 3] s; `uvsym campaign derivations/motor_hybrid_observer/campaign.toml` runs the same file. Three
detectors decide on the same runs: the hybrid detection residual (eq. 6) against z sigma with sigma
from the stated sensor noise through the loop linearised at its start and z for 1 false alarm per
hour (the estimator of eq. 18 identifies the offset 0.3 s after a detection that still stands);
the same residual against the study's calibrated threshold (1.2 x the largest |r| of three
fault-free runs at the study's noise); and the motor's Luenberger observer (LMI gain at 50 1/s, the
motor-luenberger study's) with its speed residual against z sigma. All three confirm on 5 samples
and judge from 0.5 s. A fault's detection counts from its onset to the run's end; an alarm in a
healthy run or before the onset is a false alarm. The identification error is judged against the
fault's final size (for growing profiles the estimate follows the fault as it is when identified).

{markdown_table(["detector", "detection probability", "missed", "median delay (ms)",
                 "median identification error", "false alarms per hour"], overall)}

Per case (detection probability / median delay in ms / false alarms):

{markdown_table(["case"] + [WHO[d] for d in DETECTORS], cases)}

False alarms per hour in the long healthy runs, per speed-sensor noise level (rad/s; the current
sensors' noise is 2.5 times it, in A):

{markdown_table(["noise (rad/s)"] + [WHO[d] for d in DETECTORS], healthy)}

{designed_against_measured(c)}

Speed-sensor steps ({STEP_CASE!r}): detection delay (ms) per size and noise level.

{markdown_table(["noise (rad/s)", "step (rad/s)"] + [WHO[d] for d in DETECTORS], steps)}

The other faulty runs (delays in ms; identified: the hybrid detector's offset estimate, rad/s):

{markdown_table(["case", "fault", "onset (s)"] + [WHO[d] for d in DETECTORS] + ["identified"], others)}

Where the method fails (read from the tables above):

- Small steps: the smallest step detected (rad/s) per noise level: {smallest}. Below it the
  residual's jump stays under the threshold and then decays (the speed estimate absorbs a constant
  offset), so a small offset is not seen later either.
- Growing faults missed by the hybrid detector (their growth is slow against its speed gain, so
  the estimate follows them): {", ".join(slow) or "none"}.
- A speed sensor stuck at constant speed reads what the motor does: the hybrid detector sees
  {sum(o["hybrid:detection_delay_s"] is not None for o in stuck_still)} of {len(stuck_still)} such
  runs; with the supply stepped 1 s after the onset it sees
  {sum(v is not None for v in stuck_moving)} of {len(stuck_moving)}, after
  {", ".join(_ms(v) for v in stuck_moving)} ms (at the step, when the speed changes).
- Current-sensor faults are not covered (the method's faults act on subsystem 2, the speed
  sensor): {flagged} of {len(current)} current-sensor runs raise the speed residual's alarm (which
  names the speed sensor), {flagged_d} of them an i_sd fault.
- A threshold fixed for one noise level does not carry to another: at the highest noise the
  study's calibrated threshold raises {_rate(noisiest["hybrid_study"])} false alarms per hour, the
  designed one (sigma from the stated noise) {_rate(noisiest["hybrid"])}.
"""
