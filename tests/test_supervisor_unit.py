"""FaultDiagnosis._decide_actuators on hand-made channel decisions for the docking AUV at 1.5 m/s with 20 N of
thrust (tau_d = (20, 0, 0, 0, 0, 0)): which actuators the decided rows pin down, which are cleared, the label of an
estimate, an entry of B at its relative tolerance, and which channel names an actuator's kind.

Some tests replace B by a hand-made one (the decision reads B from ``configuration_at``); the expected actuator
values then come from solving B du = tau_hat - tau_d by hand on those few entries."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import uvsym.observers.supervisor as supervisor
from uvsym.models.registry import vehicle
from uvsym.observers.identification import configuration_at
from uvsym.observers.isolation import ChannelDecision, IsolationResult
from uvsym.observers.supervisor import FaultDiagnosis

T = np.arange(3) * 0.1  # s
Y = np.r_[np.zeros(6), 1.5, np.zeros(5)]  # eta = 0, surge 1.5 m/s
U_E = np.array([20.0, 0.0, 0.0, 0.0])  # thrust N, elevator and rudders rad


def diagnose(diagnosis: FaultDiagnosis, decisions: dict[str, tuple[str, float]], time_s: float = T[-1]) -> None:
    """Record T's samples and decide the actuators on ``decisions``: channel -> (kind, f_bar), decided at time_s."""
    diagnosis._y.append(np.tile(Y, (len(T), 1)))
    diagnosis._u_expected.append(np.tile(U_E, (len(T), 1)))
    made = {c: ChannelDecision(c, kind, time_s, f_bar, 2.0**-17) for c, (kind, f_bar) in decisions.items()}
    diagnosis._decide_actuators(IsolationResult(np.concatenate([T] * len(diagnosis._y)), diagnosis.channels, {}, {},
                                                made))


def with_B(monkeypatch, edit) -> None:
    """Make the supervisor read B (6 x 4) as ``edit(B)`` returns it."""
    def configuration(model, eta, nu, u):
        config = configuration_at(model, eta, nu, u)
        return dataclasses.replace(config, B=edit(np.array(config.B, dtype=float)))

    monkeypatch.setattr(supervisor, "configuration_at", configuration)


def test_an_estimate_carries_its_actuators_label():
    """X's row of B is (1, 0, 0, 0): a 13 N bias on X is a 13 N bias of the thruster, labelled X."""
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)})
    decisions = {"X": ("bias", 13.0)} | {c: ("healthy", 0.0) for c in "YZKMN"}
    diagnose(diagnosis, decisions)
    estimate = diagnosis.identified["X"]
    assert (estimate.actuator, estimate.kind, estimate.time_s) == ("X", "bias", T[-1])
    assert estimate.value == pytest.approx(13.0, abs=1e-9)


def test_an_entry_of_b_exactly_at_its_relative_tolerance_gives_no_authority(monkeypatch):
    """An entry equal to 1e-9 times B's largest one is dust (only a larger one counts): the elevator, whose other
    channels Z and M are healthy, is healthy despite the fault on X."""
    def dusty(B):
        B[0, 1] = 1e-9 * np.abs(B).max()
        return B

    with_B(monkeypatch, dusty)
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)})
    diagnose(diagnosis, {"X": ("bias", 13.0)} | {c: ("healthy", 0.0) for c in "YZKMN"})
    assert diagnosis.healthy.get("delta_e") == T[-1] and "delta_e" not in diagnosis.identified


def test_rudders_that_one_decided_row_cannot_tell_apart_are_not_identified():
    """Only N decided (a bias): its row of B is (0, 0, b, b), so the rudders trade against each other and neither is
    pinned; the thruster and elevator do not act on N. Nothing is identified or cleared yet."""
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)})
    diagnose(diagnosis, {"N": ("bias", 0.6)})
    assert diagnosis.identified == {} and diagnosis.healthy == {}


def test_an_actuator_cleared_earlier_does_not_stop_the_others_being_cleared():
    """X healthy first clears the thruster (it acts on X alone); Y, Z, K, M, N healthy later clear the other three,
    each at the time its last channel was decided."""
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)})
    diagnose(diagnosis, {"X": ("healthy", 0.0)}, time_s=T[1])
    assert diagnosis.healthy == {"X": T[1]}
    diagnose(diagnosis, {"X": ("healthy", 0.0)} | {c: ("healthy", 0.0) for c in "YZKMN"})
    assert diagnosis.healthy == {"X": T[1], "delta_e": T[-1], "delta_ru": T[-1], "delta_rd": T[-1]}
    assert diagnosis.decided


def test_an_actuators_share_weighs_its_entry_by_its_range(monkeypatch):
    """B with rows X = (1, 1, 0, 0), Y = (0, 0, 0, 1), Z = (0, 1, 1, 0), M = (0, 0, 1, 0), K = N = 0. The elevator's
    authority on X is 1 x 0.52 rad against the thruster's 1 x 150 N (a share of 0.3 %), on Z 1 x 0.52 against the
    same for the upper rudder (1/2): its kind is read on Z (constant). Solving by hand with X biased by 2 N and Z
    stuck at 0.5: du_ru = 0 (M), du_e = 0.5 (Z), du_T = 2 - 0.5 (X), du_rd = 0 (Y)."""
    def shared(B):
        B[:] = 0.0
        B[0, :2] = 1.0
        B[1, 3] = 1.0
        B[2, 1:3] = 1.0
        B[4, 2] = 1.0
        return B

    with_B(monkeypatch, shared)
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)})
    diagnose(diagnosis, {"X": ("bias", 2.0), "Z": ("constant", 0.5)} | {c: ("healthy", 0.0) for c in "YKMN"})
    elevator, thruster = diagnosis.identified["delta_e"], diagnosis.identified["X"]
    assert (elevator.kind, thruster.kind) == ("constant", "bias")
    assert elevator.value == pytest.approx(0.5, abs=1e-12)  # stuck at 0.5 rad
    assert thruster.value == pytest.approx(1.5, abs=1e-12)  # delivers 21.5 N for 20 N
    assert diagnosis.identified["delta_ru"].value == pytest.approx(0.0, abs=1e-12)
    assert diagnosis.healthy == {"delta_rd": T[-1]}


def test_shares_are_fractions_of_the_channel_even_when_its_authority_is_below_one(monkeypatch):
    """Rudders on Y = (0.4, 0.4) and N = (0.2, 0.1) (range 0.52 rad each, so every authority sum is below 1): the
    upper rudder has 1/2 of Y and 2/3 of N, so its kind is read on N (bias) though its entry on Y is larger; the
    lower one has 1/2 of Y, 1/3 of N: read on Y (constant). With Y stuck at 0.4 N and N biased by 0.3 N m:
    0.4 (du_ru + du_rd) = 0.4, 0.2 du_ru + 0.1 du_rd = 0.3, so du_ru = 2 and du_rd = -1."""
    def small(B):
        B[:] = 0.0
        B[0, 0], B[2, 1] = 1.0, 1.0
        B[1, 2:] = 0.4
        B[5, 2:] = (0.2, 0.1)
        return B

    with_B(monkeypatch, small)
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)})
    diagnose(diagnosis, {"Y": ("constant", 0.4), "N": ("bias", 0.3)} | {c: ("healthy", 0.0) for c in "XZKM"})
    upper, lower = diagnosis.identified["delta_ru"], diagnosis.identified["delta_rd"]
    assert (upper.kind, lower.kind) == ("bias", "constant")
    assert upper.value == pytest.approx(2.0, abs=1e-12) and lower.value == pytest.approx(-1.0, abs=1e-12)
