"""The uio-zonotope study as scenario files: the uio_bank block, the zonotope_bands detector, bounded
noise, the reproduction of the study's experiment and the errors of bad input."""

from __future__ import annotations

import copy
import tomllib

import numpy as np
import pytest

from derivations.uio_zonotope import DERIVATION
from derivations.uio_zonotope.design import NOISE_BOUND, bands, design
from derivations.uio_zonotope.experiment import ONSET, Fault, Runs, _loop, detection, simulate_runs
from uvsym.diagnosis.zonotope_bands import ZonotopeBands
from uvsym.errors import ScenarioError
from uvsym.sim.result import Signal, SimResult
from uvsym.sim.system_scenario import parse_system_scenario, simulate_system_scenario


def shipped(name: str) -> dict:
    return tomllib.loads(DERIVATION.scenarios[name].read_text())


def run(table: dict) -> SimResult:
    return simulate_system_scenario(parse_system_scenario(table, root=DERIVATION.scenarios["abrupt_actuator1"].parent))


@pytest.fixture(scope="module")
def results() -> dict:
    return {name: run(shipped(name)) for name in ("abrupt_actuator1", "drift_actuator2")}


def study_runs(result: SimResult) -> Runs:
    """The study's own arithmetic (experiment.py's plant rollout and observers) fed the scenario run's
    draws: its initial state, its noise (y - h(x)), its yaw torque and its fault."""
    d = design()
    n, N = d.plant.x.size, len(result.t)
    v = result["fault_sensor"].values
    f = result["fault_actuator"].values
    w = np.column_stack([v, np.full(N, 0.02), f]).T  # (q, N): one run
    _, log = _loop(N, 1)(result["x"].values[0], w)
    log = np.asarray(log).T
    x, y, u = log[:, :n], log[:, n:2 * n], log[:, 2 * n:]
    residuals = []
    for i, obs in enumerate(d.bank.observers):
        _, out = obs.step.mapaccum("run", N)(-d.bank.designs[i].Q @ y[0], y.T, u.T, obs.p0)
        residuals.append(np.asarray(out)[n:].T[:, :, None])
    return Runs(x[..., None], y[..., None], u[..., None], f.sum(axis=1), tuple(residuals), v[..., None],
                result["x"].values[0][:, None])


@pytest.mark.parametrize("name, actuator", [("abrupt_actuator1", "Vf"), ("drift_actuator2", "Vb")])
def test_scenario_file_gives_the_numbers_of_the_study_code(results, name, actuator):
    """Same draws through experiment.py's loop and observers: states, residuals to 1e-9, and the
    same alarm sample and isolated actuator as experiment.detection on the study's bands."""
    result = results[name]
    study = study_runs(result)
    np.testing.assert_allclose(result["x"].values, study.x[..., 0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(result["lqr"].values, study.u[..., 0], rtol=0, atol=1e-9)
    for a, r in zip(design().bank.decoupled, study.residuals):
        mine = np.column_stack([result["bank"][f"r_{a}_{y}"] for y in design().plant.x.names])
        np.testing.assert_allclose(mine, r[..., 0], rtol=0, atol=1e-9)
    found = detection(study, ONSET)
    events = result.meta["events"]
    assert [e["event"] for e in events] == ["detected", "isolated"]
    assert round(events[0]["t"] / 0.01) == found["alarm"][0]
    assert found["isolated"][0] == [actuator] and events[1]["target"] == actuator


def test_detection_delays_match_the_study_runs(results):
    """The abrupt fault: the study's 20 seeded runs all alarm one sample after onset, as the scenario
    does; the drift: the scenario's delay lies within the range of the study's runs."""
    abrupt = detection(simulate_runs(1, 20, Fault(0, "abrupt", 10.0)), ONSET)["delay"]
    assert set(abrupt) == {1}
    assert results["abrupt_actuator1"].meta["events"][0]["t"] == pytest.approx((ONSET + 1) * 0.01)
    drift = detection(simulate_runs(1, 20, Fault(1, "drift", 20.0)), ONSET)["delay"]
    delay = round(results["drift_actuator2"].meta["events"][0]["t"] / 0.01) - ONSET
    assert min(drift) <= delay <= max(drift)


def test_detector_bands_are_the_study_bands():
    bank = parse_system_scenario(shipped("abrupt_actuator1"), root=DERIVATION.scenarios["abrupt_actuator1"].parent)
    detector = bank.detectors[0]
    for j, band in enumerate(bands(300)):
        np.testing.assert_array_equal(detector.lower[:, j], band.lower)
        np.testing.assert_array_equal(detector.upper[:, j], band.upper)
    half = detector.design()["band_half_width_at_horizon"]["Vf"]
    study = bands(300)[0]
    assert list(half.values()) == pytest.approx(((study.upper[-1] - study.lower[-1]) / 2).tolist(), rel=1e-12)
    assert half["bank.r_Vf_phi"] > NOISE_BOUND["phi"]  # the band holds the noise and the error it drives


def test_every_observer_but_the_decoupling_one_leaves_its_band():
    table = shipped("abrupt_actuator1")
    table["faults"][0]["actuator"] = "Vr"
    scenario = parse_system_scenario(table, root=DERIVATION.scenarios["abrupt_actuator1"].parent)
    result = simulate_system_scenario(scenario)
    outside = scenario.detectors[0].outside(result)
    assert not outside[:ONSET].any()
    assert list(outside[ONSET + 1]) == [True, True, False, False]  # the front and back observers at once
    assert list(outside[ONSET:ONSET + 50].any(axis=0)) == [True, True, False, True]  # the left one later
    assert not outside[:, 2].any()
    assert [(e["event"], e["target"]) for e in result.meta["events"]] == [("detected", None), ("isolated", "Vr")]


def test_healthy_run_within_the_bounds_never_alarms_and_beyond_them_may():
    table = shipped("abrupt_actuator1")
    table["faults"] = []
    table["duration"] = 9.99
    assert run(table).meta["events"] == []
    table["noise"] = {k: {"uniform": 3 * v["uniform"]} for k, v in table["noise"].items()}
    events = run(table).meta["events"]
    assert events and events[0]["event"] == "detected"


def test_yaw_disturbance_is_decoupled_by_every_observer():
    """The residuals do not depend on the yaw torque (T D1 = 0), though the states do."""
    table = shipped("drift_actuator2")
    calm = copy.deepcopy(table)
    calm["initial"]["d"] = {"tau_d": 0.0}
    a, b = run(table), run(calm)
    assert np.max(np.abs(a["x"].values - b["x"].values)) > 1e-3
    np.testing.assert_allclose(a["bank"].values, b["bank"].values, rtol=0, atol=1e-12)


def test_uniform_noise_is_bounded_and_uniform():
    table = shipped("abrupt_actuator1")
    table["faults"], table["detectors"], table["duration"] = [], [], 49.99
    v = run(table)["fault_sensor"].values
    bound = np.array([NOISE_BOUND[n] for n in design().plant.x.names])
    assert np.all(np.abs(v) <= bound)
    # uniform in [-b, b]: mean |v| = b / 2, standard deviation b / sqrt 3 (5000 samples: within 3 %)
    np.testing.assert_allclose(np.abs(v).mean(axis=0) / bound, 0.5, rtol=0.03)
    np.testing.assert_allclose(v.std(axis=0) / bound, 1 / np.sqrt(3), rtol=0.03)


def _record(outside: np.ndarray) -> tuple[ZonotopeBands, SimResult]:
    """A two-actuator detector with bands [-1, 1] and a record whose residual is 2 where ``outside``."""
    N = len(outside)
    detector = ZonotopeBands("bands", ("A", "B"), (("g.rA",), ("g.rB",)), -np.ones((5, 2, 1)), np.ones((5, 2, 1)),
                             0.1, isolation_window=3, release=2)
    result = SimResult(0.1 * np.arange(N), {"g": Signal(2.0 * outside, ("rA", "rB"), ("m", "m"))})
    return detector, result


@pytest.mark.parametrize("pattern, expected", [
    # B's observer alarms, A's stays inside: a fault on A
    ([(0, 0), (0, 1), (0, 1), (0, 0), (0, 0), (0, 0), (0, 0)],
     [(0.1, "detected", None), (0.3, "isolated", "A"), (0.5, "cleared", None)]),
    # both alarm within the window: no single-actuator fault fits
    ([(0, 0), (1, 0), (0, 1), (0, 0), (0, 0), (0, 0)],
     [(0.1, "detected", None), (0.3, "unexplained", None), (0.5, "cleared", None)]),
    # the exit is too short to tell: both observers inside over the rest of the window
    ([(0, 0), (1, 1), (0, 0), (0, 0), (0, 0), (0, 0), (1, 0), (0, 0), (0, 0)],
     [(0.1, "detected", None), (0.3, "unexplained", None), (0.5, "cleared", None), (0.6, "detected", None),
      (0.8, "isolated", "B")]),
    # the record ends inside the window: no isolation decision
    ([(0, 0), (0, 0), (0, 1), (0, 1)], [(0.2, "detected", None)]),
])
def test_decisions_of_exit_patterns(pattern, expected):
    detector, result = _record(np.array(pattern, dtype=float))
    assert [(e.t, e.event, e.target) for e in detector.decide(result)] == expected


def test_ambiguous_when_two_observers_stay_inside():
    detector = ZonotopeBands("bands", ("A", "B", "C"), (("g.rA",), ("g.rB",), ("g.rC",)), -np.ones((5, 3, 1)),
                             np.ones((5, 3, 1)), 0.1, isolation_window=2, release=1)
    result = SimResult(0.1 * np.arange(4), {"g": Signal([[0, 0, 0], [0, 0, 2], [0, 0, 0], [0, 0, 0]],
                                                        ("rA", "rB", "rC"), ("m",) * 3)})
    assert [(e.event, e.target) for e in detector.decide(result)] == [("detected", None), ("ambiguous", "A|B"),
                                                                       ("cleared", None)]


def _bad(change) -> dict:
    table = shipped("abrupt_actuator1")
    change(table)
    return table


@pytest.mark.parametrize("change, field, words", [
    (lambda t: t["blocks"][1].update(type="uio_bnk"), r"blocks\[1\]\.type", "uio_bank"),
    (lambda t: t["blocks"][1].update(pole=[0.5]), r"blocks\[1\]", "pole"),
    (lambda t: t["blocks"][1].update(measured=["phi", "theta", "psi"]), r"blocks\[1\]\.measured",
     "not detectable"),
    (lambda t: t["blocks"][1].update(measured=["phi", "thetta"]), r"blocks\[1\]\.measured", "theta"),
    (lambda t: t["blocks"][1].update(poles=[0.5, 0.6]), r"blocks\[1\]\.poles", "8 real eigenvalues"),
    (lambda t: t["blocks"][1].update(poles=[1.2] * 8), r"blocks\[1\]\.poles", "unit circle"),
    (lambda t: t["blocks"][1].update(decouple=["wind"]), r"blocks\[1\]\.decouple", "tau_d"),
    (lambda t: t["detectors"][0].update(type="zonotope_band"), r"detectors\[0\]\.type", "zonotope_bands"),
    (lambda t: t["detectors"][0].update(bank="bnk"), r"detectors\[0\]\.bank", "did you mean 'bank'"),
    (lambda t: t["detectors"][0].update(bank="lqr"), r"detectors\[0\]\.bank", "not a uio_bank"),
    (lambda t: t["detectors"][0]["noise_bound"].pop("w"), r"detectors\[0\]\.noise_bound", "missing w"),
    (lambda t: t["detectors"][0].update(initial_error=-1.0), r"detectors\[0\]\.initial_error", ">= 0"),
    (lambda t: t["detectors"][0].update(horizon=20), r"detectors\[0\]\.horizon", "longer horizon"),
    (lambda t: t["detectors"][0].update(reduction="best"), r"detectors\[0\]\.reduction", "girard"),
    (lambda t: t["detectors"][0].update(isolation_windw=5), r"detectors\[0\]", "isolation_windw"),
    (lambda t: t["noise"].update(phi={"uniform": -1.0}), r"noise\.phi\.uniform", "positive"),
    (lambda t: t["noise"].update(phi={"gauss": 1.0}), r"noise\.phi", "gauss"),
])
def test_bad_input_is_named_before_any_run(change, field, words):
    with pytest.raises(ScenarioError, match=field) as info:
        parse_system_scenario(_bad(change), root=DERIVATION.scenarios["abrupt_actuator1"].parent)
    assert words in str(info.value)


def test_uniform_sensor_noise_is_the_specification_not_a_fault():
    from uvsym.campaign.metrics import truth

    table = shipped("abrupt_actuator1")
    table["faults"] = []
    scenario = parse_system_scenario(table, root=DERIVATION.scenarios["abrupt_actuator1"].parent)
    assert {f.kind for f in scenario.sensor_faults} == {"uniform_noise"}
    assert truth(scenario)["n_faults"] == 0


def test_campaign_covers_every_rotor_profile_and_noise_level():
    from derivations.uio_zonotope.campaign import CAMPAIGN
    from uvsym.campaign import load_campaign

    campaign = load_campaign(CAMPAIGN)  # every run's scenario is validated here
    faulty = [run.scenario["faults"][0] for run in campaign.runs if run.scenario["faults"]]
    assert {f["actuator"] for f in faulty} == {"Vf", "Vb", "Vr", "Vl"}
    assert {f.get("profile", "step") for f in faulty} == {"step", "ramp", "intermittent"}
    assert {f["kind"] for f in faulty} == {"bias", "constant"}
    levels = {round(run.scenario["noise"]["w"]["uniform"] / NOISE_BOUND["w"], 9) for run in campaign.runs}
    assert levels == {1.0, 2.0, 3.0}
    healthy = [run.scenario for run in campaign.runs if not run.scenario["faults"]]
    assert sum(s["duration"] for s in healthy if s["noise"]["w"]["uniform"] == NOISE_BOUND["w"]) >= 300.0
    assert min(abs(f["value"]) for f in faulty if f["kind"] == "bias") < 0.5  # below the detectable


def test_campaign_metrics_hook_reads_the_first_alarm_and_decision():
    from derivations.uio_zonotope.campaign import metrics

    table = shipped("abrupt_actuator1")
    scenario = parse_system_scenario(table, root=DERIVATION.scenarios["abrupt_actuator1"].parent)
    events = [{"t": 0.2, "event": "detected", "target": None, "detector": "bands"},
              {"t": 0.4, "event": "ambiguous", "target": "Vf|Vb", "detector": "bands"},
              {"t": 0.6, "event": "detected", "target": None, "detector": "bands"},
              {"t": 0.9, "event": "unexplained", "target": None, "detector": "bands"}]
    assert metrics(scenario, None, events) == {"first_alarm_s": 0.2, "decision": "unexplained"}  # onset 0.5 s
    assert metrics(scenario, None, [])["decision"] == "none"


def test_uvsym_simulate_prints_the_bank_decisions_and_writes_the_log(tmp_path, capsys):
    import json

    from uvsym.cli import main

    assert main(["simulate", "abrupt_actuator1", "--events", str(tmp_path / "events.json")]) == 0
    lines = [line.split() for line in capsys.readouterr().out.splitlines()]
    assert ["0.5100", "s", "bands", "detected", "-"] in lines and ["1.0000", "s", "bands", "isolated", "Vf"] in lines
    log = json.loads((tmp_path / "events.json").read_text())
    assert [(e["event"], e["target"], e["detector"]) for e in log] == [("detected", None, "bands"),
                                                                       ("isolated", "Vf", "bands")]


def _figures(runs: int, fault_runs: int | None = None, **given) -> dict:
    """A group's figures as campaign_results gives them (None where the group has no such figure)."""
    keys = ("detection_probability", "correct_isolation", "ambiguous", "unexplained", "wrong_isolation",
            "median_detection_delay_s", "false_alarms_per_hour", "healthy_runs_alarmed", "median_first_false_alarm_s")
    return {"runs": runs, "fault_runs": runs if fault_runs is None else fault_runs, "false_alarms": 0,
            "healthy_hours": 0.01, **dict.fromkeys(keys), **given}


def test_the_limits_block_states_the_campaign_figures():
    """Built from fabricated figures: the smallest faults per rotor, the delays, the false alarms within and beyond
    the bound beside the proved guarantee, what the bank cannot see; one marked block without a link."""
    from derivations.uio_zonotope.campaign import limits_section
    from uvsym.report import LIMITS_MARKERS

    def healthy(runs, alarms, hours, alarmed, first):
        return _figures(runs, 0, false_alarms=alarms, healthy_hours=hours, false_alarms_per_hour=alarms / hours,
                        healthy_runs_alarmed=alarmed, median_first_false_alarm_s=first)

    c = {"by_case_and_noise": {
            "abrupt|1": _figures(16, wrong_isolation=0.125),
            "no fault|1": healthy(3, 0, 6.0, 0.0, None),
            "no fault, noise beyond the bound|2": healthy(4, 4, 2.0, 1.0, 0.01),
            "no fault, noise beyond the bound|3": healthy(4, 6, 2.0, 0.75, 0.02),
            "abrupt, noise beyond the bound|2": _figures(8, detection_probability=0.25),
            "nonlinear plant, abrupt|1": _figures(12, detection_probability=0.5, correct_isolation=0.25,
                                                  ambiguous=0.125, unexplained=0.375),
            "nonlinear plant, no fault|1": healthy(1, 0, 0.05, 0.0, None)},
         "abrupt_by_size": {"0.5": _figures(8, detection_probability=0.0, correct_isolation=0.0, ambiguous=0.0),
                            "3": _figures(8, detection_probability=1.0, correct_isolation=0.0, ambiguous=1.0,
                                          median_detection_delay_s=0.2),
                            "10": _figures(8, detection_probability=1.0, correct_isolation=1.0, ambiguous=0.0,
                                           median_detection_delay_s=0.01)},
         "drift_by_rate": {"1": _figures(8, detection_probability=0.5, median_detection_delay_s=0.9),
                           "4": _figures(8, detection_probability=1.0, median_detection_delay_s=0.3)},
         "limits": {"abrupt": [{"channel": "Vf", "kind": "bias", "sizes": [(0.5, 2, 0), (3.0, 2, 2), (10.0, 2, 2)],
                                "seen_from": 3.0, "missed_up_to": 0.5, "median_delay_s": 0.05}],
                    "drift": [{"channel": "Vf", "kind": "bias", "sizes": [(1.0, 2, 1), (4.0, 2, 2)],
                               "seen_from": 4.0, "missed_up_to": 1.0, "median_delay_s": 0.4}]}}
    text = limits_section(c, 3, 4)
    head, block = text.split(LIMITS_MARKERS[0])
    assert head.startswith("### Limits") and text.count(LIMITS_MARKERS[1]) == 1 and text.endswith(LIMITS_MARKERS[1])
    assert "](" not in block and "\n#" not in block
    flat = " ".join(block.split())  # the text's line breaks fall anywhere
    assert "tried in 2 runs per rotor" in flat
    assert "| Vf | bias | 0.5: 0/2, 3: 2/2, 10: 2/2 | 3 V | 0.5 V | 0.05 |" in flat  # the abrupt limits' row
    assert "from 0.2 s at 3 V to 0.01 s at 10 V (abrupt) and from 0.3 s at 4 V/s" in flat
    assert "| no fault | 1 | 3 | 6 | 0 | 0 | 0 | - |" in flat
    assert "prove it for 3 of 4 observers" in flat
    assert "0 false alarms in 6 h, as proved" in flat and "below 0.5 per hour" in flat  # ln 20 / 6 h
    assert "0.05 h are too few" in flat
    assert "at 2 times it every fault-free run alarms once, first at 0.01 s (median), and faults are detected in " \
           "their window with probability 0.25" in flat and "counts runs, not hours" in flat
    assert "at 3 times it a fraction 0.75 of the fault-free runs alarm, first at 0.02 s" in flat
    assert "Abrupt faults up to 0.5 V and drifts up to 1 V/s are missed" in flat
    assert "below 10 V" in flat and "a fraction 1 end ambiguous" in flat  # the 3 V runs: all detected, ambiguous
    assert "named in 2 of 16 fault runs" in flat
    assert "12 abrupt faults are detected with probability 0.5, isolated correctly in a fraction 0.25" in flat

def test_the_limits_block_says_when_the_designed_noise_gave_false_alarms():
    from derivations.uio_zonotope.campaign import _designed_rate

    assert "**not the 0 proved**" in _designed_rate(_figures(3, 0, false_alarms=2, healthy_hours=4.0,
                                                             false_alarms_per_hour=0.5))


def test_the_limits_block_states_the_bands_told_twice_the_bound_without_calling_them_proved():
    from derivations.uio_zonotope.campaign import _told

    assert _told({}) == ""
    groups = {"no fault, bands told twice the bound|2": _figures(30, 0, healthy_hours=10.0),
              "abrupt, bands told twice the bound|2": _figures(16, detection_probability=0.75,
                                                               median_detection_delay_s=0.05)}
    text = _told(groups)
    assert "0 false alarms in 10 h, as designed" in text and "as proved" not in text
    assert "detected with probability 0.75 (16 runs, median delay 0.05 s)" in text
    groups["no fault, bands told twice the bound|2"] |= {"false_alarms": 2, "false_alarms_per_hour": 0.2}
    assert "**not the 0 of the design**" in _told(groups)
