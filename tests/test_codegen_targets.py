"""Every shipped observer set built for Cortex-M4F (float and soft-float double) and Cortex-M7 (double), run
under qemu, compared with CasADi's evaluation; the figures and the budget; the host target."""

from __future__ import annotations

import json
import struct
import subprocess

import numpy as np
import pytest

from uvsym.codegen.example import evaluate_rows
from uvsym.codegen.precision import FLOAT_TOLERANCE
from uvsym.codegen.target_run import FORBIDDEN, BudgetError, check_budget, missing_tools
from uvsym.codegen.targets import TARGETS, target_vectors
from uvsym.derivation import observer_set

SETS = ("actuator-observers", "motor-luenberger", "sensor-fdi-lms", "usv-fukf-mmae", "motor-hybrid-observer")
BUILDS = (("cortex-m4f", "float"), ("cortex-m4f", "double"), ("cortex-m7", "double"))
DOUBLE_ULPS = 16  # double builds: |C - Python| within 16 ulp (2^-52) of each output's scale max(1, max|Python|)
STRICT = "-std=c99 -O2 -Wall -Wextra -Werror -pedantic"


def _needs(target: str):
    missing = missing_tools(TARGETS[target])
    if missing:
        pytest.skip(f"{', '.join(missing)} not installed (scripts/install-arm-toolchain.sh installs them)")


@pytest.fixture(scope="session")
def built(tmp_path_factory):
    """``built(set, target, precision)``: (observer set, folder, manifest), written (and measured) once."""
    cache = {}

    def build(name: str, target: str, precision: str):
        _needs(target)
        if (name, target, precision) not in cache:
            made = observer_set(name)
            out = tmp_path_factory.mktemp(f"{name}-{target}-{precision}")
            cache[name, target, precision] = made, out, made.write(out, precision, target=target)
        return cache[name, target, precision]

    return build


def _harness_rows(printed: str, precision: str) -> dict[int, np.ndarray]:
    """A harness's printed lines: outputs per function index, decoded from their bits."""
    lines = printed.split("\n")
    assert "end" in lines
    code, width = ("<d", 8) if precision == "double" else ("<f", 4)
    rows: dict[int, list] = {}
    for line in lines:
        if line.startswith("r "):
            parts = line.split()
            values = [struct.unpack(code, int(h, 16).to_bytes(width, "little"))[0] for h in parts[6:]]
            rows.setdefault(int(parts[1]), []).append(values)
    return {k: np.array(v) for k, v in rows.items()}


@pytest.mark.parametrize("target,precision", BUILDS)
@pytest.mark.parametrize("name", SETS)
def test_the_package_runs_on_the_target_as_python_computes(built, name, target, precision):
    made, out, manifest = built(name, target, precision)
    got = _harness_rows((out / "target" / "harness.out").read_text(), precision)
    vectors = target_vectors(list(made.exported), made.example)
    for k, (e, v) in enumerate(zip(made.exported, vectors)):
        expected = evaluate_rows(e.function, v)
        assert got[k].shape == expected.shape, e.function.name()
        scale = np.maximum(1.0, np.nanmax(np.abs(expected), axis=1, initial=0.0))[:, None]
        both_nan = np.isnan(expected) & np.isnan(got[k])
        error = np.where(both_nan, 0.0, np.abs(got[k] - expected)) / scale
        bound = DOUBLE_ULPS * 2.0**-52 if precision == "double" else FLOAT_TOLERANCE
        assert np.all(error <= bound), (e.function.name(), float(np.nanmax(error)))
    figures = manifest["target"]
    assert figures["flash"] > 0 and figures["ram"] > 0
    assert not set(figures["library_symbols"]) & set(FORBIDDEN)
    check = figures["cppcheck"]
    assert check is None or check["timed_out_s"] or check["findings"] == [], check
    if check is not None and not check["timed_out_s"]:  # the wrappers return early: MISRA C:2012 rule 15.5
        assert check["misra"]["rules"]["15.5"] > 0 and "MISRA C:2012 addon" in (out / "README.md").read_text()
    for function in figures["functions"].values():
        assert function["stack_bound"] is not None and function["stack_measured"] > 0
        assert function["instructions"] > 0
    text = (out / "README.md").read_text()
    assert f"## Target: {target}" in text and f"-mcpu={TARGETS[target].flags[0].split('=')[1]}" in text


def test_issue_targets_stack_and_cost_of_the_actuator_lms_and_ukf_bank_steps(built):
    """The actuator-observer and LMS steps within 5 kB of stack and 50,000 instructions per call on an M4F
    in float; the UKF bank's step within 1 ms: 168,000 instructions at 168 MHz on an M4F in float,
    600,000 at 600 MHz on an M7 in double (one instruction per cycle)."""
    for name, function in (("actuator-observers", "actuator_observers_step"), ("sensor-fdi-lms", None)):
        figures = built(name, "cortex-m4f", "float")[2]["target"]
        steps = [f for n, f in figures["functions"].items() if function is None or n == function]
        assert steps and all(max(f["stack_bound"], f["stack_measured"]) <= 5120 for f in steps)
        assert all(f["instructions"] <= 50000 for f in steps), [f["instructions"] for f in steps]
    for target, precision, most in (("cortex-m4f", "float", 168000), ("cortex-m7", "double", 600000)):
        figures = built("usv-fukf-mmae", target, precision)[2]["target"]
        assert figures["functions"]["ukf_step"]["instructions"] <= most, (target, figures["functions"])


def test_a_float_build_calls_float_math_only(built):
    """No double arithmetic or double libm in an M4F float build: CasADi writes sqrt, sin, 2.*x."""
    symbols = built("usv-fukf-mmae", "cortex-m4f", "float")[2]["target"]["library_symbols"]
    assert "sqrtf" in symbols and "sinf" in symbols
    assert not [s for s in symbols if s.startswith("__aeabi_d") or s in ("sqrt", "sin", "cos", "exp", "log")], symbols


def test_figures_are_reproducible_to_the_instruction(built, tmp_path):
    made, _, manifest = built("motor-luenberger", "cortex-m4f", "float")
    again = made.write(tmp_path, "float", target="cortex-m4f")["target"]
    assert again["functions"] == manifest["target"]["functions"] and again["flash"] == manifest["target"]["flash"]


@pytest.mark.parametrize("target,precision", (("cortex-m4f", "float"), ("cortex-m7", "double")))
def test_make_run_target_prints_what_the_package_recorded(built, target, precision):
    """The package's own `make run-target`, built with -Werror -pedantic, prints target/harness.out to the tick."""
    _, out, _ = built("sensor-fdi-lms", target, precision)
    flags = " ".join([STRICT, *TARGETS[target].flags])
    done = subprocess.run(["make", "-s", "-C", str(out), "run-target", f"TARGET_CFLAGS={flags}"], capture_output=True,
                          text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout + done.stderr == (out / "target" / "harness.out").read_text()


def test_a_budget_names_the_figure_it_refuses(built, tmp_path):
    made, _, manifest = built("motor-luenberger", "cortex-m4f", "float")
    figures = manifest["target"]
    stack = figures["functions"]["luenberger_step"]["stack_bound"]
    check_budget(figures, {"stack": 5120, "instructions": 50000, "flash": figures["flash"]})
    with pytest.raises(BudgetError, match=r"stack of luenberger_step on cortex-m4f \(float\) is \d+ bytes, over"):
        check_budget(figures, {"stack": stack - 1})
    with pytest.raises(BudgetError, match=r"flash \d+ bytes on cortex-m4f \(float\) exceeds the budget of 10 bytes"):
        made.write(tmp_path / "refused", "float", target="cortex-m4f", budget={"flash": 10})
    assert not (tmp_path / "refused").exists()  # refused before anything is written


def test_the_cli_writes_a_target_build_and_refuses_a_bad_budget(tmp_path, capsys):
    from uvsym.cli import main

    _needs("cortex-m4f")
    assert main(["codegen", "motor-luenberger", "-o", str(tmp_path / "pkg"), "--target", "cortex-m4f", "--float",
                 "--budget", "stack=5120,instructions=50000"]) == 0
    assert "instructions per call" in capsys.readouterr().out
    manifest = json.loads((tmp_path / "pkg" / "manifest.json").read_text())
    assert "target/harness.c" in manifest["files"] and "target/toolchain.cmake" in manifest["files"]
    assert "-mfpu=fpv4-sp-d16" in (tmp_path / "pkg" / "target" / "toolchain.cmake").read_text()
    assert main(["codegen", "motor-luenberger", "-o", str(tmp_path / "b"), "--target", "cortex-m4f",
                 "--budget", "heap=1"]) != 0


def test_the_host_target_runs_natively(built):
    made, out, manifest = built("motor-luenberger", "host", "double")
    assert manifest["target"]["functions"]["luenberger_step"]["difference"] <= DOUBLE_ULPS
    assert manifest["target"]["functions"]["luenberger_step"]["instructions"] is None  # no emulator to count them


def test_cppchecks_time_limit_is_the_callers_and_keys_its_memo(tmp_path):
    """A limit too short for any analysis says it timed out after that limit; a long one analyses the same
    sources (the memo keeps the two apart); the CLI refuses --analysis-seconds without --target or <= 0."""
    import shutil

    from uvsym.cli import main
    from uvsym.codegen.target_run import _cppcheck

    if shutil.which("cppcheck") is None:
        pytest.skip("cppcheck not installed (scripts/install-arm-toolchain.sh installs it)")
    (tmp_path / "src").mkdir()
    (tmp_path / "include").mkdir()
    (tmp_path / "src" / "p_casadi.c").write_text("int p_twice(int x) { return 2 * x; }\n")
    (tmp_path / "src" / "p.c").write_text("int p_twice(int x);\nint p_four(int x) { return p_twice(p_twice(x)); }\n")
    quick = _cppcheck(tmp_path, "p", 1e-4)
    assert quick["timed_out_s"] == 1e-4 and quick["findings"] == [] and quick["misra"] is None
    full = _cppcheck(tmp_path, "p", 60.0)
    assert full["timed_out_s"] is None and full["findings"] == []
    for bad in (["--analysis-seconds", "10"], ["--target", "host", "--analysis-seconds", "0"]):
        assert main(["codegen", "motor-luenberger", "-o", str(tmp_path / "out"), *bad]) != 0
