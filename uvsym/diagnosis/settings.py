"""Settings of the continuous actuator diagnosis, with units, defaults and the thresholds they imply."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from uvsym.errors import DiagnosisError
from uvsym.faults import ACTUATOR_KINDS

__all__ = ["DiagnosisSettings"]


@dataclass(frozen=True)
class DiagnosisSettings:
    """How the diagnosis decides (every field is validated; an error names it as ``diagnosis.<field>``).

    observer: the bias observer (by name) whose estimate is the residual; kinds: fault kinds
    hypothesised per actuator; actuators: candidate actuator labels (empty: all); window_s (s):
    the sliding window of every detection test; min_window_s, isolation_window_s (s): the shortest
    and the longest post-alarm record an isolation is decided on (also the longest record a size is
    identified on); period_s (s): time between decisions; confirm: consecutive decisions
    that must agree before a state changes; false_alarm_rate: probability that one test of a
    healthy window alarms (Bonferroni-split over the hypotheses); isolation_error_rate: the
    chance that noise alone puts a wrong hypothesis this far ahead of the right one (sets the
    isolation margin); resolution: the smallest fault of a kind that scales the command (-) that
    must be detectable, else the actuator is "unexcited"; noise: measured channel -> standard
    deviation of its sensor noise (the channel's unit); floor: model-error floor of each force
    channel's noise level, as a fraction of the force the actuators can produce on it; correct:
    feed the identified faults back as a command correction.
    """

    observer: str = "bias"
    kinds: tuple[str, ...] = ("proportional", "bias", "constant")
    actuators: tuple[str, ...] = ()
    window_s: float = 2.0
    min_window_s: float = 0.5
    isolation_window_s: float = 8.0
    period_s: float = 0.1
    confirm: int = 3
    false_alarm_rate: float = 1e-6
    isolation_error_rate: float = 1e-3
    resolution: float = 0.05
    noise: dict[str, float] = field(default_factory=dict)
    floor: float = 1e-3
    correct: bool = False

    def __post_init__(self):
        for name in ("window_s", "min_window_s", "isolation_window_s", "period_s", "resolution", "floor"):
            _positive(name, getattr(self, name))
        for name in ("false_alarm_rate", "isolation_error_rate"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and 0 < value < 1):
                raise DiagnosisError(f"diagnosis.{name}: expected a probability in (0, 1), got {value!r}")
        if not self.min_window_s <= self.window_s <= self.isolation_window_s:
            raise DiagnosisError(f"diagnosis.min_window_s, window_s, isolation_window_s: expected min_window_s <= "
                                 f"window_s <= isolation_window_s, got {self.min_window_s}, {self.window_s}, "
                                 f"{self.isolation_window_s} s")
        if isinstance(self.confirm, bool) or not isinstance(self.confirm, int) or self.confirm < 1:
            raise DiagnosisError(f"diagnosis.confirm: expected a positive integer (decisions), got {self.confirm!r}")
        for name in ("kinds", "actuators"):
            names = getattr(self, name)
            if isinstance(names, str) or not all(isinstance(v, str) for v in names):
                raise DiagnosisError(f"diagnosis.{name}: expected a list of names, got {names!r}")
            twice = sorted({v for v in names if list(names).count(v) > 1})
            if twice:
                raise DiagnosisError(f"diagnosis.{name}: {twice[0]!r} is listed twice")
        if not self.kinds:
            raise DiagnosisError("diagnosis.kinds: at least one fault kind is needed")
        for kind in self.kinds:
            if kind not in ACTUATOR_KINDS:
                raise DiagnosisError(f"diagnosis.kinds: unknown fault kind {kind!r}; known: "
                                     f"{', '.join(ACTUATOR_KINDS)}")
        _distinct_kinds(self.kinds)
        if self.observer != "bias":
            raise DiagnosisError(f"diagnosis.observer: the residual is the bias observer's estimate, got "
                                 f"{self.observer!r}")
        if self.floor > 1:
            raise DiagnosisError(f"diagnosis.floor: a fraction of the actuators' force, at most 1, got {self.floor}")
        for channel, std in self.noise.items():
            if not (isinstance(std, (int, float)) and math.isfinite(std) and std >= 0):
                raise DiagnosisError(f"diagnosis.noise.{channel}: expected a standard deviation >= 0, got {std!r}")
        if not isinstance(self.correct, bool):
            raise DiagnosisError(f"diagnosis.correct: expected true or false, got {self.correct!r}")

    def detection_threshold(self, hypotheses: int) -> float:
        """GLR above which a window alarms: chi2(1) quantile at false_alarm_rate / hypotheses."""
        return _chi2_1_above(self.false_alarm_rate / max(hypotheses, 1))

    @property
    def isolation_margin(self) -> float:
        """GLR lead (noise variances) the best hypothesis needs over every rival."""
        return _chi2_1_above(self.isolation_error_rate)


def _chi2_1_above(probability: float) -> float:
    """x with P(chi2(1) > x) = probability."""
    from scipy.special import chdtri  # here: scipy.special costs every uvsym command about 0.1 s

    return float(chdtri(1, probability))


def _distinct_kinds(kinds) -> None:
    """DiagnosisError when two listed kinds are one hypothesis: their (gain, shift) lines, ``(g0, s0) + f (g1, s1)``,
    coincide (e.g. loss of effectiveness ``1 - f`` and proportional ``f``)."""
    def cross(a, b):
        return a[0] * b[1] - a[1] * b[0]

    for i, first in enumerate(kinds):
        for second in kinds[i + 1:]:
            a, b = ACTUATOR_KINDS[first], ACTUATOR_KINDS[second]
            da, db = (a.gain[1], a.shift[1]), (b.gain[1], b.shift[1])
            offset = (b.gain[0] - a.gain[0], b.shift[0] - a.shift[0])
            if cross(da, db) == 0 and cross(da, offset) == 0:
                raise DiagnosisError(f"diagnosis.kinds: {first} and {second} are the same hypothesis (one size maps "
                                     f"onto the other); list one of them")


def _positive(name: str, value) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (value > 0 and math.isfinite(value)):
        raise DiagnosisError(f"diagnosis.{name}: expected a positive finite number, got {value!r}")
