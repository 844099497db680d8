"""Diagnosis and correction in the loop: isolation, identification and fault-tolerant correction.

A :class:`FaultDiagnosis` runs beside a simulation as its supervisor (every ``period`` s on the
samples just simulated). Once the isolation has decided enough generalised-force channels
(rows of B) to recover an actuator -- the decided rows of B identify it, and at least one of
its decided channels is faulty -- the channels' predicted faults give the delivered force
``tau_hat`` on those rows at the decision instant, ``u = u_e + B^+ (tau_hat - tau_d)`` the
delivered actuator values (eq. 26, u_e what healthy actuators would deliver) and the fault's
value follows; the fault kind is the one decided on the faulty channel where the actuator has the
largest share of authority (``|B_ia|`` times its range). An actuator all of whose channels are
decided healthy is healthy. With ``correct=True`` the command correction (divide by f_p,
subtract f_a, stop and redistribute) goes back to the loop and acts from the next supervisor
period on.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from uvsym.conventions import FORCE_LABELS
from uvsym.faults import actuator_kind
from uvsym.models.model import Model
from uvsym.observers.actuator import ActuatorObserver
from uvsym.observers.ftc import Correction, linear_correction
from uvsym.observers.identification import ActuatorFaultEstimate, actuator_values, configuration_at
from uvsym.observers.isolation import IsolationResult, IsolationSettings, Isolator

__all__ = ["FaultDiagnosis", "DETECTOR"]

DETECTOR = "fault_diagnosis"  # the name its events carry

# rows of the 6-DOF force vector that a model's channels occupy
_ROWS = {6: (0, 1, 2, 3, 4, 5), 3: (0, 1, 5)}


class FaultDiagnosis:
    """Supervisor: isolates, identifies and (optionally) corrects actuator faults of ``model``.

    observers: kind -> (ActuatorObserver, K), the observers running in the loop under the same
    names (their estimates arrive as ``f_hat/<kind>``). After the run, ``identified`` maps each
    faulty actuator to its :class:`ActuatorFaultEstimate`, ``healthy`` maps each actuator found
    healthy to the time (s), and ``isolator.result`` holds the isolation record.
    """

    def __init__(self, model: Model, observers: dict[str, tuple[ActuatorObserver, np.ndarray]],
                 settings: IsolationSettings | None = None, period: float = 0.1, correct: bool = True):
        self.model, self.period, self.correct = model, period, correct
        self.labels = model.input_labels
        self.channels = FORCE_LABELS[model.dof]
        self.isolator = Isolator(observers, self.channels, settings or IsolationSettings())
        self.identified: dict[str, ActuatorFaultEstimate] = {}
        self.healthy: dict[str, float] = {}
        self._y: list[np.ndarray] = []
        self._u_expected: list[np.ndarray] = []

    @property
    def decided(self) -> bool:
        """True once every actuator has been identified as faulty or found healthy."""
        return len(self.identified) + len(self.healthy) == len(self.labels)

    @property
    def isolation_time_s(self) -> float:
        """Time (s) by which every actuator was decided (NaN while some is not)."""
        times = [f.time_s for f in self.identified.values()] + list(self.healthy.values())
        return max(times) if self.decided else float("nan")

    @property
    def events(self) -> list:
        """The decisions in the one event log (:class:`uvsym.diagnosis.events.Event`, detector
        ``fault_diagnosis``): ``detected`` when the first channel is decided faulty, then per identified
        actuator ``isolated`` (its kind) and ``identified`` (its kind and value) at its decision time."""
        from uvsym.diagnosis.events import Event  # the diagnosis package builds on uvsym.sim, which builds on this

        faulty = [d.time_s for d in self.isolator.decisions.values() if d.kind != "healthy"]
        events = [Event(min(faulty), "detected", detector=DETECTOR)] if faulty else []
        for label, estimate in sorted(self.identified.items(), key=lambda item: item[1].time_s):
            events += [Event(estimate.time_s, "isolated", label, estimate.kind, detector=DETECTOR),
                       Event(estimate.time_s, "identified", label, estimate.kind, estimate.value, DETECTOR)]
        return sorted(events, key=lambda e: e.t)

    def update(self, t: np.ndarray, signals: dict[str, np.ndarray]) -> Correction | None:
        """Supervisor step (see :class:`uvsym.sim.Supervisor`); a new Correction or None."""
        self._y.append(signals["y"])
        self._u_expected.append(signals["u_expected"])
        result = self.isolator.update(t, {kind: signals[f"f_hat/{kind}"] for kind in self.isolator.observers},
                                      signals["tau_desired"])
        before = len(self.identified)
        if not self.decided and result.decisions:
            self._decide_actuators(result)
        if self.correct and len(self.identified) > before:
            y, u_e = self._y[-1][-1], self._u_expected[-1][-1]
            dof = self.model.dof
            B = configuration_at(self.model, y[:dof], y[dof:], u_e).B
            return linear_correction(self.identified, self.labels, B)
        return None

    def _decide_actuators(self, result: IsolationResult) -> None:
        """Identify or clear every actuator that the channels decided so far pin down."""
        dof, rows = self.model.dof, _ROWS[self.model.dof]
        time_s = max(d.time_s for d in result.decisions.values())
        k = int(np.argmin(np.abs(result.t - time_s)))
        y, u_e = np.vstack(self._y)[k], np.vstack(self._u_expected)[k]
        config = configuration_at(self.model, y[:dof], y[dof:], u_e)
        B = config.B[list(rows)]
        support = np.abs(B) > 1e-9 * np.abs(B).max()
        decided = [i for i, c in enumerate(self.channels) if c in result.decisions]
        faulty = [i for i in decided if result.decisions[self.channels[i]].kind != "healthy"]
        null = scipy.linalg.null_space(B[decided]) if decided else np.eye(len(self.labels))
        pinned = [a for a in range(len(self.labels)) if null.size == 0 or np.max(np.abs(null[a])) <= 1e-9]
        for a, label in enumerate(self.labels):
            if label in self.identified or label in self.healthy:
                continue
            channels = np.flatnonzero(support[:, a])
            if all(result.decisions.get(self.channels[i]) and result.decisions[self.channels[i]].kind == "healthy"
                   for i in channels):
                self.healthy[label] = max(result.decisions[self.channels[i]].time_s for i in channels)
        candidates = [a for a in pinned if self.labels[a] not in self.identified and self.labels[a] not in self.healthy
                      and any(support[i, a] for i in faulty)]
        if not candidates:
            return
        tau_d = np.zeros(6)
        tau_d[list(rows)] = np.asarray(self.model.tau(y[:dof], y[dof:], u_e, 0.0, 0.0)).ravel()
        tau_hat = tau_d.copy()
        for i in faulty:
            decision, row = result.decisions[self.channels[i]], rows[i]
            tau_hat[row] = actuator_kind(decision.kind).deliver(tau_d[row], decision.f_bar)
        u_hat = actuator_values(config, tau_hat, tau_d, u_e, rows=[rows[i] for i in decided])
        # an actuator's fault kind is read on the faulty channel where it has the largest share of authority
        authority = np.abs(B) * (self.model.u_max - self.model.u_min)
        share = authority / np.maximum(authority.sum(axis=1, keepdims=True), 1e-300)
        for a in candidates:
            channel = max((i for i in faulty if support[i, a]), key=lambda i: share[i, a])
            kind = result.decisions[self.channels[channel]].kind
            value = actuator_kind(kind).identify(u_hat[a], u_e[a])
            self.identified[self.labels[a]] = ActuatorFaultEstimate(self.labels[a], kind, value, time_s)
