"""Actuator and sensor faults: time profiles and their symbolic injection.

A fault changes a healthy value ``v`` (an actuator's applied value, or a measured state) to

    v_f = v + phi(t) * (target(v) - v)

where ``phi(t)`` in [0, 1] is the fault's time profile and ``target`` its kind (core paper,
Definition 1, for actuators). Everything is a CasADi expression of ``t``, so integrators, the
fixed-step path and generated code all see the same fault; ``phi`` is exactly 0 before onset.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca

from uvsym.errors import FaultError

__all__ = [
    "PROFILES",
    "ACTUATOR_KINDS",
    "SENSOR_KINDS",
    "Profile",
    "ActuatorFault",
    "SensorFault",
    "apply_actuator_faults",
    "apply_sensor_faults",
]

PROFILES = ("step", "ramp", "incipient", "intermittent")
ACTUATOR_KINDS = ("proportional", "bias", "constant", "loss_of_effectiveness")
SENSOR_KINDS = ("bias", "drift", "stuck", "noise")


@dataclass(frozen=True)
class Profile:
    """Time profile phi(t) of a fault (dimensionless, 0 before ``onset``, 0 after ``end``).

    step: 1; ramp: ``min((t - onset) / duration, 1)``; incipient: ``1 - exp(-rate (t - onset))``;
    intermittent: 1 for the first ``duty`` fraction of every ``period`` after onset.
    Times in s, ``rate`` in 1/s.
    """

    kind: str = "step"
    onset: float = 0.0
    end: float = math.inf
    duration: float = 1.0
    rate: float = 1.0
    period: float = 1.0
    duty: float = 0.5

    def __post_init__(self):
        if self.kind not in PROFILES:
            raise FaultError(f"unknown fault profile {self.kind!r}; known: {', '.join(PROFILES)}")
        for name in ("onset", "end", "duration", "rate", "period", "duty"):
            if math.isnan(getattr(self, name)):
                raise FaultError(f"fault profile {name} is NaN")
        if self.end <= self.onset:
            raise FaultError(f"fault profile end ({self.end} s) must be after its onset ({self.onset} s)")
        for name in ("duration", "rate", "period"):
            if not getattr(self, name) > 0.0 or math.isinf(getattr(self, name)):
                raise FaultError(f"fault profile {name} must be positive and finite, got {getattr(self, name)}")
        if not 0.0 < self.duty <= 1.0:
            raise FaultError(f"fault profile duty must be in (0, 1], got {self.duty}")

    def phi(self, t):
        """phi(t) as a CasADi expression of t (SX/MX/DM or float)."""
        s = t - self.onset
        active = ca.logic_and(s >= 0, t < self.end) if math.isfinite(self.end) else s >= 0
        if self.kind == "step":
            shape = 1.0
        elif self.kind == "ramp":
            shape = ca.fmin(s / self.duration, 1.0)
        elif self.kind == "incipient":
            shape = 1.0 - ca.exp(-self.rate * ca.fmax(s, 0.0))
        else:
            phase = s - self.period * ca.floor(s / self.period)
            shape = phase < self.duty * self.period
        return ca.if_else(active, shape, 0.0)


@dataclass(frozen=True)
class ActuatorFault:
    """A fault on one actuator (index into the model's inputs), in that input's unit.

    proportional: ``value * v`` (core paper f_p); bias: ``v + value`` (f_a); constant: ``value``
    regardless of the command (f_c, stuck); loss_of_effectiveness: ``(1 - value) * v``, value in [0, 1].
    """

    actuator: int
    kind: str
    value: float
    profile: Profile = Profile()

    def __post_init__(self):
        if self.kind not in ACTUATOR_KINDS:
            raise FaultError(f"unknown actuator fault kind {self.kind!r}; known: {', '.join(ACTUATOR_KINDS)}")
        if not math.isfinite(self.value):
            raise FaultError(f"actuator fault value must be finite, got {self.value}")
        if self.kind == "loss_of_effectiveness" and not 0.0 <= self.value <= 1.0:
            raise FaultError(f"loss_of_effectiveness must be in [0, 1], got {self.value}")

    def target(self, v):
        """The faulty value the profile blends towards."""
        if self.kind == "proportional":
            return self.value * v
        if self.kind == "bias":
            return v + self.value
        if self.kind == "constant":
            return self.value + 0.0 * v
        return (1.0 - self.value) * v


@dataclass(frozen=True)
class SensorFault:
    """A fault on one measured state (index into x = [eta; nu]), in that state's unit.

    bias: ``y + value``; drift: ``y + value (t - onset)`` (value per second); stuck: the value
    measured at the last sample before onset; noise: ``y + value n_k``, n_k standard normal per
    sample (value is the standard deviation).
    """

    channel: int
    kind: str
    value: float = 0.0
    profile: Profile = Profile()

    def __post_init__(self):
        if self.kind not in SENSOR_KINDS:
            raise FaultError(f"unknown sensor fault kind {self.kind!r}; known: {', '.join(SENSOR_KINDS)}")
        if not math.isfinite(self.value):
            raise FaultError(f"sensor fault value must be finite, got {self.value}")
        if self.kind == "noise" and self.value < 0.0:
            raise FaultError(f"sensor noise standard deviation must be >= 0, got {self.value}")


def _check_index(index: int, size: int, what: str) -> None:
    if not 0 <= index < size:
        raise FaultError(f"{what} index {index} is out of range for {size} {what}s")


def apply_actuator_faults(u, t, faults: tuple[ActuatorFault, ...]):
    """Applied actuator values (m,) with every fault injected; faults apply in the order given."""
    m = u.numel()
    parts = [u[i] for i in range(m)]
    for fault in faults:
        _check_index(fault.actuator, m, "actuator")
        v = parts[fault.actuator]
        parts[fault.actuator] = v + fault.profile.phi(t) * (fault.target(v) - v)
    return ca.vertcat(*parts)


def apply_sensor_faults(y, t, faults: tuple[SensorFault, ...], held, noise):
    """Measured values (n,) with sensor faults injected.

    y: (n,) true values; held: (n,) values latched at the last healthy sample (for stuck
    faults); noise: (n,) standard normal draws of this sample. Returns (y_f, held_next).
    """
    n = y.numel()
    parts = [y[i] for i in range(n)]
    latch = [y[i] for i in range(n)]
    for fault in faults:
        _check_index(fault.channel, n, "state")
        i, phi = fault.channel, fault.profile.phi(t)
        v = parts[i]
        if fault.kind == "bias":
            target = v + fault.value
        elif fault.kind == "drift":
            target = v + fault.value * (t - fault.profile.onset)
        elif fault.kind == "noise":
            target = v + fault.value * noise[i]
        else:
            target = held[i]
            latch[i] = ca.if_else(phi > 0, held[i], v)
        parts[i] = v + phi * (target - v)
    return ca.vertcat(*parts), ca.vertcat(*latch)
