"""The LMS compass-fault study's scenario files: they reproduce the study's own runs, run by name through
``uvsym simulate``, and refuse bad input naming the field."""

from __future__ import annotations

import copy
import math
import tomllib
import warnings

import numpy as np
import pytest

from derivations.sensor_fdi_lms import DERIVATION
from derivations.sensor_fdi_lms.design import DT, EPS0_DEG2, WARM_UP, design
from derivations.sensor_fdi_lms.experiment import Run, run
from uvsym.cli import main
from uvsym.errors import ScenarioError, StepSizeWarning
from uvsym.sim.loop import disturbance_draws, sample_inputs
from uvsym.sim.system_scenario import parse_system_scenario, simulate_system_scenario

# the study's run each shipped scenario is (experiment.Run); the spike is the one-sample pulse
PAPER_RUNS = {"compass_10deg": Run(size_deg=10.0), "compass_20deg": Run(size_deg=20.0),
              "compass_30deg": Run(size_deg=30.0), "compass_spike": Run(size_deg=10.0, profile="pulse", length=1)}
SIGNALS = [("x", "psi"), ("x", "r"), ("y", "psi"), ("u", "u"), ("ftc", "psi_sel")] + [
    ("lms", n) for n in ("psi_fir", "psi_sub", "e_psi", "eps2_psi", "R_psi", "frozen_psi", "fault_psi")]


def _table(name: str) -> dict:
    return tomllib.loads(DERIVATION.scenarios[name].read_text())


def _parsed(table: dict):
    return parse_system_scenario(table, root=DERIVATION.scenarios["compass_10deg"].parent)


@pytest.fixture(scope="module")
def study_runs():
    return {name: run(spec) for name, spec in PAPER_RUNS.items()}


def test_the_files_state_the_studys_design():
    """The typed gain and threshold are the study's designed ones (heading_gain, (3 deg)^2), to the last bit."""
    blocks = {b["name"]: b for b in _table("compass_30deg")["blocks"]}
    assert blocks["heading"]["kp"] == design().kp
    assert blocks["lms"]["eps0"] == EPS0_DEG2 * (math.pi / 180.0) ** 2
    assert _table("compass_30deg")["duration"] == pytest.approx((WARM_UP + 400) * DT)


@pytest.mark.parametrize("name", sorted(PAPER_RUNS))
def test_a_shipped_scenario_reproduces_the_studys_run(name, study_runs):
    """Same arithmetic (CasADi's virtual machine, as the study runs): every signal to 1e-9; the
    detector's detection is the sample the study's supervisor logs the confirmation at."""
    old = study_runs[name]
    new = simulate_system_scenario(_parsed(_table(name)), compiled=False)
    for group, label in SIGNALS:
        np.testing.assert_allclose(new[group][label], old.result[group][label], rtol=0, atol=1e-9,
                                   err_msg=f"{group}.{label}")
    confirmed = old.supervisor.first("R alarm")
    events = [e for e in new.meta["events"] if e["detector"] == "double_criterion"]
    detected = [e["t"] for e in events if e["event"] == "detected"]
    if confirmed is None:  # the spike: released as a disturbance, nothing decided
        assert old.supervisor.first("no R alarm") is not None and events == []
    else:
        assert detected == [pytest.approx(old.result.t[confirmed.sample], abs=1e-9)]
        assert [e["target"] for e in events] == ["psi", "psi"]


def test_the_compiled_run_decides_the_same_and_differs_only_in_r_once_latched(study_runs):
    """Compiled C sums in another order: R's window variance is near zero once the weights settle after
    the fault, so R differs there (by up to about 0.4 of R ~ 3); before the latch every signal agrees."""
    old = study_runs["compass_10deg"]
    new = simulate_system_scenario(_parsed(_table("compass_10deg")))
    np.testing.assert_array_equal(new["lms"]["fault_psi"], old.result["lms"]["fault_psi"])
    before = old.result["lms"]["fault_psi"] < 0.5
    for group, label in SIGNALS:
        np.testing.assert_allclose(new[group][label][before], old.result[group][label][before], rtol=1e-9,
                                   atol=1e-9, err_msg=f"{group}.{label}")


def test_uvsym_simulate_prints_the_decisions_by_name(capsys):
    assert main(["simulate", "compass_30deg"]) == 0
    lines = [line.split() for line in capsys.readouterr().out.splitlines() if "double_criterion" in line]
    assert [line[1:] for line in lines] == [["s", "double_criterion", "detected", "psi"],
                                           ["s", "double_criterion", "isolated", "psi"]]
    assert 114.0 <= float(lines[0][0]) <= 116.0  # within 10 samples of the onset at 114 s
    assert main(["simulate", "compass_spike"]) == 0
    assert "double_criterion" not in capsys.readouterr().out


def test_the_substitute_switches_in_the_same_sample_and_on_the_alarm_rule():
    """select: psi_sel is the substitute from the sample the flag rises; flag frozen_psi substitutes
    from the eps^2 alarm (Sec. 4.3) as the study's substitute_on="alarm" run does."""
    table = _table("compass_30deg")
    table["duration"], table["faults"][0]["onset"] = 60.0, 40.0
    result = simulate_system_scenario(_parsed(table), compiled=False)
    flag = result["lms"]["fault_psi"] > 0.5
    np.testing.assert_array_equal(result["ftc"]["psi_sel"][flag], result["lms"]["psi_sub"][flag])
    np.testing.assert_array_equal(result["ftc"]["psi_sel"][~flag], result["y"]["psi"][~flag])
    next(b for b in table["blocks"] if b["name"] == "ftc")["flag"] = "lms.frozen_psi"
    alarm = simulate_system_scenario(_parsed(table), compiled=False)
    spec = run(Run(size_deg=30.0, substitute_on="alarm", warm_up=100, record=200, onset=100))
    np.testing.assert_allclose(alarm["x"]["psi"], spec.result["x"]["psi"], rtol=0, atol=1e-9)


def test_disturbance_noise_has_its_own_stream():
    """[noise] tau_d: white torque drawn apart from the compass noise (the two are uncorrelated)."""
    draws = disturbance_draws(4000, 1, seed=3)[:, 0]
    sensor = sample_inputs(2, 4000, 0.2, 1, seed=3)[:, 1]
    assert abs(np.corrcoef(draws, sensor)[0, 1]) < 0.05
    assert np.std(draws) == pytest.approx(1.0, rel=0.05)
    quiet = _table("compass_spike")
    quiet["noise"] = {"tau_d": 1e-2}  # no compass noise: only the torque moves the heading
    quiet["faults"], quiet["duration"] = [], 20.0
    result = simulate_system_scenario(_parsed(quiet), compiled=False)
    assert np.std(result["x"]["r"]) > 0
    np.testing.assert_array_equal(result["y"]["psi"], result["x"]["psi"])  # compass noise-free


@pytest.mark.parametrize("change, field", [
    (lambda t: t["blocks"][1].update(type="lsm"), r"blocks\[1\]\.type: .*'lsm'"),
    (lambda t: t["blocks"][1].update(ordr=5), r"blocks\[1\]\.ordr: unknown field \(did you mean 'order'\?\)"),
    (lambda t: t["blocks"][1].update(order=0), r"blocks\[1\]\.order"),
    (lambda t: t["blocks"][1].update(mu=-0.01), r"blocks\[1\]\.mu"),
    (lambda t: t["blocks"][2].update(on=["lms.psi_sub", "lms.psi_fir"]), r"blocks\[2\]\.on: expected 1 signal"),
    (lambda t: t["blocks"][2].update(flag="lms.fault_pis"), r"blocks: .*fault_pis"),
    (lambda t: t["noise"].update(tau=1e-4), r"noise\.tau: unknown output or disturbance .*did you mean 'tau_d'"),
    (lambda t: t["noise"].update(tau_d=-1.0), r"noise\.tau_d"),
    (lambda t: t["detectors"][0].update(monitor="heading"), r"detectors\[0\]\.monitor: 'heading' is not an lms"),
    (lambda t: t["detectors"][0].update(type="lsm"), r"detectors\[0\]\.type"),
    (lambda t: t["faults"][0].update(sensor="depth"), r"faults\[0\]\.sensor"),
    (lambda t: t["faults"][0].update(onset=180.0, end=181.0), r"faults\[0\]\.onset: 180 s is outside the run"),
    (lambda t: t.update(seed=-1), r"seed"),
])
def test_bad_fields_are_named_before_any_run(change, field):
    table = copy.deepcopy(_table("compass_spike"))
    change(table)
    with pytest.raises(ScenarioError, match=field):
        _parsed(table)


def test_a_scenario_without_faults_decides_nothing():
    table = _table("compass_20deg")
    table["faults"], table["duration"] = [], 60.0
    assert simulate_system_scenario(_parsed(table), compiled=False).meta["events"] == []


def test_the_threshold_detectors_sigma_is_the_noise_models():
    """The error threshold's typed std is e_psi's under the file's [noise], through the loop linearised at
    its start (the noise model it is designed from), not a value read off a run."""
    table = _table("compass_20deg")
    typed = next(d for d in table["detectors"] if d["type"] == "threshold")["std"]
    for detector in table["detectors"]:
        detector.pop("std", None)
    scenario = _parsed(table)
    computed = next(d for d in scenario.detectors if d.name == "error_threshold").design()["sigma"]
    assert computed == pytest.approx(typed, rel=1e-9)


def test_the_double_criterions_design_names_its_thresholds():
    design = next(d for d in _parsed(_table("compass_20deg")).detectors if d.name == "double_criterion").design()
    assert design["sensor"] == "psi" and design["monitor"] == "lms"
    assert design["parameters"] == {"mu": 0.01, "eps0": EPS0_DEG2 * (math.pi / 180.0) ** 2, "r0": 9.0}
    assert "confirm 10" in design["settings"] and "hold 3" in design["settings"]


def test_a_step_beyond_the_mean_square_bound_of_the_runs_input_power_warns(tmp_path):
    """mu M P_u >= 1 with P_u the mean square of the command the filter regresses on: StepSizeWarning
    naming the monitor's mu and the bound (the paper's mu stays silent)."""
    table = _table("compass_20deg")
    table["duration"], table["faults"][0]["onset"] = 24.0, 4.0
    table["blocks"][1].update(order=10, mu=1e5)
    with pytest.warns(StepSizeWarning, match=r"lms\.mu = 100000 is at or beyond the mean-square stability bound "
                                             r"1 / \(M P_u\) = [0-9.e+]+ \(M = 10"):
        u = simulate_system_scenario(_parsed(table), compiled=False)["heading"]["u"]
    assert 1e5 * 10 * np.mean(u ** 2) >= 1.0  # the bound the warning names, from the record itself
    table["blocks"][1]["mu"] = 0.01
    with warnings.catch_warnings():
        warnings.simplefilter("error", StepSizeWarning)
        simulate_system_scenario(_parsed(table), compiled=False)


def test_a_detection_and_isolation_at_one_sample_are_one_false_alarm():
    from uvsym.campaign.metrics import event_metrics

    healthy = {"true_actuator": None, "true_sensor": None, "true_value": None, "onset_s": None, "end_s": None}
    events = [{"t": 150.6, "event": "detected", "target": "psi", "detector": "dc"},
              {"t": 150.6, "event": "isolated", "target": "psi", "detector": "dc"},
              {"t": 150.6, "event": "detected", "target": "psi", "detector": "th"},  # another detector: its own
              {"t": 170.0, "event": "detected", "target": "psi", "detector": "th"}]
    assert event_metrics(healthy, events)["false_alarms"] == 3
    assert event_metrics(healthy, [e for e in events if e["detector"] == "dc"])["false_alarms"] == 1


def test_the_campaign_covers_what_the_issue_asks_and_every_run_is_valid():
    """Every run's scenario parses (load_campaign validates them all); sizes span 1 to 30 deg, both signs,
    the profiles and kinds the issue lists, noise at 1, 2 and 3 times the scenario's, healthy runs
    with set-point changes and long healthy runs."""
    from derivations.sensor_fdi_lms.campaign import CAMPAIGN
    from uvsym.campaign import load_campaign

    runs = load_campaign(CAMPAIGN).runs
    faults = [r.scenario["faults"][0] for r in runs if r.scenario["faults"]]
    assert {(f.get("kind", "bias"), f.get("profile", "step")) for f in faults} >= {
        ("bias", "step"), ("bias", "ramp"), ("bias", "incipient"), ("bias", "intermittent"), ("drift", "step"),
        ("stuck", "step")}
    assert any("end" in f for f in faults)  # pulses, down to one sample
    sizes = sorted(math.degrees(f["value"]) for f in faults if f.get("kind", "bias") == "bias")
    assert sizes[0] < 0 and min(abs(s) for s in sizes) == pytest.approx(1.0) and sizes[-1] == pytest.approx(30.0)
    noise = _table("compass_20deg")["noise"]["psi"]
    assert sorted({r.scenario["noise"]["psi"] / noise for r in runs}) == pytest.approx([1.0, 2.0, 3.0])
    healthy = [r for r in runs if not r.scenario["faults"]]
    assert any(len(r.scenario["setpoints"][0]["values"]) > 1 for r in healthy)
    assert sum(r.scenario["duration"] for r in healthy) >= 10 * 3600.0
