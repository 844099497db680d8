"""Lanes for loops wired from scenario files: one compiled step for every fault of one shape, and
results equal to the scalar path's."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from uvsym.errors import SimulationError
from uvsym.sim.batch import simulate_batch
from uvsym.sim.system_scenario import parse_system_scenario, simulate_system_scenario

EXAMPLE = Path(__file__).parents[1] / "examples" / "dc_motor"


def _scenario(fault: dict | None = None, **changes):
    table = tomllib.loads((EXAMPLE / "speed_sensor_bias.toml").read_text())
    table |= {"duration": 4.0, "blocks": [b for b in table["blocks"] if b["type"] != "ukf"],
              "detectors": [d for d in table["detectors"] if d["name"] != "ukf_fd"]}
    if fault is not None:
        table["faults"] = [fault]
    table.update(changes)
    return parse_system_scenario(table, root=EXAMPLE)


BIAS = {"sensor": "omega_meas", "kind": "bias"}
VARIANTS = [
    ({"sensor": "omega_meas", "kind": "bias", "value": 2.0, "onset": 3.0}, {}),
    ({"sensor": "omega_meas", "kind": "bias", "value": -0.7, "onset": 1.234}, {"seed": 4}),
    ({"sensor": "omega_meas", "kind": "bias", "value": 5.0, "onset": 2.0, "end": 2.5}, {"seed": 2}),
    (BIAS | {"value": 1.0, "onset": 2.5}, {"noise": {"i_meas": 0.02, "omega_meas": 0.3}}),
    (BIAS | {"value": 3.0, "onset": 0.5}, {"initial": {"x": {"i": 0.5, "omega": 20.0}}}),
]


def test_faults_of_one_shape_share_one_step_and_other_shapes_do_not():
    first, second = (_scenario(f, **c) for f, c in VARIANTS[:2])
    assert first.loop.step is second.loop.step                  # sizes, onsets, seeds: inputs of one step
    drift = _scenario({"sensor": "omega_meas", "kind": "drift", "value": 1.0, "onset": 3.0})
    loss = _scenario({"actuator": "V", "kind": "proportional", "value": 0.5, "onset": 3.0})
    assert len({id(s.loop.step) for s in (first, drift, loss)}) == 3


def test_each_fault_acts_with_its_own_numbers():
    """The logged sensor fault is the bias itself from its onset to its end, and 0 elsewhere, for every
    variant run through the one shared step."""
    for fault, changes in VARIANTS:
        result = simulate_system_scenario(_scenario(fault, **changes))
        column = result["fault_sensor"]["omega_meas"]
        active = (result.t >= fault["onset"] - 1e-9) & (result.t < fault.get("end", np.inf) - 1e-9)
        # the measured-minus-true offset: noise (std below 0.5 rad/s, 6 sigma) plus the bias where active
        offset = np.asarray(column) - np.where(active, fault["value"], 0.0)
        std = changes.get("noise", {}).get("omega_meas", 0.1)
        assert np.all(np.abs(offset) < 6 * std)
        assert abs(np.mean(offset[active])) < 4 * std / np.sqrt(active.sum())


def test_lanes_equal_the_scalar_path_for_every_variant():
    scenarios = [_scenario(f, **c) for f, c in VARIANTS] + [
        _scenario({"actuator": "V", "kind": "proportional", "value": 0.8, "onset": 2.0}),
        _scenario({"actuator": "V", "kind": "proportional", "value": 0.5, "onset": 1.0}, seed=9)]
    batched = simulate_batch(scenarios, lanes=4)
    for scenario, lane in zip(scenarios, batched):
        scalar = simulate_system_scenario(scenario)
        assert lane.meta["lanes"] == 4 and lane.meta["scenario"] == scenario.name
        np.testing.assert_array_equal(lane.t, scalar.t)
        for name in scalar.signals:
            np.testing.assert_allclose(lane[name].values, scalar[name].values, rtol=1e-9, atol=1e-9, err_msg=name)
        assert [(e["event"], e["target"], e["t"]) for e in lane.events] == \
            [(e["event"], e["target"], e["t"]) for e in scalar.events]
        assert lane.meta["sensor_faults"] == scalar.meta["sensor_faults"]


def test_a_loop_with_a_ukf_runs_in_lanes_equal_to_the_scalar_path():
    """The UKF's step uses |x| (CasADi's casadi_fabs): the lanes run it too, not the scalar fallback."""
    table = tomllib.loads((EXAMPLE / "speed_sensor_bias.toml").read_text()) | {"duration": 2.0}
    scenarios = [parse_system_scenario(table | {"seed": k, "faults": [BIAS | {"value": 1.0 + k, "onset": 1.0}]},
                                       root=EXAMPLE) for k in range(3)]
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")                      # no fallback to one run after another
        batched = simulate_batch(scenarios, lanes=4)
    for scenario, lane in zip(scenarios, batched):
        scalar = simulate_system_scenario(scenario)
        for name in ("ukf", "luenberger", "x"):
            np.testing.assert_allclose(lane[name].values, scalar[name].values, rtol=1e-9, atol=1e-9, err_msg=name)
        assert [(e["event"], e["t"]) for e in lane.events] == [(e["event"], e["t"]) for e in scalar.events]


def test_a_flag_substitution_cannot_run_in_lanes_and_nothing_else_is_taken():
    table = tomllib.loads((EXAMPLE / "speed_sensor_bias.toml").read_text()) | {"duration": 4.0, "faults": []}
    table["setpoints"] = table["setpoints"] + [{"signal": "sw", "times": [0.0, 3.0], "values": [0.0, 1.0]}]
    table["substitutions"] = {"omega_meas": {"by": "luenberger.omega_hat", "when": "setpoint_sw.sw"}}
    flagged = parse_system_scenario(table, root=EXAMPLE)
    with pytest.raises(SimulationError, match=r"scenarios\[1\] \(dc_motor_speed_sensor_bias\): its substitutions "
                                              r"switch on a flag"):
        simulate_batch([_scenario(), flagged])
    with pytest.raises(SimulationError, match=r"scenarios\[1\] must be a Scenario or a SystemScenario, got str"):
        simulate_batch([_scenario(), "not a scenario"])
