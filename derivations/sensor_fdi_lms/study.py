"""Beyond the paper: detection over thresholds and noise seeds (ROC), and the detection delay.

Positive runs: the smallest of the paper's faults (+10 deg compass bias at recorded sample 70);
negative runs: a one-sample +10 deg disturbance at the same sample (what the double criterion
is meant to reject), each over ``SEEDS`` noise seeds (compass noise and yaw torque), without
fault-tolerant control (the alarms come before any substitution). One loop per kind is built
once; the seeds run through it on CasADi's virtual machine (``mapaccum``).

Detectors, per run and threshold: eps^2 alone fires on the first sample of the record with
``eps2 > eps0``; R alone on the first with ``R > r0`` on ``HOLD`` samples in a row; the double
criterion on the first confirmed fault (the monitor's own decision logic,
:func:`uvsym.observers.lms_supervisor.double_criterion`, replayed on the recorded alarms). A
positive run counts as detected when its detector fires within ``WITHIN`` samples from the onset
(its delay: the first such sample minus the onset); a negative run with any firing of the
detector anywhere in its record is a false alarm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from derivations.sensor_fdi_lms.design import (
    COMPASS_NOISE_DEG,
    CONFIRM,
    DT,
    EPS0_DEG2,
    FAULT_SAMPLE,
    HOLD,
    R0,
    RECORD,
    SET_POINT_DEG,
    SUBSTEPS,
    WARM_UP,
    design,
    torque_table,
)
from uvsym.faults import Profile, SensorFault
from uvsym.observers.lms_supervisor import double_criterion
from uvsym.sim.system_simulation import initial_state, loop_inputs
from uvsym.sim.wiring import interconnect

__all__ = ["SEEDS", "SIZE_DEG", "EPS0_GRID_DEG2", "R0_GRID", "Study", "detection_study"]

SEEDS = 100  # noise seeds per kind of run (1000 + seed, other seeds than the report's runs)
SIZE_DEG = 10.0
EPS0_GRID_DEG2 = tuple(float(v) for v in np.geomspace(0.25, 400.0, 25))
WITHIN = 25  # samples (5 s) after the onset in which a detection counts
R0_GRID = tuple(float(v) for v in np.linspace(1.0, 19.0, 25))


@dataclass(frozen=True)
class Study:
    """Per detector: thresholds, detection probability and false-alarm rate (one per threshold),
    and the delays (samples) of the detected positive runs at the nominal thresholds."""

    roc: dict
    delays: dict
    seeds: int


def _records(pulse: bool) -> tuple[np.ndarray, np.ndarray]:
    """(eps2, R) per seed: (SEEDS, N) arrays over the whole run (warm-up then record)."""
    d = design()
    plant = d.plant
    onset = (WARM_UP + FAULT_SAMPLE) * DT
    profile = Profile("step", onset=onset, end=onset + DT) if pulse else Profile("step", onset=onset)
    faults = (SensorFault(0, "noise", math.radians(COMPASS_NOISE_DEG)),
              SensorFault(0, "bias", math.radians(SIZE_DEG), profile))
    loop = interconnect(plant, d.blocks, dt=DT, sensor_faults=faults, substeps=SUBSTEPS)
    roll = _roller(loop.step, WARM_UP + RECORD)
    names = d.monitor.publishes.names
    sl = loop.signals["lms"][0]
    columns = [sl.start + names.index("eps2_psi"), sl.start + names.index("R_psi")]
    N = WARM_UP + RECORD
    out = np.empty((N, loop.step.nnz_out(1)))
    eps2, R = np.empty((SEEDS, N)), np.empty((SEEDS, N))
    for i in range(SEEDS):
        seed = 1000 + i
        W = np.ascontiguousarray(loop_inputs(loop, N, torque_table(N, seed), seed)[:N])
        z0 = initial_state(loop, [math.radians(SET_POINT_DEG), 0.0], W[0])
        roll(z0, W, out)
        eps2[i], R[i] = out[:, columns[0]], out[:, columns[1]]
    return eps2, R


def _roller(step, N: int):
    """``roll(z0, W (N, n_w), out (N, n_out))``: N steps on CasADi's virtual machine (``mapaccum``);
    for these small runs it is faster than building C, and gives the same numbers on any machine."""
    interpreted = step.mapaccum("study_roll", N)

    def roll(z0, W, out):
        out[:] = np.asarray(interpreted(z0, W.T)[1]).T

    return roll


def _held(R: np.ndarray, r0: float) -> np.ndarray:
    """R > r0 on HOLD samples in a row, per sample."""
    above = (R > r0).astype(int)
    run = np.zeros_like(above)
    for k in range(above.shape[1]):
        run[:, k] = (run[:, k - 1] + 1) * above[:, k] if k else above[:, k]
    return run >= HOLD


def _first(alarms: np.ndarray, start: int = 0, stop: int = RECORD) -> np.ndarray:
    """(runs,) first recorded sample in [start, stop) with an alarm, -1 where none."""
    part = alarms[:, WARM_UP + start:WARM_UP + stop]
    return np.where(part.any(axis=1), start + np.argmax(part, axis=1), -1)


def _decided(eps_alarm: np.ndarray, r_alarm: np.ndarray) -> np.ndarray:
    """The double criterion's fault flag per run and sample (its CasADi logic, mapped over runs)."""
    runs, N = eps_alarm.shape
    decide = double_criterion(CONFIRM)
    d, a = ca.SX.sym("d", 3), ca.SX.sym("a", 2)
    step = ca.Function("decide_step", [d, a], [decide(d, a[0], a[1])[0]])
    roll = step.mapaccum("decide_roll", N).map(runs)
    alarms = np.concatenate([eps_alarm[:, None, :], r_alarm[:, None, :]], axis=1).astype(float)
    flags = np.asarray(roll(np.zeros((3, runs)), alarms.transpose(1, 2, 0).reshape(2, N * runs, order="F")))
    return flags.reshape(3, N, runs, order="F")[2].T > 0.5


def detection_study() -> Study:
    """The ROC of the three detectors and the delays at the nominal thresholds (module docstring)."""
    eps2_pos, R_pos = _records(pulse=False)
    eps2_neg, R_neg = _records(pulse=True)
    eps0_grid = np.radians(np.sqrt(EPS0_GRID_DEG2)) ** 2
    eps0 = math.radians(math.sqrt(EPS0_DEG2)) ** 2

    def rates(pos: np.ndarray, neg: np.ndarray) -> tuple[float, float, np.ndarray]:
        first_pos, first_neg = _first(pos, FAULT_SAMPLE, FAULT_SAMPLE + WITHIN), _first(neg)
        detected = first_pos >= 0
        return float(np.mean(detected)), float(np.mean(first_neg >= 0)), first_pos[detected] - FAULT_SAMPLE

    roc, delays = {}, {}
    curves = {"eps2 alone": (EPS0_GRID_DEG2, [rates(eps2_pos > e, eps2_neg > e) for e in eps0_grid]),
              "R alone": (R0_GRID, [rates(_held(R_pos, r), _held(R_neg, r)) for r in R0_GRID]),
              "double criterion": (R0_GRID, [rates(_decided(eps2_pos > eps0, _held(R_pos, r)),
                                                   _decided(eps2_neg > eps0, _held(R_neg, r))) for r in R0_GRID])}
    for name, (grid, points) in curves.items():
        roc[name] = {"threshold": list(grid), "detection_probability": [p[0] for p in points],
                     "false_alarm_rate": [p[1] for p in points]}
    nominal = {"eps2 alone": rates(eps2_pos > eps0, eps2_neg > eps0),
               "R alone": rates(_held(R_pos, R0), _held(R_neg, R0)),
               "double criterion": rates(_decided(eps2_pos > eps0, _held(R_pos, R0)),
                                         _decided(eps2_neg > eps0, _held(R_neg, R0)))}
    for name, (pd, pfa, delay) in nominal.items():
        delays[name] = {"detection_probability": pd, "false_alarm_rate": pfa, "delays": [int(v) for v in delay]}
    return Study(roc, delays, SEEDS)
