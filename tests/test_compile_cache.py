"""The compile cache: a second compile of the same Function is a cache hit, anything that changes the
library misses, an unusable folder falls back with a warning; the fast-path flags keep the results
and the divergence report of the default flags."""

from __future__ import annotations

import functools
import subprocess
from dataclasses import replace

import casadi as ca
import numpy as np
import pytest

from uvsym.codegen import cache as cache_module
from uvsym.codegen import compile as compile_module
from uvsym.codegen.compile import DEFAULT_FLAGS, FAST_FLAGS, compile_roll, find_compiler
from uvsym.errors import SimulationError
from uvsym.faults import Profile, SensorFault

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="no C compiler")


def _halving_step() -> ca.Function:
    """z_next = z / 2 + w, out = 3 z: built afresh on every call."""
    z, w = ca.SX.sym("z"), ca.SX.sym("w")
    return ca.Function("halving_step", [z, w], [z / 2 + w, 3 * z], ["z", "w"], ["z_next", "out"])


@pytest.fixture
def compiler_calls(monkeypatch, tmp_path):
    """The cache folder pointed at tmp_path; a list recording every compilation (compiler runs with -shared)."""
    monkeypatch.setenv(cache_module.CACHE_ENV, str(tmp_path / "cache"))
    calls, run = [], subprocess.run

    def counting(command, *args, **kwargs):
        if "-shared" in command:
            calls.append(command)
        return run(command, *args, **kwargs)

    monkeypatch.setattr(compile_module.subprocess, "run", counting)
    return calls


def _roll_twice(roll) -> tuple[np.ndarray, np.ndarray]:
    out = np.empty((2, 1))
    return roll(np.array([4.0]), np.array([[1.0], [0.0]]), out), out


def test_a_second_compile_of_the_same_function_is_a_cache_hit(compiler_calls, tmp_path):
    z_end, out = _roll_twice(compile_roll(_halving_step()))
    # by hand: z = 4 -> 4/2 + 1 = 3 -> 3/2 + 0 = 1.5; out = 3 z before each step
    assert z_end.tolist() == [1.5] and out.ravel().tolist() == [12.0, 9.0]
    assert len(compiler_calls) == 1
    libraries = sorted((tmp_path / "cache").glob("*.so"))
    assert len(libraries) == 1 and not list((tmp_path / "cache").glob("*.part"))
    z_end, out = _roll_twice(compile_roll(_halving_step()))  # a Function built again, equal
    assert z_end.tolist() == [1.5] and out.ravel().tolist() == [12.0, 9.0]
    assert len(compiler_calls) == 1 and sorted((tmp_path / "cache").glob("*.so")) == libraries


def test_other_flags_or_another_function_compile_again(compiler_calls, tmp_path):
    compile_roll(_halving_step())
    compile_roll(_halving_step(), DEFAULT_FLAGS)
    z, w = ca.SX.sym("z"), ca.SX.sym("w")
    compile_roll(ca.Function("halving_step", [z, w], [z / 4 + w, 3 * z], ["z", "w"], ["z_next", "out"]))
    assert len(compiler_calls) == 3 and len(list((tmp_path / "cache").glob("*.so"))) == 3


def test_an_unusable_cache_folder_falls_back_to_a_temporary_one_with_a_warning(monkeypatch, tmp_path):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    monkeypatch.setenv(cache_module.CACHE_ENV, str(blocker / "cache"))
    monkeypatch.setattr(cache_module, "_WARNED", set())
    with pytest.warns(UserWarning, match="compile cache folder unusable"):
        z_end, _ = _roll_twice(compile_roll(_halving_step()))
    assert z_end.tolist() == [1.5]


def test_the_cache_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv(cache_module.CACHE_ENV, str(tmp_path / "mine"))
    assert cache_module.cache_dir() == tmp_path / "mine"
    monkeypatch.delenv(cache_module.CACHE_ENV)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_module.cache_dir() == tmp_path / "xdg" / "uvsym"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert cache_module.cache_dir() == tmp_path / "home" / ".cache" / "uvsym"


@pytest.fixture(scope="module")
def docking_run():
    """The docking scenario (10 s) and its prepared run (the user's cache folder, as every simulation's)."""
    from uvsym.sim.scenario import load_scenario
    from uvsym.sim.simulation import prepare_run, scenario_arguments

    scenario = replace(load_scenario("docking_faults"), duration=10.0)
    return scenario, prepare_run(scenario.model, scenario.controller, **scenario_arguments(scenario))


def test_the_fast_flags_agree_with_the_default_flags_on_the_docking_loop(docking_run):
    _, run = docking_run
    outputs = []
    for flags in (DEFAULT_FLAGS, FAST_FLAGS):
        out = np.empty((run.W.shape[0] - 1, run.loop.step.nnz_out(1)))
        compile_roll(run.loop.step, flags)(run.z0, run.W[:-1], out)
        outputs.append(out)
    scale = np.maximum(np.abs(outputs[0]), 1.0)
    assert np.all(np.isfinite(outputs[1])) and np.max(np.abs(outputs[1] - outputs[0]) / scale) < 1e-10


def test_a_loop_that_diverges_is_reported_alike_with_either_flags(docking_run, monkeypatch):
    from uvsym.sim import run as run_module
    from uvsym.sim.simulation import simulate_scenario

    scenario, _ = docking_run
    # a surge speed measured 1e308 m/s from 0.5 s: the controller's and observers' arithmetic overflows to NaN
    blowing_up = replace(scenario, duration=1.0,
                         sensor_faults=(SensorFault(6, "bias", 1e308, Profile("step", onset=0.5)),))
    messages = []
    for flags in (DEFAULT_FLAGS, FAST_FLAGS):
        monkeypatch.setattr(run_module, "compile_roll", functools.partial(compile_roll, flags=flags))
        with pytest.raises(SimulationError, match=r"diverged: .* is non-finite from t = 0\.5\d* s") as error:
            simulate_scenario(blowing_up)
        messages.append(str(error.value))
    assert messages[0] == messages[1]



def test_the_straight_line_roll_agrees_with_casadi_s_own_evaluation(docking_run):
    _, run = docking_run
    k = 200
    out = np.empty((k, run.loop.step.nnz_out(1)))
    z_end = compile_roll(run.loop.step)(run.z0, run.W[:k], out)
    states, expected = run.loop.step.mapaccum("interpreted", k)(run.z0, run.W[:k].T)  # CasADi's virtual machine
    scale = np.maximum(np.abs(np.asarray(expected).T), 1.0)
    assert np.max(np.abs(out - np.asarray(expected).T) / scale) < 1e-10
    np.testing.assert_allclose(z_end, np.asarray(states)[:, -1], rtol=1e-10, atol=1e-10)


def test_a_step_that_calls_another_function_rolls_through_casadi_s_code(compiler_calls):
    halving = _halving_step()
    z, w = ca.MX.sym("z"), ca.MX.sym("w")
    z_next, out = halving(z, w)  # an MX step: its C calls the halving step's, not straight-line code
    z_end, out = _roll_twice(compile_roll(ca.Function("calling_step", [z, w], [z_next, out], ["z", "w"],
                                                      ["z_next", "out"])))
    assert z_end.tolist() == [1.5] and out.ravel().tolist() == [12.0, 9.0]  # as worked by hand above
