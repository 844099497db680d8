"""Simulation: methods agree, faults act from their onset, results round-trip, scenarios are checked."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvsym.errors import FaultError, ScenarioError, SimulationError
from uvsym.faults import ActuatorFault, Profile, SensorFault
from uvsym.sim import SimResult, simulate
from uvsym.sim.scenario import load_scenario, parse_scenario, shipped_scenarios
from uvsym.sim.simulation import simulate_scenario

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python < 3.11 is not supported
    raise


@pytest.fixture(scope="module")
def docking():
    return load_scenario("docking_faults")


@pytest.fixture(scope="module")
def docking_fast(docking):
    return simulate_scenario(docking, method="fast")


def _short(scenario, duration):
    from dataclasses import replace

    return replace(scenario, duration=duration)


def test_fast_and_cvodes_agree_on_the_docking_plant_to_1e6(docking, docking_fast):
    accurate = simulate_scenario(docking, method="cvodes")
    difference = np.abs(accurate["x"].values - docking_fast["x"].values).max()
    assert difference < 1e-6, f"max |x_cvodes - x_rk4| = {difference:.3g}"


@pytest.mark.parametrize("method, tolerance", [("idas", 1e-6), ("rk", 1e-3), ("collocation", 1e-3)])
def test_every_integrator_agrees_with_the_fast_path(docking, method, tolerance):
    short = _short(docking, 5.0)
    reference = simulate_scenario(short, method="fast")["x"].values
    other = simulate_scenario(short, method=method)["x"].values
    assert np.abs(other - reference).max() < tolerance


def test_collocation_runs_the_remus100_with_its_stern_plane_fault_as_cvodes_does():
    """A second vehicle (6 DOF, coupled M, fins) diving and turning with a stern-plane bias from the start: for 3 s
    collocation with its default options stays within 1e-6 of cvodes at 1e-12 tolerances (with CasADi's own
    default, 20 elements per sample, its Newton solver fails at 1.88 s: CasADi 3.8)."""
    short = _short(load_scenario("remus100_stern_plane_bias"), 3.0)
    accurate = simulate_scenario(short, method="cvodes")["x"].values
    assert np.abs(simulate_scenario(short, method="collocation")["x"].values - accurate).max() < 1e-6


def test_an_integrator_feels_the_current_as_the_fast_path_does(docking):
    from dataclasses import replace

    drifting = replace(_short(docking, 5.0), current=(0.3, 0.5))
    integrated = simulate_scenario(drifting, method="rk")["x"].values
    assert np.abs(integrated - simulate_scenario(drifting, method="fast")["x"].values).max() < 1e-3
    still = simulate_scenario(replace(drifting, current=(0.0, 0.0)), method="rk")["x"].values
    assert np.abs(integrated - still).max() > 0.1  # 0.3 m/s for 5 s moves the vehicle


def test_interpreted_fast_path_equals_compiled(docking):
    short = _short(docking, 2.0)
    compiled = simulate_scenario(short, compiled=True)["x"].values
    interpreted = simulate_scenario(short, compiled=False)["x"].values
    assert np.abs(compiled - interpreted).max() < 1e-9


def _healthy_and_faulty(docking, **faults):
    from dataclasses import replace

    short = _short(replace(docking, actuator_faults=(), sensor_faults=(), observers=()), 3.0)
    return simulate_scenario(short), simulate_scenario(replace(short, **faults))


def test_actuator_fault_acts_exactly_from_its_onset(docking):
    onset = 1.5
    healthy, faulty = _healthy_and_faulty(
        docking, actuator_faults=(ActuatorFault(0, "bias", 10.0, Profile("step", onset=onset)),))
    t = healthy.t
    before, after = t < onset - 1e-12, t > onset + 1e-12
    # identical up to rounding (the two runs are different compiled programs) until the onset ...
    np.testing.assert_allclose(faulty["x"].values[before], healthy["x"].values[before], rtol=0, atol=1e-9)
    # ... and clearly apart from the first sample after it (10 N on ~32 kg for 10 ms: ~3 mm/s)
    assert np.all(np.abs(faulty["x"]["u"][after] - healthy["x"]["u"][after]) > 1e-4)
    at_or_after = t >= onset - 1e-12
    # the thruster delivers exactly 10 N more than a healthy one would, from the onset on
    delivered_minus_healthy = faulty["u_actual"]["X"] - faulty["u_expected"]["X"]
    np.testing.assert_array_equal(delivered_minus_healthy[~at_or_after], 0.0)
    np.testing.assert_allclose(delivered_minus_healthy[at_or_after], 10.0, rtol=0, atol=1e-12)


def test_sensor_bias_appears_exactly_at_onset(docking):
    onset = 1.0
    _, faulty = _healthy_and_faulty(docking, sensor_faults=(SensorFault(5, "bias", 0.2, Profile("step", onset=onset)),))
    t = faulty.t
    offset = faulty["y"]["psi"] - faulty["x"]["psi"]
    assert np.all(offset[t < onset - 1e-12] == 0.0)
    np.testing.assert_allclose(offset[t >= onset - 1e-12], 0.2, rtol=0, atol=1e-12)


def test_stuck_sensor_holds_the_last_healthy_sample(docking):
    onset = 1.0
    stuck = SensorFault(0, "stuck", 0.0, Profile("step", onset=onset))
    _, faulty = _healthy_and_faulty(docking, sensor_faults=(stuck,))
    t, y, x = faulty.t, faulty["y"]["x"], faulty["x"]["x"]
    last_healthy = x[np.flatnonzero(t < onset - 1e-12)[-1]]
    assert np.all(y[t >= onset - 1e-12] == last_healthy)
    assert x[-1] > last_healthy + 1.0


@pytest.mark.parametrize("profile, expected", [
    (Profile("step", onset=1.0), lambda t: (t >= 1.0) * 1.0),
    (Profile("ramp", onset=1.0, duration=2.0), lambda t: np.clip((t - 1.0) / 2.0, 0, 1)),
    (Profile("incipient", onset=1.0, rate=0.5), lambda t: (t >= 1.0) * (1 - np.exp(-0.5 * (t - 1.0)))),
    (Profile("intermittent", onset=1.0, period=1.0, duty=0.25),
     lambda t: ((t >= 1.0) & (((t - 1.0) % 1.0) < 0.25)) * 1.0),
    (Profile("step", onset=1.0, end=2.0), lambda t: ((t >= 1.0) & (t < 2.0)) * 1.0),
])
def test_fault_profiles_follow_their_formulas(profile, expected):
    t = np.linspace(0.0, 4.0, 401) + 1e-9
    phi = np.array([float(profile.phi(ti)) for ti in t])
    np.testing.assert_allclose(phi, expected(t), atol=1e-12)


@pytest.mark.parametrize("kwargs, message", [
    ({"kind": "wobble"}, "unknown fault profile"),
    ({"kind": "step", "onset": 2.0, "end": 1.0}, "must be after its onset"),
    ({"kind": "ramp", "duration": 0.0}, "duration must be positive"),
    ({"kind": "intermittent", "duty": 1.5}, "duty"),
])
def test_bad_profiles_are_refused(kwargs, message):
    with pytest.raises(FaultError, match=message):
        Profile(**kwargs)


@pytest.mark.parametrize("suffix", [".npz", ".csv", ".mat"])
def test_results_round_trip_through_every_format(docking_fast, tmp_path, suffix):
    path = docking_fast.save(tmp_path / f"run{suffix}")
    loaded = SimResult.load(path)
    np.testing.assert_array_equal(loaded.t, docking_fast.t)
    assert list(loaded.signals) == list(docking_fast.signals)
    for name, signal in docking_fast.signals.items():
        np.testing.assert_array_equal(loaded[name].values, signal.values, err_msg=name)
        assert loaded[name].labels == signal.labels and loaded[name].units == signal.units
    assert loaded.meta == docking_fast.meta


def test_unknown_result_format_is_refused(docking_fast, tmp_path):
    with pytest.raises(SimulationError, match="unknown result format"):
        docking_fast.save(tmp_path / "run.xlsx")


def test_quick_plot_writes_a_figure(docking_fast, tmp_path):
    docking_fast.plot(tmp_path / "run.svg")
    assert (tmp_path / "run.svg").read_text().startswith("<?xml")


def test_line_of_sight_brings_the_vehicle_onto_the_path(docking):
    from dataclasses import replace

    off_path = docking.eta0 + np.array([0.0, -3.0, 0.0, 0.0, 0.0, 0.0])  # 3 m to port of the path
    healthy = simulate_scenario(replace(docking, actuator_faults=(), observers=(), eta0=off_path))
    cross_track = np.abs(healthy["reference"]["cross_track"])
    assert cross_track[0] > 2.9
    settled = (healthy.t > 74.0) & (healthy.t < 75.0)  # on the final straight, before the dock
    assert cross_track[settled].max() < 0.1


def test_progress_is_reported_up_to_completion(docking):
    seen = []
    simulate_scenario(_short(docking, 5.0), method="rk", progress=seen.append)
    assert seen == sorted(seen) and seen[-1] == 1.0 and len(seen) >= 2


def _scenario_data():
    return tomllib.loads(shipped_scenarios()["docking_faults"].read_text())


@pytest.mark.parametrize("edit, field", [
    (lambda d: d.update(colour="red"), "colour"),
    (lambda d: d.update(duration=-1.0), "duration"),
    (lambda d: d.update(step=0.007), "step"),
    (lambda d: d.update(vehicle="submarine"), "vehicle"),
    (lambda d: d.update(vehicle_parameters={"mass": -1.0}), "vehicle"),
    (lambda d: d["initial"].update(eta=[0.0, 1.0]), "initial.eta"),
    (lambda d: d["initial"].update(nu="fast"), "initial.nu"),
    (lambda d: d["controller"]["speed"].pop("kp"), "controller.speed.kp"),
    (lambda d: d["controller"]["speed"].update(kq=1.0), "controller.speed.kq"),
    (lambda d: d["controller"]["outputs"].update(roll={"X": 1.0}), "controller.outputs"),
    (lambda d: d["controller"]["outputs"]["yaw"].update(delta_q=1.0), "controller.outputs.yaw"),
    (lambda d: d["controller"]["path"].update(waypoints=[[0.0, 0.0]]), "path.waypoints"),
    (lambda d: d["faults"][1].update(kind="wobble"), "faults[1]"),
    (lambda d: d["faults"][0].update(actuator="propeller"), "faults[0].actuator"),
    (lambda d: d["faults"][2].update(profile="ramp", duration=0.0), "faults[2]"),
    (lambda d: d["faults"].append({"kind": "bias", "value": 1.0}), "faults[3]"),
    (lambda d: d["faults"].append({"sensor": "depth", "kind": "bias"}), "faults[3].sensor"),
    (lambda d: d["observers"][0].pop("tau_d"), "observers[0].tau_d"),
    (lambda d: d["observers"][1].update(kind="sliding"), "observers[1].kind"),
    (lambda d: d["current"].update(speed=math.nan), "current.speed"),
    (lambda d: d["current"].update(time_constant=0.0), "current.time_constant"),
])
def test_bad_scenario_names_the_field(edit, field):
    data = _scenario_data()
    edit(data)
    with pytest.raises(ScenarioError, match=field.replace("[", r"\[").replace("]", r"\]").replace(".", r"\.")):
        parse_scenario(data)


def test_bad_toml_file_is_reported_with_its_path(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("duration = = 3")
    with pytest.raises(ScenarioError, match="bad.toml"):
        load_scenario(bad)


def test_every_shipped_scenario_runs():
    for name in shipped_scenarios():
        result = simulate_scenario(_short(load_scenario(name), 2.0))
        assert np.all(np.isfinite(result["x"].values)), name


def test_bad_simulation_arguments_are_refused(docking):
    with pytest.raises(SimulationError, match="unknown method"):
        simulate_scenario(_short(docking, 1.0), method="euler")
    with pytest.raises(SimulationError, match="does not divide"):
        simulate(docking.model, docking.controller, duration=1.0, dt=0.3, eta0=docking.eta0, nu0=docking.nu0)
    with pytest.raises(SimulationError, match="eta0"):
        simulate(docking.model, docking.controller, duration=1.0, dt=0.1, eta0=[0.0], nu0=docking.nu0)


def test_the_compiled_fast_path_leaves_the_floating_point_state_alone(docking):
    import sys

    simulate_scenario(_short(docking, 0.5), compiled=True)
    tiny = sys.float_info.min / 4  # subnormal: flushed to zero if a library switched on FTZ/DAZ
    assert tiny > 0.0 and tiny * 2 > tiny


def test_fault_signals_show_what_each_fault_does(docking):
    _, faulty = _healthy_and_faulty(docking, actuator_faults=docking.actuator_faults,
                                    sensor_faults=(SensorFault(2, "bias", 0.5, Profile("step", onset=1.0)),))
    np.testing.assert_allclose(faulty["fault_actuator"]["X"], 13.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(faulty["fault_actuator"]["delta_ru"], -0.2 * faulty["u_expected"]["delta_ru"],
                               rtol=1e-12, atol=1e-15)
    t = faulty.t
    np.testing.assert_array_equal(faulty["fault_sensor"]["z"][t < 1.0 - 1e-12], 0.0)
    np.testing.assert_allclose(faulty["fault_sensor"]["z"][t >= 1.0 - 1e-12], 0.5, atol=1e-12)


def test_observer_estimates_carry_the_unit_of_their_fault_kind(docking):
    from uvsym.sim.simulation import observer_blocks

    units = {obs.name: obs.publishes.units for obs in observer_blocks(docking.model, docking.observers, docking.step)}
    assert units == {"proportional": ("-",) * 6, "bias": ("N", "N", "N", "N m", "N m", "N m")}


def test_current_variation_is_seeded_and_has_the_requested_spread(docking):
    from dataclasses import replace

    from uvsym.sim.simulation import current_profile

    varied = replace(docking, current=(0.5, 0.3), current_variation=(0.1, 5.0), duration=2000.0, step=0.1)
    profile = current_profile(varied)
    np.testing.assert_array_equal(profile, current_profile(varied))  # same seed, same draws
    assert not np.array_equal(profile, current_profile(replace(varied, seed=varied.seed + 5)))
    assert profile.shape == (20001, 2) and np.all(profile[:, 1] == 0.3)
    assert abs(np.std(profile[:, 0]) - 0.1) < 0.02 and abs(np.mean(profile[:, 0]) - 0.5) < 0.03
    assert current_profile(docking) == docking.current  # no variation: a constant pair
