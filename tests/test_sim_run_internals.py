"""The simulation runner's internals (uvsym.sim.run): decision columns, the stepper, chunk checks, substitutions,
the first non-finite sample and the sizes it prints, with expected values worked out by hand."""

import warnings
from fractions import Fraction
from pathlib import Path
from types import SimpleNamespace

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import CodegenError, SimulationError
from uvsym.observers.ftc import Correction
from uvsym.sim import run
from uvsym.sim.loop import SampledLoop
from uvsym.sim.run import Substitution


def _counter(dt=0.5) -> SampledLoop:
    """z' = z + 1 per sample, logging z (signal ``z.c``, m); w = [t]."""
    z, w = ca.SX.sym("z"), ca.SX.sym("w")
    discrete = ca.Function("discrete", [z, w], [ca.SX(0, 1), ca.SX(0, 1), z], ["z", "w"], ["z_disc", "u_cmd", "out"])
    step = ca.Function("step", [z, w], [z + 1, z], ["z", "w"], ["z_next", "out"])
    return SampledLoop(dt=dt, substeps=1, n_z=1, n_w=1, n_s=1, discrete=discrete, plant_ode=None, step=step,
                       layout={}, signals={"z": (slice(0, 1), ("c",), ("m",))}, env_columns=slice(1, 1))


def test_a_substitution_holds_one_channel_named_by_a_string_and_any_collection_as_a_frozenset():
    assert Substitution("psi").channels == frozenset({"psi"})  # not the letters p, s, i
    listed = Substitution(["q", "r", "q"])
    assert type(listed.channels) is frozenset and listed.channels == {"q", "r"}
    assert hash(listed) == hash(Substitution({"r", "q"}))  # hashable: a frozen, set-valued decision


def test_a_chunk_whose_rows_are_finite_but_whose_final_state_is_not_names_the_state_and_the_chunks_end():
    """4 finite rows from sample 6 at dt 0.5 s: the state is non-finite from sample 6 + 4 = 10, t = 5 s."""
    loop = SimpleNamespace(dt=0.5, signals={"x": (slice(0, 1), ("a",), ("m",))})
    rows = np.zeros((4, 1))
    with pytest.raises(SimulationError) as caught:
        run.check_chunk(loop, "fast", 6, np.zeros((4, 1)), rows, np.array([0.0, np.inf]))
    assert str(caught.value) == ("the loop diverged: its state is non-finite from t = 5 s (fast); look for an unstable "
                                 "loop (gains, signs), a model that gives NaN there, or too large a step")


def test_the_first_non_finite_entry_is_named_by_the_signal_that_holds_its_column():
    """x holds columns 0-1, y columns 2-3: column 2 is y.c (not past x's end), column 3 is y.d."""
    loop = SimpleNamespace(signals={"x": (slice(0, 2), ("a", "b"), ("m", "m")),
                                    "y": (slice(2, 4), ("c", "d"), ("s", "s"))})
    assert run._first_non_finite(loop, np.array([0.0, 1.0, np.nan, 2.0])) == "y.c (nan)"
    assert run._first_non_finite(loop, np.array([0.0, 1.0, 2.0, -np.inf])) == "y.d (-inf)"
    assert run._first_non_finite(loop, np.array([0.0, 1.0, 2.0, 3.0, np.inf])) == "logged entry 4 (inf)"


@pytest.mark.parametrize("S, o", [
    (np.array([[1.0, 2.0], [3.0, 4.0]]), np.array([5.0, 6.0])),
    ([[1, 2], [3, 4]], [5, 6]),  # integers, nested lists
    (np.array([[1, 2], [3, 4]], np.uint8), np.array([5, 6], np.longdouble)),  # any real dtype
])
def test_a_correction_goes_to_its_columns_as_vec_s_column_by_column_then_o(S, o):
    """S = [[1, 2], [3, 4]]: vec(S) stacks the columns, (1, 3, 2, 4), then o = (5, 6)."""
    loop = SimpleNamespace(correction_columns=slice(3, 9), substitution_columns={})
    columns, values = run._decision_columns(loop, Correction(S, o))
    assert columns == slice(3, 9)
    np.testing.assert_array_equal(values, [1.0, 3.0, 2.0, 4.0, 5.0, 6.0])


def test_a_correction_of_one_command_may_be_boolean():
    """m = 1 takes 1 (1 + 1) = 2 columns: S = [[True]] is 1, o = [False] is 0."""
    loop = SimpleNamespace(correction_columns=slice(4, 6))
    np.testing.assert_array_equal(run._decision_columns(loop, Correction(np.array([[True]]), np.array([False])))[1],
                                  [1.0, 0.0])


@pytest.mark.parametrize("S, o, dtypes", [
    (np.eye(2) + 1j, np.zeros(2), "complex128 S and float64 o"),  # refused, not truncated to its real part
    (np.eye(2), [1j, 0.0], "float64 S and complex128 o"),
    (np.eye(2), ["1", "0"], "float64 S and <U1 o"),
    ([[Fraction(1, 2), 0], [0, 1]], np.zeros(2), "object S and float64 o"),
])
def test_a_correction_that_is_not_real_numbers_is_refused_with_its_types(S, o, dtypes):
    loop = SimpleNamespace(correction_columns=slice(3, 9), substitution_columns={})
    with pytest.raises(SimulationError) as caught:
        run._decision_columns(loop, Correction(S, o))
    assert str(caught.value) == f"supervisor returned a Correction of {dtypes}; it takes real numbers"


def test_a_ragged_correction_is_refused():
    loop = SimpleNamespace(correction_columns=slice(3, 9), substitution_columns={})
    with pytest.raises(SimulationError, match=r"^supervisor returned a Correction that is not two arrays: \S"):
        run._decision_columns(loop, Correction([[1.0, 2.0], [3.0]], np.zeros(2)))


@pytest.mark.parametrize("S, o, shapes", [
    (np.eye(3), np.zeros(3), "S (3, 3) and o (3,)"),  # a 3-command correction for 2 commands: 12 values, not 6
    (np.arange(4.0), np.zeros(2), "S (4,) and o (2,)"),  # 6 values, but S is no matrix
    (np.ones((1, 4)), np.zeros(2), "S (1, 4) and o (2,)"),  # 6 values, S not square
    (np.eye(2), np.zeros((2, 1)), "S (2, 2) and o (2, 1)"),  # 6 values, o not a vector
    (np.eye(2), np.zeros(3), "S (2, 2) and o (3,)"),  # 7 values
])
def test_a_correction_of_the_wrong_shape_is_refused_with_both_shapes_and_the_loops_width(S, o, shapes):
    """The loop's 6 correction columns take m = 2 commands: S (2, 2), o (2,), 2 (2 + 1) = 6."""
    loop = SimpleNamespace(correction_columns=slice(3, 9), substitution_columns={})
    with pytest.raises(SimulationError) as caught:
        run._decision_columns(loop, Correction(S, o))
    assert str(caught.value) == (f"supervisor returned a Correction with {shapes}; this loop takes S (m, m) and o (m,) "
                                 "with m (m + 1) = 6")


def test_a_substitution_switches_its_channels_on_and_every_other_off():
    loop = SimpleNamespace(correction_columns=None, substitution_columns={"q": 4, "r": 7, "s": 5})
    columns, values = run._decision_columns(loop, Substitution({"r"}))
    assert columns == [4, 7, 5]
    np.testing.assert_array_equal(values, [0.0, 1.0, 0.0])


@pytest.mark.parametrize("channels, listed", [({"q": 4, "r": 5}, "q, r"), ({}, "none")])
def test_an_unknown_substitution_channel_is_refused_with_the_loops_channels(channels, listed):
    loop = SimpleNamespace(correction_columns=None, substitution_columns=channels)
    with pytest.raises(SimulationError) as caught:
        run._decision_columns(loop, Substitution({"psi", "phi"}))
    assert str(caught.value) == ("supervisor switched on substitution channels ['phi', 'psi'] the loop does not have; "
                                 f"channels: {listed}")


def test_a_decision_the_loop_cannot_apply_names_the_kind_it_expects():
    corrects = SimpleNamespace(correction_columns=slice(1, 3), substitution_columns={})
    with pytest.raises(SimulationError) as caught:
        run._decision_columns(corrects, "stop")
    assert str(caught.value) == "supervisor returned str, which this loop cannot apply; expected Correction or None"
    switches = SimpleNamespace(correction_columns=None, substitution_columns={"q": 4})
    with pytest.raises(SimulationError) as caught:
        run._decision_columns(switches, Correction(np.eye(1), np.zeros(1)))
    assert str(caught.value) == ("supervisor returned Correction, which this loop cannot apply; expected Substitution "
                                 "or None")


def _fake_compiler(monkeypatch, compiler, roll):
    """find_compiler returns ``compiler``; compile_roll records its step and answers ``roll(step)``."""
    compiled = []

    def compile_roll(step):
        compiled.append(step)
        return roll(step)

    monkeypatch.setattr(run, "find_compiler", lambda: compiler)
    monkeypatch.setattr(run, "compile_roll", compile_roll)
    return compiled


def test_the_fast_path_is_compiled_only_when_asked_and_a_compiler_is_there(monkeypatch):
    loop = _counter()
    compiled = _fake_compiler(monkeypatch, "/usr/bin/cc", lambda step: "the C roll")
    before = run.time.perf_counter()
    advance, build_s = run._stepper(loop, "fast", 4, {}, True)
    assert advance == "the C roll" and compiled == [loop.step]
    assert 0.0 <= build_s <= run.time.perf_counter() - before
    for compiler, asked in (("/usr/bin/cc", False), (None, True)):
        compiled = _fake_compiler(monkeypatch, compiler, lambda step: "the C roll")
        advance, _ = run._stepper(loop, "fast", 4, {}, asked)
        assert compiled == [] and callable(advance)


def _recording_step(loop, calls):
    """A stand-in for ``loop.step`` whose mapaccum records (name, n) in ``calls`` and builds the real one."""
    class Step:
        def mapaccum(self, name, n):
            calls.append((name, n))
            return loop.step.mapaccum(name, n)

    return Step


def test_the_interpreted_fast_path_rolls_its_own_mapaccum_named_for_the_loop(monkeypatch):
    """The counter from z = 2 over 3 samples logs 2, 3, 4 and ends at 5."""
    loop, calls = _counter(), []
    Step = _recording_step(loop, calls)
    _fake_compiler(monkeypatch, None, None)
    advance, _ = run._stepper(SimpleNamespace(step=Step(), n_z=1, plant_ode=None), "fast", 3, {}, True)
    out = np.empty((3, 1))
    np.testing.assert_array_equal(advance(np.array([2.0]), np.zeros((3, 1)), out), [5.0])
    np.testing.assert_array_equal(out[:, 0], [2.0, 3.0, 4.0])
    assert calls == [("closed_loop_roll", 3)]


def test_the_interpreted_fast_path_rolls_a_shorter_last_chunk_with_a_mapaccum_of_its_own(monkeypatch):
    """Chunk 3, then a last chunk of 2 rows from an integer z = 7: logs 7, 8 and ends at 9 (7 read as a float,
    not its bytes); the 2-row roll is a second mapaccum of 2 steps under the same name."""
    loop, calls = _counter(), []
    Step = _recording_step(loop, calls)
    _fake_compiler(monkeypatch, None, None)
    before = run.time.perf_counter()
    advance, build_s = run._stepper(SimpleNamespace(step=Step(), n_z=1, plant_ode=None), "fast", 3, {}, True)
    assert 0.0 <= build_s <= run.time.perf_counter() - before
    out = np.empty((2, 1))
    np.testing.assert_array_equal(advance(np.array([7]), np.zeros((2, 1)), out), [9.0])
    np.testing.assert_array_equal(out[:, 0], [7.0, 8.0])
    assert calls == [("closed_loop_roll", 3), ("closed_loop_roll", 2)]


def test_a_failed_compilation_warns_at_the_runs_caller_and_runs_interpreted(monkeypatch):
    """The counter from z = 0 over 3 samples logs 0, 1, 2 and 3 (the last from the discrete part)."""

    def fails(step):
        raise CodegenError("no room for the library")

    _fake_compiler(monkeypatch, "/usr/bin/cc", fails)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result, _ = run.run_closed_loop(_counter(), np.zeros(1), np.zeros((4, 1)))
    assert [str(w.message) for w in caught] == ["running the fast path interpreted: no room for the library"]
    # at the caller: this file, or the wrapper mutmut puts between a test and a mutated function
    assert caught[0].category is UserWarning
    assert caught[0].filename == __file__ or "mutmut" in Path(caught[0].filename).parts
    np.testing.assert_array_equal(result.signals["z"].values[:, 0], [0.0, 1.0, 2.0, 3.0])


@pytest.mark.parametrize("count, text", [
    (1023, "1023 B"), (1024, "1 KiB"),  # the first KiB
    (2**20, "1 MiB"), (3 * 2**20, "3 MiB"),  # 1024 KiB is already 1 MiB
    (5 * 2**50, "5 PiB"), (2**60, "1 EiB"),
])
def test_sizes_print_in_the_largest_binary_unit_below_1024(count, text):
    assert run._bytes(count) == text


# --- available memory: the fallback (mutation survivors) -----------------------------------------------------------


def test_available_memory_falls_back_to_the_physical_memory(monkeypatch):
    """Without /proc/meminfo, the physical memory: MemTotal (kB) is the same page count on Linux."""
    try:
        with open("/proc/meminfo") as handle:
            total = next(int(line.split()[1]) * 1024 for line in handle if line.startswith("MemTotal:"))
    except (OSError, StopIteration):
        pytest.skip("no /proc/meminfo to compare with")

    def unreadable(*args, **kwargs):
        raise OSError("no /proc")

    monkeypatch.setattr(run, "open", unreadable, raising=False)
    assert run.available_memory() == total
