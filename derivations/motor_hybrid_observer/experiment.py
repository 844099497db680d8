"""The four observers in one closed loop with the motor: fault-free, case a (incipient) and case b (step).

The motor starts off its operating point on constant voltages (as in the motor's Luenberger
study, whose initial offset, noise, fault gain, profiles, threshold rule and alarm confirmation
are reused), with the paper's disturbance: the rotor resistance drifts up by ``RR_DRIFT`` (20 %)
linearly over the run (uvsym's choice; the paper gives no profile), entering as ``d = dRr x``.
From ``FAULT_ONSET`` the speed sensor reads ``omega_m + 2 f_s``, ``f_s`` the paper's case a
``1 - exp(-0.8 (t - 1))`` or case b (unit step). Runs ``DURATION`` s at the observers' sample
period on CasADi's virtual machine.
"""

from __future__ import annotations

import functools

import casadi as ca
import numpy as np

from derivations.motor_hybrid_observer.design import design
from derivations.motor_luenberger.experiment import (
    CALIBRATION_SEEDS,
    FAULT_ONSET,
    INCIPIENT_RATE,
    INITIAL_OFFSET,
    NOISE,
    SENSOR_GAIN,
    THRESHOLD_FACTOR,
    confirmed_alarm_time,
)
from uvsym.faults import Profile, SensorFault
from uvsym.observers.hybrid import observer_state
from uvsym.sim import observer_block, open_loop, renamed, simulate_system
from uvsym.systems.signals import signals
from uvsym.systems.system import System, system

__all__ = ["CASES", "DETECTORS", "DURATION", "RR_DRIFT", "detection_time", "drifting_plant", "run", "run_cases"]

DURATION = 10.0  # s (the paper's figures run to 10 s)
COMPILED = True  # the loop as generated C (-O3, no fast-math): 3.5 times the virtual machine's speed
RR_DRIFT = 0.2  # the rotor resistance's relative rise over the run
CONVERGED_AFTER = 0.5  # s: residuals are judged from here on
DETECTORS = ("detection", "baseline")  # the observers whose speed residual raises alarms
CASES = {"fault-free": None, "case a (incipient)": Profile("incipient", onset=FAULT_ONSET, rate=INCIPIENT_RATE),
         "case b (step)": Profile("step", onset=FAULT_ONSET)}


@functools.lru_cache(maxsize=1)
def drifting_plant() -> System:
    """The motor with the rotor-resistance change dRr (Ohm) as its one disturbance, ``d = dRr x``."""
    motor = design().plant
    return system(f"{motor.name}_rr_drift", f"{motor.description}; disturbance d = dRr x", x=motor.x, u=motor.u,
                  d=signals(("dRr", "Ohm", "rotor-resistance change"), group="disturbance"), p=motor.p, y=motor.y,
                  rhs=lambda x, u, d, p: motor.f(x, u, d[0] * x, p), output=lambda x, u, p: motor.h(x, u, p),
                  p0=motor.p0, x_op=motor.x_op, u_op=motor.u_op, source=motor.source)


def _block(name: str, obs, x0: np.ndarray | None):
    """The observer as a block whose published names carry its name (four observers publish alike),
    started at the estimate x0 (None: its own start, the operating point)."""
    d = design()
    if x0 is None:
        s0 = None
    elif name == "corrected":
        s0 = np.concatenate([x0, np.zeros(obs.state.size - x0.size)])
    else:
        dec = d.full if name == "baseline" else d.split
        s0 = observer_state(dec, x0, d.lin.C, obs.state.size - len(dec.iz1) - len(dec.iz2))
    blk = observer_block(obs, s0=s0)
    return renamed(blk, publishes={n: f"{obs.name}_{n}" for n in blk.publishes.names})


def run(profile: Profile | None, seed: int = 0, duration: float = DURATION, known_start: bool = True,
        noise: bool = True) -> dict:
    """name -> array of the run: t, the true states and fault, and every observer's published signals.

    known_start: the observers start at the motor's true initial state (the paper's setting); else
    at the operating point. noise: measurement noise NOISE on the sensors (the paper states none)."""
    d = design()
    plant = drifting_plant()
    faults = [SensorFault(plant.y.index(name), "noise", sigma) for name, sigma in NOISE.items() if noise]
    if profile is not None:
        faults.append(SensorFault(plant.y.index("omega_m"), "bias", SENSOR_GAIN, profile))
    supply = open_loop("supply", [0.0], [plant.u_op], publishes=plant.u.names)
    dt = d.observers["detection"].dt
    steps = int(round(duration / dt))
    Rr = float(d.plant.constants.v("Rr"))
    drift = RR_DRIFT * Rr * np.linspace(0.0, 1.0, steps + 1)[:, None] * (duration / DURATION)
    x0 = plant.x_op + INITIAL_OFFSET
    blocks = [_block(name, o, x0 if known_start else None) for name, o in d.observers.items()]
    result = simulate_system(plant, [supply] + blocks, duration=duration, dt=dt, x0=x0, sensor_faults=tuple(faults),
                             d=drift, seed=seed, compiled=COMPILED)
    out = {"t": result.t, "omega_m": result["x"]["omega_m"],
           "f_s": np.zeros_like(result.t) if profile is None else
           np.asarray(ca.evalf(profile.phi(ca.DM(result.t)))).ravel()}
    for name, obs in d.observers.items():
        for signal in obs.publishes.names:
            out[f"{name}_{signal}"] = result[name][f"{name}_{signal}"]
    for state in d.plant.x.names:
        out[f"true_{state}"] = result["x"][state]
    return out


def alarms(run_: dict, detector: str, threshold: float) -> np.ndarray:
    """Per sample: the residual is judged (t >= CONVERGED_AFTER) and ``|r_omega_m| > threshold``."""
    return (np.abs(run_[f"{detector}_r_omega_m"]) > threshold) & (run_["t"] >= CONVERGED_AFTER)


def detection_time(run_: dict, detector: str, threshold: float) -> float | None:
    """Time (s) of the first sample completing ``CONFIRM`` consecutive alarms, or None."""
    return confirmed_alarm_time(run_["t"], alarms(run_, detector, threshold))


def run_cases() -> dict:
    """The runs, each detector's threshold (``THRESHOLD_FACTOR`` x its largest judged |r| in
    fault-free runs with the calibration seeds' noise), alarm times, and the hybrid estimator's
    final estimate (mean over the last second) in each calibration run; the fault cases once more
    without measurement noise (``noise-free`` runs: the paper states no noise)."""
    runs = {name: run(profile) for name, profile in CASES.items()}
    runs.update({f"{name}, noise-free": run(profile, noise=False) for name, profile in CASES.items()
                 if profile is not None})
    runs["fault-free, observers start at the operating point"] = run(None, known_start=False)
    calibration = [run(None, seed=seed) for seed in CALIBRATION_SEEDS]
    thresholds = {det: THRESHOLD_FACTOR * max(float(np.max(np.abs(c[f"{det}_r_omega_m"][c["t"] >= CONVERGED_AFTER])))
                                              for c in calibration) for det in DETECTORS}
    detection = {det: {name: detection_time(r, det, thresholds[det]) for name, r in runs.items()} for det in DETECTORS}
    wander = [float(np.mean(c["estimator_f_s_hat"][c["t"] >= DURATION - 1.0])) for c in calibration]
    return {"runs": runs, "thresholds": thresholds, "detection_time_s": detection, "fault_free_final_estimates": wander}
