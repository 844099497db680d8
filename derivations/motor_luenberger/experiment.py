"""The motor observer in closed loop: a speed-sensor fault, step (case b) and incipient (case a).

The motor runs at its operating point on constant supply voltages (an open-loop table) from a
perturbed initial state; the observer starts at the operating point, reads the three measured
outputs (with noise) and the voltages, and publishes its estimates and residuals. The speed
sensor then reads ``omega_m + F f(t)`` with ``F = 2`` and ``f`` a unit step or
``1 - exp(-0.8 (t - 1))`` from t = 1 s (the two cases of Yu et al. 2018). The
detection threshold on ``|r_omega_m|`` is 1.2 times its largest value in three fault-free runs
with other noise than the runs it judges, after the observer has converged; an alarm needs
``CONFIRM`` samples in a row above it (uvsym's choices). Runs on CasADi's virtual machine so the
numbers do not depend on the C compiler's flags.
"""

from __future__ import annotations

import numpy as np

from derivations.motor_luenberger.design import design
from uvsym.faults import Profile, SensorFault
from uvsym.sim import observer_block, open_loop, simulate_system

__all__ = ["CASES", "DURATION", "FAULT_ONSET", "confirmed_alarm_time", "detection_time", "run", "run_cases"]

DURATION = 2.0  # s
FAULT_ONSET = 1.0  # s
SENSOR_GAIN = 2.0  # F of y = C x + F f_s (the paper's F = (0 0 0 0 2)^T)
INITIAL_OFFSET = np.array([2.0, -2.0, 0.005, -0.005, 1.0])  # plant start minus operating point (A, A, Wb, Wb, rad/s)
NOISE = {"i_sq": 0.05, "i_sd": 0.05, "omega_m": 0.02}  # standard deviations (A, A, rad/s), uvsym's choice
CONVERGED_AFTER = 0.5  # s: the fault-free residual's maximum is taken from here to the end
THRESHOLD_FACTOR = 1.2
CONFIRM = 5  # consecutive samples above the threshold make an alarm (0.5 ms): one noise excursion does not
CALIBRATION_SEEDS = (1, 2, 3)  # noise of the fault-free runs the threshold is fitted on; the runs judged use seed 0
INCIPIENT_RATE = 0.8  # 1/s, of 1 - exp(-0.8 (t - 1))
CASES = {"fault-free": None, "step (case b)": Profile("step", onset=FAULT_ONSET),
         "incipient (case a)": Profile("incipient", onset=FAULT_ONSET, rate=INCIPIENT_RATE)}


def run(profile: Profile | None, size: float = SENSOR_GAIN, seed: int = 0):
    """The closed loop with the speed sensor reading ``omega_m + size phi(t)`` (phi the profile), or healthy."""
    d = design()
    plant, obs = d.plant, d.observer
    y = plant.y
    faults = [SensorFault(y.index(name), "noise", sigma) for name, sigma in NOISE.items()]
    if profile is not None:
        faults.append(SensorFault(y.index("omega_m"), "bias", size, profile))
    supply = open_loop("supply", [0.0], [plant.u_op], publishes=plant.u.names)
    return simulate_system(plant, [supply, observer_block(obs)], duration=DURATION, dt=obs.dt,
                           x0=plant.x_op + INITIAL_OFFSET, sensor_faults=tuple(faults), seed=seed, compiled=False)


def run_cases() -> dict:
    """name -> SimResult for the fault-free run and both faults, plus the detection figures."""
    results = {name: run(profile) for name, profile in CASES.items()}
    t = results["fault-free"].t
    calibration = [run(None, seed=seed)[design().observer.name]["r_omega_m"] for seed in CALIBRATION_SEEDS]
    threshold = THRESHOLD_FACTOR * max(float(np.max(np.abs(r[t >= CONVERGED_AFTER]))) for r in calibration)
    detection = {name: detection_time(result, threshold) for name, result in results.items()}
    above = {name: float(np.count_nonzero(_alarms(result, threshold)) * (t[1] - t[0]))
             for name, result in results.items()}
    return {"results": results, "threshold": threshold, "detection_time_s": detection, "time_above_threshold_s": above}


def _alarms(result, threshold: float) -> np.ndarray:
    """Per sample: the observer has converged and ``|r_omega_m| > threshold``."""
    return (np.abs(result[design().observer.name]["r_omega_m"]) > threshold) & (result.t >= CONVERGED_AFTER)


def confirmed_alarm_time(t: np.ndarray, alarms: np.ndarray) -> float | None:
    """Time (s) of the first sample that completes ``CONFIRM`` consecutive alarms (t, alarms: (N,)), or None."""
    runs = np.convolve(np.asarray(alarms, dtype=int), np.ones(CONFIRM, dtype=int), mode="valid")
    hits = np.flatnonzero(runs == CONFIRM)
    return float(t[hits[0] + CONFIRM - 1]) if hits.size else None


def detection_time(result, threshold: float) -> float | None:
    """Time (s) of the alarm: the first sample that completes ``CONFIRM`` consecutive samples with
    ``|r_omega_m| > threshold`` after the observer has converged, or None."""
    return confirmed_alarm_time(result.t, _alarms(result, threshold))
