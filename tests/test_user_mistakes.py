"""Mistakes a new user made in a trial, each answered by a typed error naming the problem (or, for
a scenario without a fault, by a run without one)."""

from __future__ import annotations

import tomllib

import pytest

import uvsym
from uvsym.errors import ArgumentError, FaultError, ObserverError, ScenarioError, SimulationError
from uvsym.faults import Profile, SensorFault
from uvsym.sim import open_loop, simulate_system
from uvsym.sim.scenario import parse_scenario, shipped_scenarios
from uvsym.sim.simulation import simulate_scenario


def _docking() -> dict:
    return tomllib.loads(shipped_scenarios()["docking_faults"].read_text())


def test_misspelt_fields_are_pointed_at():
    data = _docking()
    data["durration"] = data.pop("duration")
    with pytest.raises(ScenarioError, match=r"duration: required number is missing \(is 'durration' a misspelt"):
        parse_scenario(data)
    with pytest.raises(ScenarioError, match=r"vehicle: missing; .* is 'plnat' a misspelt 'plant'\?"):
        parse_scenario({"plnat": "rov_yaw"})
    data = _docking()
    data["controller"]["path"]["lookahed"] = 5.0
    with pytest.raises(ScenarioError, match=r"path\.lookahed: unknown field \(did you mean 'lookahead'\?\)"):
        parse_scenario(data)


def test_a_loop_that_is_non_finite_at_its_first_sample_is_a_typed_error_naming_the_signal():
    data = _docking()
    data["duration"] = 1.0
    data["controller"]["outputs"]["speed"] = {"delta_e": 1.0}  # speed drives the elevator: -inf at once
    with pytest.raises(SimulationError, match=r"diverged: .* is non-finite from t = 0 s"):
        simulate_scenario(parse_scenario(data), method="fast")


def test_a_one_entry_list_for_a_vector_argument_is_refused_but_a_scalar_broadcasts():
    rov = uvsym.plant("rov_yaw")
    with pytest.raises(ArgumentError, match=r"rov_yaw\.f: argument x has 1 entries .* expected 2"):
        rov.f([0.1], [0.2], [0.0], [])
    assert float(rov.f(0.1, [0.2], [0.0], [])[0]) == pytest.approx(0.1)  # x = (0.1, 0.1): psi' = r = 0.1


def test_fault_onsets_before_zero_or_after_the_run_and_negative_observer_gains_are_refused():
    with pytest.raises(FaultError, match="onset must be a finite time >= 0 s"):
        Profile("step", onset=-1.0)
    motor = uvsym.plant("induction_motor")
    supply = open_loop("supply", [0.0], [motor.u_op], publishes=motor.u.names)
    late = SensorFault(motor.y.index("omega_m"), "bias", 2.0, Profile("step", onset=5.0))
    with pytest.raises(SimulationError, match=r"sensor_faults\[0\]: onset 5 s is not before the end of the run"):
        simulate_system(motor, [supply], duration=0.01, dt=1e-4, x0=motor.x_op, sensor_faults=(late,))
    from uvsym.observers.discrete import actuator_fault_observer

    with pytest.raises(ObserverError, match="gains K must be 3 positive finite numbers"):
        actuator_fault_observer(uvsym.vehicle("otter3dof"), "bias", 0.01, [-1.0, 1.0, 1.0])
