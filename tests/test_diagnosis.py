"""The continuous actuator diagnosis (uvsym.diagnosis): its residual model against the simulator,
its statistics under noise, its decisions on faults the shipped experiment does not have, and its
errors. Expected values are the injected faults (by construction) or closed-form properties."""

from __future__ import annotations

import json
import re
from dataclasses import replace

import numpy as np
import pytest

from uvsym.cli import main
from uvsym.diagnosis import DiagnosisSettings
from uvsym.diagnosis.fits import Hypothesis, fit_window
from uvsym.diagnosis.run import diagnosis_for
from uvsym.errors import DiagnosisError, ScenarioError
from uvsym.faults import ActuatorFault, Profile, SensorFault, actuator_kind
from uvsym.sim.scenario import load_scenario, parse_scenario, read_scenario_file, shipped_scenarios
from uvsym.sim.simulation import simulate_scenario

VELOCITY_NOISE = {"u": 0.01, "v": 0.01, "w": 0.01, "p": 0.001, "q": 0.001, "r": 0.001}


def docking(faults=(), duration=20.0, noise=False, **settings):
    """The docking scenario with the given faults ((actuator, kind, value, profile) tuples) and a diagnosis."""
    base = load_scenario("docking_faults")
    labels = base.model.input_labels
    sensors = ()
    if noise:
        sensors = tuple(SensorFault(base.model.state_labels.index(c), "noise", s) for c, s in VELOCITY_NOISE.items())
        settings.setdefault("noise", VELOCITY_NOISE)
    return replace(base, duration=duration, sensor_faults=sensors, diagnosis=DiagnosisSettings(**settings),
                   actuator_faults=tuple(ActuatorFault(labels.index(a), k, v, p) for a, k, v, p in faults))


def events_of(scenario):
    return simulate_scenario(scenario).events


def test_residual_model_matches_the_simulated_observer():
    """The bias observer's estimate in a closed-loop run equals the exact filtered effect of the injected
    fault (free response aside) to well under a per mille: the regression model is the simulator's."""
    scenario = docking([("X", "bias", 10.0, Profile(onset=5.0))], duration=12.0)
    result = simulate_scenario(scenario)
    diagnosis = diagnosis_for(scenario)
    diagnosis.update(result.t, {name: result[name].values for name in diagnosis.reads})
    bank = diagnosis.bank
    rows = np.arange(len(result.t))
    fit = fit_window(bank, rows, [Hypothesis(0, actuator_kind("bias"), onset=500, at=10.0)], np.array([10.0]), [])
    assert fit.theta_model[0] == pytest.approx(10.0, rel=1e-3)
    # the same fault placed one second late explains the record far worse
    late = fit_window(bank, rows, [Hypothesis(0, actuator_kind("bias"), onset=600, at=10.0)], np.array([10.0]), [])
    assert late.J_model > 100 * max(fit.J_model, 1.0)


def test_noise_level_is_not_underestimated():
    """With sensor noise and no fault nothing alarms; the typical GLR of a hypothesis on a window is at most
    a chi-square(1)'s (median 0.45: the observer's differenced noise makes the white-noise thresholds
    conservative), and model error in the turn stays below half the detection threshold; an
    underestimated noise level would give GLRs >> 1."""
    scenario = docking(duration=24.0, noise=True)
    result = simulate_scenario(scenario)
    assert not [e for e in result.events if e["event"] != "unexcited"]
    diagnosis = diagnosis_for(scenario)
    diagnosis.update(result.t, {name: result[name].values for name in diagnosis.reads})
    bank, W = diagnosis.bank, diagnosis.W
    hypotheses = [Hypothesis(a, actuator_kind(k)) for a in range(4) for k in ("bias", "proportional")]
    glr = []
    for end in range(W, len(result.t), W):  # disjoint windows
        rows = np.arange(end - W, end)
        glr.append(fit_window(bank, rows, [], np.zeros(0), hypotheses).glr)
    assert 0.0 < np.median(glr) < 0.45
    assert np.max(glr) < diagnosis.h_detect / 2
    # the same noise left out of the noise level: the statistic explodes, so the check can fail
    quiet = replace(scenario, diagnosis=replace(scenario.diagnosis, noise={}))
    naive = diagnosis_for(quiet)
    naive.update(result.t, {name: result[name].values for name in naive.reads})
    rows = np.arange(W, 2 * W)
    assert np.mean(fit_window(naive.bank, rows, [], np.zeros(0), hypotheses).glr) > 10


@pytest.mark.parametrize("actuator, kind, value", [("X", "constant", 20.0), ("delta_ru", "bias", 0.05),
                                                    ("delta_rd", "proportional", 0.5)])
def test_a_late_fault_is_found_isolated_and_sized(actuator, kind, value):
    onset = 9.0
    events = events_of(docking([(actuator, kind, value, Profile(onset=onset))], duration=16.0))
    assert all(e["t"] >= onset for e in events if e["event"] != "unexcited")  # nothing before the onset
    isolated = [e for e in events if e["event"] == "isolated"]
    assert isolated and isolated[0]["target"] == actuator and isolated[0]["kind"] == kind
    assert isolated[0]["t"] - onset <= 2.0
    identified = [e for e in events if e["event"] == "identified" and e["target"] == actuator]
    assert identified and identified[0]["value"] == pytest.approx(value, rel=0.02)


def test_redundant_rudders_with_equal_faults_are_both_identified():
    """Both rudders at 0.8 from the start: no single rudder explains it; the pair is found and sized."""
    events = events_of(docking([("delta_ru", "proportional", 0.8, Profile()),
                                ("delta_rd", "proportional", 0.8, Profile())], duration=8.0))
    identified = {e["target"]: e["value"] for e in events if e["event"] == "identified"}
    assert set(identified) == {"delta_ru", "delta_rd"}
    assert identified["delta_ru"] == pytest.approx(0.8, rel=0.01)
    assert identified["delta_rd"] == pytest.approx(0.8, rel=0.01)


@pytest.mark.parametrize("seed", [1, 3])
def test_sizes_under_told_noise_lie_within_their_stated_std(seed):
    """The shipped docking diagnosis (thruster bias 13 N, both rudders 0.8 from the start) with velocity
    noise the diagnosis is told: the rudders are isolated one after the other, seconds after the start,
    and each is sized over the record since its estimated onset. Every identified size is within 2 %
    and within 3 of its stated standard deviations of the truth (with these seeds, an onset searched only
    in the window before the alarm put the first rudder's onset seconds late: 0.778 and 0.774, -6 and
    -7 std)."""
    data = read_scenario_file(shipped_scenarios()["docking_diagnosis"])
    data |= {"seed": seed, "duration": 12.0}
    data["faults"] += [{"sensor": channel, "kind": "noise", "value": std}
                       for channel, std in [("u", 0.01), ("v", 0.01), ("r", float(np.deg2rad(0.1)))]]
    events = simulate_scenario(parse_scenario(data)).events
    identified = {e["target"]: e for e in events if e["event"] == "identified"}
    truth = {"X": 13.0, "delta_ru": 0.8, "delta_rd": 0.8}
    assert set(identified) == set(truth)
    for target, value in truth.items():
        event = identified[target]
        assert 0 < event["std"] < 0.01 * value
        assert event["value"] == pytest.approx(value, rel=0.02)
        assert abs(event["value"] - value) <= 3 * event["std"], (target, event)


def test_an_intermittent_fault_is_cleared_and_found_again():
    profile = Profile(kind="intermittent", onset=4.0, period=16.0, duty=0.5)  # on 4-12 s, off 12-20 s, on 20-28 s
    events = events_of(docking([("X", "bias", 10.0, profile)], duration=26.0))
    times = {kind: [e["t"] for e in events if e["event"] == kind and e["target"] == "X"]
             for kind in ("isolated", "cleared")}
    assert len(times["isolated"]) == 2 and 4.0 < times["isolated"][0] < 6.0 and 20.0 < times["isolated"][1] < 22.0
    assert len(times["cleared"]) == 1 and 12.0 < times["cleared"][0] < 16.0


def test_an_unexcited_actuator_is_not_declared_healthy_or_misjudged():
    """The elevator holds a near-constant trim: a proportional fault on it cannot be told from a bias."""
    events = events_of(docking([("delta_e", "proportional", 0.6, Profile(onset=5.0))], duration=14.0))
    on_elevator = [e for e in events if e["target"] == "delta_e"]
    assert any(e["event"] == "unexcited" for e in on_elevator)
    assert not [e for e in events if e["event"] == "isolated" and e["kind"] != "proportional"]


def test_regressors_take_the_slope_inside_the_limits():
    """A command on its limit: B is the force model's slope inside the range (1 N/N for the thruster),
    not the saturation's kink (0.5); the filter's steady-state gain is 1."""
    scenario = docking(duration=1.0)
    diagnosis = diagnosis_for(scenario)
    model = scenario.model
    y = np.concatenate([scenario.eta0, scenario.nu0])[None].repeat(2000, axis=0)
    u = np.zeros((2000, model.n_inputs))
    u[:, model.input_labels.index("X")] = model.u_max[model.input_labels.index("X")]
    diagnosis.bank.append(y, u, np.zeros((2000, model.dof)))
    assert diagnosis.bank.G[-1, model.input_labels.index("X"), 0] == pytest.approx(1.0, rel=1e-6)


def test_correction_from_the_diagnosis_acts_on_the_commands():
    scenario = docking([("X", "bias", 10.0, Profile(onset=3.0))], duration=10.0, correct=True)
    result = simulate_scenario(scenario)
    X = scenario.model.input_labels.index("X")
    isolated = next(e["t"] for e in result.events if e["event"] == "isolated")
    k = int(np.searchsorted(result.t, isolated + 0.5))
    shift = result["u_command"].values[k:, X] - result["u_desired"].values[k:, X]
    assert np.allclose(shift, -10.0, atol=0.2)  # the bias is taken off the thrust command
    before = result["u_command"].values[:k - 60, X] - result["u_desired"].values[:k - 60, X]
    assert np.allclose(before, 0.0)


def _table(**diagnosis):
    table = read_scenario_file(shipped_scenarios()["docking_faults"])
    table["diagnosis"] = diagnosis
    return table


@pytest.mark.parametrize("diagnosis, field", [
    ({"actuators": ["X", "rudder"]}, "diagnosis.actuators"),
    ({"kinds": ["bias", "stuck"]}, "diagnosis.kinds"),
    ({"window_s": 0.0}, "diagnosis.window_s"),
    ({"period_s": -1.0}, "diagnosis.period_s"),
    ({"false_alarm_rate": 2.0}, "diagnosis.false_alarm_rate"),
    ({"confirm": 0}, "diagnosis.confirm"),
    ({"observer": "proportional"}, "diagnosis.observer"),
    ({"noise": {"speed": 0.1}}, "diagnosis.noise.speed"),
    ({"windw_s": 1.0}, "diagnosis.windw_s"),
    ({"min_window_s": 5.0}, "diagnosis.min_window_s"),
    ({"kinds": ["bias", "bias"]}, "diagnosis.kinds"),
    ({"actuators": ["X", "X"]}, "diagnosis.actuators"),
    ({"kinds": ["proportional", "loss_of_effectiveness"]}, "diagnosis.kinds"),
    ({"window_s": 95.0, "isolation_window_s": 96.0}, "diagnosis.window_s"),
    ({"period_s": 0.015}, "diagnosis.period_s"),
    ({"floor": 5.0}, "diagnosis.floor"),
])
def test_bad_diagnosis_tables_name_the_field(diagnosis, field):
    with pytest.raises(ScenarioError, match=field.replace(".", r"\.")):
        parse_scenario(_table(**diagnosis))


def test_settings_refuse_bad_values_directly():
    with pytest.raises(DiagnosisError, match="diagnosis.resolution"):
        DiagnosisSettings(resolution=float("nan"))
    with pytest.raises(DiagnosisError, match="diagnosis.noise.u"):
        DiagnosisSettings(noise={"u": -1.0})


def test_a_diagnosis_needs_the_bias_observer():
    table = _table()
    table["observers"] = [o for o in table["observers"] if o["kind"] != "bias"]
    with pytest.raises(ScenarioError, match="diagnosis.observer"):
        parse_scenario(table)


def test_cli_writes_the_decision_log(tmp_path, capsys):
    scenario_file = tmp_path / "late.toml"
    text = shipped_scenarios()["docking_diagnosis"].read_text()
    text = text.replace("duration = 90.0", "duration = 6.0").replace("correct = true", "correct = false")
    scenario_file.write_text(text)
    out = tmp_path / "events.json"
    assert main(["simulate", str(scenario_file), "--events", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "faults standing at the end: X bias" in printed
    assert re.search(r"X bias 1[23](\.\d+)? \+- [\d.e-]+ \(2 std\) \((identified|isolated) at", printed), printed
    log = json.loads(out.read_text())
    assert [e["event"] for e in log][:2] == ["detected", "isolated"]
    assert all(set(e) == {"t", "event", "target", "kind", "value", "detector", "std"} for e in log)
    assert all((e["std"] or 0) > 0 for e in log if e["event"] == "identified")
    assert main(["simulate", str(scenario_file), "--events", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert main(["simulate", "docking_faults", "--events", str(tmp_path / "x.json")]) == 2
    assert "[diagnosis]" in capsys.readouterr().err


def test_a_fault_outside_the_candidates_is_not_blamed_on_them():
    """Only the thruster and the elevator are candidates; a rudder fault ends no run and is pinned on neither."""
    events = events_of(docking([("delta_ru", "bias", 0.05, Profile(onset=6.0))], duration=14.0,
                               actuators=("X", "delta_e")))
    assert not [e for e in events if e["event"] in ("isolated", "identified")]


def test_the_log_is_not_written_into_a_folder_that_does_not_exist(tmp_path):
    from uvsym.diagnosis.events import write_events
    from uvsym.errors import PathError

    with pytest.raises(PathError, match="does not exist"):
        write_events([], tmp_path / "missing" / "events.json")
    assert not (tmp_path / "missing").exists()


def test_the_fits_pseudo_inverse_is_numpys_bit_for_bit():
    """fits._pinv replaces np.linalg.pinv(gram, rcond=1e-12, hermitian=True) on the diagnosis's Gram matrices: the
    same bits, full rank or not (repeated and zero columns), of every size 1 to 40 and some larger (BLAS picks
    other kernels from 32 on: a product of other layouts rounds otherwise there), a zero and an empty matrix."""
    from uvsym.diagnosis.fits import _pinv

    rng = np.random.default_rng(7)
    for size in (*range(1, 41), 64, 90, 100):
        for trial in range(6):
            Z = rng.standard_normal((size + 30, size)) * rng.uniform(1e-3, 1e3, size)
            if trial % 3 == 1 and size > 1:
                Z[:, -1] = Z[:, 0]  # rank deficient: an eigenvalue at rounding level, cut off
            if trial % 5 == 2:
                Z[:, 0] = 0.0
            gram = Z.T @ Z
            assert _pinv(gram).tobytes() == np.linalg.pinv(gram, rcond=1e-12, hermitian=True).tobytes()
    for special in (np.zeros((4, 4)), np.zeros((0, 0))):
        expected = np.linalg.pinv(special, rcond=1e-12, hermitian=True)
        assert _pinv(special).shape == expected.shape and _pinv(special).tobytes() == expected.tobytes()


def test_the_ends_of_runs_of_consecutive_flags_are_what_a_box_convolution_counts():
    from uvsym.diagnosis.detectors import ends_of_runs

    rng = np.random.default_rng(11)
    for size in (1, 2, 7, 300):
        for density in (0.2, 0.7, 0.97):
            flags = rng.random(size) < density
            for length in {1, 2, 3, size, size + 2}:
                box = np.convolve(flags.astype(int), np.ones(length, int))[:size] >= length
                assert np.array_equal(ends_of_runs(flags, length), box), (size, density, length)
    assert ends_of_runs(np.array([1, 1, 0, 1, 1, 1]), 2).tolist() == [False, True, False, False, True, True]
