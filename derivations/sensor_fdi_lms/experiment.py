"""Runs of the heading loop with a compass fault, with and without fault-tolerant control.

A run is :class:`Run`: the loop of :mod:`.design` trains its filter for ``warm_up`` samples,
then records ``record`` samples; a fault of ``size_deg`` on ``sensor`` (kind ``kind``, profile
``profile``) starts at recorded sample ``onset`` and, for a pulse, lasts ``length`` samples.
Sample indices below count from the start of the record, as the paper's figures do.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from derivations.sensor_fdi_lms.design import (
    BANDWIDTH,
    COMPASS_NOISE_DEG,
    DT,
    EPS0_DEG2,
    FAULT_SAMPLE,
    MU,
    ORDER,
    R0,
    RECORD,
    SET_POINT_DEG,
    SUBSTEPS,
    WARM_UP,
    design,
    torque_table,
)
from uvsym.faults import Profile, SensorFault
from uvsym.observers.lms_supervisor import SubstitutionSupervisor, switch_flag
from uvsym.sim import simulate_system
from uvsym.sim.result import SimResult

__all__ = ["Run", "Outcome", "run", "first_sample", "PROFILES"]

PROFILES = ("step", "pulse", "ramp", "incipient", "intermittent")


@dataclass(frozen=True)
class Run:
    """One run: fault on ``sensor`` (an output of the plant) of ``size_deg`` (deg; deg/s for
    kind drift), ``profile`` (step, pulse: ``length`` samples, ramp over ``length`` samples,
    incipient with time constant ``length`` samples, intermittent of period ``2 length``) from
    recorded sample ``onset``; None size: no fault. ftc: the controller reads the frozen filter's
    substitute, switched in the same sample, once the fault is confirmed (``substitute_on="fault"``)
    or from the first eps^2 alarm to the release (``"alarm"``, Sec. 4.3).
    bandwidth (rad/s): of the proportional heading law; integral: the PI law instead. decision:
    ``"paper"`` (the double criterion switches the substitute) or ``"calibrated"`` (the sensor-step
    monitor does, :func:`.design.step_monitor`); noise_deg: the compass noise (told to that monitor)."""

    size_deg: float | None = 30.0
    onset: int = FAULT_SAMPLE
    sensor: str = "psi"
    kind: str = "bias"
    profile: str = "step"
    length: int = 1
    ftc: bool = True
    substitute_on: str = "fault"
    seed: int = 0
    warm_up: int = WARM_UP
    record: int = RECORD
    order: int = ORDER
    mu: float = MU
    eps0_deg2: float = EPS0_DEG2
    r0: float = R0
    bandwidth: float = BANDWIDTH
    integral: bool = False
    decision: str = "paper"
    noise_deg: float = COMPASS_NOISE_DEG

    def profile_object(self) -> Profile:
        """The fault's time profile in s of loop time."""
        onset = (self.warm_up + self.onset) * DT
        span = self.length * DT
        if self.profile == "pulse":
            return Profile("step", onset=onset, end=onset + span)
        if self.profile == "step":
            return Profile("step", onset=onset)
        return Profile(self.profile, onset=onset, duration=span, rate=1.0 / span, period=2 * span)


@dataclass(frozen=True)
class Outcome:
    """A run's result (from the record's start) and the supervisor holding its event log."""

    spec: Run
    result: SimResult
    supervisor: SubstitutionSupervisor

    @property
    def k(self) -> np.ndarray:
        """(N,) recorded sample index of every logged sample (negative during the warm-up)."""
        return np.arange(len(self.result.t)) - self.spec.warm_up

    def monitor(self, name: str) -> np.ndarray:
        """(N,) one signal the monitor published."""
        return self.result["lms"][name]

    def substituted(self) -> np.ndarray:
        """(N,) bool: the controller read the substitute ``psi_sub`` at this sample (never without ftc)."""
        if not self.spec.ftc:
            return np.zeros(len(self.result.t), dtype=bool)
        return self.monitor(switch_flag("psi", self.spec.substitute_on)) > 0.5

    def heading_deg(self) -> np.ndarray:
        """(N,) true heading (deg)."""
        return np.degrees(self.result["x"]["psi"])


def run(spec: Run) -> Outcome:
    """Simulate ``spec`` (fixed-step RK4, 4 steps per sample, on CasADi's virtual machine: for one
    run of 900 samples building C would cost more than it saves). The substitution is switched
    inside the loop (:func:`.design.design`); the supervisor only logs, from the recorded flags."""
    d = design(order=spec.order, mu=spec.mu, eps0_deg2=spec.eps0_deg2, r0=spec.r0, bandwidth=spec.bandwidth,
               integral=spec.integral, substitute_on=spec.substitute_on if spec.ftc else None,
               decision=spec.decision, noise_deg=spec.noise_deg)
    plant = d.plant
    samples = spec.warm_up + spec.record
    faults = [SensorFault(plant.y.index("psi"), "noise", math.radians(spec.noise_deg))]
    if spec.size_deg is not None:
        faults.append(SensorFault(plant.y.index(spec.sensor), spec.kind, math.radians(spec.size_deg),
                                  spec.profile_object()))
    result = simulate_system(plant, d.blocks, duration=samples * DT, dt=DT, x0=[math.radians(SET_POINT_DEG), 0.0],
                             sensor_faults=tuple(faults), d=torque_table(samples, spec.seed), seed=spec.seed,
                             substeps=SUBSTEPS, compiled=False)
    supervisor = SubstitutionSupervisor(d.monitor, correct=False, substitute_on=spec.substitute_on)
    supervisor.update(result.t, {d.monitor.name: result[d.monitor.name].values})
    return Outcome(spec, result, supervisor)


def first_sample(flags: np.ndarray, k: np.ndarray, start: int = 0) -> int | None:
    """The first recorded sample >= start where ``flags`` is set, or None."""
    hits = np.flatnonzero((flags > 0.5) & (k >= start))
    return int(k[hits[0]]) if hits.size else None

