"""Liu et al.'s actuator-fault observers and the continuous diagnosis in scenarios over a plant."""

from __future__ import annotations

import copy
import tomllib
from importlib import resources

import numpy as np
import pytest

from uvsym.errors import ScenarioError
from uvsym.sim.system_scenario import parse_system_scenario, simulate_system_scenario

SHIPPED = tomllib.loads(resources.files("uvsym.sim").joinpath("scenarios/plants/docking_auv_thruster_bias.toml")
                        .read_text())


def _run(**faults):
    """The shipped scenario's events and result, with its fault table replaced by ``faults`` (none: healthy)."""
    table = copy.deepcopy(SHIPPED)
    table["faults"] = [faults] if faults else []
    result = simulate_system_scenario(parse_system_scenario(table))
    return [e for e in result.events if e["event"] != "unexcited"], result


def test_the_shipped_thruster_bias_is_detected_isolated_and_sized_from_its_estimate():
    events, result = _run(**SHIPPED["faults"][0])
    first = {e["event"]: e for e in reversed(events)}
    assert {e["target"] for e in events} == {"X"}
    assert 5.0 < first["detected"]["t"] < 6.0
    assert first["isolated"]["kind"] == "bias"
    assert first["identified"]["value"] == pytest.approx(13.0, rel=0.01)
    late = result.t > 10.0  # the bias observer's estimate of the surge force follows the 13 N bias
    assert np.mean(result["bias"]["f_hat.X"][late]) == pytest.approx(13.0, rel=0.01)


@pytest.mark.parametrize("actuator, kind, value", [("X", "proportional", 0.7), ("delta_ru", "bias", 0.05),
                                                   ("X", "constant", 10.0)])
def test_other_actuators_and_kinds_are_isolated_and_sized(actuator, kind, value):
    events, _ = _run(actuator=actuator, kind=kind, value=value, onset=8.0)
    identified = [e for e in events if e["event"] == "identified"]
    assert identified and identified[0]["target"] == actuator and identified[0]["kind"] == kind
    assert identified[0]["value"] == pytest.approx(value, rel=0.05)
    assert all(e["target"] == actuator for e in events if e["event"] in ("detected", "isolated"))


def test_a_healthy_run_gives_no_decision_but_unexcited():
    events, _ = _run()
    assert events == []


def _table(**changes):
    table = copy.deepcopy(SHIPPED)
    for path, value in changes.items():
        section, index, key = path.split(".")
        table[section][int(index)][key] = value
    return table


@pytest.mark.parametrize("change, message", [
    ({"blocks.4.kind": "proportional"}, r"blocks\[4\]\.tau_d: the proportional observer's rate depends on tau_d"),
    ({"blocks.4.kindd": "bias"}, r"blocks\[4\]\.kindd: unknown field \(did you mean 'kind'\?\)"),
    ({"blocks.4.commands": ["X"]}, r"blocks\[4\]\.commands: expected 4 signal names"),
    ({"blocks.4.kind": "proportional", "blocks.4.form": "paper", "blocks.4.tau_d": [8.0, 0.5, 1.0, 0.1, 1.0, 0.3]},
     r"blocks\[4\] \(actuator_observer 'bias'\): docking_auv: the paper's proportional observer needs a diagonal"),
    ({"detectors.0.observer": "speed"}, r"detectors\[0\]\.observer: 'speed' is not an actuator_observer block"),
    ({"detectors.0.correct": True}, r"detectors\[0\]\.correct: a command correction"),
    ({"detectors.0.kinds": ["bais"]}, r"detectors\[0\]\.kinds: unknown name 'bais' \(did you mean 'bias'\?\)"),
    ({"detectors.0.window_ss": 2.0}, r"detectors\[0\]\.window_ss: unknown field \(did you mean 'window_s'\?\)"),
    ({"detectors.0.period_s": 0.015}, r"detectors\[0\]\.period_s: 0.015 s is not a whole number of steps"),
])
def test_bad_fields_are_named_before_anything_runs(change, message):
    with pytest.raises(ScenarioError, match=message):
        parse_system_scenario(_table(**change))


def test_the_observer_needs_a_vehicle_plant():
    table = tomllib.loads(resources.files("uvsym.sim").joinpath("scenarios/plants/rov_yaw_compass_bias.toml")
                          .read_text())
    table["blocks"].append({"type": "actuator_observer", "name": "obs", "kind": "bias", "time_constant": 0.3})
    message = r"blocks\[2\]\.type: needs a marine vehicle plant \(remus100, .*\), got plant 'rov_yaw'"
    with pytest.raises(ScenarioError, match=message):
        parse_system_scenario(table)
