"""The double criterion and the substitution supervisor of an LMS-FIR monitor: expectations worked out by hand
from the rules in the module docstring of uvsym.observers.lms_supervisor."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from uvsym.errors import ObserverError
from uvsym.observers.lms import lms_monitor
from uvsym.observers.lms_supervisor import SubstitutionSupervisor, double_criterion
from uvsym.systems.signals import signals


def lms_y_monitor():
    """An LMS-FIR monitor of sensor y (m) from input u, order 2, period 0.1 s."""
    return lms_monitor(signals(("y", "m", "sensor"), group="output"), signals(("u", "-", "input"), group="input"),
                       order=2, mu=0.01, eps0=1.0, r0=2.0, dt=0.1)


def flag_rows(monitor, **columns) -> np.ndarray:
    """(N, n_out) published values of ``monitor``: zeros but the named flags, given as 0/1 sequences of length N."""
    names = monitor.publishes.names
    n = len(next(iter(columns.values())))
    rows = np.zeros((n, len(names)))
    for name, values in columns.items():
        rows[:, names.index(name)] = values
    return rows


@pytest.mark.parametrize("confirm", [1, np.int64(1)])
def test_confirm_of_one_sample_releases_the_next_sample_unless_R_fires_by_then(confirm):
    # by hand, confirm = 1: eps2 alarm at 0 freezes (age 0); no R by age 1 -> released at 1 and the filter is live
    # again (2); eps2 alarm at 3 freezes anew, R at 4 (age 1 <= 1) confirms the fault and keeps the filter frozen
    decide = double_criterion(confirm)
    d, rows = np.zeros(3), []
    for a_e, a_r in zip([1, 0, 0, 1, 0], [0, 0, 0, 0, 1]):
        d, snapshot, released = (np.asarray(v).ravel() for v in decide(d, a_e, a_r))
        rows.append([d[0], d[2], snapshot[0], released[0]])
    frozen, fault, snapshot, released = np.array(rows).T
    assert list(frozen) == [1, 0, 0, 1, 1]
    assert list(fault) == [0, 0, 0, 0, 1]
    assert list(snapshot) == [1, 0, 0, 1, 0]
    assert list(released) == [0, 1, 0, 0, 0]


def test_double_criterion_is_named_and_its_alarm_symbols_are_a_e_and_a_R():
    decide = double_criterion(2)
    assert decide.name() == "double_criterion"
    assert (str(decide.sx_in(1)), str(decide.sx_in(2))) == ("a_e", "a_R")


def test_a_monitor_without_the_three_flags_is_refused_naming_what_it_publishes():
    fake = SimpleNamespace(name="fir", dt=0.1, reads_y=SimpleNamespace(names=("y",)),
                           publishes=SimpleNamespace(names=("frozen_y", "fault_y")))
    with pytest.raises(ObserverError) as info:
        SubstitutionSupervisor(fake)
    assert str(info.value) == ("supervisor: fir does not publish frozen_y, fault_y and disturbance_y; "
                               "it publishes frozen_y, fault_y")


def test_freeze_and_fault_on_the_very_first_sample_are_logged_there():
    # eps2 and R alarms together at sample 0: frozen and confirmed at once (age 0 <= confirm)
    obs = lms_y_monitor()
    supervisor = SubstitutionSupervisor(obs, correct=False)
    supervisor.update(np.array([0.0, 0.1]), {obs.name: flag_rows(obs, frozen_y=[1, 1], fault_y=[1, 1])})
    assert [(e.sample, e.what) for e in supervisor.events] == [
        (0, "eps2 alarm: filter frozen"), (0, "R alarm: sensor fault confirmed")]


def test_a_fresh_supervisor_given_an_empty_chunk_logs_and_substitutes_nothing():
    obs = lms_y_monitor()
    supervisor = SubstitutionSupervisor(obs)
    assert supervisor.update(np.zeros(0), {obs.name: np.zeros((0, len(obs.publishes.names)))}) is None
    assert supervisor.events == []


def test_the_release_is_logged_at_its_sample_time():
    obs = lms_y_monitor()
    supervisor = SubstitutionSupervisor(obs, correct=False)
    t = np.array([0.0, 0.1, 0.2, 0.3])  # frozen at 0.1 (sample 1), released unconfirmed at 0.3 (sample 3)
    supervisor.update(t, {obs.name: flag_rows(obs, frozen_y=[0, 1, 1, 0], disturbance_y=[0, 0, 0, 1])})
    release = supervisor.first("no R alarm")
    assert (release.t, release.sample) == (0.3, 3) and isinstance(release.t, float)
