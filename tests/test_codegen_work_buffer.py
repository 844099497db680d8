"""A C package whose function needs CasADi work buffers (real w and integer iw) and more argument slots than
it has inputs: no shipped observer does, so the wrapper's buffer sizing is exercised here, under AddressSanitizer,
against answers worked out independently (numpy's solve, linear interpolation of t^2 by hand)."""

from __future__ import annotations

import subprocess

import casadi as ca
import numpy as np
import pytest

from uvsym.codegen import find_compiler
from uvsym.codegen.package import Exported, write_package

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="no C compiler (set $CC or install gcc)")
CFLAGS = ["-std=c99", "-O1", "-g", "-Wall", "-Wextra", "-Werror", "-pedantic", "-fsanitize=address,undefined",
          "-fno-sanitize-recover=all"]


def _buffered() -> ca.Function:
    """(b (3,), a (9,) column-major A, t) -> (y = A^-1 b (3,), z = linear interpolation of s^2 at s = 0..3 (1,))."""
    b, a, t = ca.MX.sym("b", 3), ca.MX.sym("a", 9), ca.MX.sym("t")
    square = ca.interpolant("square", "linear", [[0.0, 1.0, 2.0, 3.0]], [0.0, 1.0, 4.0, 9.0])
    return ca.Function("solve", [b, a, t], [ca.solve(ca.reshape(a, 3, 3), b, "qr", {}), square(t)],
                       ["b", "a", "t"], ["y", "z"])


def test_a_function_with_work_buffers_runs_clean_and_matches_independent_answers(tmp_path):
    function = _buffered()
    assert function.sz_w() > 0 and function.sz_iw() > 0 and function.sz_arg() > function.n_in()
    write_package(tmp_path, [Exported(function, ("b", "A, column-major", "t (s)"), ("y", "z"), "solve and look up")],
                  "buffered")
    sources = [tmp_path / "src" / "buffered_casadi.c", tmp_path / "src" / "buffered.c", tmp_path / "harness.c"]
    exe = tmp_path / "harness"
    subprocess.run([find_compiler(), *CFLAGS, "-I", str(tmp_path / "include"), *map(str, sources), "-o", str(exe),
                    "-lm"], check=True, capture_output=True, text=True)
    rng = np.random.default_rng(5)
    cases = [(rng.normal(size=3), rng.normal(size=(3, 3)) + 3 * np.eye(3), t) for t in (0.0, 0.5, 1.25, 2.75, 3.0)]
    text = "".join("0 " + " ".join(repr(float(v)) for v in np.r_[b, A.ravel(order="F"), t]) + "\n"
                   for b, A, t in cases)
    done = subprocess.run([str(exe)], input=text, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and "runtime error" not in done.stderr, done.stderr
    rows = [np.array([float(v) for v in line.split()]) for line in done.stdout.splitlines()]
    assert len(rows) == len(cases)
    for row, (b, A, t) in zip(rows, cases):
        assert row[0] == 0  # BUFFERED_OK
        np.testing.assert_allclose(row[1:4], np.linalg.solve(A, b), rtol=1e-12, atol=1e-14)
        lower = min(int(t), 2)  # the segment [lower, lower + 1] holding t; s^2 at its ends, linearly between
        assert row[4] == pytest.approx(lower**2 + (t - lower) * (2 * lower + 1), rel=1e-15, abs=1e-15)
    source = (tmp_path / "src" / "buffered.c").read_text()
    assert "static casadi_real w[buffered_casadi_solve_SZ_W > 0 ? buffered_casadi_solve_SZ_W : 1];" in source
    assert "static casadi_int iw[buffered_casadi_solve_SZ_IW > 0 ? buffered_casadi_solve_SZ_IW : 1];" in source
