"""Scenario files over any System: a plant the user writes, blocks from the catalogue wired by
name, faults on its signals, calibrated detectors and the one event log, through simulate and
campaign."""

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from uvsym.campaign import load_campaign, run_campaign
from uvsym.cli import main
from uvsym.diagnosis.calibration import residual_covariance
from uvsym.diagnosis.detectors import threshold_factor
from uvsym.errors import ScenarioError
from uvsym.sim.system_scenario import parse_system_scenario, simulate_system_scenario
from uvsym.sim.system_simulation import loop_inputs

EXAMPLE = Path(__file__).parents[1] / "examples" / "dc_motor"
SCENARIO = EXAMPLE / "speed_sensor_bias.toml"


def _table(**changes) -> dict:
    table = tomllib.loads(SCENARIO.read_text())
    table.update(changes)
    return table


def _parse(table: dict):
    return parse_system_scenario(table, root=EXAMPLE)


@pytest.fixture(scope="module")
def shipped():
    scenario = _parse(_table())
    return scenario, simulate_system_scenario(scenario)


def test_both_estimators_detect_the_speed_bias_soon_after_its_onset(shipped):
    scenario, result = shipped
    assert {"luenberger", "ukf"} <= set(result.signals)         # same names, told apart by their blocks
    events = result.events
    assert all(set(e) == {"t", "event", "target", "kind", "value", "detector", "std"} for e in events)
    for detector in ("luenberger_fd", "ukf_fd"):
        own = [e for e in events if e["detector"] == detector]
        assert own[0]["event"] == "detected" and 3.0 <= own[0]["t"] <= 3.05 and own[0]["target"] == "omega_meas"
        assert [e["event"] for e in own[1:]] == ["cleared"]    # unstructured residuals: no isolation claimed
    assert not [e for e in events if e["t"] < 3.0]               # nothing before the onset: no false alarm


def test_isolation_is_claimed_only_for_structured_residuals():
    """An actuator fault moves the current residual as a current-sensor fault does: without isolate the
    detector must not name a culprit; with isolate (the user's claim) it isolates the largest one's target."""
    loss = [{"actuator": "V", "kind": "proportional", "value": 0.5, "onset": 3.0}]
    events = simulate_system_scenario(_parse(_table(faults=loss))).events
    assert [e for e in events if e["event"] == "detected"] and not [e for e in events if e["event"] == "isolated"]
    table = _table()
    table["detectors"][0]["isolate"] = True
    events = simulate_system_scenario(_parse(table)).events
    isolated = [e for e in events if e["event"] == "isolated"]
    assert [(e["detector"], e["target"]) for e in isolated] == [("luenberger_fd", "omega_meas")]
    detected = next(e for e in events if e["event"] == "detected" and e["detector"] == "luenberger_fd")
    assert isolated[0]["t"] == detected["t"]
    table["detectors"][0].pop("targets")
    with pytest.raises(ScenarioError, match=r"detectors\[0\]\.isolate: expected true \(with targets\) or false"):
        _parse(table)


def test_the_residual_spread_computed_from_the_noise_model_matches_a_long_healthy_run():
    """The calibration linearises the loop; the check simulates it (independent of the Jacobians)."""
    table = _table(faults=[], duration=60.0, step=0.01, detectors=[], seed=5)
    table["blocks"] = [b for b in table["blocks"] if b["type"] != "ukf"]
    scenario = _parse(table)
    names = ("luenberger.r_i_meas", "luenberger.r_omega_meas")
    w0 = loop_inputs(scenario.loop, 0, scenario.d, scenario.seed)[0]  # the sensor-noise levels live in w
    predicted = np.sqrt(np.diag(residual_covariance(scenario.loop, scenario.z0, w0, names)))
    result = simulate_system_scenario(scenario)
    settled = result.t > 2.0
    measured = np.array([np.std(result["luenberger"][n.split(".")[1]][settled]) for n in names])
    np.testing.assert_allclose(measured, predicted, rtol=0.05)


def test_threshold_factor_is_the_gaussian_quantile_of_the_designed_rate():
    # 36 alarms per hour at 0.1 s: 1e-3 per sample; one residual, two-sided: Phi^-1(1 - 5e-4) = 3.2905
    assert threshold_factor(36.0, 0.1, 1) == pytest.approx(3.290527, abs=1e-6)
    # two residuals share it (Bonferroni): Phi^-1(1 - 2.5e-4) = 3.4808
    assert threshold_factor(36.0, 0.1, 2) == pytest.approx(3.480756, abs=1e-6)


def test_a_healthy_hour_stays_within_the_designed_false_alarms(tmp_path):
    table = _table(faults=[], duration=3600.0, step=0.01, seed=11)
    table["blocks"] = [b for b in table["blocks"] if b["type"] != "ukf"]
    table["detectors"] = [dict(table["detectors"][0], false_alarms_per_hour=1.0)]
    result = simulate_system_scenario(_parse(table))
    assert len([e for e in result.events if e["event"] == "detected"]) <= 3   # 1 designed; P(> 3) < 2 %


def test_a_substitution_switches_from_the_flag_on(tmp_path):
    table = _table(faults=[], detectors=[], duration=4.0)
    table["setpoints"] = table["setpoints"] + [{"signal": "sw", "times": [0.0, 3.0], "values": [0.0, 1.0]}]
    table["substitutions"] = {"omega_meas": {"by": "luenberger.omega_hat", "when": "setpoint_sw.sw"}}
    result = simulate_system_scenario(_parse(table))
    on = result["substitution"]["omega_meas"]
    assert not on[result.t <= 3.0 + 1e-9].any() and on[result.t > 3.0 + 1e-9].all()   # from the next sample


@pytest.mark.parametrize("change, message", [
    ({"plant": "dc_motr:dc_motor"}, "cannot import module 'dc_motr'"),
    ({"plant": "dc_motor:dc_motorr"}, "has no function 'dc_motorr'"),
    ({"plant": "dc_motor:NOMINAL"}, "dc_motor:NOMINAL is a dict, not a function returning a System"),
    ({"plant": "induction_motr"}, "did you mean 'induction_motor'"),
    ({"plant_parameters": {"RR": 2.0}}, "plant_parameters: dc_motor:dc_motor refuses them"),
    ({"durration": 2.0}, "durration: unknown field (did you mean 'duration'?)"),
    ({"noise": {"omega": 0.1}}, "noise.omega: unknown output or disturbance of dc_motor (did you mean 'omega_meas'?)"),
    ({"faults": [{"sensor": "omega", "kind": "bias", "value": 1.0}]}, "faults[0].sensor: unknown value 'omega'"),
    ({"faults": [{"sensor": "omega_meas", "kind": "bias", "value": 0.0}]}, "faults[0].value: a bias sensor fault of 0"),
    ({"faults": [{"actuator": "V", "kind": "bias", "value": 1.0, "onset": 9.0}]}, "faults[0].onset: 9 s is outside"),
    ({"initial": {"x": {"omegaa": 1.0}}}, "initial.x.omegaa: unknown state (did you mean 'omega'?)"),
    ({"initial": {"x": [0.0, float("nan")]}}, "initial.x: entries must be finite"),
])
def test_bad_scenario_fields_are_named_before_anything_runs(change, message):
    with pytest.raises(ScenarioError) as info:
        _parse(_table(**change))
    assert message in str(info.value)


def test_a_plant_function_returning_something_else_is_named(tmp_path):
    (tmp_path / "not_a_plant.py").write_text("def build():\n    return 42\n")
    with pytest.raises(ScenarioError, match="plant: not_a_plant:build returned int, not a uvsym System"):
        parse_system_scenario(_table(plant="not_a_plant:build"), root=tmp_path)


def test_bad_blocks_and_detectors_are_named():
    table = _table()
    table["blocks"][1] = {"type": "luenbergr", "name": "luenberger", "decay": 20.0}
    with pytest.raises(ScenarioError, match=r"blocks\[1\]\.type: unknown value 'luenbergr'"):
        _parse(table)
    table = _table()
    table["blocks"][1]["decayy"] = 3.0
    with pytest.raises(ScenarioError, match=r"blocks\[1\]\.decayy: unknown field \(did you mean 'decay'\?\)"):
        _parse(table)
    table = _table()
    table["blocks"][1]["decay"] = 1e300
    with pytest.raises(ScenarioError, match=r"blocks\[1\]\.decay: 1e\+300 1/s is not below 1/step = 1000 1/s"):
        _parse(table)
    table = _table()
    table["blocks"][0]["measured"] = "omega_hat"                  # both estimators publish it
    with pytest.raises(ScenarioError, match="'luenberger.omega_hat' or 'ukf.omega_hat'"):
        _parse(table)
    table = _table()
    table["detectors"][0]["residuals"] = ["luenberger.r_omega"]
    del table["detectors"][0]["targets"]
    with pytest.raises(ScenarioError, match=r"detectors\[0\]\.residuals: no logged signal 'luenberger.r_omega'; did"):
        _parse(table)
    table = _table()
    table["detectors"][0] = {"type": "lms", "name": "x", "monitor": "luenberger"}
    with pytest.raises(ScenarioError, match=r"detectors\[0\]\.monitor: 'luenberger' is not an lms block"):
        _parse(table)
    table = _table()
    table["detectors"][1]["name"] = "luenberger"
    with pytest.raises(ScenarioError, match=r"detectors\[1\]\.name: 'luenberger' names a block"):
        _parse(table)


def test_cli_prints_each_decision_and_writes_the_log(tmp_path, capsys):
    out = tmp_path / "events.json"
    assert main(["simulate", str(SCENARIO), "--events", str(out)]) == 0
    printed = capsys.readouterr().out
    lines = [line.split() for line in printed.splitlines() if line.startswith("  ") and " s  " in line]
    log = json.loads(out.read_text())
    assert len(lines) == len(log) >= 4
    assert [(float(p[0]), p[2], p[3], p[4]) for p in lines] == [(e["t"], e["detector"], e["event"], e["target"] or "-")
                                                               for e in log]


def test_a_campaign_compares_the_detectors_on_the_same_runs(tmp_path):
    text = f"""name = "dc"
[[case]]
name = "speed bias"
scenario = "{SCENARIO}"
set = {{ duration = 4.0 }}
[case.grid]
"faults[0].value" = [0.05, 3.0]
[[case]]
name = "healthy"
scenario = "{SCENARIO}"
set = {{ duration = 4.0, faults = [] }}
"""
    path = tmp_path / "c.toml"
    path.write_text(text)
    campaign = load_campaign(path)
    rows = run_campaign(campaign, tmp_path / "out", executor="local", workers=1).to_pylist()
    assert [r["status"] for r in rows] == ["ok"] * 3
    by_size = {r["true_value"]: r for r in rows}
    for detector in ("luenberger_fd", "ukf_fd"):
        assert by_size[3.0][f"{detector}:detected"] and not by_size[0.05][f"{detector}:detected"]
        assert by_size[3.0][f"{detector}:detection_delay_s"] < 0.05
        assert by_size[3.0][f"{detector}:isolation_delay_s"] is None     # detection only (isolate unset)
        assert by_size[None][f"{detector}:false_alarms"] == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert set(summary["detectors"]) == {"luenberger_fd", "ukf_fd"}
    for figures in summary["detectors"].values():
        assert figures["detection_probability"] == 0.5 and figures["missed_detections"] == 1
        assert figures["healthy_hours"] == pytest.approx((4.0 + 3.0 + 3.0) / 3600)
        assert 0 < figures["decision_cpu_s_per_simulated_hour"] < figures["wall_s_per_simulated_hour"]
    assert all(r["luenberger_fd:decision_cpu_s"] > 0 for r in rows)
    assert "## Detectors side by side" in (tmp_path / "out" / "report.md").read_text()


def _sequential(outside, confirm, release):
    """The decision rule sample by sample, as the module docstring states it: (sample, event) pairs."""
    decisions, alarm, run_in, run_out = [], False, 0, 0
    for k, over in enumerate(outside):
        run_in, run_out = (run_in + 1, 0) if over else (0, run_out + 1)
        if not alarm and run_in >= confirm:
            alarm = True
            decisions.append((k, "detected"))
        elif alarm and run_out >= release:
            alarm = False
            decisions.append((k, "cleared"))
    return decisions


@pytest.mark.parametrize("seed", range(6))
def test_threshold_decisions_follow_the_rule_sample_by_sample(seed):
    from uvsym.diagnosis.detectors import ResidualThreshold
    from uvsym.sim.result import Signal, SimResult

    rng = np.random.default_rng(seed)
    n = 3000
    # bursts over the threshold of random lengths, so that confirm and release both bite
    outside = np.repeat(rng.random(300) < 0.4, rng.integers(1, 8, 300))[:n]
    t = 0.01 * np.arange(outside.size)
    sigma = 0.5
    detector = ResidualThreshold("d", ("obs.r",), [sigma], 0.01, confirm=int(rng.integers(1, 5)),
                                 release=int(rng.integers(1, 9)), targets=("y",))
    residual = np.where(outside, 1.5, 0.5) * detector.thresholds[0]
    result = SimResult(t, {"obs": Signal(residual[:, None], ("r",), ("m",))}, {})
    events = [(round(e.t / 0.01), e.event) for e in detector.decide(result) if e.event != "isolated"]
    assert events == _sequential(outside, detector.confirm, detector.release)


def test_a_campaign_substeps_option_is_refused_for_plant_scenarios(tmp_path):
    from uvsym.errors import CampaignError

    path = tmp_path / "c.toml"
    path.write_text(f'name = "dc"\n[simulation]\nsubsteps = 4\n[[case]]\nname = "a"\nscenario = "{SCENARIO}"\n')
    with pytest.raises(CampaignError, match="simulation.substeps: a scenario over a plant sets its own substeps"):
        load_campaign(path)
    path.write_text(f'name = "dc"\n[[case]]\nname = "a"\nscenario = "{SCENARIO}"\nset = {{ substeps = 4 }}\n')
    assert load_campaign(path).runs[0].scenario["substeps"] == 4


def test_a_latched_detector_keeps_its_detection_while_the_observer_absorbs_the_bias():
    """The Luenberger observer follows the +2 rad/s speed bias, so its residual comes back inside and
    the default rule clears while the fault persists; latch = true keeps the detection to the end."""
    events = simulate_system_scenario(_parse(_table())).events
    own = [e["event"] for e in events if e["detector"] == "luenberger_fd"]
    assert own == ["detected", "cleared"]
    table = _table()
    for d in table["detectors"]:
        d["latch"] = True
    latched = simulate_system_scenario(_parse(table)).events
    assert [e["event"] for e in latched if e["detector"] == "luenberger_fd"] == ["detected"]
    table["detectors"][0]["latch"] = "yes"
    with pytest.raises(ScenarioError, match=r"detectors\[0\]\.latch: expected true or false, got 'yes'"):
        _parse(table)


def test_a_detector_reads_a_bare_residual_name_that_one_block_logs_and_names_the_choices_otherwise():
    table = _table()
    table["detectors"][0]["residuals"] = ["r_i_meas", "r_omega_meas"]
    with pytest.raises(ScenarioError, match=r"detectors\[0\]\.residuals: 'r_i_meas' is logged by several groups: "
                                            r"name one of luenberger\.r_i_meas, ukf\.r_i_meas"):
        _parse(table)
    table["blocks"] = [b for b in table["blocks"] if b["type"] != "ukf"]
    table["detectors"] = table["detectors"][:1]
    assert _parse(table).detectors[0].residuals == ("luenberger.r_i_meas", "luenberger.r_omega_meas")
    table["detectors"][0]["residuals"] = ["luenberger.r_i_mes", "r_omega_meas"]
    with pytest.raises(ScenarioError, match=r"no logged signal 'luenberger\.r_i_mes'; did you mean "
                                            r"'luenberger\.r_i_meas'"):
        _parse(table)


def test_a_misspelt_block_type_gets_its_close_match():
    table = _table()
    table["blocks"][1]["type"] = "luenbergr"
    with pytest.raises(ScenarioError, match=r"blocks\[1\]\.type: unknown value 'luenbergr' \(did you mean "
                                            r"'luenberger'\?\); known: pid"):
        _parse(table)


def test_the_quick_look_figure_marks_the_fault_onset_and_the_alarms(shipped):
    _, result = shipped
    fig = result.plot()
    first = fig.axes[0]
    marks = {line.get_label(): line.get_xdata()[0] for line in first.lines if line.get_label() in ("fault onset",
                                                                                                  "alarm")}
    assert marks["fault onset"] == 3.0                       # the bias, not the whole-run sensor noise
    assert 3.0 <= marks["alarm"] <= 3.05                     # the first detection
    assert all(any(line.get_linestyle() == "--" for line in ax.lines) for ax in fig.axes)
