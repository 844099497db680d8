"""Actuator and sensor faults: kinds, time profiles and their symbolic injection.

A fault changes a healthy value ``v`` (an actuator's applied value, or a measured state) to

    v_f = v + phi(t) * (target(v) - v)

where ``phi(t)`` in [0, 1] is the fault's time profile and ``target`` its kind (Liu et al. 2014,
Definition 1, for actuators). Everything is a CasADi expression of ``t``, so integrators, the
fixed-step path and generated code all see the same fault; ``phi`` is exactly 0 before onset.
A fault's numbers (:data:`FAULT_PARAMETERS`: value and profile times) can be symbols instead
(:func:`symbolic_fault`), so that one compiled loop runs every fault of the same shape (target,
kind, profile kind), the numbers given per run (:func:`fault_parameters`).

Each kind is one object (:class:`ActuatorKind`, :class:`SensorKind`) in the registries
``ACTUATOR_KINDS`` and ``SENSOR_KINDS``; identification, correction, isolation and units ask it
instead of testing names, so a new kind is one entry here. Faults keep their kind as its name
(a string, as scenarios and results write it): ``fault.kind == "bias"``, and
``fault.kind_object`` (or :func:`actuator_kind` / :func:`sensor_kind`) gives the object.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from types import MappingProxyType
from typing import Callable, ClassVar

import casadi as ca
import numpy as np

from uvsym.errors import FaultError, IdentifiabilityError

__all__ = ["PROFILES", "ACTUATOR_KINDS", "SENSOR_KINDS", "ActuatorKind", "SensorKind", "actuator_kind", "sensor_kind",
           "Profile", "ActuatorFault", "SensorFault", "apply_actuator_faults", "apply_sensor_faults",
           "actuator_fault_affine", "FAULT_PARAMETERS", "fault_parameters", "fault_shape", "symbolic_fault"]

PROFILES = ("step", "ramp", "incipient", "intermittent")
TIME_TOLERANCE = 1e-9  # s


@dataclass(frozen=True)
class _Kind:
    """A fault kind: its name and the closed interval its values must lie in."""

    TARGET: ClassVar[str]
    name: str
    limits: tuple[float, float]

    def check(self, value) -> None:
        """Raise FaultError unless ``value`` is a finite number within :attr:`limits`."""
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
            raise FaultError(f"{self.TARGET} {self.name} fault value must be a finite number, got {value!r}")
        lower, upper = self.limits
        if not lower <= value <= upper:
            raise FaultError(f"{self.TARGET} {self.name} fault value must be in [{lower:g}, {upper:g}], got {value}")


@dataclass(frozen=True)
class ActuatorKind(_Kind):
    """How an actuator fault of value f changes the commanded value v (Definition 1).

    Every kind is affine in v and in f: ``deliver(v, f) = (g0 + g1 f) v + (s0 + s1 f)`` with
    ``gain = (g0, g1)`` (dimensionless) and ``shift = (s0, s1)`` (s0 in v's unit), so
    identification, correction and the unit of f follow from these four numbers. ``healthy`` is
    the f that changes nothing (None when that is the command itself, as for constant).
    """

    TARGET: ClassVar[str] = "actuator"
    gain: tuple[float, float]
    shift: tuple[float, float]
    healthy: float | None

    @property
    def scales(self) -> bool:
        """True when f multiplies the command: f is dimensionless and unseen while v = 0 (Remark 2)."""
        return self.gain[1] != 0.0

    @property
    def ignores_command(self) -> bool:
        """True when the delivered value does not depend on the command (a stuck actuator)."""
        return self.gain == (0.0, 0.0)

    def unit(self, input_unit: str) -> str:
        """Unit of f for an input in ``input_unit``: ``-`` when f scales, else the input's own."""
        return "-" if self.scales else input_unit

    def affine(self, f):
        """(gain, shift) with ``deliver(v, f) = gain v + shift``."""
        return self.gain[0] + self.gain[1] * f, self.shift[0] + self.shift[1] * f

    def deliver(self, v, f):
        """The value delivered for command v (float, numpy or CasADi SX/MX/DM)."""
        gain, shift = self.affine(f)
        return gain * v + shift

    def identify(self, delivered: float, command: float) -> float:
        """The f with ``deliver(command, f) = delivered`` (IdentifiabilityError where f has no effect)."""
        sensitivity = self.gain[1] * command + self.shift[1]
        if abs(sensitivity) <= 1e-12:
            raise IdentifiabilityError(f"a {self.name} fault cannot be sized while the desired value is zero")
        return float((delivered - self.gain[0] * command - self.shift[0]) / sensitivity)

    def severity(self, value, command=None):
        """``|value - healthy|``, or ``|value - command|`` for a kind without a fixed healthy value (f's unit)."""
        reference = self.healthy if self.healthy is not None else command
        if reference is None:
            raise FaultError(f"a {self.name} fault is healthy only at the command: pass the command")
        return abs(value - reference)

    def correction(self, value) -> tuple[float, float] | None:
        """(scale, offset) such that the command ``scale u + offset`` delivers u despite the fault.

        None when the delivered value ignores the command (stop the actuator and hand its share to
        the others); IdentifiabilityError when the fault leaves the command (almost) no effect.
        """
        if self.ignores_command:
            return None
        gain, shift = self.affine(value)
        if abs(gain) <= 1e-9:
            raise IdentifiabilityError(f"a {self.name} fault of {value} leaves the command no effect to correct")
        return 1.0 / gain, -shift / gain


@dataclass(frozen=True)
class SensorKind(_Kind):
    """How a sensor fault of value f changes the measurement of v.

    ``measure(v, f, t, onset, held, noise)`` is the faulty measurement (t, onset in s; held the
    value latched at the last healthy sample; noise a standard normal draw); ``latches`` is True
    for a kind that keeps ``held`` from the onset on; ``noise`` for a kind that is sensor noise (the
    sensors' specification when it acts the whole run, not a fault).
    """

    TARGET: ClassVar[str] = "sensor"
    measure: Callable
    latches: bool = False
    noise: bool = False


_ANY = (-math.inf, math.inf)
ACTUATOR_KINDS = MappingProxyType({kind.name: kind for kind in (
    ActuatorKind("proportional", _ANY, gain=(0.0, 1.0), shift=(0.0, 0.0), healthy=1.0),  # f v (f_p)
    ActuatorKind("bias", _ANY, gain=(1.0, 0.0), shift=(0.0, 1.0), healthy=0.0),  # v + f (f_a)
    ActuatorKind("constant", _ANY, gain=(0.0, 0.0), shift=(0.0, 1.0), healthy=None),  # f, stuck (f_c)
    ActuatorKind("loss_of_effectiveness", (0.0, 1.0), gain=(1.0, -1.0), shift=(0.0, 0.0), healthy=0.0),  # (1 - f) v
)})
SENSOR_KINDS = MappingProxyType({kind.name: kind for kind in (
    SensorKind("bias", _ANY, lambda v, f, t, onset, held, noise: v + f),
    SensorKind("drift", _ANY, lambda v, f, t, onset, held, noise: v + f * (t - onset)),  # f per second
    SensorKind("stuck", _ANY, lambda v, f, t, onset, held, noise: held, latches=True),
    SensorKind("noise", (0.0, math.inf), lambda v, f, t, onset, held, noise: v + f * noise, noise=True),  # f: std
    # f: the bound; erf(n / sqrt 2) of a standard normal n is uniform in [-1, 1]
    SensorKind("uniform_noise", (0.0, math.inf),
               lambda v, f, t, onset, held, noise: v + f * ca.erf(noise / math.sqrt(2.0)), noise=True),
)})


def _lookup(registry, name, target: str):
    if not isinstance(name, str) or name not in registry:
        raise FaultError(f"unknown {target} fault kind {name!r}; known: {', '.join(registry)}")
    return registry[name]


def actuator_kind(name: str) -> ActuatorKind:
    """The actuator fault kind called ``name`` (FaultError listing the known ones otherwise)."""
    return _lookup(ACTUATOR_KINDS, name, "actuator")


def sensor_kind(name: str) -> SensorKind:
    """The sensor fault kind called ``name`` (FaultError listing the known ones otherwise)."""
    return _lookup(SENSOR_KINDS, name, "sensor")


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
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, numbers.Real) or math.isnan(value):
                raise FaultError(f"fault profile {name} must be a number (s, 1/s or -), got {value!r}")
        if not 0.0 <= self.onset < math.inf:
            raise FaultError(f"fault profile onset must be a finite time >= 0 s (runs start at 0), got {self.onset}")
        if self.end <= self.onset:
            raise FaultError(f"fault profile end ({self.end} s) must be after its onset ({self.onset} s)")
        for name in ("duration", "rate", "period"):
            if not getattr(self, name) > 0.0 or math.isinf(getattr(self, name)):
                raise FaultError(f"fault profile {name} must be positive and finite, got {getattr(self, name)}")
        if not 0.0 < self.duty <= 1.0:
            raise FaultError(f"fault profile duty must be in (0, 1], got {self.duty}")

    def active(self, t):
        """True from onset until end (CasADi expression); a time within ``TIME_TOLERANCE`` of
        either counts as at it, so that a sample k dt that rounds just below an onset is in."""
        started = t - self.onset >= -TIME_TOLERANCE
        if isinstance(self.end, numbers.Real) and math.isinf(self.end):
            return started
        return ca.logic_and(started, t < self.end - TIME_TOLERANCE)

    def phi(self, t):
        """phi(t) as a CasADi expression of t (SX/MX/DM or float)."""
        s = ca.fmax(t - self.onset, 0.0)
        if self.kind == "step":
            shape = 1.0
        elif self.kind == "ramp":
            shape = ca.fmin(s / self.duration, 1.0)
        elif self.kind == "incipient":
            shape = 1.0 - ca.exp(-self.rate * s)
        else:
            phase = s - self.period * ca.floor(s / self.period)
            shape = phase < self.duty * self.period
        return ca.if_else(self.active(t), shape, 0.0)

    def jumps(self, t: np.ndarray, dt: float) -> np.ndarray:
        """(len(t),) True where phi jumps within the sample from t (s) to t + dt: its onset (step,
        intermittent), each switch of an intermittent profile, its end (a time within ``TIME_TOLERANCE``
        of a sample counts as at it, as :meth:`active` has it). t ascending."""
        t = np.asarray(t, dtype=float)
        last = min(self.end, float(t[-1]) + dt) if t.size else self.onset
        edges = [self.onset] if self.kind in ("step", "intermittent") else []
        on_at_end = True
        if self.kind == "intermittent" and self.duty < 1.0:
            cycles = self.onset + self.period * np.arange(math.floor((last - self.onset) / self.period) + 2)
            edges += [e for e in (*cycles[1:], *(cycles + self.duty * self.period)) if e < self.end]
            on_at_end = (self.end - self.onset) % self.period < self.duty * self.period
        if math.isfinite(self.end) and on_at_end:
            edges.append(self.end)
        edges = np.sort(np.asarray(edges, dtype=float)) - TIME_TOLERANCE
        return np.searchsorted(edges, t + dt, side="right") > np.searchsorted(edges, t, side="right")


@dataclass(frozen=True)
class ActuatorFault:
    """A fault on one actuator (index into the model's inputs), ``value`` in the kind's unit.

    kind: a name in ACTUATOR_KINDS -- proportional ``value * v`` (Liu et al. 2014's f_p); bias
    ``v + value`` (f_a); constant ``value`` regardless of the command (f_c, stuck);
    loss_of_effectiveness ``(1 - value) * v``, value in [0, 1].
    """

    actuator: int
    kind: str
    value: float
    profile: Profile = Profile()

    def __post_init__(self):
        _check_index_type(self.actuator, "actuator")
        self.kind_object.check(self.value)
        healthy = self.kind_object.healthy
        if isinstance(self.value, (int, float)) and healthy is not None and self.value == healthy:
            raise FaultError(f"a {self.kind} actuator fault of {self.value!r} changes nothing (the healthy value)")

    @property
    def kind_object(self) -> ActuatorKind:
        """The :class:`ActuatorKind` named by ``kind``."""
        return actuator_kind(self.kind)


@dataclass(frozen=True)
class SensorFault:
    """A fault on one measured output (index into the plant's outputs y; for a vehicle y = x =
    [eta; nu]), in that output's unit.

    kind: a name in SENSOR_KINDS -- bias ``y + value``; drift ``y + value (t - onset)`` (value
    per second); stuck: the value measured at the last sample before onset; noise
    ``y + value n_k``, n_k standard normal per sample (value is the standard deviation, >= 0);
    uniform_noise ``y + value erf(n_k / sqrt 2)``, uniform in ``[-value, value]`` (value the bound).
    """

    channel: int
    kind: str
    value: float = 0.0
    profile: Profile = Profile()

    def __post_init__(self):
        _check_index_type(self.channel, "channel")
        self.kind_object.check(self.value)
        if isinstance(self.value, (int, float)) and self.value == 0 and self.kind != "stuck":
            raise FaultError(f"a {self.kind} sensor fault of 0 changes nothing: give its value "
                             f"({'per second' if self.kind == 'drift' else 'the output unit'})")

    @property
    def kind_object(self) -> SensorKind:
        """The :class:`SensorKind` named by ``kind``."""
        return sensor_kind(self.kind)


FAULT_PARAMETERS = ("value", "onset", "end", "duration", "rate", "period", "duty")
_NEVER = 1.7976931348623157e308  # an end of inf, finite


def fault_parameters(fault: ActuatorFault | SensorFault) -> tuple[float, ...]:
    """The fault's numbers in the order of :data:`FAULT_PARAMETERS` (its value, its profile's times; an
    end of never as the largest float, so that the numbers stay finite)."""
    values = (fault.value,) + tuple(getattr(fault.profile, name) for name in FAULT_PARAMETERS[1:])
    return tuple(min(float(v), _NEVER) for v in values)


def fault_shape(fault: ActuatorFault | SensorFault) -> tuple:
    """What a fault's symbolic injection depends on besides its numbers: (class, index, kind, profile kind)."""
    index = fault.actuator if isinstance(fault, ActuatorFault) else fault.channel
    return type(fault).__name__, index, fault.kind, fault.profile.kind


@dataclass(frozen=True)
class _SymbolicProfile:
    """A :class:`Profile` whose times are CasADi symbols (validated as numbers before, per run)."""

    kind: str
    onset: ca.SX
    end: ca.SX
    duration: ca.SX
    rate: ca.SX
    period: ca.SX
    duty: ca.SX

    active = Profile.active
    phi = Profile.phi


@dataclass(frozen=True)
class _SymbolicFault:
    """A fault whose value and profile are symbols: what the ``apply_*`` functions read of a fault."""

    actuator: int
    channel: int
    kind: str
    value: ca.SX
    profile: _SymbolicProfile
    kind_object: ActuatorKind | SensorKind


def symbolic_fault(shape: tuple, theta: ca.SX) -> _SymbolicFault:
    """The fault of ``shape`` (:func:`fault_shape`) with the symbols theta (len(FAULT_PARAMETERS),) for its
    numbers, in that order, for :func:`apply_actuator_faults` / :func:`apply_sensor_faults`."""
    cls, index, kind, profile_kind = shape
    profile = _SymbolicProfile(profile_kind, *(theta[i] for i in range(1, len(FAULT_PARAMETERS))))
    kind_object = actuator_kind(kind) if cls == ActuatorFault.__name__ else sensor_kind(kind)
    return _SymbolicFault(index, index, kind, theta[0], profile, kind_object)


def _check_index_type(index, what: str) -> None:
    if isinstance(index, bool) or not isinstance(index, numbers.Integral):
        raise FaultError(f"fault {what} must be an integer index (e.g. system.y.index(name)), got {index!r}")


def _check_index(index: int, size: int, what: str) -> None:
    if not 0 <= index < size:
        raise FaultError(f"{what} index {index} is out of range for {size} {what}s")


def actuator_fault_affine(faults: tuple[ActuatorFault, ...], m: int, phis,
                          shape: tuple[int, ...]) -> tuple[list[tuple[int, int]], np.ndarray]:
    """The faults composed, as affine maps of the actuator values: ``applied = a + D a + B``.

    phis: one array of ``shape`` P per fault, its profile's phi at the times wanted. Returns
    (parts, folded of shape ``(len(parts), *P)``): parts the (0, actuator) of each D and (1, actuator) of each B the
    faults can make non-zero (a D where a gain is not 1, a B where a shift is not 0), sorted; every other
    D and B is 0. A fault ``v -> v + phi (g v + b - v)`` (``(g, b) = kind.affine(value)``) maps (D, B) to
    ``(D + c + c D, B + c B + phi b)`` with ``c = phi (g - 1)``, faults in order, composed in place in one
    buffer (temporaries of a run's length cost their page faults on every call).
    """
    affine = []
    for fault in faults:
        _check_index(fault.actuator, m, "actuator")
        affine.append((fault.actuator, *fault.kind_object.affine(fault.value)))
    parts = sorted({(part, actuator) for actuator, gain, shift in affine
                    for part, acts in ((0, gain != 1.0), (1, shift != 0.0)) if acts})
    where = {part: i for i, part in enumerate(parts)}
    folded, c, scratch = np.zeros((len(parts), *shape)), np.empty(shape), np.empty(shape)
    for phi, (actuator, gain, shift) in zip(phis, affine):
        np.multiply(phi, gain - 1.0, out=c)
        for part in (0, 1):
            if (part, actuator) in where:  # D + c + c D, B + c B + phi b
                value = folded[where[part, actuator]]
                value += np.multiply(c, value, out=scratch)
                value += c if part == 0 else np.multiply(phi, shift, out=scratch)
    return parts, folded


def apply_actuator_faults(u, t, faults: tuple[ActuatorFault, ...]):
    """Applied actuator values (m,) with every fault injected; faults apply in the order given."""
    m = u.numel()
    parts = [u[i] for i in range(m)]
    for fault in faults:
        _check_index(fault.actuator, m, "actuator")
        v = parts[fault.actuator]
        parts[fault.actuator] = v + fault.profile.phi(t) * (fault.kind_object.deliver(v, fault.value) - v)
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
        _check_index(fault.channel, n, "measured output")
        i, phi, kind = fault.channel, fault.profile.phi(t), fault.kind_object
        v = parts[i]
        target = kind.measure(v, fault.value, t, fault.profile.onset, held[i], noise[i])
        if kind.latches:
            latch[i] = ca.if_else(fault.profile.active(t), held[i], v)
        parts[i] = v + phi * (target - v)
    return ca.vertcat(*parts), ca.vertcat(*latch)
