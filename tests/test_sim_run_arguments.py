"""The simulation runner's arguments (uvsym.sim.run.run_closed_loop, memory_needed): methods, supervisor periods,
the chunks between progress reports, input tables and initial states of other dtypes, with expected values
worked out by hand."""

import math
import time
from fractions import Fraction
from types import SimpleNamespace

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import SimulationError
from uvsym.sim import run
from uvsym.sim.loop import SampledLoop


def _adder(dt=0.5) -> SampledLoop:
    """z' = z + w[1] per sample, logging z (signal ``z.c``, m); w = [t, a]; no integrated plant."""
    z, w = ca.SX.sym("z"), ca.SX.sym("w", 2)
    discrete = ca.Function("discrete", [z, w], [ca.SX(0, 1), ca.SX(0, 1), z], ["z", "w"], ["z_disc", "u_cmd", "out"])
    step = ca.Function("step", [z, w], [z + w[1], z], ["z", "w"], ["z_next", "out"])
    return SampledLoop(dt=dt, substeps=1, n_z=1, n_w=2, n_s=1, discrete=discrete, plant_ode=None, step=step,
                       layout={}, signals={"z": (slice(0, 1), ("c",), ("m",))}, env_columns=slice(2, 2))


def _ramp(dt=0.5) -> SampledLoop:
    """An integrated plant s' = u with u = 1 held over each sample, logging s (signal ``s.c``, m); w = [t]."""
    s, w = ca.SX.sym("s"), ca.SX.sym("w")
    discrete = ca.Function("discrete", [s, w], [ca.SX(0, 1), ca.SX(1), s], ["z", "w"], ["z_disc", "u_cmd", "out"])
    u, env, t = ca.SX.sym("u"), ca.SX.sym("env", 0), ca.SX.sym("t")
    plant_ode = ca.Function("plant_ode", [s, u, env, t], [u])
    step = ca.Function("step", [s, w], [s + dt, s], ["z", "w"], ["z_next", "out"])
    return SampledLoop(dt=dt, substeps=1, n_z=1, n_w=1, n_s=1, discrete=discrete, plant_ode=plant_ode, step=step,
                       layout={}, signals={"s": (slice(0, 1), ("c",), ("m",))}, env_columns=slice(1, 1))


def _times(N: int, dt: float = 0.5) -> np.ndarray:
    """W (N + 1, 1): the sample times k dt (s)."""
    return (dt * np.arange(N + 1))[:, None]


class _Recorder:
    """A supervisor of the given period that records the sample times of every chunk it sees and decides nothing."""

    def __init__(self, period):
        self.period, self.seen = period, []

    def update(self, t, signals):
        self.seen.append(list(t))


def test_an_unknown_method_is_refused_with_the_known_ones():
    with pytest.raises(SimulationError) as caught:
        run.run_closed_loop(_adder(), np.zeros(1), np.zeros((3, 2)), method="euler")
    assert str(caught.value) == "unknown method 'euler'; known: fast, cvodes, idas, rk, collocation"


@pytest.mark.parametrize("period", [0, 0.0, -0.5, -1, math.inf, -math.inf, math.nan, "1", None])
def test_a_supervisor_period_that_is_not_a_positive_finite_number_is_refused(period):
    with pytest.raises(SimulationError) as caught:
        run.run_closed_loop(_adder(), np.zeros(1), np.zeros((3, 2)), supervisor=_Recorder(period), compiled=False)
    assert str(caught.value) == f"a supervisor needs a positive, finite period (s), got {period!r}"


@pytest.mark.parametrize("period, chunks", [
    (0.1, [[0.0], [0.5], [1.0]]),  # 0.2 samples rounds to none: at least one
    (0.5, [[0.0], [0.5], [1.0]]),  # one sample
    (0.7, [[0.0], [0.5], [1.0]]),  # 1.4 samples rounds to 1
    (1.0, [[0.0, 0.5], [1.0]]),  # two samples, the last chunk shorter
])
def test_a_supervisor_sees_every_chunk_of_its_period_in_whole_samples(period, chunks):
    """dt = 0.5 s, 3 samples at t = 0, 0.5, 1 s; the counter adds 1 a sample, whatever the chunks."""
    W = np.column_stack([_times(3), np.ones(4)])
    supervisor = _Recorder(period)
    result, _ = run.run_closed_loop(_adder(), np.zeros(1), W, supervisor=supervisor, compiled=False)
    assert supervisor.seen == chunks
    np.testing.assert_array_equal(result.signals["z"].values[:, 0], [0.0, 1.0, 2.0, 3.0])


@pytest.mark.parametrize("method, reports", [
    ("fast", [1.0]),  # 150 samples in one call (up to 10000)
    ("rk", [100 / 150, 1.0]),  # 100 samples a call, then the last 50
])
def test_without_a_supervisor_progress_is_reported_after_each_chunk_of_the_method(method, reports):
    """s' = 1 from s = 0 at dt = 0.5 s: s = k / 2 at sample k, exact for fixed steps and RK4 (up to rounding)."""
    seen = []
    result, _ = run.run_closed_loop(_ramp(), np.zeros(1), _times(150), method=method, compiled=False,
                                    progress=seen.append)
    assert seen == reports
    np.testing.assert_allclose(result.signals["s"].values[:, 0], np.arange(151) / 2, rtol=1e-12, atol=1e-12)


def test_an_integer_input_table_is_read_as_numbers():
    """W of int64: a = 1 each sample, so the counter from 0 logs 0, 1, 2, 3 (not the bytes of 1 read as a float)."""
    W = np.column_stack([np.arange(4), np.ones(4, dtype=np.int64)])
    assert W.dtype == np.int64
    result, _ = run.run_closed_loop(_adder(), np.zeros(1), W, compiled=False)
    np.testing.assert_array_equal(result.signals["z"].values[:, 0], [0.0, 1.0, 2.0, 3.0])
    np.testing.assert_array_equal(result.t, [0.0, 1.0, 2.0, 3.0])


def test_an_exact_initial_state_is_read_as_a_float():
    """s(0) = 1/2 as a Fraction, s' = 1 over 2 samples of 0.5 s: 0.5, 1, 1.5."""
    result, _ = run.run_closed_loop(_ramp(), [Fraction(1, 2)], _times(2), method="rk")
    np.testing.assert_allclose(result.signals["s"].values[:, 0], [0.5, 1.0, 1.5], rtol=0, atol=1e-12)


def test_the_memory_needed_is_the_input_table_and_two_copies_of_the_logged_outputs():
    """10 samples, 3 inputs, 5 logged outputs: the arrays' own sizes, 240 B of W plus 2 x 400 B, 1040 B."""
    x = ca.SX.sym("x")
    loop = SimpleNamespace(n_w=3, discrete=ca.Function("discrete", [x], [ca.SX(2, 1), ca.SX(1, 1), ca.repmat(x, 5)],
                                                       ["z"], ["z_disc", "u_cmd", "out"]))
    W, outputs = np.empty((10, 3)), np.empty((10, 5))
    assert run.memory_needed(10, loop) == W.nbytes + 2 * outputs.nbytes == 1040


def test_a_divergence_is_named_with_its_signal_time_and_method():
    # z' = z + a with a = inf at sample 1: z is finite at t = 0 and 0.5 s, inf from sample 2 (t = 1 s) on
    W = np.zeros((4, 2))
    W[1, 1] = math.inf
    with pytest.raises(SimulationError) as caught:
        run.run_closed_loop(_adder(), np.zeros(1), W, compiled=False)
    assert str(caught.value).startswith("the loop diverged: z.c (inf) is non-finite from t = 1 s (fast); ")


def test_the_guard_sees_the_times_and_rows_of_every_chunk():
    seen = []
    W = np.column_stack([0.5 * np.arange(4), np.ones(4)])
    run.run_closed_loop(_adder(), np.zeros(1), W, compiled=False,
                        guard=lambda t, rows: seen.append((list(t), rows[:, 0].tolist())))
    assert [t for chunk in seen for t in chunk[0]] == [0.0, 0.5, 1.0]
    assert [z for chunk in seen for z in chunk[1]] == [0.0, 1.0, 2.0]


def test_the_result_has_empty_meta_and_the_timing_its_wall_clock_seconds():
    before = time.perf_counter()
    result, timing = run.run_closed_loop(_adder(), np.zeros(1), np.zeros((4, 2)), compiled=False)
    elapsed = time.perf_counter() - before
    assert result.meta == {} and isinstance(result.meta, dict)
    assert set(timing) == {"wall_s", "build_s"} and 0.0 <= timing["wall_s"] <= elapsed


@pytest.mark.parametrize("duration, dt", [(1e12, 1.0), (1e6, 1e-7), (2e12, 0.5)])
def test_a_grid_of_a_trillion_samples_or_more_is_refused(duration, dt):
    with pytest.raises(SimulationError, match=r"samples, more than 1e\+12 \(no machine holds them\)"):
        run.grid(duration, dt)


def test_a_grid_just_under_a_trillion_samples_is_counted():
    assert run.grid(999_999_999_999.0, 1.0) == 999_999_999_999


def test_the_refusal_of_a_huge_grid_gives_its_sample_count():
    with pytest.raises(SimulationError) as caught:
        run.grid(2e12, 0.5)
    assert str(caught.value) == ("duration 2e+12 s at step 0.5 s is 4e+12 samples, more than 1e+12 (no machine holds "
                                 "them); shorten the run or lengthen the step")


def test_a_step_must_divide_the_duration_to_a_relative_1e_9():
    # 1 us at a step 0.1 ns too long: one sample, 1e-10 s short of the step, far above 1e-9 of the duration (1e-15 s)
    with pytest.raises(SimulationError, match=r"^step 1.0001e-06 s does not divide duration 1e-06 s$"):
        run.grid(1e-6, 1.0001e-6)
    # the smallest double divided by itself: no gap at all, where 1e-9 of the duration rounds to 0
    assert run.grid(5e-324, 5e-324) == 1
