"""The lanes' compiled library: its width from the processor, its math through libmvec's vector
functions, its arithmetic in vector registers, and lanes equal to the scalar roll of the same step
(uvsym.codegen.compile), also over each run's own arrays."""

from __future__ import annotations

import re
import shutil
import subprocess
import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from uvsym.codegen import lane_width
from uvsym.codegen.compile import compile_lanes, compile_roll, find_compiler, vector_doubles
from uvsym.errors import CodegenError
from uvsym.sim.batch import LANES, default_lanes
from uvsym.sim.inputs import compact

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="no C compiler")


def _step() -> ca.Function:
    """A small loop step z' = (z0 + dt cos(w0 z1), z1 + dt sin(z0) exp(-w1^2)), out = (atan2(z1, z0), z0 z1)."""
    z, w = ca.SX.sym("z", 2), ca.SX.sym("w", 2)
    dt = 0.01
    z_next = ca.vertcat(z[0] + dt * ca.cos(w[0] * z[1]), z[1] + dt * ca.sin(z[0]) * ca.exp(-w[1] ** 2))
    return ca.Function("lanes_probe", [z, w], [z_next, ca.vertcat(ca.atan2(z[1], z[0]), z[0] * z[1])])


def _cpu_flags() -> set[str]:
    text = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    line = re.search(r"^flags\s*:(.*)$", text, re.M)
    return set(line.group(1).split()) if line else set()


def test_vector_width_is_the_processors():
    flags = _cpu_flags()
    if not flags:
        pytest.skip("no /proc/cpuinfo flags to compare with")
    expected = 8 if "avx512f" in flags else 4 if "avx" in flags else 2
    assert vector_doubles() == expected
    # 8 doubles: 4 or 8 lanes as measured on this machine; narrower vectors: one vector, at most LANES
    assert default_lanes() in ((4, 8) if expected == 8 else (min(expected, LANES),))


def test_the_measured_width_is_cached_per_machine_and_measured_again_when_unreadable(tmp_path, monkeypatch):
    """On a processor of 8 doubles the choice is measured (both widths timed), written to the cache folder's
    lanes.json, read back without measuring, and measured again when the file is corrupt; narrower processors
    measure nothing."""
    calls = []

    def timings():
        calls.append(1)
        return {4: 100.0, 8: 60.0}  # 8 lanes 1.67x faster per trajectory-step: kept

    monkeypatch.setenv("UVSYM_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(lane_width, "vector_doubles", lambda: 8)
    monkeypatch.setattr(lane_width, "lane_timings", timings)
    lane_width._measured.cache_clear()
    assert lane_width.measured_lanes() == 8 and len(calls) == 1
    lane_width._measured.cache_clear()
    assert lane_width.measured_lanes() == 8 and len(calls) == 1  # read from lanes.json
    (tmp_path / "lanes.json").write_text("{not json")
    lane_width._measured.cache_clear()
    monkeypatch.setattr(lane_width, "lane_timings", lambda: calls.append(1) or {4: 100.0, 8: 95.0})
    assert lane_width.measured_lanes() == 4 and len(calls) == 2  # 5 % faster is not enough for 8
    monkeypatch.setattr(lane_width, "vector_doubles", lambda: 4)
    assert lane_width.measured_lanes() == 4 and len(calls) == 2
    lane_width._measured.cache_clear()


def test_the_calibration_loop_times_both_widths_and_its_lanes_equal_the_scalar_roll():
    if vector_doubles() < 4:
        pytest.skip("this processor has no 256-bit vectors")
    timings = lane_width.lane_timings(steps=200, calls=2)
    assert set(timings) == set(lane_width.CANDIDATES) and all(0 < t < 1e6 for t in timings.values())
    step, N, lanes = lane_width.calibration_step(), 300, 8
    rng = np.random.default_rng(3)
    z0 = rng.uniform(-1.0, 1.0, (lane_width.N_Z, lanes))
    Ws = [np.ascontiguousarray(rng.uniform(-1.0, 1.0, (N, lane_width.N_W))) for _ in range(lanes)]
    outs = [np.empty((N, lane_width.N_OUT)) for _ in range(lanes)]
    compile_lanes(step, lanes).runs(z0, Ws, outs)
    for lane in range(lanes):
        own = np.empty((N, lane_width.N_OUT))
        compile_roll(step)(z0[:, lane], Ws[lane], own)
        np.testing.assert_allclose(outs[lane], own, rtol=1e-12, atol=1e-14)
        assert np.all(np.abs(outs[lane]) < 2.0)  # bounded: the loop times arithmetic, not overflow


def _vector_symbols(library: Path) -> set[str]:
    listing = subprocess.run(["nm", "-D", "--undefined-only", str(library)], capture_output=True, text=True)
    return {name for name in re.findall(r"\b(_ZGV\w+)", listing.stdout)}


@pytest.mark.skipif(shutil.which("nm") is None, reason="no nm (binutils) to list the library's symbols")
@pytest.mark.parametrize("lanes", [4, 8])
def test_the_lanes_call_libmvec_vector_functions_of_their_width(lanes):
    """Vector-ABI names (_ZGV<isa><mask><lanes>...): 'e' is AVX-512, 'd' AVX2, 'c' AVX, 'b' SSE."""
    if vector_doubles() < 4:
        pytest.skip("this processor has no 256-bit vectors")
    symbols = _vector_symbols(compile_lanes(_step(), lanes).library)
    # 8 lanes on AVX-512 fill one 512-bit register; otherwise 256-bit (AVX2) vectors of 4
    isa, width = ("e", 8) if vector_doubles() == 8 and lanes == 8 else ("d", 4)
    expected = {f"_ZGV{isa}N{width}v_sin", f"_ZGV{isa}N{width}v_cos", f"_ZGV{isa}N{width}v_exp",
                f"_ZGV{isa}N{width}vv_atan2"}
    assert expected <= symbols, symbols


@pytest.mark.parametrize("lanes", [1, 4, 8])
def test_each_lane_equals_the_scalar_roll(lanes):
    """Lanes that start apart stay equal to the scalar roll of each (libmvec within a few ulp of libm)."""
    step, N = _step(), 500
    rng = np.random.default_rng(lanes)
    z0 = rng.uniform(-1.0, 1.0, (2, lanes))
    W = rng.uniform(-2.0, 2.0, (N, 2, lanes))
    out = np.empty((N, 2, lanes))
    z_end = compile_lanes(step, lanes)(np.ascontiguousarray(z0), np.ascontiguousarray(W), out)
    scalar = compile_roll(step)
    for lane in range(lanes):
        own = np.empty((N, 2))
        z_lane = scalar(z0[:, lane], np.ascontiguousarray(W[:, :, lane]), own)
        np.testing.assert_allclose(out[:, :, lane], own, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(z_end[:, lane], z_lane, rtol=1e-12, atol=1e-14)
    assert not np.allclose(out[:, :, 0], out[:, :, -1]) or lanes == 1  # the lanes ran apart


@pytest.mark.skipif(shutil.which("nm") is None, reason="no nm (binutils) to list the library's symbols")
def test_erf_runs_in_the_lanes_through_libmvec():
    """Uniform noise from normal draws goes through erf (the wired loops): its lanes call libmvec's vector
    erf and equal the scalar roll."""
    if vector_doubles() < 4:
        pytest.skip("this processor has no 256-bit vectors")
    z, w = ca.SX.sym("z", 1), ca.SX.sym("w", 1)
    step = ca.Function("erf_probe", [z, w], [0.5 * z + ca.erf(w), ca.erf(z * w)])
    roll = compile_lanes(step, 4)
    assert "_ZGVdN4v_erf" in _vector_symbols(roll.library)
    rng = np.random.default_rng(3)
    W, z0, out = rng.normal(0, 1, (200, 1, 4)), rng.normal(0, 1, (1, 4)), np.empty((200, 1, 4))
    roll(z0, W, out)
    for lane in range(4):
        own = np.empty((200, 1))
        compile_roll(step)(z0[:, lane].copy(), np.ascontiguousarray(W[:, :, lane]), own)
        np.testing.assert_allclose(out[:, :, lane], own, rtol=1e-12, atol=1e-15)


def test_the_runs_roll_equals_the_lanes_roll_over_each_runs_own_arrays():
    """roll.runs reads each run's own (k, n_w) rows and writes its own (k, n_out) rows: the same numbers as
    the structure-of-arrays roll, a padding lane sharing its run's arrays; mismatched arrays are refused."""
    step, N, lanes = _step(), 300, 4
    rng = np.random.default_rng(7)
    z0 = rng.uniform(-1.0, 1.0, (2, 3))
    Ws = [np.ascontiguousarray(rng.uniform(-2.0, 2.0, (N, 2))) for _ in range(3)]
    roll = compile_lanes(step, lanes)
    outs = [np.empty((N, 2)) for _ in range(3)]
    z_end = roll.runs(np.column_stack([z0, z0[:, -1]]), Ws + Ws[-1:], outs + outs[-1:])
    soa = np.empty((N, 2, lanes))
    soa_end = roll(np.column_stack([z0, z0[:, -1]]), np.ascontiguousarray(np.stack(Ws + Ws[-1:], axis=-1)), soa)
    for lane in range(3):
        np.testing.assert_array_equal(outs[lane], soa[:, :, lane])
    np.testing.assert_array_equal(z_end, soa_end)
    with pytest.raises(CodegenError, match="C-contiguous float64 W"):
        roll.runs(z_end, Ws + [Ws[0][:, :1]], outs + outs[-1:])
    with pytest.raises(CodegenError, match="of one k"):
        roll.runs(z_end, Ws + Ws[-1:], outs[:2] + [outs[2][:-1], outs[2][:-1]])


def test_the_runs_roll_reads_compact_inputs_as_their_dense_tables():
    """Lanes whose W holds one column still (a constant), one varying, or every column varying read the same
    numbers as from the dense tables, bitwise; mixed in one call."""
    step, N, lanes = _step(), 250, 4
    rng = np.random.default_rng(11)
    z0 = rng.uniform(-1.0, 1.0, (2, lanes))
    dense = [np.ascontiguousarray(rng.uniform(-2.0, 2.0, (N, 2))) for _ in range(lanes)]
    dense[0][:, 1], dense[1][:, 0], dense[2][:] = 0.7, -1.3, [0.4, 0.2]  # w1 still; w0 still; both still
    given = [compact(W) for W in dense[:3]] + dense[3:]
    assert [W.columns.tolist() for W in given[:3]] == [[0], [1], []]
    compacted, plain = [np.empty((N, 2)) for _ in range(lanes)], [np.empty((N, 2)) for _ in range(lanes)]
    roll = compile_lanes(step, lanes)
    np.testing.assert_array_equal(roll.runs(z0, given, compacted), roll.runs(z0, dense, plain))
    for mine, theirs in zip(compacted, plain):
        np.testing.assert_array_equal(mine, theirs)
    with pytest.raises(CodegenError, match="compact inputs"):
        roll.runs(z0, [given[0][:-1]] + given[1:], compacted)  # one lane a sample short


@pytest.mark.skipif(shutil.which("objdump") is None, reason="no objdump (binutils) to read the library's code")
def test_the_dc_motor_step_runs_its_lanes_in_vector_registers():
    """The DC motor loop (PI with saturation, Luenberger, UKF) holds CasADi's ``c ? b : 0`` of comparisons,
    which gcc's partial redundancy elimination once turned into masks it could not vectorise: the lane
    loop then ran one lane at a time (only scalar double arithmetic, ...sd). Its lanes step must compute
    in packed doubles (...pd)."""
    if vector_doubles() < 4:
        pytest.skip("this processor has no 256-bit vectors")
    from uvsym.sim.system_scenario import parse_system_scenario

    root = Path(__file__).resolve().parents[1] / "examples" / "dc_motor"
    table = tomllib.loads((root / "speed_sensor_bias.toml").read_text())
    step = parse_system_scenario(table, root=root).loop.step
    listing = subprocess.run(["objdump", "-d", str(compile_lanes(step, 4).library)], capture_output=True,
                             text=True).stdout
    body = re.search(rf"<{step.name()}_lanes_step>:\n(.*?)\n\n", listing, re.S).group(1)
    arithmetic = r"v(add|sub|mul|div|fn?m(add|sub)\d*)"
    packed, scalar = len(re.findall(arithmetic + "pd", body)), len(re.findall(arithmetic + "sd", body))
    assert packed > 10 * max(scalar, 1), (packed, scalar)


def test_the_runs_roll_keeps_each_lanes_largest_state_and_finds_its_first_non_finite_row():
    """z_max: the largest |z_i| of z_0 .. z_k (out logs z_k before each step, z_end is z_k); first_bad: the
    first step whose row holds 1/0 or 0/0 in that lane only, counted within the call; -1 elsewhere."""
    z, w = ca.SX.sym("z", 2), ca.SX.sym("w", 1)
    step = ca.Function("lanes_watch", [z, w], [ca.vertcat(0.9 * z[0] + ca.sin(w), z[1] - 0.5),
                                              ca.vertcat(z, 1.0 / w, w / w)])
    lanes, N = 4, 60
    roll = compile_lanes(step, lanes)
    rng = np.random.default_rng(5)
    z0 = np.ascontiguousarray(rng.uniform(-3.0, 3.0, (2, lanes)))
    Ws = [np.ascontiguousarray(rng.uniform(0.5, 2.0, (N, 1))) for _ in range(lanes)]
    Ws[2][37, 0] = 0.0  # 1 / 0 and 0 / 0 at step 37 of lane 2
    outs = [np.empty((N, 4)) for _ in range(lanes)]
    z_max, first_bad = np.zeros((2, lanes)), np.full(lanes, -1, dtype=np.int_)
    z_end = roll.runs(z0, Ws, outs, z_max, first_bad)
    assert first_bad.tolist() == [-1, -1, 37, -1]
    for lane in range(lanes):
        states = np.vstack([outs[lane][:, :2], z_end[:, lane]])
        np.testing.assert_array_equal(z_max[:, lane], np.abs(states).max(axis=0))
    again = roll.runs(z_end, [W[:5] for W in Ws], [out[:5] for out in outs], z_max, first_bad)
    assert first_bad.tolist() == [-1, -1, 37, -1]  # kept: the first bad step is the caller's to clear
    assert np.all(z_max >= np.abs(again))
    first, fresh = np.zeros((1, lanes)), [np.empty((N, 4)) for _ in range(lanes)]  # the first entry only
    z_end = roll.runs(z0, Ws, fresh, first, np.full(lanes, -1, dtype=np.int_))
    for lane in range(lanes):
        assert first[0, lane] == np.abs(np.append(fresh[lane][:, 0], z_end[0, lane])).max()
    with pytest.raises(CodegenError, match="z_max"):
        roll.runs(z0, Ws, outs, np.zeros((2, lanes + 1)), first_bad)
    with pytest.raises(CodegenError, match="z_max"):
        roll.runs(z0, Ws, outs, np.zeros((3, lanes)), first_bad)  # more entries than z has
