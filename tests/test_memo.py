"""The in-process memo of a rerun: keys by value (a changed parameter, gain, fault or file is a new build,
never a stale one), and a run with the memo filled gives exactly what a run from empty memos gives."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from uvsym.codegen.cache import clear_memos, frozen, memoized
from uvsym.faults import ActuatorFault, Profile, SensorFault
from uvsym.models.registry import vehicle
from uvsym.sim.closed_loop import build_closed_loop
from uvsym.sim.scenario import ObserverSpec, load_scenario, shipped_scenarios
from uvsym.sim.simulation import observer_blocks, simulate_scenario


@pytest.fixture(scope="module")
def docking():
    return replace(load_scenario("docking_faults"), duration=2.0)


def test_frozen_keys_tell_apart_what_builds_differently():
    assert frozen((1.0, [2, 3], {"a": np.ones(2)})) == frozen((1.0, [2, 3], {"a": np.ones(2)}))
    assert frozen(0.0) != frozen(-0.0)  # signed zeros: bit for bit
    assert frozen({"a": 1, "b": 2}) != frozen({"b": 2, "a": 1})  # order can change a symbolic build
    assert frozen(np.zeros(2)) != frozen(np.zeros((2, 1)))
    assert frozen(Profile("step", onset=1.0)) != frozen(Profile("step", onset=1.5))
    hashable_identity = object()
    assert frozen(hashable_identity) == frozen(hashable_identity) and frozen(hashable_identity) != frozen(object())


def test_memoized_is_bounded_and_keyed_by_value():
    calls = []

    @memoized(2)
    def double(values):
        calls.append(list(values))
        return [2 * v for v in values]

    assert double([1, 2]) == [2, 4] and double([1, 2]) == [2, 4] and len(calls) == 1
    double([3]), double([4])  # [1, 2] is now the oldest of three: dropped
    double([1, 2])
    assert calls == [[1, 2], [3], [4], [1, 2]]


def test_a_reloaded_scenario_shares_its_model_but_not_its_arrays_or_controller(tmp_path):
    first, second = load_scenario("docking_faults"), load_scenario("docking_faults")
    assert second.model is first.model and frozen(second.controller) == frozen(first.controller)
    assert second.eta0 is not first.eta0 and np.array_equal(second.eta0, first.eta0)
    assert second.controller.outputs is not first.controller.outputs
    second.eta0[0] = 1e3  # a caller's edit stays its own
    assert load_scenario("docking_faults").eta0[0] == -40.0  # the file's value
    edited = tmp_path / "docking_faults.toml"
    text = shipped_scenarios()["docking_faults"].read_text()
    edited.write_text(text.replace("kp = 0.2", "kp = 0.25"))
    assert load_scenario(edited).controller.speed.kp == 0.25
    edited.write_text(text)  # the file changed back: its new content is read
    assert load_scenario(edited).controller.speed.kp == 0.2


def test_a_changed_parameter_gain_fault_or_observer_builds_a_new_loop(docking):
    model, controller, dt = docking.model, docking.controller, docking.step
    observers = observer_blocks(model, docking.observers, dt)
    assert observer_blocks(model, docking.observers, dt) is observers
    loop = build_closed_loop(model, controller, dt, observers=observers)
    assert build_closed_loop(model, replace(controller), dt, observers=observers) is loop  # equal controller
    heavier = vehicle("docking_auv", L=1.1 * model.parameters.v("L"))
    faster = replace(controller, speed=replace(controller.speed, kp=0.4))
    bias = (SensorFault(0, "bias", 0.5),)
    changed = [build_closed_loop(heavier, controller, dt, observers=observers),
               build_closed_loop(model, faster, dt, observers=observers),
               build_closed_loop(model, controller, dt, observers=observers, sensor_faults=bias),
               build_closed_loop(model, controller, dt, observers=observers, substeps=2),
               build_closed_loop(model, controller, dt, observers=observers,
                                 actuator_faults=(ActuatorFault(0, "bias", 1.0),))]
    assert all(other is not loop for other in changed) and len({id(other) for other in changed}) == len(changed)
    # the new gain acts: at u = 1 m/s, 0.5 m/s below the reference, the thrust asked for differs
    z, w = np.zeros(loop.n_z), np.zeros(loop.n_w)
    z[6] = 1.0
    desired = [np.asarray(candidate.discrete(z, w)[2]).ravel()[candidate.signals["u_desired"][0]][0]
               for candidate in (loop, changed[1])]
    assert desired[0] != desired[1]

    slower = tuple(replace(spec, time_constant=0.6) if spec.kind == "bias" else spec for spec in docking.observers)
    retuned = {obs.name: obs for obs in observer_blocks(model, slower, dt)}
    # momentum-form bias observer: error rate k_i exactly, so K = 1 / time constant
    np.testing.assert_allclose(retuned["bias"].p0, np.full(6, 1 / 0.6), rtol=1e-12)
    assert observer_blocks(model, (ObserverSpec("bias", "momentum", 0.6, None),), dt)[0].p0.tolist() == \
        retuned["bias"].p0.tolist()


def test_results_with_filled_memos_equal_those_from_empty_ones(docking):
    faulty = replace(docking, actuator_faults=(ActuatorFault(0, "bias", 20.0, Profile("step", onset=0.5)),))
    warm = [simulate_scenario(docking), simulate_scenario(faulty)]
    again = [simulate_scenario(docking), simulate_scenario(faulty)]
    clear_memos()
    cold = [simulate_scenario(docking), simulate_scenario(faulty)]
    for a, b, c in zip(warm, again, cold):
        for name in a.signals:
            assert np.array_equal(a[name].values, b[name].values) and np.array_equal(a[name].values, c[name].values)
    # each run has its own faults, not a stale loop's: the scenario file's 13 N thruster bias from the start,
    # the replacement's 20 N from its onset at 0.5 s only
    t, ran = warm[1].t, warm[1]["fault_actuator"].values[:, 0]
    np.testing.assert_allclose(warm[0]["fault_actuator"].values[:, 0], 13.0, atol=1e-9)
    np.testing.assert_allclose(ran[t > 0.5 + 1e-9], 20.0, atol=1e-9)
    assert np.all(ran[t < 0.5 - 1e-9] == 0.0)
