"""Batched simulation: every lane equals the scalar run of its scenario, actuator faults as per-sample
columns deliver what the symbolic fault model delivers, and the batch refuses what lanes cannot run."""

from __future__ import annotations

import tomllib
import warnings
from dataclasses import replace
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from uvsym.codegen.compile import find_compiler
from uvsym.errors import IntegrationAccuracyWarning, SimulationError
from uvsym.faults import ActuatorFault, Profile, apply_actuator_faults
from uvsym.sim.batch import simulate_batch
from uvsym.sim.closed_loop import actuator_fault_table, build_closed_loop
from uvsym.sim.scenario import load_scenario
from uvsym.sim.simulation import observer_blocks, simulate_scenario
from uvsym.sim.system_scenario import parse_system_scenario, simulate_system_scenario


@pytest.fixture(scope="module")
def scenarios():
    """Three 5 s docking runs differing in actuator faults (kinds, profiles, onsets), seeds and current."""
    base = replace(load_scenario("docking_faults"), duration=5.0)
    return [
        base,
        replace(base, seed=5, current=(0.2, 0.5), actuator_faults=(
            ActuatorFault(1, "bias", 0.05, Profile("ramp", onset=1.0, duration=2.0)),)),
        replace(base, seed=7, actuator_faults=(
            ActuatorFault(2, "constant", 0.1, Profile("intermittent", onset=2.5, period=1.5)),
            ActuatorFault(2, "proportional", 0.5, Profile("incipient", onset=1.0)),
            ActuatorFault(0, "loss_of_effectiveness", 0.4, Profile("step", onset=0.73)))),
    ]


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler")
def test_each_lane_equals_the_scalar_run_of_its_scenario(scenarios):
    with warnings.catch_warnings():  # the intermittent fault switches inside the step from 3.99 s, its actuator
        warnings.simplefilter("error", IntegrationAccuracyWarning)  # already faulty: a smear, not checked
        batch = simulate_batch(scenarios, lanes=4)  # three lanes and one padding lane
        scalars = [simulate_scenario(scenario) for scenario in scenarios]
    assert [result.meta["lanes"] for result in batch] == [4, 4, 4]
    for scenario, lane, scalar in zip(scenarios, batch, scalars):
        # the step check of a lane (its loop shared, the faults from the run) finds what the run's own finds
        assert lane.meta["rk4_error"]["steps_checked"] == scalar.meta["rk4_error"]["steps_checked"] > 20
        assert lane.meta["rk4_error"]["largest_error_ratio"] == pytest.approx(
            scalar.meta["rk4_error"]["largest_error_ratio"], rel=1e-9)
        assert lane.t.tolist() == scalar.t.tolist()
        for name in scalar.signals:
            expected = scalar[name].values
            np.testing.assert_allclose(lane[name].values, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max(),
                                       err_msg=name)
        # the per-sample fault columns deliver what the symbolic fault model delivers for the same actuator state
        healthy = lane["u_actual"].values - lane["fault_actuator"].values
        symbolic = np.column_stack([np.asarray(apply_actuator_faults(ca.DM(a), t, scenario.actuator_faults)).ravel()
                                    for a, t in zip(healthy[::25], lane.t[::25])]).T
        np.testing.assert_allclose(lane["u_actual"].values[::25], symbolic, rtol=1e-12, atol=1e-12)


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler")
def test_the_step_check_of_a_group_in_one_call_finds_what_each_runs_own_check_finds():
    """Three DC motor runs (bias sizes, onsets, seeds apart): each lane's rk4_error as its scalar run's."""
    root = Path(__file__).resolve().parents[1] / "examples" / "dc_motor"
    table = tomllib.loads((root / "speed_sensor_bias.toml").read_text())
    variants = [parse_system_scenario(dict(table, duration=2.0, seed=k, faults=[
        dict(table["faults"][0], value=1.0 + k, onset=0.5 + 0.3 * k)]), root=root) for k in range(3)]
    for scenario, lane in zip(variants, simulate_batch(variants, lanes=4)):
        checked, alone = lane.meta["rk4_error"], simulate_system_scenario(scenario).meta["rk4_error"]
        assert checked["steps_checked"] > 20 and checked["largest_error_ratio"] > 0
        assert checked["largest_error_ratio"] == pytest.approx(alone["largest_error_ratio"], rel=1e-9)
        assert {k: v for k, v in checked.items() if k != "largest_error_ratio"} == \
            {k: v for k, v in alone.items() if k != "largest_error_ratio"}


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler")
@pytest.mark.filterwarnings("ignore::uvsym.errors.IntegrationAccuracyWarning")
def test_runs_sharing_one_constant_current_run_it_built_into_the_lanes_step(scenarios):
    """A current every run of a group holds (here 0.3 m/s from 0.8 rad) is built into the shared step, as
    the scalar path builds each run's: each lane still equals its scalar run."""
    currents = [replace(s, current=(0.3, 0.8)) for s in scenarios]
    for scenario, lane in zip(currents, simulate_batch(currents, lanes=4)):
        expected = simulate_scenario(scenario)["x"].values
        np.testing.assert_allclose(lane["x"].values, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    still = simulate_scenario(scenarios[0])["x"].values
    assert not np.allclose(simulate_batch(currents[:1])[0]["x"].values, still)  # the current did act


def test_fault_columns_compose_faults_in_order_as_worked_by_hand(scenarios):
    model, dt = scenarios[0].model, 0.25
    loop = build_closed_loop(model, scenarios[0].controller, dt,
                             observers=observer_blocks(model, scenarios[0].observers, dt))
    faults = (ActuatorFault(1, "proportional", 0.5, Profile("ramp", onset=0.0, duration=1.0)),
              ActuatorFault(1, "bias", 2.0, Profile("step", onset=0.5)))
    touched, values = actuator_fault_table(loop, faults, 4)  # samples at 0, 0.25, ..., 1 s; stages +0, +dt/2, +dt
    m, stages = model.n_inputs, 3
    columns = np.zeros((5, 2 * stages * m))
    columns[:, touched] = values
    assert touched.tolist() == [1, m + 1, 2 * m + 1, 3 * m + 1, 4 * m + 1, 5 * m + 1]  # actuator 1's D and B only
    D = columns[:, :m * stages].reshape(5, stages, m)[:, :, 1]
    B = columns[:, m * stages:].reshape(5, stages, m)[:, :, 1]
    # v -> v + phi (0.5 v - v) = (1 - phi / 2) v with phi = min(t, 1), then + 2 from t = 0.5 s
    times = 0.25 * np.arange(5)[:, None] + np.array([0.0, 0.125, 0.25])
    np.testing.assert_allclose(D, -np.minimum(times, 1.0) / 2, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(B, np.where(times >= 0.5, 2.0, 0.0))
    others = np.delete(columns.reshape(5, 2, stages, m), 1, axis=3)
    assert not others.any()


def test_runs_without_a_compiler_fall_back_to_the_scalar_path(scenarios):
    interpreted = simulate_batch(scenarios[1:2], compiled=False)[0]
    scalar = simulate_scenario(scenarios[1], compiled=False)
    np.testing.assert_allclose(interpreted["x"].values, scalar["x"].values, rtol=1e-13, atol=1e-13)


def test_a_batch_refuses_a_supervisor_and_what_is_not_a_scenario(scenarios):
    with pytest.raises(SimulationError, match="without a supervisor"):
        simulate_batch(scenarios, supervisor=object())
    with pytest.raises(SimulationError, match=r"scenarios\[1\] must be a Scenario or a SystemScenario, got dict"):
        simulate_batch([scenarios[0], {}])
    for lanes in (0, -4, 2.5, True, "4"):  # a typed error, not a quiet fall back to one run after another
        with pytest.raises(SimulationError, match=f"lanes must be a positive integer .*got {lanes!r}"):
            simulate_batch(scenarios, lanes=lanes)


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler")
def test_a_diverging_lane_is_reported_as_its_scalar_run_is_naming_it(scenarios):
    wild = replace(scenarios[0], name="wild_current", current=(1e200, 0.3))  # drag overflows in the first step
    with pytest.raises(SimulationError) as scalar:
        simulate_scenario(wild)
    with pytest.raises(SimulationError) as lanes:
        simulate_batch([scenarios[0], wild], lanes=4)
    assert "diverged: x." in str(scalar.value) and str(lanes.value) == f"run wild_current: {scalar.value}"


def test_a_watching_diagnosis_logs_in_a_batch_as_alone_and_a_correcting_one_is_refused():
    scenario = replace(load_scenario("docking_diagnosis"), duration=5.0)
    watching = replace(scenario, diagnosis=replace(scenario.diagnosis, correct=False))
    alone, batched = simulate_scenario(watching).meta["events"], simulate_batch([watching])[0].meta["events"]
    numbers = ("value", "std")
    assert alone and [e | dict.fromkeys(numbers) for e in batched] == [e | dict.fromkeys(numbers) for e in alone]
    for a, b in zip(alone, batched):  # sizes identified from records equal to the last bits
        for key in numbers:
            assert b[key] == pytest.approx(a[key], rel=1e-9) if a[key] is not None else b[key] is None
    with pytest.raises(SimulationError, match=r"scenarios\[0\] \(docking_diagnosis\): its \[diagnosis\] corrects"):
        simulate_batch([scenario])
