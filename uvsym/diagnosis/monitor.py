"""Continuous actuator-fault diagnosis: a per-actuator state machine over the whole mission.

Every ``period_s`` the last ``window_s`` of the bias observer's estimate is fitted with the faults
decided so far (:func:`~uvsym.diagnosis.fits.fit_window`) and every other actuator is tested for
each fault kind by its generalised likelihood ratio (GLR). The states and the events they log
(:mod:`uvsym.diagnosis.events`):

- *detected*: the best candidate's GLR is above the detection threshold in ``confirm``
  consecutive decisions (an alarm episode starts; the actuator logged is the leading candidate);
- *isolated*: on the record since the alarm, one (actuator, kind) leads every other actuator and
  every other kind by the isolation margin in ``confirm`` consecutive decisions; its onset is
  then estimated (the change time that fits best) and the fault joins the model;
- *ambiguous*: other actuators stay within the margin (redundant actuators whose effects the
  geometry and the commands do not tell apart), logged once per episode with the candidates;
- *unexcited*: an actuator whose commands are too small for a fault of ``resolution`` of a
  kind that scales the command to be seen (Liu et al. 2014, Remark 2) -- or, during an episode,
  whose fault kinds cannot be told apart because its command does not vary: "cannot tell yet";
- *identified*: once a window lies wholly after the fault's onset, its size from that fit;
- *cleared*: the fault at its identified size would be plainly visible in the window, yet
  dropping it does not worsen the fit (an intermittent fault that went away).

With ``correct`` the identified faults (and their clearing) go back to the loop as a command
correction (:func:`uvsym.observers.ftc.linear_correction`) from the next decision on.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace

import numpy as np

from uvsym.diagnosis.events import Event
from uvsym.diagnosis.fits import Hypothesis, fit_window
from uvsym.diagnosis.regressors import RegressorBank, ResidualNoise
from uvsym.diagnosis.settings import DiagnosisSettings
from uvsym.errors import DiagnosisError
from uvsym.faults import actuator_kind
from uvsym.models.model import Model
from uvsym.observers.actuator import ActuatorObserver
from uvsym.observers.ftc import Correction, linear_correction
from uvsym.observers.identification import ActuatorFaultEstimate, configuration_at

__all__ = ["ActuatorDiagnosis", "residual_noise"]

DETECTOR = "diagnosis"  # the name its events carry
_GAUSS_NEWTON_STEPS = 8  # at most, when a decided fault is sized


@dataclass
class _Decided:
    """A fault in the model: its hypothesis, size, decision times (s) and whether it is identified."""

    hypothesis: Hypothesis
    value: float
    isolated_s: float
    identified: bool = False
    clear_streak: int = 0
    revise_streak: int = 0


def residual_noise(model: Model, observer: ActuatorObserver, K, dt: float, settings: DiagnosisSettings,
                   y0) -> ResidualNoise:
    """The noise of the bias observer's estimate (:class:`~uvsym.diagnosis.regressors.ResidualNoise`).

    Sensor noise on the velocities (``settings.noise``) reaches the estimate through ``L = dR/dnu``
    (sampled-data gain ``(I - dt/2 P)^-1 L``) -- and, depending on the state, through the observer's
    force terms (evaluated per sample by the bank); noise on positions and attitudes does not. ``floor``
    times the force the actuators can produce on a channel at the state y0 (each actuator taken
    from 0 to either limit) is added in quadrature; a channel no actuator reaches gets 1e-3 of the
    largest level (it carries no hypothesis, only model error).
    """
    n = model.dof
    labels = model.state_labels
    unknown = sorted(set(settings.noise) - set(labels))
    if unknown:
        raise DiagnosisError(f"diagnosis.noise: unknown measured channel {unknown[0]!r}; the measured channels "
                             f"of {model.name} are {', '.join(labels)}")
    std = np.array([settings.noise.get(label, 0.0) for label in labels[n:]])
    y0 = np.asarray(y0, dtype=float)
    lower, upper = np.asarray(model.u_min, dtype=float), np.asarray(model.u_max, dtype=float)
    u0 = np.clip(0.0, lower, upper)
    tau0 = np.asarray(model.tau(y0[:n], y0[n:], u0, 0.0, 0.0)).ravel()
    scale = np.zeros(n)
    for a in range(model.n_inputs):
        reach = 0.0
        for limit in (lower[a], upper[a]):
            u = u0.copy()
            u[a] = limit
            reach = np.maximum(reach, np.abs(np.asarray(model.tau(y0[:n], y0[n:], u, 0.0, 0.0)).ravel() - tau0))
        scale += reach
    L = np.asarray(observer.L(y0[n:], tau0, K))
    P = np.asarray(observer.error_matrix(tau0, K))
    gain = np.linalg.solve(np.eye(n) - dt / 2 * P, L)
    white = np.sqrt((gain**2) @ std**2 + (settings.floor * scale) ** 2)
    if not np.any(white > 0):
        raise DiagnosisError(f"diagnosis: no actuator of {model.name} produces any force at the initial state "
                             "and no sensor noise is given; set diagnosis.noise")
    return ResidualNoise(np.maximum(white, 1e-3 * np.max(white)), std)


class ActuatorDiagnosis:
    """Supervisor (see :class:`uvsym.sim.Supervisor`) that diagnoses the actuators of ``model``.

    observer, K: the bias observer running in the loop under ``settings.observer`` (its estimate
    arrives as ``f_hat/<name>``); dt: sample period (s); noise: the noise of its estimate
    (:func:`residual_noise`). After a run, ``events`` is the decision log and ``faults`` maps each
    actuator in the model to its :class:`ActuatorFaultEstimate`.
    """

    def __init__(self, model: Model, observer: ActuatorObserver, K, dt: float, noise: ResidualNoise,
                 settings: DiagnosisSettings | None = None):
        settings = settings or DiagnosisSettings()
        if not actuator_kind(observer.kind).shift[1] or actuator_kind(observer.kind).gain != (1.0, 0.0):
            raise DiagnosisError(f"diagnosis.observer: the residual must come from a bias observer, "
                                 f"got a {observer.kind} observer")
        labels = model.input_labels
        for label in settings.actuators:
            if label not in labels:
                raise DiagnosisError(f"diagnosis.actuators: unknown actuator {label!r}; {model.name} has "
                                     f"{', '.join(labels)}")
        self.model, self.settings, self.labels = model, settings, labels
        self.period = settings.period_s
        self.K = np.asarray(K, dtype=float)
        self.candidates = [labels.index(a) for a in settings.actuators] or list(range(len(labels)))
        self.kinds = [actuator_kind(k) for k in settings.kinds]
        P = np.asarray(observer.error_matrix(np.ones(model.dof), self.K))
        self.bank = RegressorBank(model, P, dt, noise)
        self.every = max(1, int(round(settings.period_s / dt)))
        self.W = max(3, int(round(settings.window_s / dt)))
        self.W_min = max(3, int(round(settings.min_window_s / dt)))
        self.W_iso = max(self.W, int(round(settings.isolation_window_s / dt)))
        self.h_detect = settings.detection_threshold(len(self.candidates) * len(self.kinds))
        self.h_iso = settings.isolation_margin
        self.name = settings.observer
        self.reads = ("y", "u_expected", f"f_hat/{self.name}")
        self.events: list[Event] = []
        self.decided: dict[int, _Decided] = {}
        self._alarms = 0
        self._episode: int | None = None  # first alarming row of the current episode
        self._logged: set[str] = set()  # what this episode has logged already
        self._lead: tuple | None = None
        self._lead_streak = 0
        self._undecided_streak = 0
        self._unexcited: dict[int, int] = {}  # actuator -> consecutive low-information decisions (-1: logged)
        self._t = np.zeros(0)

    @property
    def faults(self) -> dict[str, ActuatorFaultEstimate]:
        """Actuator label -> its fault in the model (kind, size, isolation time)."""
        return {self.labels[a]: ActuatorFaultEstimate(self.labels[a], d.hypothesis.kind.name, d.value, d.isolated_s)
                for a, d in self.decided.items()}

    def update(self, t: np.ndarray, signals: dict[str, np.ndarray]) -> Correction | None:
        """Take the samples t (k,) with signals y, u_expected and f_hat/<observer>; decide on the grid."""
        first = len(self.bank)
        self._t = np.concatenate([self._t, np.asarray(t, dtype=float)])
        self.bank.append(*(np.asarray(signals[name]) for name in self.reads))
        before = {a: (d.hypothesis.kind.name, d.identified) for a, d in self.decided.items()}
        for k in range(first, len(self.bank)):
            if k >= self.W - 1 and k % self.every == 0:
                self._decide(k)
        after = {a: (d.hypothesis.kind.name, d.identified) for a, d in self.decided.items()}
        if self.settings.correct and after != before:
            y, u_e = self.bank.y[-1], self.bank.u_e[-1]
            n = self.model.dof
            B = configuration_at(self.model, y[:n], y[n:], u_e).B
            return linear_correction(self.faults, self.labels, B)
        return None

    def _fit(self, rows: np.ndarray, candidates: list[Hypothesis]):
        model = [replace(d.hypothesis, at=d.value) for d in self.decided.values()]
        values = np.array([d.value for d in self.decided.values()])
        return fit_window(self.bank, rows, model, values, candidates)

    def _log(self, k: int, event: str, actuator: str | None, kind: str | None = None, value=None,
             std: float | None = None) -> None:
        t = round(float(self._t[k]), 9)  # the sample time, without the float noise of k * dt
        self.events.append(Event(t, event, actuator, kind, None if value is None else float(value), DETECTOR,
                                 std))

    def _decide(self, k: int) -> None:
        rows = np.arange(k - self.W + 1, k + 1)
        free = [a for a in self.candidates if a not in self.decided]
        candidates = [Hypothesis(a, kind) for a in free for kind in self.kinds]
        fit = self._fit(rows, candidates)
        explained = not candidates or np.nanmax(fit.glr) <= self.h_detect
        self._update_model(k, rows, fit, explained)
        if (k // self.every) % max(1, self.W // self.every) == 0:  # once a window
            self._revise(k, rows, fit.J_model)
        self._watch_excitation(k, candidates, fit)
        glr = np.nan_to_num(fit.glr, nan=-np.inf)
        if candidates and np.max(glr) > self.h_detect:
            self._alarms += 1
        else:
            self._alarms, self._episode, self._logged = 0, None, set()
            self._lead, self._lead_streak, self._undecided_streak = None, 0, 0
            return
        if self._alarms < self.settings.confirm:
            return
        if self._episode is None:
            self._episode = k - (self.settings.confirm - 1) * self.every
            self._log(k, "detected", self.labels[candidates[int(np.argmax(glr))].actuator])
        self._isolate(k, candidates)

    def _update_model(self, k: int, rows: np.ndarray, fit, explained: bool) -> None:
        """Re-size the model's faults; identify those whose onset the window has left behind once the
        model explains the window (no candidate alarms); clear those gone."""
        for i, (a, decided) in enumerate(list(self.decided.items())):
            if not decided.identified and np.isfinite(fit.theta_model[i]):
                decided.value = float(fit.theta_model[i])
            if rows[0] < decided.hypothesis.onset:
                continue
            if not decided.identified:
                if not explained:
                    continue
                (decided.value, std), decided.identified = self._size(k, a), True
                self._log(k, "identified", self.labels[a], decided.hypothesis.kind.name, decided.value, std)
                continue
            gone = fit.power[i] > self.h_detect and fit.removal[i] < self.h_iso
            decided.clear_streak = decided.clear_streak + 1 if gone else 0
            if decided.clear_streak >= self.settings.confirm:
                del self.decided[a]
                self._log(k, "cleared", self.labels[a], decided.hypothesis.kind.name)

    def _size(self, k: int, actuator: int) -> tuple[float, float]:
        """The size of a decided fault fitted on the record since its onset (at most isolation_window_s),
        Gauss-Newton through the exact force model until the size moves less than 1e-6 of itself, and its
        standard deviation under the residual's noise model (the joint fit's inverse information)."""
        decided = self.decided[actuator]
        rows = np.arange(max(decided.hypothesis.onset, k - self.W_iso + 1), k + 1)
        index = list(self.decided).index(actuator)
        std = np.nan
        for _ in range(_GAUSS_NEWTON_STEPS):
            fit = self._fit(rows, [])
            value, std = float(fit.theta_model[index]), float(np.sqrt(max(fit.cov_model[index, index], 0.0)))
            if not np.isfinite(value):
                break
            step, decided.value = value - decided.value, value
            if abs(step) <= 1e-6 * max(abs(value), 1e-12):
                break
        return decided.value, std

    def _revise(self, k: int, rows: np.ndarray, J_model: float) -> None:
        """Re-judge each decided fault's kind, once a window, on a window wholly after its onset: a rival
        kind on the same actuator that fits better by the isolation margin (both through the exact force
        model) in ``confirm`` checks running -- windows that do not overlap, so that a fault coming and
        going does not count -- replaces it -- e.g. a bias first seen while the command sat on its
        limit, where it acts like an actuator stuck there."""
        for a, decided in list(self.decided.items()):
            h = decided.hypothesis
            if rows[0] < h.onset or len(self.kinds) < 2:
                continue
            others = [replace(d.hypothesis, at=d.value) for b, d in self.decided.items() if b != a]
            values = np.array([d.value for b, d in self.decided.items() if b != a])
            rivals = [Hypothesis(a, kind, h.onset) for kind in self.kinds if kind.name != h.kind.name]
            linear = fit_window(self.bank, rows, others, values, rivals)
            if not np.any(np.isfinite(linear.theta)):
                continue
            best = int(np.nanargmax(np.where(np.isfinite(linear.theta), linear.glr, -np.inf)))
            rival = replace(rivals[best], at=float(linear.theta[best]))
            exact = fit_window(self.bank, rows, others + [rival], np.append(values, rival.at), [])
            # a rival that explains the window only by acting like no fault leaves the fault to clearing
            better = (exact.J_model + self.h_iso < J_model and np.isfinite(exact.theta_model[-1])
                      and exact.power[-1] > self.h_detect)
            decided.revise_streak = decided.revise_streak + 1 if better else 0
            if decided.revise_streak >= self.settings.confirm:
                value = float(exact.theta_model[-1])
                self.decided[a] = _Decided(replace(rival, at=None), value, float(self._t[k]))
                self._log(k, "isolated", self.labels[a], rival.kind.name, value)

    def _watch_excitation(self, k: int, candidates: list[Hypothesis], fit) -> None:
        """Log an actuator as unexcited when a fault of ``resolution`` that scales its command would stay unseen."""
        for j, h in enumerate(candidates):
            if not h.kind.scales:
                continue
            visible = fit.info[j] * self.settings.resolution**2
            count = self._unexcited.get(h.actuator, 0)
            if visible < self.h_detect:
                if count >= 0:
                    count += 1
                    if count >= self.settings.confirm:
                        self._log(k, "unexcited", self.labels[h.actuator], h.kind.name)
                        count = -1
            elif visible > 2 * self.h_detect:
                count = 0
            self._unexcited[h.actuator] = count

    def _isolate(self, k: int, candidates: list[Hypothesis]) -> None:
        """One isolation decision on the record since the episode's first alarm (module docstring)."""
        start = max(self._episode, k - self.W_iso + 1)
        if k - start + 1 < self.W_min:
            return
        rows = np.arange(start, k + 1)
        fit = self._fit(rows, candidates)
        glr = np.nan_to_num(fit.glr, nan=-np.inf)
        best = int(np.argmax(glr))
        lead = candidates[best]
        rival_actuators = [j for j, h in enumerate(candidates) if h.actuator != lead.actuator]
        rival_kinds = [j for j, h in enumerate(candidates) if h.actuator == lead.actuator and j != best]
        close = [j for j in rival_actuators if glr[best] - glr[j] < self.h_iso]
        kind_told = all(glr[best] - glr[j] >= self.h_iso for j in rival_kinds)
        decision = None
        if glr[best] > self.h_detect and not close and kind_told:
            decision = ((lead, float(fit.theta[best])),)
        elif close:
            group = sorted({candidates[j].actuator for j in close} | {lead.actuator})
            decision = self._pair(rows, candidates, group, fit.J_model - glr[best])
        if decision is not None:
            key = tuple((h.actuator, h.kind.name) for h, _ in decision)
            self._lead_streak = self._lead_streak + 1 if self._lead == key else 1
            self._lead, self._undecided_streak = key, 0
            if self._lead_streak >= self.settings.confirm:
                self._accept(k, decision)
            return
        self._lead, self._lead_streak = None, 0
        self._undecided_streak += 1
        if self._undecided_streak < self.settings.confirm:
            return
        if close and "ambiguous" not in self._logged:
            names = sorted({self.labels[candidates[j].actuator] for j in close} | {self.labels[lead.actuator]})
            kinds = {candidates[j].kind.name for j in close} | {lead.kind.name}
            self._log(k, "ambiguous", "|".join(names), kinds.pop() if len(kinds) == 1 else None)
            self._logged.add("ambiguous")
        elif not close and not kind_told and "unexcited" not in self._logged:
            self._log(k, "unexcited", self.labels[lead.actuator])
            self._logged.add("unexcited")

    def _pair(self, rows: np.ndarray, candidates: list[Hypothesis], group: list[int], J_single: float):
        """Two simultaneous faults within ``group`` (actuators no single fault tells apart): the pair
        that fits best, if it beats the best single fault and every other pair by the margin."""
        model = [replace(d.hypothesis, at=d.value) for d in self.decided.values()]
        values = np.array([d.value for d in self.decided.values()] + [np.nan])
        pairs = []
        for i, a in enumerate(group):
            for first in (h for h in candidates if h.actuator == a):
                seconds = [h for h in candidates if h.actuator in group[i + 1:]]
                if not seconds:
                    continue
                fit = fit_window(self.bank, rows, model + [first], values, seconds)
                for j, second in enumerate(seconds):
                    if np.isfinite(fit.glr[j]):
                        pairs.append((fit.J_model - fit.glr[j], ((first, float(fit.theta_model[-1])),
                                                                 (second, float(fit.theta[j])))))
        if len(pairs) < 1:
            return None
        pairs.sort(key=lambda p: p[0])
        J_best = pairs[0][0]
        runner_up = pairs[1][0] if len(pairs) > 1 else np.inf
        if J_single - J_best >= self.h_iso and runner_up - J_best >= self.h_iso:
            return pairs[0][1]
        return None

    def _accept(self, k: int, decision) -> None:
        """Put the decided faults into the model with their onset estimated; log; end the episode."""
        onset = self._onset(k, decision[0][0])
        for lead, theta in decision:
            self.decided[lead.actuator] = _Decided(Hypothesis(lead.actuator, lead.kind, onset), theta,
                                                   float(self._t[k]))
            self._log(k, "isolated", self.labels[lead.actuator], lead.kind.name, theta)
            self._unexcited.pop(lead.actuator, None)
        self._alarms, self._episode, self._logged = 0, None, set()
        self._lead, self._lead_streak, self._undecided_streak = None, 0, 0

    def _onset(self, k: int, lead: Hypothesis) -> int:
        """The change time (sample) that fits ``lead`` best on the record since the episode's first alarm
        and up to ``isolation_window_s`` (at least ``window_s``) before it: 40 candidates across that span,
        then every sample around the best of them (the episode's start where no onset lets it be seen)."""
        first = max(0, min(self._episode - self.W + 1, k - self.W_iso + 1))
        rows = np.arange(first, k + 1)

        @functools.cache  # the coarse best is looked at again in the fine search
        def misfit(onset: int) -> float:
            fit = self._fit(rows, [Hypothesis(lead.actuator, lead.kind, onset)])
            J = float(fit.J_model - fit.glr[0])
            return J if np.isfinite(J) else np.inf

        spacing = max(1, (self._episode - first) // 40)
        coarse = min(range(first, self._episode + 1, spacing), key=misfit)
        if not np.isfinite(misfit(coarse)):  # the hypothesis is not seen at any onset
            return self._episode
        return min(range(max(first, coarse - spacing + 1), min(self._episode, coarse + spacing - 1) + 1), key=misfit)
