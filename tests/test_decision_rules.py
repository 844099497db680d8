"""The decision rules of isolation and of the diagnosis supervisor on hand-made records.

Isolation (Liu et al. 2014, sec. 2.2, as uvsym.observers.isolation states it): per channel, the observer with the
smallest f_bar variance names the fault once that variance is below ``threshold`` and at most ``margin`` times every
other observer's; the first sample where this holds is the decision time; an observer that settled at its no-fault
value names no fault (healthy). The variances and means below are set by hand (powers of two, so that the margin
boundary is exact), and the expected decision row follows from the rule, not from the code. The supervisor's
timing is read on a stub isolation result: the correction comes back from the very update that identifies a
fault, and a channel decided healthy clears the actuators that act only on healthy channels; a simulated loop
applies a correction from the first sample after the chunk its supervisor checked.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from problems import DT, first_order

from uvsym.errors import ObserverError, SimulationError
from uvsym.models.registry import vehicle
from uvsym.observers.ftc import Correction
from uvsym.observers.identification import configuration_at
from uvsym.observers.isolation import ChannelDecision, IsolationResult, IsolationSettings, Isolator
from uvsym.observers.supervisor import FaultDiagnosis
from uvsym.sim import simulate_system, state_feedback
from uvsym.sim.scenario import load_scenario
from uvsym.sim.simulation import simulate_scenario

T = np.arange(6) * 0.1  # s
V = 2.0**-17  # a variance well below the default threshold (1e-4)


def decide(records: dict[str, dict], settings=None, tau_d=5.0, first=0):
    """The decision on one channel "X" from per-observer records: kind -> {"var", "mean", "visible"} (each a
    scalar or a (6,) sequence over T), deciding from row ``first`` on."""
    isolator = Isolator({kind: (None, None) for kind in records}, ("X",), settings or IsolationSettings())
    isolator.t, isolator.tau_d = T, np.full((len(T), 1), tau_d)
    for kind, record in records.items():
        isolator.variance[kind] = np.broadcast_to(np.asarray(record["var"], float), T.shape)[:, None].copy()
        isolator.mean[kind] = np.broadcast_to(np.asarray(record["mean"], float), T.shape)[:, None].copy()
        isolator.visible[kind] = np.broadcast_to(np.asarray(record.get("visible", True)), T.shape)[:, None].copy()
    isolator._decide(first)
    return isolator.decisions.get("X")


def test_the_winner_must_beat_every_other_variance_by_the_margin_and_the_first_such_sample_decides():
    # margin 1/4: V <= (1/4) var_p from var_p = 4 V on (row 2, exactly at the bound), and at every later row
    records = {"bias": {"var": V, "mean": 2.0}, "proportional": {"var": [2 * V, 3 * V, 4 * V, 8 * V, 16 * V, 16 * V],
                                                                  "mean": 1.3}}
    decision = decide(records, IsolationSettings(margin=0.25))
    assert decision == ChannelDecision("X", "bias", T[2], 2.0, V)
    assert decide(records, IsolationSettings(margin=0.125)).time_s == T[3]  # needs var_p >= 8 V
    assert decide(records, IsolationSettings(margin=0.0625)).time_s == T[4]
    assert decide(records, IsolationSettings(margin=0.01)) is None  # never separated enough


def test_the_winner_must_be_below_the_threshold():
    records = {"bias": {"var": [4e-4, 2e-4, 1e-4, 5e-5, 5e-5, 5e-5], "mean": 2.0},
               "proportional": {"var": 1.0, "mean": 1.3}}
    assert decide(records).time_s == T[3]  # 1e-4 is not below the threshold 1e-4


def test_the_smallest_variance_names_the_kind_and_its_mean_and_variance_are_reported():
    records = {"bias": {"var": 1e-3, "mean": 7.0}, "proportional": {"var": [1e-3, 1e-3, V, V, V, V], "mean": 0.6}}
    assert decide(records) == ChannelDecision("X", "proportional", T[2], 0.6, V)


def test_a_winner_settled_at_its_no_fault_value_names_no_fault():
    """The bias observer wins (small variance, other one large) but its f_bar is 0.01 <= healthy_tolerance."""
    records = {"bias": {"var": V, "mean": 0.01}, "proportional": {"var": 1e-2, "mean": 1.3}}
    decision = decide(records)
    assert decision.kind == "healthy" and decision.time_s == T[0] and decision.f_bar == 0.01


def test_every_observer_settled_at_its_no_fault_value_is_healthy_without_a_margin():
    """Both variances small and equal (no winner by the margin); both means at the no-fault values from row 1."""
    records = {"bias": {"var": V, "mean": [0.2, 0.04, 0.04, 0.04, 0.04, 0.04]}, "proportional": {"var": V,
                                                                                              "mean": 1.005}}
    decision = decide(records)
    assert decision.kind == "healthy" and decision.time_s == T[1]


def test_the_proportional_observer_has_its_own_tolerance():
    """|1.02 - 1| = 0.02 is within healthy_tolerance (0.05) but not healthy_tolerance_p (0.01); equal variances:
    neither a fault (no margin) nor healthy (the proportional observer is not at its no-fault value)."""
    records = {"bias": {"var": V, "mean": 0.02}, "proportional": {"var": V, "mean": 1.02}}
    assert decide(records) is None
    records["proportional"]["mean"] = 1.009
    assert decide(records).kind == "healthy"
    records["bias"]["mean"] = 0.06  # beyond healthy_tolerance
    assert decide(records) is None


def test_a_constant_fault_is_healthy_at_the_desired_action():
    """The constant kind's no-fault value is tau_d (here 5): a channel whose stuck value equals it is healthy."""
    records = {"constant": {"var": V, "mean": 5.0}, "bias": {"var": V, "mean": 0.0}}
    assert decide(records, tau_d=5.0).kind == "healthy"
    records = {"constant": {"var": V, "mean": 3.0}, "bias": {"var": 1e-2, "mean": -2.0}}
    assert decide(records, tau_d=5.0).kind == "constant"


def test_an_observer_that_never_saw_the_channel_does_not_vote_but_one_that_did_must():
    unseen = {"bias": {"var": V, "mean": 2.0}, "proportional": {"var": np.nan, "mean": np.nan, "visible": False}}
    assert decide(unseen).kind == "bias"  # no other variance: the margin holds against none
    seen_once = {"bias": {"var": V, "mean": 2.0},
                 "proportional": {"var": np.nan, "mean": np.nan, "visible": [True, False, False, False, False, False]}}
    assert decide(seen_once) is None  # it saw the channel and has no variance yet: no vote, no decision
    healthy = {"bias": {"var": V, "mean": 0.0}, "proportional": {"var": np.nan, "mean": np.nan, "visible": False}}
    assert decide(healthy).kind == "healthy"


def test_a_decision_is_kept_once_made():
    isolator = Isolator({"bias": (None, None)}, ("X",))
    isolator.decisions["X"] = ChannelDecision("X", "bias", 0.1, 2.0, V)
    isolator.t, isolator.tau_d = T, np.zeros((6, 1))
    isolator.variance["bias"], isolator.mean["bias"] = np.full((6, 1), V), np.zeros((6, 1))
    isolator.visible["bias"] = np.ones((6, 1), bool)
    isolator._decide(0)  # now it would be healthy
    assert isolator.decisions["X"].kind == "bias"


class StubIsolator:
    """Isolation that decides the channels given per update call (each decision's time is the call's last t)."""

    def __init__(self, schedule: list[dict[str, tuple[str, float]]]):
        self.observers, self.schedule, self.decisions, self.t = {"bias": None}, list(schedule), {}, np.zeros(0)

    def update(self, t, f_hat, tau_d):
        self.t = np.concatenate([self.t, t])
        for channel, (kind, f_bar) in self.schedule.pop(0).items():
            self.decisions[channel] = ChannelDecision(channel, kind, float(t[-1]), f_bar, 0.0)
        return IsolationResult(self.t, (), {}, {}, dict(self.decisions))


def _signals(k: int) -> dict[str, np.ndarray]:
    """k samples of the docking AUV at 1.5 m/s with 20 N of desired thrust (the rudders at 0)."""
    y = np.tile(np.r_[np.zeros(6), 1.5, np.zeros(5)], (k, 1))
    return {"y": y, "u_expected": np.tile([20.0, 0.0, 0.0, 0.0], (k, 1)), "f_hat/bias": np.zeros((k, 6)),
            "tau_desired": np.tile([20.0, 0, 0, 0, 0, 0], (k, 1))}


def test_the_correction_comes_back_from_the_update_that_identifies_the_fault():
    """At 1.5 m/s the X row of B is (1, 0, 0, 0): a bias of 13 N on channel X is a 13 N thruster bias, corrected
    by subtracting 13 N from its command (S = I, o = (-13, 0, 0, 0)). Channels Y, Z, K, M, N found healthy clear
    the elevator and both rudders (they act on those channels only). Until every channel is decided, B's decided
    rows cannot separate the actuators: nothing is identified."""
    healthy = {c: ("healthy", 0.0) for c in ("Y", "Z", "K", "M", "N")}
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)}, period=0.3)
    diagnosis.isolator = StubIsolator([{}, healthy, {"X": ("bias", 13.0)}, {}])
    assert diagnosis.update(T[:2], _signals(2)) is None
    assert diagnosis.update(T[2:4], _signals(2)) is None  # rudders and elevator cleared, the thruster undecided
    assert diagnosis.healthy == {"delta_e": T[3], "delta_ru": T[3], "delta_rd": T[3]} and not diagnosis.decided
    assert np.isnan(diagnosis.isolation_time_s)
    correction = diagnosis.update(T[4:], _signals(2))
    assert correction is not None
    np.testing.assert_allclose(correction.S, np.eye(4), atol=1e-12)
    np.testing.assert_allclose(correction.o, [-13.0, 0.0, 0.0, 0.0], atol=1e-9)
    estimate = diagnosis.identified["X"]
    assert (estimate.kind, estimate.time_s) == ("bias", T[5]) and estimate.value == pytest.approx(13.0, abs=1e-9)
    assert diagnosis.decided and diagnosis.isolation_time_s == T[5]
    assert diagnosis.update(T[5:] + 0.1, _signals(1)) is None  # nothing new identified: no new correction
    log = [e.as_dict() for e in diagnosis.events]                # the one event log's vocabulary
    assert [(e["event"], e["target"], e["kind"], e["t"]) for e in log] == [
        ("detected", None, None, T[5]), ("isolated", "X", "bias", T[5]), ("identified", "X", "bias", T[5])]
    assert log[2]["value"] == pytest.approx(13.0, abs=1e-9) and {e["detector"] for e in log} == {"fault_diagnosis"}


def test_without_correction_the_supervisor_only_identifies():
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)}, period=0.3, correct=False)
    diagnosis.isolator = StubIsolator([{"X": ("bias", -4.0)} | {c: ("healthy", 0.0) for c in "YZKMN"}])
    assert diagnosis.update(T[:3], _signals(3)) is None
    assert diagnosis.identified["X"].value == pytest.approx(-4.0, abs=1e-9)


def test_a_three_dof_vehicle_reads_its_channels_from_rows_x_y_and_n():
    """Otter (3 DOF, thrusters T_L, T_R; B rows X = (1, 1), N = (0.395, -0.395) at 1 m/s): a 10 N bias on T_L
    delivers X = tau_d + 10 and N = 3.95; solving those rows gives T_L + 10 N and T_R unchanged (bias 0)."""
    model = vehicle("otter3dof")
    diagnosis = FaultDiagnosis(model, {"bias": (None, None)}, period=0.3)
    diagnosis.isolator = StubIsolator([{"X": ("bias", 10.0), "Y": ("healthy", 0.0), "N": ("bias", 3.95)}])
    signals = {"y": np.tile([0.0, 0.0, 0.0, 1.0, 0.0, 0.0], (3, 1)), "u_expected": np.tile([50.0, 50.0], (3, 1)),
               "f_hat/bias": np.zeros((3, 3)), "tau_desired": np.tile([100.0, 0.0, 0.0], (3, 1))}
    correction = diagnosis.update(T[:3], signals)
    assert diagnosis.identified["T_L"].kind == "bias" and diagnosis.identified["T_L"].value == pytest.approx(10.0)
    assert diagnosis.identified["T_R"].value == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(correction.o, [-10.0, 0.0], atol=1e-9)
    assert diagnosis.decided and diagnosis.isolation_time_s == T[2]


def test_an_actuators_kind_is_read_where_it_has_the_largest_share_first_on_a_tie():
    """The elevator alone acts on Z and M (a share of 1 on both): a tie, so the first of them, Z, names its kind
    (bias). With its command at 0, tau_d is 0 on both rows and the bias of 2 N on Z alone is, by least squares
    over the rows Z and M of B, u = b_Z 2 / (b_Z^2 + b_M^2)."""
    model = vehicle("docking_auv")
    diagnosis = FaultDiagnosis(model, {"bias": (None, None)}, period=0.3)
    decided = {c: ("healthy", 0.0) for c in ("X", "Y", "K", "N")} | {"Z": ("bias", 2.0), "M": ("proportional", 0.5)}
    diagnosis.isolator = StubIsolator([decided])
    diagnosis.update(T[:3], _signals(3))
    B = configuration_at(model, np.zeros(6), np.r_[1.5, np.zeros(5)], np.array([20.0, 0.0, 0.0, 0.0])).B
    b_Z, b_M = B[2, 1], B[4, 1]
    assert diagnosis.identified["delta_e"].kind == "bias"
    assert diagnosis.identified["delta_e"].value == pytest.approx(b_Z * 2.0 / (b_Z**2 + b_M**2), rel=1e-9)


def test_an_entry_of_b_below_its_relative_tolerance_gives_no_authority(monkeypatch):
    """B's largest entry at 1.5 m/s is about 10.7; an entry of 5e-9 (below 1e-9 of it) on the elevator's X row is
    numerical dust: the elevator acts on Z and M only, both healthy, so it is healthy despite the fault on X."""
    import dataclasses

    import uvsym.observers.supervisor as supervisor

    def dusty(model, eta, nu, u):
        config = configuration_at(model, eta, nu, u)
        B = np.array(config.B, dtype=float)
        B[0, 1] = 5e-9
        return dataclasses.replace(config, B=B)

    monkeypatch.setattr(supervisor, "configuration_at", dusty)
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)}, period=0.3)
    diagnosis.isolator = StubIsolator([{"X": ("bias", 13.0)} | {c: ("healthy", 0.0) for c in "YZKMN"}])
    diagnosis.update(T[:3], _signals(3))
    assert "delta_e" in diagnosis.healthy and "delta_e" not in diagnosis.identified
    assert diagnosis.identified["X"].value == pytest.approx(13.0, abs=1e-6)


def test_the_supervisor_defaults_and_takes_its_settings():
    model = vehicle("docking_auv")
    assert FaultDiagnosis(model, {"bias": (None, None)}).period == 0.1  # s
    settings = IsolationSettings(margin=0.5, window_s=2.0)
    assert FaultDiagnosis(model, {"bias": (None, None)}, settings).isolator.settings is settings


class CorrectOnce:
    """A supervisor that returns one correction (add 5 N to the thruster command) at its first check."""

    period = 0.3  # s: 30 samples of 0.01 s

    def __init__(self):
        self.checked = []

    def update(self, t, signals):
        self.checked.append((t[0], t[-1]))
        return Correction(np.eye(4), np.array([5.0, 0.0, 0.0, 0.0])) if len(self.checked) == 1 else None


def test_a_correction_acts_from_the_first_sample_after_the_checked_chunk():
    """The first check sees t = 0 ... 0.29 s; its correction changes the command from t = 0.3 s on, not later."""
    scenario = replace(load_scenario("docking_faults"), duration=1.0)
    supervisor = CorrectOnce()
    result = simulate_scenario(scenario, supervisor=supervisor)
    assert supervisor.checked[:2] == [(0.0, pytest.approx(0.29)), (pytest.approx(0.3), pytest.approx(0.59))]
    added = result["u_command"].values - result["u_desired"].values
    on = result.t >= 0.3 - 1e-9
    assert np.count_nonzero(~on) == 30
    np.testing.assert_array_equal(added[~on], 0.0)
    np.testing.assert_allclose(added[on], np.tile([5.0, 0.0, 0.0, 0.0], (np.count_nonzero(on), 1)), atol=1e-12)


def test_an_isolator_needs_an_observer_and_reports_its_faulty_channels_apart():
    with pytest.raises(ObserverError, match="^isolation needs at least one observer$"):
        Isolator({}, ("X",))
    decisions = {"X": ChannelDecision("X", "bias", 1.0, 2.0, V), "Y": ChannelDecision("Y", "healthy", 1.5, 0.0, V)}
    result = IsolationResult(T, ("X", "Y"), {}, {}, decisions)
    assert result.faulty == {"X": decisions["X"]}


def test_a_supervisor_without_a_period_is_refused_by_name():
    class Periodless:
        def update(self, t, signals):
            return None

    ctrl = state_feedback("p", [[1.0]], reads=["m"], publishes=["F"])
    with pytest.raises(SimulationError, match="a supervisor needs a positive, finite period"):
        simulate_system(first_order(0.5, 2.0), [ctrl], duration=0.5, dt=DT, x0=[1.0], supervisor=Periodless())


def test_a_stuck_actuators_share_is_taken_over_less_what_it_still_delivers():
    """Two thrusters on one force (B = [1, 2]), the first stuck at 0.3: for u_d = (0.5, 0.5) the force asked is
    0.5 + 1.0 = 1.5, the stuck one gives 0.3, so the second must be commanded (1.5 - 0.3) / 2 = 0.6."""
    from uvsym.observers.ftc import linear_correction
    from uvsym.observers.identification import ActuatorFaultEstimate

    B = np.array([[1.0, 2.0]])
    correction = linear_correction({"T1": ActuatorFaultEstimate("T1", "constant", 0.3, 5.0)}, ("T1", "T2"), B)
    commanded = correction.S @ np.array([0.5, 0.5]) + correction.o
    assert commanded[1] == pytest.approx(0.6, abs=1e-12)
    assert commanded[0] == 0.0  # its command no longer matters: it is left at 0
    assert 0.3 * B[0, 0] + commanded[1] * B[0, 1] == pytest.approx(1.5, abs=1e-12)


def test_a_chunk_of_one_sample_that_identifies_a_fault_returns_its_correction():
    """A -4 N thruster bias found on the only sample of a chunk is corrected by adding 4 N to the command."""
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)}, period=0.01)
    diagnosis.isolator = StubIsolator([{"X": ("bias", -4.0)} | {c: ("healthy", 0.0) for c in "YZKMN"}])
    correction = diagnosis.update(T[:1], _signals(1))
    np.testing.assert_allclose(correction.o, [4.0, 0.0, 0.0, 0.0], atol=1e-9)


def test_decisions_on_channels_the_model_lacks_decide_no_actuator():
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)}, period=0.3)
    diagnosis.isolator = StubIsolator([{"Q": ("bias", 1.0)}])
    assert diagnosis.update(T[:3], _signals(3)) is None
    assert diagnosis.identified == {} and diagnosis.healthy == {}


def test_actuator_values_are_solved_on_the_decided_rows_only():
    """Rows X, Z, K and N of B decided (Y and M not) already separate the four actuators. A bias of 0.6 N m on N
    with K healthy: the rudders move equally (K: -b_K du_ru + b_K du_rd = 0) and N gives 2 b_N du = 0.6, so each
    rudder has a bias of 0.3 / b_N -- the undecided Y row (where the rudders act too) takes no part."""
    model = vehicle("docking_auv")
    diagnosis = FaultDiagnosis(model, {"bias": (None, None)}, period=0.3)
    decided = {"X": ("healthy", 0.0), "Z": ("healthy", 0.0), "K": ("healthy", 0.0), "N": ("bias", 0.6)}
    diagnosis.isolator = StubIsolator([decided])
    diagnosis.update(T[:3], _signals(3))
    b_N = configuration_at(model, np.zeros(6), np.r_[1.5, np.zeros(5)], np.array([20.0, 0.0, 0.0, 0.0])).B[5, 2]
    for rudder in ("delta_ru", "delta_rd"):
        assert diagnosis.identified[rudder].kind == "bias"
        assert diagnosis.identified[rudder].value == pytest.approx(0.3 / b_N, rel=1e-9)
    assert diagnosis.healthy == {"X": T[2]} and "delta_e" not in diagnosis.identified


def test_an_actuators_kind_is_read_where_its_share_of_the_channel_is_largest_not_its_authority(monkeypatch):
    """With the lower rudder's N entry cut to 0.5, the upper rudder holds b_N / (b_N + 0.5) > 1/2 of N but only 1/2
    of Y (where its |B| is larger): its kind is read on N (bias), the lower rudder's on Y (constant)."""
    import dataclasses

    import uvsym.observers.supervisor as supervisor

    def weak_lower_rudder(model, eta, nu, u):
        config = configuration_at(model, eta, nu, u)
        B = np.array(config.B, dtype=float)
        B[5, 3] = 0.5
        return dataclasses.replace(config, B=B)

    monkeypatch.setattr(supervisor, "configuration_at", weak_lower_rudder)
    diagnosis = FaultDiagnosis(vehicle("docking_auv"), {"bias": (None, None)}, period=0.3)
    decided = {c: ("healthy", 0.0) for c in "XZKM"} | {"Y": ("constant", 0.5), "N": ("bias", 1.0)}
    diagnosis.isolator = StubIsolator([decided])
    diagnosis.update(T[:3], _signals(3))
    assert diagnosis.identified["delta_ru"].kind == "bias" and diagnosis.identified["delta_rd"].kind == "constant"


def test_only_the_rows_from_first_on_are_decided():
    """Separated from row 0 on; deciding from row 3 (then from the last row alone) dates the decision there."""
    records = {"bias": {"var": V, "mean": 2.0}, "proportional": {"var": 1.0, "mean": 1.3}}
    assert decide(records, first=3) == ChannelDecision("X", "bias", T[3], 2.0, V)
    assert decide(records, first=5).time_s == T[5]
    assert decide(records, first=6) is None  # no new row


def test_a_channel_decided_earlier_does_not_stop_the_next_ones():
    isolator = Isolator({"bias": (None, None)}, ("X", "Y"))
    isolator.decisions["X"] = ChannelDecision("X", "healthy", 0.1, 0.0, V)
    isolator.t, isolator.tau_d = T, np.zeros((6, 2))
    isolator.variance["bias"], isolator.mean["bias"] = np.full((6, 2), V), np.full((6, 2), 3.0)
    isolator.visible["bias"] = np.ones((6, 2), bool)
    isolator._decide(0)
    assert isolator.decisions["Y"] == ChannelDecision("Y", "bias", T[0], 3.0, V)


def test_a_mean_exactly_at_the_healthy_tolerance_is_healthy():
    """A lone bias observer wins by default; |f_bar| = 2^-4 = healthy_tolerance is settled at no fault (<=), a
    value one step beyond it names a bias."""
    settings = IsolationSettings(healthy_tolerance=2.0**-4)
    assert decide({"bias": {"var": V, "mean": 2.0**-4}}, settings).kind == "healthy"
    assert decide({"bias": {"var": V, "mean": np.nextafter(2.0**-4, 1.0)}}, settings).kind == "bias"


def test_a_variance_exactly_at_the_threshold_has_not_settled():
    """Variance 2^-14 = threshold: neither a fault nor settled at no fault (both need var < threshold)."""
    settings = IsolationSettings(threshold=2.0**-14)
    assert decide({"bias": {"var": 2.0**-14, "mean": 0.0}}, settings) is None
    assert decide({"bias": {"var": 2.0**-15, "mean": 0.0}}, settings).kind == "healthy"


def test_a_healthy_row_needs_an_observer_settled_in_that_row():
    """The lone observer sees the channel from row 3 on and settles at 0 there: rows 0-2 (nobody voting) are not
    healthy, row 3 is."""
    visible = [False, False, False, True, True, True]
    records = {"bias": {"var": [np.nan] * 3 + [V] * 3, "mean": [np.nan] * 3 + [0.0] * 3, "visible": visible}}
    assert decide(records).time_s == T[3]


def test_a_new_isolator_has_empty_records_of_its_channel_count():
    isolator = Isolator({"bias": (None, None), "proportional": (None, None)}, ("X", "Y", "N"))
    result = isolator.result
    assert result.t.shape == (0,) and result.labels == ("X", "Y", "N")
    for kind in ("bias", "proportional"):
        assert result.f_bar[kind].shape == result.variance[kind].shape == (0, 3)
        assert isolator.mean[kind].shape == isolator.visible[kind].shape == (0, 3)
        assert isolator.visible[kind].dtype == bool
