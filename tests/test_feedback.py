"""Controllers as blocks: PID, open-loop tables, LQR, each against a closed form or an independent solution."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from problems import DT, first_order, integrator

from uvsym.faults import ActuatorFault, Profile
from uvsym.sim import lqr, lqr_gain, open_loop, pid, simulate_system
from uvsym.systems import signals, system


def test_pid_brings_a_first_order_plant_to_its_set_point_within_limits():
    controller = pid("speed", measured="m", reference=1.0, kp=2.0, ki=1.5, output="F", limits=(-0.4, 0.4), dt=DT)
    result = simulate_system(first_order(), [controller], duration=30.0, dt=DT, x0=[0.0])
    assert abs(result["x"]["v"][-1] - 1.0) < 1e-4
    assert result["speed"]["F"].max() <= 0.4 and result["speed"]["F"][0] == pytest.approx(0.4)
    assert result["speed"]["F"][-1] == pytest.approx(0.25, abs=1e-4)  # holds a v = b F: F = 0.5 / 2


def test_pid_clamps_its_integral_only_while_the_output_is_pushed_beyond_a_limit():
    controller = pid("c", measured="y", reference=1.0, kp=1.0, ki=2.0, kd=0.5, output="u", limits=(-1.0, 1.0), dt=0.1)
    # v = kp e + ki I - kd (y - y_prev) / dt; the new integral is I + e dt unless clamped
    s_next, out = controller.step([3.0, 0.0], [0.0])  # e = 1, v = 1 + 6 - 0 = 7 > 1 and e > 0: held
    np.testing.assert_allclose(np.asarray(s_next).ravel(), [3.0, 0.0])
    assert float(out) == 1.0
    s_next, out = controller.step([3.0, 2.2], [2.0])  # e = -1, v = -1 + 6 + 1 = 6 > 1 but e < 0: integrates
    np.testing.assert_allclose(np.asarray(s_next).ravel(), [2.9, 2.0])
    s_next, out = controller.step([0.1, 0.5], [0.5])  # e = 0.5, v = 0.5 + 0.2 = 0.7 within limits
    np.testing.assert_allclose(np.asarray(s_next).ravel(), [0.15, 0.5])
    assert float(out) == pytest.approx(0.7)
    assert controller.initial_state([0.3]).tolist() == [0.0, 0.3]  # no derivative kick at the start


@pytest.mark.parametrize("interpolation", ["previous", "linear"])
def test_open_loop_table_drives_an_integrator(interpolation):
    times, values = [0.5, 1.0, 2.0], [1.0, -1.0, 0.5]
    table = open_loop("table", times, values, publishes=["u"], interpolation=interpolation)
    result = simulate_system(integrator(), [table], duration=3.0, dt=DT, x0=[0.0])
    t = result.t
    if interpolation == "linear":
        u = np.interp(t, times, values)
    else:  # the last point at or before t, the first one before the table starts
        u = np.asarray(values)[np.clip(np.searchsorted(times, t + 1e-9, side="right") - 1, 0, None)]
    np.testing.assert_allclose(result["table"]["u"], u, rtol=0, atol=1e-12)
    np.testing.assert_allclose(result["x"]["q"], np.concatenate([[0.0], np.cumsum(u[:-1]) * DT]), atol=1e-12)


@pytest.mark.parametrize("interpolation", ["previous", "linear"])
def test_a_table_evaluated_on_a_numpy_time_vector_is_the_casadi_block_to_the_last_bit(interpolation):
    """The disturbance schedules take the numpy path of the table's rule; the block steps take CasADi's."""
    from uvsym.sim.feedback import table_value

    times, values = np.array([0.3, 1.0, 2.5]), np.array([[1.0, 0.1], [-1.7, 0.2], [0.45, -3.0]])
    table = open_loop("table", times, values, publishes=["a", "b"], interpolation=interpolation)
    t = np.concatenate([np.linspace(0.0, 3.0, 301), times - 1e-9, times - 2e-9, times + 1e-12])
    from_casadi = np.asarray(table.step.map(t.size)(np.zeros((0, t.size)), t[None, :])[1]).T
    from_numpy = table_value(t, times, values, interpolation)
    assert from_numpy.shape == (t.size, 2)
    np.testing.assert_array_equal(from_numpy, from_casadi)
    expected = np.column_stack([np.interp(t, times, values[:, j]) for j in range(2)]) if interpolation == "linear" \
        else values[np.clip(np.searchsorted(times, t + 1e-9, side="right") - 1, 0, None)]
    np.testing.assert_allclose(from_numpy, expected, rtol=0, atol=1e-12)


def test_lqr_gain_of_a_double_integrator_is_the_closed_form():
    A, B = np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]])
    # Q = I, R = 1: K = [1, sqrt(3)] (P = [[sqrt 3, 1], [1, sqrt 3]])
    np.testing.assert_allclose(lqr_gain(A, B, np.eye(2), [[1.0]]), [[1.0, math.sqrt(3.0)]], rtol=1e-10)
    Ad, Bd = np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.005], [0.1]])
    P = np.eye(2)
    for _ in range(5000):  # Riccati recursion to its fixed point
        P = np.eye(2) + Ad.T @ P @ Ad - Ad.T @ P @ Bd @ np.linalg.solve(2.0 + Bd.T @ P @ Bd, Bd.T @ P @ Ad)
    np.testing.assert_allclose(lqr_gain(Ad, Bd, np.eye(2), [[2.0]], dt=0.1),
                               np.linalg.solve(2.0 + Bd.T @ P @ Bd, Bd.T @ P @ Ad), rtol=1e-9)


def test_fast_path_and_cvodes_agree_on_a_nonlinear_plant_under_lqr():
    pendulum = system("pendulum", "theta'' = -sin(theta) - 0.1 omega + tau",
                      x=signals(("theta", "rad"), ("omega", "rad/s"), group="state"),
                      u=signals(("tau", "1/s^2"), group="input"),
                      rhs=lambda x, u, d, p: ca.vertcat(x[1], -ca.sin(x[0]) - 0.1 * x[1] + u[0]))
    blocks = [lqr(pendulum, np.diag([10.0, 1.0]), [[1.0]], dt=DT)]
    runs = {method: simulate_system(pendulum, blocks, duration=5.0, dt=DT, x0=[2.5, 0.0], method=method)
            for method in ("fast", "cvodes")}
    assert np.abs(runs["fast"]["x"].values - runs["cvodes"]["x"].values).max() < 1e-6
    assert abs(runs["fast"]["x"]["theta"][-1]) < 1e-2  # and the loop is stable
    interpreted = simulate_system(pendulum, blocks, duration=1.0, dt=DT, x0=[2.5, 0.0], compiled=False)
    np.testing.assert_allclose(interpreted["x"].values, runs["fast"]["x"].values[:101], rtol=0, atol=1e-12)


# -- observers -------------------------------------------------------------------------------------------------


def test_quick_look_of_a_wired_loop_shows_states_inputs_and_blocks(tmp_path):
    controller = pid("c", measured="m", reference=1.0, kp=2.0, ki=1.0, output="F", dt=DT)
    result = simulate_system(first_order(), [controller], duration=1.0, dt=DT, x0=[0.0])
    figure = result.plot(tmp_path / "loop.svg")
    labels = [ax.get_ylabel() for ax in figure.axes]
    assert labels == ["x (m/s)", "u (N)"]  # the command is the plant input: drawn once
    assert (tmp_path / "loop.svg").read_text().startswith("<?xml")
    faulty = simulate_system(first_order(), [controller], duration=1.0, dt=DT, x0=[0.0],
                             actuator_faults=(ActuatorFault(0, "bias", 0.5, Profile(onset=0.5)),))
    assert [ax.get_ylabel() for ax in faulty.plot().axes] == ["x (m/s)", "u (N)", "c (N)"]
