"""The C package of the actuator observers: builds, runs clean under sanitizers, matches Python."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from uvsym.codegen import find_compiler
from uvsym.codegen.package import Exported, casadi_name, write_package
from uvsym.derivation import observer_set
from uvsym.errors import CodegenError

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="no C compiler (set $CC or install gcc)")

STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
FLOAT_RTOL = 1e-5  # single precision: bound on max |c - python| / max(1, max |python|) per call (normwise)


@pytest.fixture(scope="module")
def observers():
    made = observer_set("actuator-observers", vehicle="docking_auv", form="momentum")
    return made.package_name, made.description, list(made.exported)


@pytest.fixture(scope="module")
def package(tmp_path_factory, observers):
    name, description, functions = observers
    out = tmp_path_factory.mktemp("pkg")
    write_package(out, functions, name, "double", description)
    return out, name, functions


def _build_harness(package_dir: Path, name: str, extra: list[str]) -> Path:
    exe = package_dir / f"harness_{abs(hash(tuple(extra)))}"
    sources = [str(package_dir / "src" / f"{name}_casadi.c"), str(package_dir / "src" / f"{name}.c"),
               str(package_dir / "harness.c")]
    subprocess.run([find_compiler(), *STRICT, *extra, "-I", str(package_dir / "include"), *sources, "-o", str(exe),
                    "-lm"], check=True, capture_output=True, text=True)
    return exe


def _inputs(functions, rng, special: bool):
    """Records (index, [input arrays]) for every function: random, and NaN/Inf/huge when special."""
    records = []
    for index, e in enumerate(functions):
        f = e.function
        for _ in range(12):
            args = [rng.normal(scale=[3.0, 0.5, 2.0, 50.0, 1.0, 0.05][min(i, 5)], size=f.nnz_in(i))
                    for i in range(f.n_in())]
            args[-1] = np.abs(args[-1]) + 0.01 if f.name_in(f.n_in() - 1) == "dt" else np.abs(args[-1]) + 0.1
            if special and rng.random() < 0.5:
                which = rng.integers(f.n_in())
                args[which] = args[which].copy()
                args[which][rng.integers(args[which].size)] = rng.choice([np.nan, np.inf, -np.inf, 1e300, -1e300])
            records.append((index, args))
    return records


def _run(exe: Path, records) -> tuple[np.ndarray, list[np.ndarray], str]:
    """(return code per record, outputs per record, stderr) of the harness."""
    text = "\n".join(f"{i} " + " ".join(repr(float(v)) for a in args for v in a) for i, args in records) + "\n"
    done = subprocess.run([str(exe)], input=text, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    rows = [np.array([float(v) for v in line.split()]) for line in done.stdout.strip().splitlines()]
    return np.array([int(r[0]) for r in rows]), [r[1:] for r in rows], done.stderr


def _python(functions, records):
    rows = []
    for index, args in records:
        with np.errstate(all="ignore"):
            result = getattr(functions[index].function, "raw", functions[index].function)(*args)  # unchecked
        rows.append(np.concatenate([np.asarray(r, dtype=float).ravel(order="F") for r in result]))
    return rows


def test_same_inputs_give_byte_identical_packages(tmp_path, observers):
    name, description, functions = observers
    write_package(tmp_path / "a", functions, name, "double", description)
    again = observer_set("actuator-observers", vehicle="docking_auv", form="momentum")  # derived anew
    write_package(tmp_path / "b", list(again.exported), again.package_name, "double", again.description)
    files = sorted(p.relative_to(tmp_path / "a") for p in (tmp_path / "a").rglob("*") if p.is_file())
    assert len(files) == 10 and Path("README.md") in files
    for relative in files:
        assert (tmp_path / "a" / relative).read_bytes() == (tmp_path / "b" / relative).read_bytes(), relative


def test_make_builds_libraries_and_example_with_strict_cflags(tmp_path, package):
    source, name, _ = package
    work = tmp_path / "build"
    shutil.copytree(source, work)
    done = subprocess.run(["make", "CFLAGS=-std=c99 -O2 -Wall -Wextra -Werror -fPIC"], cwd=work,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    for artefact in (f"lib{name}.a", f"lib{name}.so", "example", "harness"):
        assert (work / artefact).exists(), artefact
    assert subprocess.run([str(work / "example")], capture_output=True, text=True).returncode == 0


def test_c_matches_python_under_sanitizers_and_flags_nan_inf_and_overflow(package):
    """Finite inputs: C equals Python (code 0), or code 3 where Python's outputs overflow too;
    a NaN or infinite input: code 2, outputs untouched."""
    source, name, functions = package
    exe = _build_harness(source, name, ["-O1", "-g", "-fsanitize=address,undefined", "-fno-sanitize-recover=all"])
    records = _inputs(functions, np.random.default_rng(7), special=True)
    codes, c_rows, stderr = _run(exe, records)
    assert "runtime error" not in stderr and "AddressSanitizer" not in stderr
    python_rows = _python(functions, records)
    assert len(c_rows) == len(python_rows) == len(records)
    for (index, args), code, c, py in zip(records, codes, c_rows, python_rows):
        if not all(np.all(np.isfinite(a)) for a in args):
            assert code == 2, functions[index].function.name()
            continue
        assert code == (0 if np.all(np.isfinite(py)) else 3), functions[index].function.name()
        scale = np.maximum(1.0, np.abs(np.where(np.isfinite(py), py, 0.0)))
        with np.errstate(invalid="ignore"):
            close = np.abs(c - py) <= 1e-12 * scale
        same_special = (np.isnan(c) & np.isnan(py)) | (np.isinf(c) & (c == py))
        assert np.all(close | same_special), functions[index].function.name()
    assert {0, 2, 3} <= set(codes.tolist())


def test_float_build_matches_python_within_its_bound(tmp_path, observers):
    name, description, functions = observers
    write_package(tmp_path, functions, name, "float", description)
    exe = _build_harness(tmp_path, name, ["-O2"])
    records = _inputs(functions, np.random.default_rng(3), special=False)
    codes, c_rows, _ = _run(exe, records)
    assert not codes.any()
    for c, py in zip(c_rows, _python(functions, records)):
        assert np.max(np.abs(c - py)) <= FLOAT_RTOL * max(1.0, float(np.max(np.abs(py))))


def test_the_double_library_loads_through_casadi_external(tmp_path, package):
    source, name, functions = package
    work = tmp_path / "build"
    shutil.copytree(source, work)
    subprocess.run(["make", f"lib{name}.so"], cwd=work, check=True, capture_output=True)
    combined = functions[-1].function
    loaded = ca.external(casadi_name(name, combined.name()), str(work / f"lib{name}.so"))
    rng = np.random.default_rng(0)
    args = [rng.normal(size=combined.nnz_in(i)) for i in range(combined.n_in())]
    for ours, theirs in zip(loaded(*args), combined(*args)):
        np.testing.assert_allclose(np.asarray(ours), np.asarray(theirs), rtol=1e-13, atol=1e-15)


def test_unknown_precision_and_bad_names_are_refused(tmp_path, observers):
    name, _, functions = observers
    with pytest.raises(CodegenError, match="unknown precision"):
        write_package(tmp_path, functions, name, "half")
    with pytest.raises(CodegenError, match="C identifier"):
        write_package(tmp_path, functions, "my-observers")


def test_generated_sources_allocate_nothing(package):
    source, _, _ = package
    code = "".join(p.read_text() for p in [*source.glob("src/*.c"), *source.glob("include/*.h"), source / "main.c"])
    for call in ("malloc(", "calloc(", "realloc(", "free("):
        assert call not in code, call
    assert "static casadi_real w[" in code  # work buffers are static


def test_check_package_compiles_compares_and_names_a_broken_source(tmp_path, observers):
    from uvsym.codegen.check import check_package

    name, description, functions = observers
    write_package(tmp_path, functions, name, "double", description)
    check = check_package(tmp_path, functions, name, calls=3)
    assert check.max_relative_difference <= 1e-12 and "-Werror" in check.flags
    source = tmp_path / "src" / f"{name}.c"
    source.write_text(source.read_text() + "\nstatic int unused_and_warned;\n")
    with pytest.raises(CodegenError, match="does not compile cleanly"):
        check_package(tmp_path, functions, name, calls=3)


def test_two_packages_of_either_precision_link_into_one_program_from_one_source_file(tmp_path):
    """Every external name carries the package's prefix and a package's header stands alone: a double and
    a float package that both export bias_step are included by one source file and linked together."""
    x = ca.SX.sym("x", 2)
    for package, expression, precision in (("pkg_a", x + 1, "double"), ("pkg_b", 2 * ca.sin(x), "float")):
        function = ca.Function("bias_step", [x], [expression], ["x"], ["y"])
        write_package(tmp_path / package, [Exported(function, ("x (-)",), ("y (-)",), "test")], package, precision)
    (tmp_path / "main.c").write_text("""#include <stdio.h>
#include "pkg_a.h"
#include "pkg_b.h"

int main(void) {
  pkg_a_real x[2] = {0.5, 1.0}, a[2];
  pkg_b_real xf[2] = {0.5f, 1.0f}, b[2];
  if (pkg_a_bias_step(x, a) || pkg_b_bias_step(xf, b)) return 1;
  printf("%.17g %.17g %.17g %.17g %d\\n", a[0], a[1], (double)b[0], (double)b[1], (int)sizeof b[0]);
  return 0;
}
""")
    sources = [str(tmp_path / p / "src" / f"{p}{suffix}.c") for p in ("pkg_a", "pkg_b") for suffix in ("_casadi", "")]
    includes = [flag for p in ("pkg_a", "pkg_b") for flag in ("-I", str(tmp_path / p / "include"))]
    exe = tmp_path / "both"
    done = subprocess.run([find_compiler(), *STRICT, *includes, str(tmp_path / "main.c"), *sources, "-o", str(exe),
                           "-lm"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    *values, float_size = [float(v) for v in subprocess.run([str(exe)], capture_output=True, text=True).stdout.split()]
    assert values[:2] == pytest.approx([1.5, 2.0], rel=1e-15) and float_size == 4
    assert values[2:] == pytest.approx([2 * np.sin(0.5), 2 * np.sin(1.0)], rel=1e-6)  # single precision


def test_a_filter_whose_covariance_is_indefinite_returns_unhealthy(tmp_path):
    """The C status covers the estimator's health: pd_margin <= 0 (where Python's run_filter raises) returns
    <NAME>_UNHEALTHY (4), a healthy step 0; the header and manifest say so."""
    import json

    from problems import double_integrator

    from uvsym.codegen.estimators import exported_observer
    from uvsym.observers.ukf import ukf

    obs = ukf(double_integrator(outputs=("pos",)), dt=0.1, Q=np.diag([1e-4, 1e-2]), R=0.01, P0=np.eye(2))
    exported = exported_observer(obs)
    write_package(tmp_path, [exported], "filt", "double", "UKF of a double integrator")
    header = (tmp_path / "include" / "filt.h").read_text()
    assert "FILT_UNHEALTHY 4" in header and "FILT_NONFINITE_OUTPUT or FILT_UNHEALTHY." in header
    assert json.loads((tmp_path / "manifest.json").read_text())["return_codes"]["FILT_UNHEALTHY"]["value"] == 4
    exe = _build_harness(tmp_path, "filt", ["-O1"])
    x, y, u, p = [0.5, -0.2], [0.4], [0.1], []
    healthy, indefinite = [1.0, 0.0, 1.0], [1.0, 0.0, -1.0]  # tril(P) column by column: P = diag(1, +-1)
    codes, outputs, _ = _run(exe, [(0, [np.array(x + healthy), np.array(y), np.array(u), np.array(p)]),
                                   (0, [np.array(x + indefinite), np.array(y), np.array(u), np.array(p)])])
    margin = obs.publishes.index("pd_margin")
    python = [np.asarray(obs.step(x + P, y, u, p)[1]).ravel()[margin] for P in (healthy, indefinite)]
    assert python[0] > 0 >= python[1]
    assert codes.tolist() == [0, 4]
    assert outputs[1][len(x) + 3 + margin] == pytest.approx(python[1])
