"""What a C package gives an outside user: example on experiment data, README, units, citation,
install and find_package, linking several packages, finite check, refused float builds."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import warnings
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from derivations.papers import paper
from uvsym.cli import main
from uvsym.codegen import find_compiler
from uvsym.codegen.arguments import Entries, per_second, unit_symbol
from uvsym.codegen.example import Example
from uvsym.codegen.observer_sets import ObserverSet
from uvsym.codegen.package import Exported, write_package
from uvsym.derivation import observer_set
from uvsym.errors import CodegenError, PrecisionError
from uvsym.models.registry import vehicle
from uvsym.observers.actuator import actuator_observer

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="no C compiler (set $CC or install gcc)")
STRICT = ["-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", "-pedantic"]
DOCKING_BIAS_N, RUDDER_FACTOR = 13.0, 0.8  # the faults injected in the shipped docking scenario


@pytest.fixture(scope="module")
def docking(tmp_path_factory):
    made = observer_set("actuator-observers", vehicle="docking_auv", form="momentum")
    out = tmp_path_factory.mktemp("docking")
    return made, out, made.write(out)


def _compile(out: Path, name: str, program: str, exe: Path) -> Path:
    sources = [out / program, out / "src" / f"{name}_casadi.c", out / "src" / f"{name}.c"]
    done = subprocess.run([find_compiler(), *STRICT, "-I", str(out / "include"), *map(str, sources), "-o", str(exe),
                           "-lm"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return exe


def _printed(exe: Path) -> dict[str, np.ndarray]:
    done = subprocess.run([str(exe)], capture_output=True, text=True, check=True)
    return {line.split()[0]: np.array([float(v) for v in line.split()[1:]]) for line in done.stdout.splitlines()}


def _raw(function):
    return getattr(function, "raw", function)


def test_main_c_runs_the_docking_step_and_prints_what_python_computes(docking, tmp_path):
    made, out, manifest = docking
    assert manifest["example"]["function"] == "uvsym_docking_auv_observers_actuator_observers_step"
    printed = _printed(_compile(out, made.package_name, "main.c", tmp_path / "example"))
    combined = next(e.function for e in made.exported if e.function.name() == made.example.function)
    expected = [np.asarray(r).ravel() for r in _raw(combined)(*made.example.first_call())]
    for (name, values), python in zip(printed.items(), expected):
        np.testing.assert_allclose(values, python, rtol=1e-14, atol=1e-300, err_msg=name)
    f_hat = printed["f_hat"].reshape(3, 6)  # proportional, bias, constant; channels X Y Z K M N
    assert f_hat[1, 0] == pytest.approx(DOCKING_BIAS_N, abs=0.01)  # the thruster bias, converged
    assert f_hat[0, [1, 5]] == pytest.approx([RUDDER_FACTOR] * 2, abs=1e-3)  # both rudders at 80 %


def test_motor_main_c_prints_what_python_computes(tmp_path):
    made = observer_set("motor-luenberger")
    made.write(tmp_path / "pkg")
    assert made.citation == ""  # uvsym's own Luenberger design: it implements no paper's observer
    printed = _printed(_compile(tmp_path / "pkg", made.package_name, "main.c", tmp_path / "example"))
    expected = [np.asarray(r).ravel() for r in _raw(made.exported[0].function)(*made.example.first_call())]
    assert list(printed) == ["s_next", "out"]
    for values, python in zip(printed.values(), expected):
        np.testing.assert_allclose(values, python, rtol=1e-14)
    prototypes = re.findall(r"(?m)^int uvsym_induction_motor_\w+\(.*\);$", (tmp_path / "pkg" / "README.md").read_text())
    header = (tmp_path / "pkg" / "include" / "uvsym_induction_motor.h").read_text()
    assert prototypes and all(p in header for p in prototypes)  # p[0] is a pointer in both (no zero-size arrays)
    measured = made.example.first_call()[1]  # i_sq, i_sd, omega_m as the noisy sensors read them
    assert np.abs(printed["out"][[0, 1, 4]] - measured).max() < 0.5  # converged estimates near the readings


def test_readme_header_and_manifest_document_units_codes_threads_and_cite_the_paper(docking):
    made, out, manifest = docking
    reference = paper("liu2014").reference()
    readme, header = (out / "README.md").read_text(), (out / "include" / f"{made.package_name}.h").read_text()
    assert manifest["citation"] == reference and reference in readme and reference in header
    for f in manifest["functions"]:
        assert f"`{f['c_function']}`" in readme and f"int {f['c_function']}(" in header
        for argument in f["inputs"] + f["outputs"]:
            assert len(argument["units"]) == len(argument["entries"]) == argument["size"], argument["name"]
            assert not any(" " in unit for unit in argument["units"]), argument["units"]
    for macro, code in manifest["return_codes"].items():
        assert f"#define {macro} {code['value']}" in header and f"`{macro}`" in readme
    for needed in ("`make`", "find_package", "thread-safe", "not reentrant", "-lm", "## Return codes"):
        assert needed in readme, needed
    bias_rate = manifest["functions"][2]["outputs"][0]  # bias_observer's x_dot: N/s, N/s, N/s, (N*m)/s x 3
    assert bias_rate["units"] == ["N/s"] * 3 + ["(N*m)/s"] * 3
    assert "[5] N [(N*m)/s]" in header and "N m/s" not in header
    everything = "".join(p.read_text() for p in out.rglob("*") if p.is_file())
    assert "seeds/" not in everything and "core paper" not in everything


def test_units_are_written_unambiguously():
    assert unit_symbol("N m") == "N*m" and unit_symbol(" kg  m^2 ") == "kg*m^2" and unit_symbol("") == "-"
    assert per_second("N m") == "(N*m)/s" and per_second("N") == "N/s" and per_second("-") == "1/s"
    assert per_second("m^2") == "m^2/s" and per_second("m/s") == "(m/s)/s"


def test_two_observer_packages_link_into_one_program_and_export_only_prefixed_names(tmp_path, docking):
    made, out, _ = docking
    other = observer_set("actuator-observers", vehicle="otter3dof", form="momentum")
    other.write(tmp_path / "otter")
    packages = {made.package_name: out, other.package_name: tmp_path / "otter"}
    objects = []
    for name, folder in packages.items():  # every defined external symbol carries the package's name
        for source in ("_casadi", ""):
            objects.append(tmp_path / f"{name}{source}.o")
            subprocess.run([find_compiler(), *STRICT, "-c", "-I", str(folder / "include"),
                            str(folder / "src" / f"{name}{source}.c"), "-o", str(objects[-1])], check=True)
            symbols = subprocess.run(["nm", "-g", "--defined-only", str(objects[-1])], capture_output=True, text=True,
                                     check=True).stdout.split()[2::3]
            assert symbols and all(s.startswith(name) for s in symbols), [s for s in symbols if not s.startswith(name)]
    (tmp_path / "both.c").write_text(f"""#include <stdio.h>
#include "{made.package_name}.h"
#include "{other.package_name}.h"

int main(void) {{
  double x6[6] = {{0}}, eta6[6] = {{0}}, nu6[6] = {{1, 0, 0, 0, 0, 0}}, tau6[6] = {{10, 0, 0, 0, 0, 0}}, k6[6];
  double x3[3] = {{0}}, eta3[3] = {{0}}, nu3[3] = {{1, 0, 0}}, tau3[3] = {{10, 0, 0}}, k3[3];
  double dot6[6], f6[6], dot3[3], f3[3];
  int i;
  for (i = 0; i < 6; ++i) k6[i] = 1.0;
  for (i = 0; i < 3; ++i) k3[i] = 1.0;
  if ({made.package_name}_proportional_observer(x6, eta6, nu6, tau6, k6, dot6, f6)) return 1;
  if ({other.package_name}_proportional_observer(x3, eta3, nu3, tau3, k3, dot3, f3)) return 2;
  printf("%.17g %.17g\\n", f6[0], f3[0]);
  return 0;
}}
""")
    includes = [flag for folder in packages.values() for flag in ("-I", str(folder / "include"))]
    done = subprocess.run([find_compiler(), *STRICT, *includes, str(tmp_path / "both.c"), *map(str, objects),
                           "-o", str(tmp_path / "both"), "-lm"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    values = [float(v) for v in subprocess.run([str(tmp_path / "both")], capture_output=True, text=True,
                                               check=True).stdout.split()]
    for value, model in zip(values, ("docking_auv", "otter3dof")):
        n = vehicle(model).dof
        python = actuator_observer(vehicle(model), "proportional", "momentum").function.raw(
            np.zeros(n), np.zeros(n), np.eye(n)[0], 10 * np.eye(n)[0], np.ones(n))[1]
        assert value == pytest.approx(float(np.asarray(python).ravel()[0]), rel=1e-13, abs=1e-300)


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("cmake") is None, reason="cmake is not installed: install() and find_package untested")
def test_cmake_release_build_installs_a_package_that_find_package_links(tmp_path, docking):
    made, out, _ = docking
    name, build, prefix = made.package_name, tmp_path / "build", tmp_path / "prefix"
    for command in (["cmake", "-S", str(out), "-B", str(build), "-DCMAKE_EXPORT_COMPILE_COMMANDS=ON"],
                    ["cmake", "--build", str(build)], ["cmake", "--install", str(build), "--prefix", str(prefix)]):
        done = subprocess.run(command, capture_output=True, text=True)
        assert done.returncode == 0, done.stdout + done.stderr
    assert "CMAKE_BUILD_TYPE:STRING=Release" in (build / "CMakeCache.txt").read_text()
    commands = " ".join(c["command"] for c in json.loads((build / "compile_commands.json").read_text()))
    assert all(flag in commands for flag in ("-O3", "-Wall", "-Wextra", "-pedantic", "-std=c99"))
    consumer = tmp_path / "consumer"
    consumer.mkdir()
    shutil.copy(out / "main.c", consumer / "main.c")
    (consumer / "CMakeLists.txt").write_text(f"""cmake_minimum_required(VERSION 3.10)
project(consumer C)
find_package({name} REQUIRED)
add_executable(consumer main.c)
target_link_libraries(consumer PRIVATE {name}::{name})
""")
    for command in (["cmake", "-S", str(consumer), "-B", str(consumer / "build"), f"-DCMAKE_PREFIX_PATH={prefix}"],
                    ["cmake", "--build", str(consumer / "build")]):
        done = subprocess.run(command, capture_output=True, text=True)
        assert done.returncode == 0, done.stdout + done.stderr
    assert _printed(consumer / "build" / "consumer").keys() == {"x_next", "f_hat"}
    assert (prefix / "share" / name / "README.md").exists()


def _tiny(finite_check: bool, out: Path) -> Path:
    x = ca.SX.sym("x", 2)
    function = ca.Function("halve", [x], [ca.vertcat(x[0] / 2, 1 / x[1])], ["x"], ["y"])
    write_package(out, [Exported(function, (Entries("x", ("a", "b"), ("m", "m")),), ("y (m, 1/m)",), "halve")],
                  "tiny", finite_check=finite_check)
    return _compile(out, "tiny", "harness.c", out / "harness")


def test_finite_check_codes_and_the_option_to_leave_it_out(tmp_path):
    records = "0 1 2\n0 nan 2\n0 1 0\n"  # fine; a NaN input; an infinite output (1/0)
    checked = subprocess.run([str(_tiny(True, tmp_path / "on"))], input=records, capture_output=True, text=True)
    lines = [line.split() for line in checked.stdout.splitlines()]
    assert [line[0] for line in lines] == ["0", "2", "3"] and lines[0][1:] == ["0.5", "0.5"]
    assert lines[2][1:] == ["0.5", "inf"]  # outputs written when an output is not finite
    unchecked = subprocess.run([str(_tiny(False, tmp_path / "off"))], input=records, capture_output=True, text=True)
    assert [line.split()[0] for line in unchecked.stdout.splitlines()] == ["0", "0", "0"]
    assert "isfinite" not in (tmp_path / "off" / "src" / "tiny.c").read_text()
    manifest = json.loads((tmp_path / "off" / "manifest.json").read_text())
    assert not manifest["finite_check"] and "TINY_NONFINITE_INPUT" not in manifest["return_codes"]
    assert main(["codegen", "motor-luenberger", "--no-finite-check", "-o", str(tmp_path / "cli")]) == 0
    assert not json.loads((tmp_path / "cli" / "manifest.json").read_text())["finite_check"]
    assert "isfinite" not in (tmp_path / "cli" / "src" / "uvsym_induction_motor.c").read_text()


def _stiff(made, factor: float) -> Example:
    """The docking example with the proportional gains times ``factor`` and its states kept consistent
    (x = f_hat + R(nu, tau_d, K)): the double step is as good as before, float must resolve a
    difference of terms ``factor`` times larger."""
    x, eta, nu, tau_d, K, dt = (np.array(a) for a in made.example.inputs)
    R = actuator_observer(vehicle("docking_auv"), "proportional", "momentum").R.map(made.example.samples)
    stiff = K.copy()
    stiff[:, :6] *= factor
    x[:, :6] += (np.asarray(R(nu.T, tau_d.T, stiff[:, :6].T)) - np.asarray(R(nu.T, tau_d.T, K[:, :6].T))).T
    return Example(made.example.function, (x, eta, nu, tau_d, stiff, dt), f"stiff gains (x {factor:g})")


def test_float_export_is_measured_and_refused_when_the_gains_are_stiff_for_the_step(docking, tmp_path, capsys):
    made, _, _ = docking
    command = ["codegen", "actuator-observers", "--vehicle", "docking_auv", "--float", "-o", str(tmp_path / "ok")]
    assert main(command) == 0
    check = json.loads((tmp_path / "ok" / "manifest.json").read_text())["float_check"]
    assert check["samples"] == 500 and check["max_relative_difference"] <= 1e-4
    assert "largest relative difference" in capsys.readouterr().out
    stiff = ObserverSet(made.package_name, made.description, made.exported, made.citation, _stiff(made, 1e4))
    with pytest.raises(PrecisionError, match=r"strays [0-9.e+]+ \(relative\).*more than 0.001") as refused:
        stiff.write(tmp_path / "stiff", "float")
    assert float(re.search(r"strays ([0-9.e+]+)", str(refused.value)).group(1)) > 1.0
    assert not (tmp_path / "stiff").exists()  # refused before anything was written
    stiff.write(tmp_path / "stiff-double")  # double precision resolves the same data
    no_example = ObserverSet("tiny_set", "no data", made.exported[:1])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert "float_check" not in no_example.write(tmp_path / "unmeasured", "float")
    assert any("not measured" in str(w.message) for w in caught)


def test_bad_examples_and_units_are_typed_errors(docking, tmp_path):
    made, _, _ = docking
    function = made.exported[0].function
    with pytest.raises(CodegenError, match="argument K has 6 entries, its units 2"):
        Exported(function, (*made.exported[0].input_units[:4], Entries("K", ("a", "b"), ("1/s", "1/s"))),
                 made.exported[0].output_units, "bad")
    with pytest.raises(CodegenError, match="2 units for 3 entries"):
        Entries("eta", ("x", "y", "z"), ("m", "m"))
    rows = [np.zeros((2, 6))] * 5
    with pytest.raises(CodegenError, match="finite"):
        Example("proportional_observer", (np.full((2, 6), np.nan), *rows[1:]), "nan")
    with pytest.raises(CodegenError, match="same number"):
        Example("proportional_observer", (np.zeros((3, 6)), *rows[1:]), "rows")
    with pytest.raises(CodegenError, match="input eta has 6 entries, the example's rows 2"):
        Example("proportional_observer", (rows[0], np.zeros((2, 2)), *rows[2:]), "size").check_against(function)
    with pytest.raises(CodegenError, match="calls nowhere_step, not one of"):
        write_package(tmp_path, list(made.exported), "pkg", example=Example("nowhere_step", rows, "x"))
    with pytest.raises(CodegenError, match="example must be an Example"):
        ObserverSet("pkg", "d", made.exported, example={"x": 1})


def test_the_documented_rk4_stability_bound_of_the_exported_steps(docking):
    """bias_step (momentum form: e' = -K e) amplifies an error by the RK4 polynomial of z = K dt:
    below 1 in size up to z = 2.785, above 1 beyond, as its description says (2.78)."""
    made, _, _ = docking
    step = next(e for e in made.exported if e.function.name() == "bias_step")
    assert "below 2.78" in step.description
    rng = np.random.default_rng(1)
    eta, nu, tau_d = rng.normal(size=6), rng.normal(size=6), 10 * rng.normal(size=6)
    x0, delta, dt = rng.normal(size=6), 1e-3 * np.ones(6), 0.01
    for z in (0.5, 2.7, 2.9):
        K = np.full(6, z / dt)
        base, moved = (np.asarray(_raw(step.function)(x, eta, nu, tau_d, K, dt)[0]).ravel() for x in (x0, x0 + delta))
        factor = (moved - base) / delta
        np.testing.assert_allclose(factor, 1 - z + z**2 / 2 - z**3 / 6 + z**4 / 24, rtol=1e-6)
        assert (np.abs(factor) < 1).all() == (z < 2.78)


def test_a_package_of_empty_arguments_compiles_without_an_unused_finite_check(tmp_path):
    function = ca.Function("nothing", [ca.SX.sym("x", 0)], [ca.SX.sym("y", 0)], ["x"], ["y"])
    write_package(tmp_path, [Exported(function, ("x (-)",), ("y (-)",), "empty")], "empty")
    done = subprocess.run([find_compiler(), *STRICT, "-c", "-I", str(tmp_path / "include"),
                           str(tmp_path / "src" / "empty.c"), "-o", str(tmp_path / "empty.o")], capture_output=True,
                          text=True)
    assert done.returncode == 0, done.stderr


def test_exported_functions_and_package_names_are_checked(tmp_path):
    x, m = ca.SX.sym("x", 2), ca.SX.sym("m", 2, 2)
    twice = ca.Function("twice", [x], [2 * x], ["x"], ["y"])
    with pytest.raises(CodegenError, match=r"twice: give one unit per input \(1\) and output \(1\)"):
        Exported(twice, (), ("y",), "doubles x")
    with pytest.raises(CodegenError, match=r"twice: give one unit per input \(1\) and output \(1\)"):
        Exported(twice, ("x",), ("y", "z"), "doubles x")
    with pytest.raises(CodegenError, match="first: input m must be a dense column vector"):
        Exported(ca.Function("first", [m], [m[0, 0]], ["m"], ["y"]), ("m",), ("y",), "reads m")
    with pytest.raises(CodegenError, match="twice: argument y has 2 entries, its units 1"):
        Exported(twice, ("x",), (Entries("y", ("a",), ("m",)),), "doubles x")
    exported = Exported(twice, ("x",), ("y",), "doubles x")
    with pytest.raises(CodegenError, match="'2pkg' is not a C identifier"):
        write_package(tmp_path / "a", [exported], "2pkg")
    with pytest.raises(CodegenError, match="package pkg: function names must differ; given twice, twice"):
        write_package(tmp_path / "b", [exported, exported], "pkg")
    with pytest.raises(CodegenError, match="unknown precision 'half'; known: double, float"):
        write_package(tmp_path / "c", [exported], "pkg", "half")
    assert not any((tmp_path / name).exists() for name in "abc")  # refused before anything is written
    (tmp_path / "a_file").write_text("not a folder")
    with pytest.raises(CodegenError, match=r"^cannot write the package into \S+a_file: \S+ is a file, not a folder$"):
        write_package(tmp_path / "a_file", [exported], "pkg")


def test_build_files_manifest_names_and_layout_follow_the_package_name(tmp_path):
    """The module docstring's layout: a Makefile (make finds no other spelling) and a CMakeLists.txt for the
    package's own name, the CasADi API named <name>_casadi_<function>, manifest.json with sorted keys indented by
    two spaces (so that the same package gives the same bytes)."""
    x = ca.SX.sym("x", 2)
    twice = Exported(ca.Function("twice", [x], [2 * x], ["x"], ["y"]), ("x",), ("y",), "doubles x")
    manifest = write_package(tmp_path, [twice], "pkg")
    written = {p.name for p in tmp_path.iterdir()}
    assert {"Makefile", "CMakeLists.txt", "manifest.json"} <= written and "makefile" not in written
    assert {"Makefile", "CMakeLists.txt"} <= set(manifest["files"])
    assert "libpkg.a" in (tmp_path / "Makefile").read_text()
    assert re.search(r"(?m)^project\(pkg VERSION ", (tmp_path / "CMakeLists.txt").read_text())
    assert "None" not in (tmp_path / "CMakeLists.txt").read_text()
    text = (tmp_path / "manifest.json").read_text()
    assert json.loads(text)["functions"][0]["casadi_function"] == "pkg_casadi_twice"
    assert manifest["functions"][0]["casadi_function"] == "pkg_casadi_twice"
    assert "int pkg_casadi_twice(" in (tmp_path / "src" / "pkg_casadi.c").read_text()  # the name the manifest gives
    # sorted top-level keys start with "casadi" (the version); nested keys one level deeper by two more spaces
    assert text.startswith('{\n  "casadi": "') and '\n    "PKG_OK": {\n      "meaning": ' in text


# --- C package: SX graphs and header comments (mutation survivors) -----------------------------------------------


def test_a_renamed_sx_function_stays_an_sx_graph():
    from uvsym.codegen.package import _renamed
    x = ca.SX.sym("x", 2)
    renamed = _renamed(ca.Function("f", [x], [x[0] * x[1]], ["x"], ["y"]), "g")
    assert renamed.is_a("SXFunction") and renamed.name() == "g" and float(renamed([2.0, 3.0])) == 6.0


def test_the_header_comment_is_one_line_per_entry_before_the_prototype(tmp_path):
    x = ca.SX.sym("x", 2)
    function = ca.Function("halve", [x], [x / 2], ["x"], ["y"])
    write_package(tmp_path, [Exported(function, (Entries("x", ("a", "b"), ("m", "m")),), ("y (m)",), "halve")],
                  "tiny")
    expected = ("/* halve\n *\n * in  x[2]: x\n *       [0] a [m]\n *       [1] b [m]\n * out y[2]: y (m)\n"
                " * Returns TINY_OK, TINY_EVAL_FAILED, TINY_NONFINITE_INPUT or TINY_NONFINITE_OUTPUT.\n"
                " * Uses static work buffers: not reentrant. */\n"
                "int tiny_halve(const tiny_real x[2], tiny_real y[2]);\n")
    assert expected in (tmp_path / "include" / "tiny.h").read_text()
