"""The double criterion of an LMS-FIR sensor monitor, and the supervisor that substitutes the sensor.

Zhu Daqi et al. (LMS-FIR compass-fault paper, Sec. 3.2): the error criterion ``eps^2(k) > eps0``
fires at once but also on disturbances; the weight-drift criterion ``R(k) > r0`` is robust but
lags. On the first ``eps^2`` alarm the filter is frozen (its weights stored); if ``R`` also fires
the sensor is faulty and the frozen filter's prediction replaces it in the loop; if only
``eps^2`` fired it was a disturbance.

Per sample, with ``a_e``, ``a_R`` the two alarms (0 or 1) and ``(frozen, age, fault)`` the state
carried from the last sample::

    armed      = frozen or a_e                     (a new freeze when not frozen and a_e)
    age_k      = 0 on a new freeze, else age + 1   (samples since the eps^2 alarm)
    fault_k    = fault or (armed and a_R and age_k <= confirm)      (latched)
    released_k = armed and not fault_k and age_k >= confirm         (a disturbance)
    frozen_k   = armed and not released_k

``confirm`` (samples) is how long ``R`` has to confirm an ``eps^2`` alarm; after a release the
next ``eps^2`` alarm freezes the filter anew. :func:`double_criterion` is that logic as a
casadi.Function (used inside the LMS observer's step, so it runs compiled and in C).

Two ways to put the substitute in the loop. In the same sample: a switch block
(:func:`uvsym.sim.blocks.select`) on the flag :func:`switch_flag` names publishes ``flag ? <y>_sub
: <y>`` for the controller to read; the flag of sample k is computed from y_k, the substitute from
data up to k - 1, so the controller acts on the substitute from the sample the flag rises.
From the next sample: :class:`SubstitutionSupervisor` turns the published flag into a measurement
substitution (:class:`uvsym.sim.run.Substitution`), one sample late. Both keep the event log of
:class:`SubstitutionSupervisor` (with ``correct=False`` it only logs).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.errors import ObserverError

__all__ = ["DECISION_STATE", "SWITCH_FLAGS", "double_criterion", "switch_flag", "Event", "SubstitutionSupervisor"]

DECISION_STATE = ("frozen", "age", "fault")
SWITCH_FLAGS = {"fault": "fault", "alarm": "frozen"}  # substitute_on -> the flag that switches the sensor out


def switch_flag(channel: str, substitute_on: str = "fault") -> str:
    """The monitor's published flag (0/1) that is set while ``channel`` is replaced by its substitute:
    ``fault_<y>`` once the fault is confirmed (``"fault"``), ``frozen_<y>`` from the first eps^2
    alarm to the release (``"alarm"``; a confirmed fault keeps the filter frozen).
    ObserverError naming substitute_on for another rule."""
    if substitute_on not in SWITCH_FLAGS:
        raise ObserverError(f"substitute_on must be one of {', '.join(SWITCH_FLAGS)}, got {substitute_on!r}")
    return f"{SWITCH_FLAGS[substitute_on]}_{channel}"


def double_criterion(confirm: int) -> ca.Function:
    """``decide(d, a_e, a_R) -> (d_next, snapshot, released)`` (module docstring).

    d: (3,) ``[frozen, age, fault]`` (0/1, samples, 0/1); a_e, a_R: the alarms of this sample
    (0/1); d_next: the state after this sample (its entries are this sample's decision);
    snapshot: 1 on the sample that freezes the filter; released: 1 on the sample an unconfirmed
    freeze is let go (a disturbance). ObserverError unless confirm is a positive integer.
    """
    if isinstance(confirm, bool) or not isinstance(confirm, (int, np.integer)) or confirm < 1:
        raise ObserverError(f"double criterion: confirm must be a positive integer (samples), got {confirm!r}")
    d, a_e, a_r = ca.SX.sym("d", 3), ca.SX.sym("a_e"), ca.SX.sym("a_R")
    frozen, age, fault = d[0], d[1], d[2]
    snapshot = ca.logic_and(ca.logic_not(frozen), a_e)
    armed = ca.logic_or(frozen, a_e)
    age_k = ca.if_else(snapshot, 0.0, age + 1.0)
    fault_k = ca.logic_or(fault, ca.logic_and(ca.logic_and(armed, a_r), age_k <= confirm))
    released = ca.logic_and(ca.logic_and(armed, ca.logic_not(fault_k)), age_k >= confirm)
    frozen_k = ca.logic_and(armed, ca.logic_not(released))
    return ca.Function("double_criterion", [d, a_e, a_r],
                       [ca.vertcat(frozen_k, ca.if_else(armed, age_k, 0.0), fault_k), snapshot, released],
                       ["d", "a_e", "a_R"], ["d_next", "snapshot", "released"])


@dataclass(frozen=True)
class Event:
    """One entry of the event log: time (s), sample index and what happened."""

    t: float
    sample: int
    what: str


class SubstitutionSupervisor:
    """Supervisor (:class:`uvsym.sim.run.Supervisor`) of one LMS-FIR monitor in a wired loop.

    Every sample it reads the monitor's published flags ``frozen_<y>``, ``fault_<y>`` and
    ``disturbance_<y>`` (y its measured channel) and, once the fault is confirmed, returns
    ``Substitution({y})``: from the next sample on the loop reads the monitor's substitute
    ``<y>_sub`` instead of the sensor (wire ``substitutions={y: f"{y}_sub"}``). With
    ``substitute_on="alarm"`` (the paper's Sec. 4.3) it substitutes from the first ``eps^2``
    alarm and switches back when the freeze is released unconfirmed (:func:`switch_flag`).
    ``correct=False`` logs without substituting (the run without fault-tolerant control, or a
    loop that switches in the same sample); ``update`` then takes a chunk of any length, so the
    log can be built after the run. ``events``: the log.
    """

    MODES = tuple(SWITCH_FLAGS)

    def __init__(self, monitor, *, correct: bool = True, substitute_on: str = "fault"):
        channel = monitor.reads_y.names[0]
        try:
            switch_flag(channel, substitute_on)
        except ObserverError as exc:
            raise ObserverError(f"supervisor: {exc}") from None
        names = monitor.publishes.names
        try:
            self._columns = [names.index(f"{flag}_{channel}") for flag in ("frozen", "fault", "disturbance")]
        except ValueError:
            raise ObserverError(f"supervisor: {monitor.name} does not publish frozen_{channel}, fault_{channel} and "
                                f"disturbance_{channel}; it publishes {', '.join(names)}") from None
        self.monitor, self.channel, self.period, self.correct = monitor.name, channel, monitor.dt, correct
        self.substitute_on = substitute_on
        self.events: list[Event] = []
        self._samples, self._frozen, self._fault, self._switched = 0, False, False, False

    def update(self, t: np.ndarray, signals: dict[str, np.ndarray]):
        """Log this chunk's freezes, confirmations and releases; a Substitution once a fault is confirmed.

        t (N,) s; signals[monitor] (N, n_out) its published values; a flag is set where it exceeds 0.5."""
        from uvsym.sim.run import Substitution  # sim builds on observers, not the other way round

        frozen, fault, released = (signals[self.monitor][:, c] > 0.5 for c in self._columns)
        for i, ti in enumerate(t):
            k = self._samples + i
            if frozen[i] and not self._frozen:
                self.events.append(Event(float(ti), k, "eps2 alarm: filter frozen"))
            if fault[i] and not self._fault:
                self.events.append(Event(float(ti), k, "R alarm: sensor fault confirmed"))
            if released[i]:
                self.events.append(Event(float(ti), k, "no R alarm in time: disturbance, filter released"))
            self._frozen, self._fault = bool(frozen[i]), bool(fault[i])
        self._samples += len(t)
        wanted = self._fault if SWITCH_FLAGS[self.substitute_on] == "fault" else self._frozen
        if not self.correct or wanted == self._switched:
            return None
        self._switched = wanted
        self.events.append(Event(float(t[-1]), self._samples - 1, f"substitution {'on' if wanted else 'off'} "
                                 "from the next sample"))
        return Substitution({self.channel} if wanted else frozenset())

    def first(self, what: str) -> Event | None:
        """The first logged event whose text starts with ``what`` ("eps2", "R", "no R", "substitution on"), or None."""
        return next((e for e in self.events if e.what.startswith(what)), None)
