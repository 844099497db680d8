"""Edges of wired loops found in review: sample timing at fault onsets, latches, initial states,
sample periods of designed blocks, reserved names and the hints of wiring errors."""

import math
import re
import time

import numpy as np
import pytest
from problems import DT, double_integrator, first_order, integrator

from uvsym.errors import FaultError, SimulationError, WiringError
from uvsym.faults import ActuatorFault, Profile, SensorFault
from uvsym.sim import Substitution, block, interconnect, lqr, open_loop, pid, simulate_system, state_feedback


def test_a_fault_starts_at_the_sample_that_rounds_just_below_its_onset():
    dt, onset = 0.03, 0.45  # 15 * 0.03 = 0.44999999999999996 in doubles
    assert 15 * dt < onset
    hold = open_loop("hold", [0.0], [0.0], publishes=["u"])
    result = simulate_system(integrator(), [hold], duration=0.6, dt=dt, x0=[0.0],
                             actuator_faults=(ActuatorFault(0, "bias", 10.0, Profile("step", onset=onset)),),
                             sensor_faults=(SensorFault(0, "bias", 1.0, Profile("step", onset=onset)),))
    assert result["fault_actuator"].values[14, 0] == 0.0 and result["fault_actuator"].values[15, 0] == 10.0
    assert result["fault_sensor"].values[14, 0] == 0.0 and result["fault_sensor"].values[15, 0] == 1.0


def test_a_stuck_sensor_latches_the_last_sample_before_onset_whatever_its_profile():
    drive = open_loop("drive", [0.0], [1.0], publishes=["u"])  # q = t
    for profile in (Profile("step", onset=0.3), Profile("ramp", onset=0.3, duration=0.5)):
        result = simulate_system(integrator(), [drive], duration=0.6, dt=0.1, x0=[0.0],
                                 sensor_faults=(SensorFault(0, "stuck", profile=profile),))
        measured = result["y"]["q"]
        assert abs(measured[-1] - 0.2) < 1e-12 or profile.kind == "ramp", profile.kind  # held at q(0.2)
        if profile.kind == "ramp":  # y = q + phi (held - q), held = q(0.2)
            phi = min((0.6 - 0.3) / 0.5, 1.0)
            assert abs(measured[-1] - (0.6 + phi * (0.2 - 0.6))) < 1e-9


def test_a_pid_on_a_sensor_stuck_from_the_start_does_not_kick():
    controller = pid("c", measured="m", kp=0.0, ki=0.0, kd=0.5, output="F", dt=DT)
    result = simulate_system(first_order(), [controller], duration=0.1, dt=DT, x0=[0.3],
                             sensor_faults=(SensorFault(0, "stuck"),))
    assert np.allclose(result["c"]["F"], 0.0)  # y = 0.3 throughout: no derivative


def test_blocks_designed_for_a_sample_period_refuse_another():
    plant = double_integrator()
    with pytest.raises(WiringError, match="0.01"):
        interconnect(plant, [lqr(plant, np.eye(2), [[1.0]], dt=0.01)], dt=0.5)
    with pytest.raises(WiringError, match="reserved"):
        interconnect(plant, [state_feedback("z", [[1.0, 1.0]], reads=["pos", "vel"], publishes=["acc"])], dt=DT)


def test_wiring_errors_and_bad_faults_are_typed_and_hint():
    plant = integrator()
    pre = block("pre", step=lambda s, r: (s, 2 * r), reads="q", publishes="a")
    est = block("est", step=lambda s, r: (s, r), reads="a", publishes="q_hat")
    ctrl = state_feedback("ctrl", [[1.0]], reads=["q"], publishes=["u"])
    with pytest.raises(WiringError, match=r"substitution of q: a block that must see the sensor reads 'q.raw'"):
        interconnect(plant, [pre, est, ctrl], dt=DT, substitutions={"q": "q_hat"})
    with pytest.raises(WiringError, match="a substitution joins two published signals"):
        interconnect(plant, [ctrl], dt=DT, substitutions={"q": "q.raw"})
    with pytest.raises(FaultError, match="integer index"):
        SensorFault("q", "bias", 1.0)
    with pytest.raises(FaultError, match="onset must be a number"):
        Profile("step", onset="1")

    class Broken:
        period = math.nan

        def update(self, t, signals):
            return None

    with pytest.raises(SimulationError, match="positive, finite period"):
        simulate_system(plant, [ctrl], duration=1.0, dt=DT, x0=[0.0], supervisor=Broken())


def test_a_discrete_plant_steps_its_own_map_in_the_loop():
    """The ZOH double integrator under u = -K x follows (Ad - Bd K)^k x0 exactly."""
    plant = double_integrator().discretize(0.1, "zoh")
    K = np.array([[2.0, 1.5]])
    feedback = state_feedback("sf", K, reads=["pos", "vel"], publishes=["acc"])
    result = simulate_system(plant, [feedback], duration=2.0, dt=0.1, x0=[1.0, 0.0])
    Ad, Bd = np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.005], [0.1]])
    expected = [np.linalg.matrix_power(Ad - Bd @ K, k) @ [1.0, 0.0] for k in range(21)]
    np.testing.assert_allclose(np.column_stack([result["x"]["pos"], result["x"]["vel"]]), expected, atol=1e-12)
    with pytest.raises(SimulationError, match="nothing to integrate"):
        simulate_system(plant, [feedback], duration=1.0, dt=0.1, x0=[1.0, 0.0], method="cvodes")
    with pytest.raises(WiringError, match="sampled every 0.1 s, the loop every 0.05 s"):
        interconnect(plant, [feedback], dt=0.05)


def test_a_diverging_loop_names_the_first_non_finite_signal_and_the_time():
    unstable = pid("c", measured="m", reference=1.0, kp=-50.0, output="F", dt=DT)
    with pytest.raises(SimulationError) as caught:
        simulate_system(first_order(), [unstable], duration=200.0, dt=DT, x0=[0.0])
    message = str(caught.value)
    assert re.search(r"diverged: \w+\.\w+ \((nan|-?inf)\) is non-finite from t = \d", message), message
    assert "unstable loop" in message


def test_available_memory_reads_memavailable_in_kib(monkeypatch):
    import io

    from uvsym.sim import run

    def fake_open(path, *args, **kwargs):
        if path != "/proc/meminfo":
            raise FileNotFoundError(path)
        return io.StringIO("MemTotal:       16384 kB\nMemFree:     1024 kB\nMemAvailable:    2048 kB\n")

    monkeypatch.setattr(run, "open", fake_open, raising=False)
    assert run.available_memory() == 2048 * 1024


def test_too_much_memory_or_too_many_samples_is_refused_with_both_figures(monkeypatch):
    from uvsym.sim import run

    monkeypatch.setattr(run, "available_memory", lambda: 1000)
    with pytest.raises(SimulationError, match=r"^the log needs at least 1.95 KiB of memory, 1000 B are available; "
                                              r"shorten the run or lengthen the step$"):
        run.check_memory(2000, "the log")
    run.check_memory(1000, "the log")  # exactly what is available: taken
    with pytest.raises(SimulationError, match=r"^duration 1e\+13 s at step 1 s is 1e\+13 samples, more than 1e\+12 "
                                              r"\(no machine holds them\); shorten the run or lengthen the step$"):
        run.grid(1e13, 1.0)


def test_memory_figures_are_read_in_binary_units_up_to_exbibytes(monkeypatch):
    """5 TiB = 5 * 2**40 B asked of 3 GiB; 2048 EiB = 2**71 B is past the last unit and stays in EiB."""
    from uvsym.sim import run

    monkeypatch.setattr(run, "available_memory", lambda: 3 * 2**30)
    with pytest.raises(SimulationError, match=r"^the log needs at least 5 TiB of memory, 3 GiB are available"):
        run.check_memory(5 * 2**40, "the log")
    with pytest.raises(SimulationError, match=r"^the log needs at least 2\.05e\+03 EiB of memory"):
        run.check_memory(2**71, "the log")


def _blow_up():
    """q' = q^2 + u: from q(0) = 1 with u = 0, q = 1 / (1 - t) escapes to infinity at t = 1 s."""
    from uvsym.systems import signals, system

    return system("blow_up", "q' = q^2", x=signals(("q", "m"), group="state"),
                  u=signals(("u", "m/s"), group="input"), rhs=lambda x, u, d, p: x**2 + u)


def test_an_integrator_failure_names_the_sample_it_failed_in_and_the_solvers_reason():
    hold = open_loop("hold", [0.0], [0.0], publishes=["u"])
    # the escape at t = 1 s lies in the sample from 0.9 s on; CVODES gives up there (too much work)
    with pytest.raises(SimulationError, match=r'^cvodes failed at t = 0\.9 s: .*CVode returned "CV_TOO_MUCH_WORK"'):
        simulate_system(_blow_up(), [hold], duration=2.0, dt=0.1, x0=[1.0], method="cvodes")
    with pytest.raises(SimulationError, match=r"^cannot build the cvodes integrator with options \{.*'bogus': 1\}: "
                                              r"Use print_options\(\) to get a full list of options\.$"):
        simulate_system(integrator(), [hold], duration=0.1, dt=0.1, x0=[0.0], method="cvodes", options={"bogus": 1})


def test_casadis_diagnostics_name_the_integrator_plant(capfd):
    hold = open_loop("hold", [0.0], [0.0], publishes=["u"])
    with pytest.raises(SimulationError, match="diverged"):
        simulate_system(_blow_up(), [hold], duration=1.5, dt=0.1, x0=[1.0], method="rk")
    assert "plant:step failed" in capfd.readouterr().err


def test_the_build_time_is_part_of_the_calls_wall_time():
    hold = open_loop("hold", [0.0], [0.0], publishes=["u"])
    started = time.perf_counter()
    result = simulate_system(integrator(), [hold], duration=0.1, dt=0.1, x0=[0.0], method="rk")
    assert 0.0 <= result.meta["build_s"] <= time.perf_counter() - started


def test_a_wired_loop_refuses_a_correction_and_says_it_expects_a_substitution():
    from uvsym.observers.ftc import Correction

    class Corrects:
        period = 0.1  # s

        def update(self, t, signals):
            return Correction(np.eye(1), np.zeros(1))

    ctrl = state_feedback("ctrl", [[1.0]], reads=["q"], publishes=["u"])
    with pytest.raises(SimulationError, match=r"^supervisor returned Correction, which this loop cannot apply; "
                                              r"expected Substitution or None$"):
        simulate_system(integrator(), [ctrl], duration=0.3, dt=0.1, x0=[0.0], supervisor=Corrects())


def test_a_supervisor_switching_on_a_channel_the_loop_lacks_is_refused_with_the_loops_channels():
    class Unknown:
        period = 0.1  # s

        def update(self, t, signals):
            return Substitution({"psi"})

    est = block("est", step=lambda s, r: (s, r), reads="q.raw", publishes="q_hat")
    ctrl = state_feedback("ctrl", [[1.0]], reads=["q"], publishes=["u"])
    with pytest.raises(SimulationError, match=r"^supervisor switched on substitution channels \['psi'\] the loop does "
                                              r"not have; channels: q$"):
        simulate_system(integrator(), [est, ctrl], duration=0.3, dt=0.1, x0=[0.0], substitutions={"q": "q_hat"},
                        supervisor=Unknown())


def test_check_chunk_guards_the_finite_rows_by_their_times_and_names_the_first_non_finite_row():
    """Rows 0-1 finite, row 2 NaN in x.b, row 3 inf in x.a: the guard sees rows 0-1 with their times (column 0 of
    W), the error names x.b at sample start + 2 = 8, i.e. t = 8 * 0.5 s = 4 s."""
    from types import SimpleNamespace

    from uvsym.sim.run import check_chunk

    loop = SimpleNamespace(dt=0.5, signals={"x": (slice(0, 2), ("a", "b"), ("m", "m"))})
    W_rows = np.array([[3.0, 9.0], [3.5, 9.0], [4.0, 9.0], [4.5, 9.0]])
    rows = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, np.nan], [np.inf, 3.0]])
    seen = []
    with pytest.raises(SimulationError, match=r"^the loop diverged: x\.b \(nan\) is non-finite from t = 4 s \(rk\)"):
        check_chunk(loop, "rk", 6, W_rows, rows, np.zeros(1), guard=lambda t, out: seen.append((t.copy(), out)))
    np.testing.assert_array_equal(seen[0][0], [3.0, 3.5])
    np.testing.assert_array_equal(seen[0][1], rows[:2])
    with pytest.raises(SimulationError, match=r"x\.a \(inf\) is non-finite from t = 3\.5 s"):  # a single bad row
        check_chunk(loop, "rk", 6, W_rows[:2], np.array([[0.0, 0.0], [np.inf, 0.0]]), np.zeros(1))


@pytest.mark.parametrize("duration, dt", [(0.0, 0.1), (1.0, 0.0)])
def test_a_zero_duration_or_step_is_refused_by_name(duration, dt):
    from uvsym.sim import run

    with pytest.raises(SimulationError, match=rf"^duration and step must be positive and finite, got {duration} s "
                                              rf"and {dt} s$"):
        run.grid(duration, dt)


def test_each_integrator_is_built_with_its_documented_defaults_under_the_runs_own_options():
    """cvodes and idas at tolerances 1e-12, collocation with one element per sample, rk with CasADi's own: the
    message of a refused option shows the options the integrator was built with; a run's option replaces a default."""
    hold = open_loop("hold", [0.0], [0.0], publishes=["u"])
    expected = {"cvodes": "{'abstol': 1e-12, 'reltol': 1e-12, 'bogus': 1}",
                "idas": "{'abstol': 1e-12, 'reltol': 1e-12, 'bogus': 1}",
                "collocation": "{'number_of_finite_elements': 1, 'bogus': 1}", "rk": "{'bogus': 1}"}
    for method, shown in expected.items():
        with pytest.raises(SimulationError) as error:
            simulate_system(integrator(), [hold], duration=0.1, dt=0.1, x0=[0.0], method=method, options={"bogus": 1})
        assert str(error.value).startswith(f"cannot build the {method} integrator with options {shown}: "), method
    with pytest.raises(SimulationError) as error:
        simulate_system(integrator(), [hold], duration=0.1, dt=0.1, x0=[0.0], method="collocation",
                        options={"number_of_finite_elements": 3, "bogus": 1})
    assert "with options {'number_of_finite_elements': 3, 'bogus': 1}: " in str(error.value)


def test_integrator_options_are_checked_where_a_user_gives_them():
    """A NaN tolerance would hang SUNDIALS; a string or options for the fast method would be a raw TypeError or
    silently ignored: each is refused by name before the run, by simulate_system and by simulate."""
    from dataclasses import replace

    from uvsym.sim.scenario import load_scenario
    from uvsym.sim.simulation import simulate_scenario

    hold = open_loop("hold", [0.0], [0.0], publishes=["u"])
    refused = [("idas", {"abstol": float("nan")}, r"^options\['abstol'\] is nan; an integrator option must be finite$"),
               ("collocation", {"rootfinder_options": {"abstol": float("inf")}},
                r"^options\['rootfinder_options'\]\['abstol'\] is inf; an integrator option must be finite$"),
               ("cvodes", "abstol=1e-6",
                r"^options must be a dict of CasADi integrator options, got str 'abstol=1e-6'$"),
               ("rk", {1: 2}, r"^options: option names are text, got 1$"),
               ("fast", {"number_of_finite_elements": 3},
                r"^options \['number_of_finite_elements'\] go to a CasADi integrator .*the fast method takes none")]
    docking = replace(load_scenario("docking_faults"), duration=0.1)
    for method, options, message in refused:
        with pytest.raises(SimulationError, match=message):
            simulate_system(integrator(), [hold], duration=0.1, dt=0.1, x0=[0.0], method=method, options=options)
        with pytest.raises(SimulationError, match=message):
            simulate_scenario(docking, method=method, options=options)
    result = simulate_system(integrator(), [hold], duration=0.1, dt=0.1, x0=[0.0], method="fast", options={})
    assert result.t[-1] == pytest.approx(0.1)  # empty options are no options
