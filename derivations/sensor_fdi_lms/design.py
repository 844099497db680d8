"""The heading loop of the LMS-FIR compass-fault paper, with uvsym's choices where it is silent.

Paper (Zhu Daqi et al., seed 001): FIR order M = 70 (L165-167), LMS step mu = 0.01 (L183),
sample period 0.2 s (L563), heading set-point 150 deg (L515), compass faults of +30, +20, +10
deg added to the measurement at sample 70 (L511-519). Not in the paper (uvsym's choices, stated
in the report): the vehicle (``rov_yaw``, a VideoRay Pro III yaw proxy), the controller, the
thresholds eps0 and r0, the R window n, the noise, the run length and the initial weights.

The loop: a set-point table publishes ``psi_ref``; a proportional heading controller (the
paper's PID with ``ki = kd = 0``: an integral winds up on the faulty samples before the fault is
confirmed and then turns the vehicle open loop, see the report) reads ``psi`` and publishes
``u``; the LMS-FIR monitor reads ``psi``, ``u`` and ``psi_ref``. With fault-tolerant control a
switch block (:func:`uvsym.sim.blocks.select`) publishes ``psi_sel = flag ? psi_sub : psi`` in
the same sample (flag: the monitor's ``fault_psi``, or ``frozen_psi`` to substitute from the
eps^2 alarm) and the controller reads ``psi_sel`` instead. Its gain gives the loop of the
linearised yaw model ``psi / u = K / (s (T s + 1))`` the natural frequency ``BANDWIDTH``
(``K kp = T BANDWIDTH^2``; damping ratio ``1 / (2 T BANDWIDTH)``, 1.4: no overshoot). A seeded
white yaw torque and compass noise excite the loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

import uvsym
from uvsym.errors import ObserverError
from uvsym.observers.base import Observer
from uvsym.observers.lms import lms_monitor
from uvsym.observers.lms_supervisor import switch_flag
from uvsym.observers.step_monitor import sensor_step_monitor
from uvsym.sim import observer_block
from uvsym.sim.blocks import select
from uvsym.sim.feedback import open_loop, pid
from uvsym.sim.loop import disturbance_draws
from uvsym.systems.signals import signals
from uvsym.systems.system import System

__all__ = ["Design", "design", "DT", "ORDER", "MU", "SET_POINT_DEG", "EPS0_DEG2", "R0", "WINDOW", "HOLD", "CONFIRM",
           "BANDWIDTH", "COMPASS_NOISE_DEG",
           "DECISIONS", "STEP_MONITOR", "STEP_FALSE_ALARMS_PER_HOUR", "STEP_WINDOW",
           "TORQUE_NOISE", "WARM_UP", "RECORD", "FAULT_SAMPLE", "FAULT_SIZES_DEG"]

# the paper's numbers
DT = 0.2  # s (L563)
SUBSTEPS = 8  # RK4 steps of the plant per sample: 4 miss the fast path's step-error tolerance (1e-4) after a turn
ORDER = 70  # M (L165-167)
MU = 0.01  # LMS step, per unit of u squared (L183)
SET_POINT_DEG = 150.0  # (L515)
FAULT_SAMPLE = 70  # recorded sample of the fault's onset (L553)
FAULT_SIZES_DEG = (30.0, 20.0, 10.0)  # (L519)
# uvsym's choices (not in the paper)
EPS0_DEG2 = 9.0  # eps^2 threshold, (3 deg)^2: the paper's FTC tolerance
R0 = 9.0  # R threshold: a squared z-score of 3
WINDOW = 20  # n, samples in R's window (4 s)
HOLD = 3  # samples R must stay above r0: one large update (a one-sample disturbance) gives R = n - 1 once
CONFIRM = 10  # samples R has to confirm an eps^2 alarm (2 s)
BANDWIDTH = 0.7  # rad/s, natural frequency of the linearised heading loop
COMPASS_NOISE_DEG = 0.5  # standard deviation of the compass noise
TORQUE_NOISE = 1e-4  # N m, standard deviation of the white yaw torque (held over each sample)
WARM_UP = 500  # samples before the record starts (100 s): the filter trains on the healthy loop
RECORD = 400  # samples recorded (80 s): the fault at 70 leaves 66 s after it
DECISIONS = ("paper", "calibrated")  # the double criterion, or the calibrated sensor-step monitor
STEP_MONITOR = "step"  # the step monitor's block name
STEP_FALSE_ALARMS_PER_HOUR = 0.1  # designed bound on its false confirmations (the scenario files' too)
STEP_WINDOW = (10, 8, 3)  # its samples before and after a candidate step, and the longest glitch released


@dataclass(frozen=True)
class Design:
    """plant (rov_yaw), monitor (the LMS-FIR Observer), kp (1/rad) and the loop's blocks."""

    plant: System
    monitor: Observer
    kp: float
    blocks: tuple


def yaw_model(plant: System) -> tuple[float, float]:
    """(T, K) of the linearised yaw model ``psi / u = K / (s (T s + 1))``: T in s, K in rad/s per unit u."""
    lin = plant.linearize()
    T = -1.0 / lin.A[1, 1]  # m66 / |N_r|
    return T, lin.B[1, 0] * T


def turn_rate(plant: System, u: float) -> float:
    """The steady yaw rate (rad/s, >= 0) of the nonlinear yaw model under a constant command of size
    ``|u|`` (0 < |u| <= 1) and no torque: the root of ``r' = 0``."""
    def acceleration(r: float) -> float:
        return float(plant.f([0.0, r], [abs(u)], [0.0], plant.p0)[1])

    return float(brentq(acceleration, 0.0, 100.0))


def heading_gain(plant: System, bandwidth: float = BANDWIDTH) -> float:
    """kp (per rad) of ``u = kp (psi_ref - psi)``: the linearised loop's natural frequency is ``bandwidth`` (rad/s)."""
    T, K = yaw_model(plant)
    return T * bandwidth ** 2 / K


def pi_gains(plant: System) -> tuple[float, float]:
    """(kp per rad, ki per rad s) of a PI heading law placing the linearised loop's three poles at
    ``-1 / (3 T)`` (``T s^3 + s^2 + K kp s + K ki``, the fastest triple pole without derivative)."""
    T, K = yaw_model(plant)
    a = 1.0 / (3.0 * T)
    return 3.0 * a ** 2 * T / K, a ** 3 * T / K


def design(order: int = ORDER, mu: float = MU, eps0_deg2: float = EPS0_DEG2, r0: float = R0, window: int = WINDOW,
           hold: int = HOLD, confirm: int = CONFIRM, set_point_deg: float = SET_POINT_DEG,
           bandwidth: float = BANDWIDTH, integral: bool = False, substitute_on: str | None = None,
           decision: str = "paper", noise_deg: float = COMPASS_NOISE_DEG) -> Design:
    """The plant, the monitor and the heading loop's blocks (ObserverError for bad monitor settings);
    ``integral``: the PI law of :func:`pi_gains` instead of the proportional one; substitute_on:
    None (the controller reads the compass), ``"fault"`` or ``"alarm"`` (it reads ``psi_sel``,
    switched in the same sample by the flag of :func:`uvsym.observers.lms_supervisor.switch_flag`);
    decision ``"calibrated"`` adds the sensor-step monitor (:func:`step_monitor`, told the compass
    noise ``noise_deg``) and, with substitute_on set, the controller reads its ``psi_sub`` instead."""
    if decision not in DECISIONS:
        raise ObserverError(f"decision must be one of {', '.join(DECISIONS)}, got {decision!r}")
    plant = uvsym.plant("rov_yaw")
    monitor = lms_monitor(plant.y, plant.u, reference=signals(("psi_ref", "rad", "heading set-point")),
                          order=order, mu=mu, eps0=eps0_deg2 * (math.pi / 180.0) ** 2, r0=r0, dt=DT, window=window,
                          hold=hold, confirm=confirm, name="lms")
    kp, ki = pi_gains(plant) if integral else (heading_gain(plant, bandwidth), 0.0)
    reference = open_loop("reference", [0.0], [math.radians(set_point_deg)], publishes=["psi_ref"])
    blocks = (reference, observer_block(monitor))
    measured = "psi"
    if decision == "calibrated":
        blocks += (observer_block(step_monitor(plant, noise_deg)),)
        if substitute_on is not None:
            measured = f"{STEP_MONITOR}.psi_sub"
    elif substitute_on is not None:
        measured = "psi_sel"
        blocks += (select("ftc", flag=switch_flag("psi", substitute_on), on="psi_sub", off="psi", output=measured,
                          unit=plant.y.unit("psi")),)
    controller = pid("heading", measured, "psi_ref", output="u", kp=kp, ki=ki, limits=(-1.0, 1.0), dt=DT)
    return Design(plant, monitor, kp, (reference, controller) + blocks[1:])


def step_monitor(plant: System, noise_deg: float = COMPASS_NOISE_DEG) -> Observer:
    """The calibrated sensor-step monitor of the compass (:mod:`uvsym.observers.step_monitor`), told its
    noise (deg), with confirmations designed for ``STEP_FALSE_ALARMS_PER_HOUR``."""
    return sensor_step_monitor(plant.y, noise_std=math.radians(noise_deg), dt=DT,
                               false_alarms_per_hour=STEP_FALSE_ALARMS_PER_HOUR, before=STEP_WINDOW[0],
                               after=STEP_WINDOW[1], glitch=STEP_WINDOW[2], name=STEP_MONITOR)


def torque_table(samples: int, seed: int, sigma: float = TORQUE_NOISE) -> np.ndarray:
    """(samples + 1, 1) white yaw torque (N m), seeded: the draws of a scenario's ``[noise] tau_d``
    (:func:`uvsym.sim.loop.disturbance_draws`, independent of the compass noise's)."""
    return sigma * disturbance_draws(samples, 1, seed)
