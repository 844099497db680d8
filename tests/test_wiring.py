"""Loops of any System wired by signal name: closed-form responses, blocks, faults, substitution, errors."""

from __future__ import annotations

import math
from dataclasses import replace

import casadi as ca
import numpy as np
import pytest
from problems import DT, double_integrator, first_order, integrator

from uvsym.errors import WiringError
from uvsym.faults import ActuatorFault, Profile, SensorFault
from uvsym.observers.base import observer
from uvsym.sim import (
    Substitution,
    block,
    interconnect,
    observer_block,
    open_loop,
    pid,
    renamed,
    simulate_system,
    state_feedback,
)
from uvsym.systems import signals, system


def test_state_feedback_on_a_double_integrator_follows_the_exact_sampled_solution():
    K = np.array([[4.0, 3.0]])
    x0 = np.array([1.0, -0.5])
    result = simulate_system(double_integrator(), [state_feedback("sf", K, reads=["pos", "vel"], publishes=["acc"])],
                             duration=2.0, dt=DT, x0=x0)
    # zero-order hold of pos'' = acc over DT: Ad = expm([[0, 1], [0, 0]] DT), Bd = int_0^DT expm(A s) ds B
    Ad, Bd = np.array([[1.0, DT], [0.0, 1.0]]), np.array([[DT * DT / 2], [DT]])
    expected = [x0]
    for _ in range(len(result.t) - 1):
        expected.append((Ad - Bd @ K) @ expected[-1])
    np.testing.assert_allclose(result["x"].values, np.array(expected), rtol=0, atol=1e-12)
    np.testing.assert_allclose(result["sf"]["acc"], -np.array(expected) @ K[0], rtol=0, atol=1e-12)
    assert result["sf"].units == ("m/s^2",)  # taken from the plant input it drives


def test_first_order_plant_under_feedback_matches_the_exponential_and_cvodes_agrees():
    a, b, k = 0.5, 2.0, 0.8
    result = simulate_system(first_order(a, b), [state_feedback("p", [[k]], reads=["m"], publishes=["F"])],
                             duration=3.0, dt=DT, x0=[1.0], method="cvodes")
    phi = math.exp(-a * DT)
    per_sample = phi - (1 - phi) * b * k / a  # v_{k+1} = phi v_k + (1 - phi) b / a F_k, F_k = -k v_k
    expected = per_sample ** np.arange(len(result.t))
    np.testing.assert_allclose(result["x"]["v"], expected, rtol=0, atol=1e-9)



def luenberger(L, dt=DT):
    """x_hat+ = Ad x_hat + Bd acc + L (pos - x_hat[0]); publishes x_hat (no feed-through)."""
    Ad, Bd, L = ca.DM([[1.0, dt], [0.0, 1.0]]), ca.DM([dt * dt / 2, dt]), ca.DM(L)
    return observer("luen", step=lambda s, y, u, p: (ca.mtimes(Ad, s) + Bd * u[0] + L * (y[0] - s[0]), s),
                    state=signals(("pos_hat", "m"), ("vel_hat", "m/s"), group="state"),
                    reads_y=signals(("pos", "m")), reads_u=signals(("acc", "m/s^2")),
                    publishes=signals(("pos_hat", "m"), ("vel_hat", "m/s")), dt=dt)


def test_luenberger_observer_feeding_its_own_input_converges_as_its_error_dynamics_say():
    L = np.array([0.5, 5.0])
    obs = observer_block(luenberger(L), s0=[0.0, 0.0])
    ctrl = state_feedback("ctrl", [[4.0, 3.0]], reads=["pos_hat", "vel_hat"], publishes=["acc"])
    result = simulate_system(double_integrator(("pos",)), [obs, ctrl], duration=4.0, dt=DT, x0=[1.0, 0.5])
    assert result.meta["order"].index("pos_hat") < result.meta["order"].index("acc")  # no false algebraic loop
    error = result["x"].values - result["luen"].values
    A_e = np.array([[1.0, DT], [0.0, 1.0]]) - np.outer(L, [1.0, 0.0])  # e+ = (Ad - L C) e
    expected = [np.array([1.0, 0.5])]
    for _ in range(len(result.t) - 1):
        expected.append(A_e @ expected[-1])
    np.testing.assert_allclose(error, np.array(expected), rtol=0, atol=1e-10)
    assert np.abs(error[-1]).max() < 1e-6


def test_observer_block_starts_from_its_init_of_the_first_sample():
    obs = replace(luenberger([0.5, 5.0]), init=lambda y0, u0, p: np.array([y0[0], 0.0]))
    ctrl = state_feedback("ctrl", [[4.0, 3.0]], reads=["pos_hat", "vel_hat"], publishes=["acc"])
    result = simulate_system(double_integrator(("pos",)), [observer_block(obs), ctrl], duration=0.1, dt=DT,
                             x0=[1.0, 0.5])
    assert result["luen"]["pos_hat"][0] == 1.0


# -- measurement substitution ------------------------------------------------------------------------------------


class SwitchAt:
    """Switches substitution channel psi on at the first check whose samples reach t_on."""

    period = 0.25

    def __init__(self, t_on):
        self.t_on, self.seen = t_on, []

    def update(self, t, signals):
        self.seen.append(sorted(signals))
        return Substitution({"psi"}) if t[-1] >= self.t_on - 1e-9 else None


def test_substitution_switched_on_by_a_supervisor_changes_what_the_controller_reads_from_that_sample():
    plant = system("heading", "psi' = r", x=signals(("psi", "rad"), group="state"),
                   u=signals(("r", "rad/s"), group="input"), rhs=lambda x, u, d, p: u)
    estimator = state_feedback("est", [[-1.0]], reads=["psi"], u_ref=[1.0], publishes=["psi_hat"])  # psi + 1
    ctrl = state_feedback("ctrl", [[1.0]], reads=["psi"], x_ref=[0.5], publishes=["r"])  # r = -(psi - 0.5)
    raw = renamed(state_feedback("watch", [[-1.0]], reads=["psi"], publishes=["seen"]), reads={"psi": "psi.raw"})
    supervisor = SwitchAt(0.5)
    result = simulate_system(plant, [estimator, ctrl, raw], duration=1.5, dt=DT, x0=[0.0],
                             substitutions={"psi": "psi_hat"}, supervisor=supervisor)
    # checks at the ends of [0, 0.25), [0.25, 0.5), [0.5, 0.75): the third one switches; on from t = 0.75
    on = result.t >= 0.75 - 1e-9
    psi = result["y"]["psi"]
    np.testing.assert_array_equal(result["substitution"]["psi"], on.astype(float))
    np.testing.assert_allclose(result["ctrl"]["r"][~on], -(psi[~on] - 0.5), rtol=0, atol=1e-15)
    np.testing.assert_allclose(result["ctrl"]["r"][on], -(psi[on] + 1.0 - 0.5), rtol=0, atol=1e-15)
    np.testing.assert_allclose(result["est"]["psi_hat"], psi + 1.0, rtol=0, atol=1e-15)  # its sensor, always
    np.testing.assert_allclose(result["watch"]["seen"], psi, rtol=0, atol=1e-15)  # psi.raw: never substituted
    assert {"x", "y", "u", "ctrl", "est", "substitution"} <= set(supervisor.seen[0])
    assert result["est"].units == ("rad",)  # psi_hat: the unit of the channel it replaces


class SubstituteOnResidual:
    """Switches psi to its estimate once the gyro observer's residual exceeds 0.05 rad."""

    period = 0.1

    def update(self, t, signals):
        return Substitution({"psi"}) if abs(signals["gyro"][-1, 1]) > 0.05 else None


def test_a_stuck_heading_sensor_replaced_by_a_gyro_estimate_keeps_the_heading_loop_working():
    boat = system("boat", "psi' = r, r' = u - r", x=signals(("psi", "rad"), ("r", "rad/s"), group="state"),
                  u=signals(("u", "rad/s^2"), group="input"), rhs=lambda x, u, d, p: ca.vertcat(x[1], u[0] - x[1]))
    gyro = observer("gyro", step=lambda s, y, u, p: (s + DT * y[1], ca.vertcat(s, y[0] - s)),
                    state=signals(("psi_hat", "rad")), reads_y=signals(("psi", "rad"), ("r", "rad/s")),
                    reads_u=signals(), publishes=signals(("psi_hat", "rad"), ("residual", "rad")), dt=DT,
                    init=lambda y0, u0, p: y0[:1])
    blocks = [open_loop("reference", [0.0, 4.0], [0.0, 0.8], publishes=["psi_ref"]),
              pid("heading", measured=boat.y.select(["psi"]), reference="psi_ref", kp=2.0, ki=0.2, kd=0.5,
                  output="u", limits=(-1.0, 1.0), dt=DT),
              observer_block(gyro)]  # publishes psi_hat: keeps reading the sensor's psi
    stuck = (SensorFault(0, "stuck", profile=Profile("step", onset=3.0)),)
    kept = simulate_system(boat, blocks, duration=20.0, dt=DT, x0=[0.0, 0.0], sensor_faults=stuck,
                           substitutions={"psi": "psi_hat"}, supervisor=SubstituteOnResidual())
    lost = simulate_system(boat, blocks, duration=20.0, dt=DT, x0=[0.0, 0.0], sensor_faults=stuck)
    switched = kept.t[np.argmax(kept["substitution"]["psi"])]
    assert 4.0 < switched < 5.0  # once the heading moves away from the stuck reading
    assert np.all(kept["y"]["psi"][kept.t >= 3.0] == kept["y"]["psi"][300])  # the sensor stays stuck
    assert abs(kept["x"]["psi"][-1] - 0.8) < 0.02
    assert abs(lost["x"]["psi"][-1] - 0.8) > 1.0
    assert kept["reference"].units == ("rad",)


# -- faults ----------------------------------------------------------------------------------------------------


def test_sensor_fault_shows_in_the_measurement_and_not_in_the_state():
    plant = first_order(gain=2.0)
    table = open_loop("table", [0.0], [0.3], publishes=["F"])
    healthy = simulate_system(plant, [table], duration=2.0, dt=DT, x0=[0.1])
    faulty = simulate_system(plant, [table], duration=2.0, dt=DT, x0=[0.1],
                             sensor_faults=(SensorFault(0, "bias", 0.7, Profile("step", onset=1.0)),))
    after = faulty.t >= 1.0 - 1e-9
    np.testing.assert_allclose(faulty["x"].values, healthy["x"].values, rtol=0, atol=1e-15)
    np.testing.assert_allclose(faulty["y"]["m"], 2.0 * faulty["x"]["v"] + 0.7 * after, rtol=0, atol=1e-14)
    np.testing.assert_allclose(faulty["fault_sensor"]["m"], 0.7 * after, rtol=0, atol=1e-14)


def test_actuator_fault_acts_on_the_plant_input_from_its_onset():
    table = open_loop("table", [0.0], [1.0], publishes=["u"])
    result = simulate_system(integrator(), [table], duration=2.0, dt=DT, x0=[0.0], method="cvodes",
                             actuator_faults=(ActuatorFault(0, "bias", 0.5, Profile("step", onset=1.0)),))
    after = result.t >= 1.0 - 1e-9
    np.testing.assert_array_equal(result["u"]["u"], 1.0 + 0.5 * after)
    np.testing.assert_array_equal(result["fault_actuator"]["u"], 0.5 * after)
    np.testing.assert_array_equal(result["table"]["u"], 1.0)  # the command is not changed
    np.testing.assert_allclose(result["x"]["q"], result.t + 0.5 * np.maximum(result.t - 1.0, 0.0), atol=1e-8)


def test_disturbance_table_reaches_the_plant():
    N = 100
    d = np.where(np.arange(N + 1) < 50, 0.0, 0.25)[:, None]
    table = open_loop("table", [0.0], [0.0], publishes=["F"])
    result = simulate_system(first_order(a=0.0, b=2.0), [table], duration=1.0, dt=DT, x0=[0.0], d=d)
    np.testing.assert_allclose(result["x"]["v"][-1], 2.0 * 0.25 * 0.5, rtol=1e-12)


# -- wiring errors ---------------------------------------------------------------------------------------------


def _feedback(reads, publishes, name="ctrl"):
    return state_feedback(name, [[1.0]], reads=[reads], publishes=[publishes])


def test_a_read_nobody_publishes_names_the_block_the_signal_and_the_published_ones():
    with pytest.raises(WiringError, match=r"block ctrl reads 'speed', which nothing publishes; published: F, m, t"):
        interconnect(first_order(), [_feedback("speed", "F")], dt=DT)


def test_a_plant_input_two_blocks_publish_is_refused():
    with pytest.raises(WiringError, match=r"plant first_order input 'F' is driven by blocks a and b; rename"):
        interconnect(first_order(), [_feedback("m", "F", "a"), _feedback("m", "F", "b")], dt=DT)


def test_a_plant_input_nobody_drives_is_refused():
    with pytest.raises(WiringError, match=r"plant first_order input 'F' is driven by no block"):
        interconnect(first_order(), [_feedback("m", "G")], dt=DT)


def test_an_algebraic_loop_is_named():
    chain = [_feedback("q", "s1", "a"), _feedback("s1", "u", "b"), _feedback("u", "s2", "c")]
    interconnect(integrator(), chain, dt=DT)  # starts at the plant's output q, which needs no input: no loop
    loop = [_feedback("s2", "s1", "a")] + chain[1:]
    with pytest.raises(WiringError, match="algebraic loop: ") as caught:
        interconnect(integrator(), loop, dt=DT)
    for part in ("s1 (block a)", "u (block b)", "s2 (block c)"):
        assert part in str(caught.value)


def test_feed_through_of_the_plant_closes_an_algebraic_loop_with_a_static_controller():
    plant = system("direct", "y = q + u", x=signals(("q", "m"), group="state"), u=signals(("u", "m/s")),
                   rhs=lambda x, u, d, p: u, y=signals(("y", "m")), output=lambda x, u, p: x + u)
    with pytest.raises(WiringError, match="algebraic loop: ") as caught:
        interconnect(plant, [_feedback("y", "u")], dt=DT)
    assert "y (plant direct)" in str(caught.value) and "u (block ctrl)" in str(caught.value)


def test_other_wiring_errors_name_what_is_wrong():
    plant = first_order()
    with pytest.raises(WiringError, match=r"substitution 'm' -> 'm_hat'.*'m_hat', which nothing publishes"):
        interconnect(plant, [_feedback("m", "F")], dt=DT, substitutions={"m": "m_hat"})
    with pytest.raises(WiringError, match=r"block ctrl reads 'm' in 'rad' but plant first_order publishes it in 'm/s'"):
        interconnect(plant, [state_feedback("ctrl", [[1.0]], reads=signals(("m", "rad")), publishes=["F"])], dt=DT)
    with pytest.raises(WiringError, match=r"block speed was designed for dt = 0.1 s"):
        interconnect(plant, [pid("speed", "m", 1.0, kp=1.0, output="F", dt=0.1)], dt=DT)
    with pytest.raises(WiringError, match=r"block name 'y' is used twice or reserved"):
        interconnect(plant, [_feedback("m", "F", "y")], dt=DT)
    with pytest.raises(WiringError, match=r"block wrong: step output out has 2 entries but 1"):
        block("wrong", step=lambda s, r: (s, ca.vertcat(r, r)), reads=["m"], publishes=["F"])
