"""Packages import their names on first use: a campaign worker and the simulator start without scipy.signal,
sympy or matplotlib, and every exported name still resolves to the object its submodule defines."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

from uvsym.lazy import lazy_exports

HEAVY = ("scipy.signal", "sympy", "matplotlib")


def test_a_campaign_worker_and_the_simulator_start_without_the_heavy_libraries_and_every_name_resolves():
    """In a fresh interpreter (the order of first imports is a new user's): then every exported name is the
    object it names, not a module of the same name."""
    code = ("import sys, types, uvsym.campaign.worker, uvsym.sim.simulation, uvsym.observers.base, uvsym.report\n"
            f"print(' '.join(m for m in {HEAVY!r} if m in sys.modules))\n"
            "import uvsym.observers as o, uvsym.report as r\n"
            "print(' '.join(f'{p.__name__}.{n}' for p in (o, r) for n in p.__all__ "
            "if isinstance(getattr(p, n), types.ModuleType)))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.splitlines() == ["", ""]


def test_uvsym_simulate_of_a_docking_run_imports_no_scipy_at_all():
    """The docking run (vehicle, controller, two observers, compiled loop, event log) needs none of scipy: its
    linalg, optimize, special, io and signal imports are where they are used (each 0.1-0.14 s of every call)."""
    code = ("import sys\nfrom uvsym.cli import main\nassert main(['simulate', 'docking_faults']) == 0\n"
            "print(' '.join(sorted(m for m in sys.modules if m.split('.')[0] in ('scipy', 'sympy', 'matplotlib', "
            "'cvxpy'))))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.splitlines()[-1] == ""


@pytest.mark.parametrize("package", ["uvsym.observers", "uvsym.report", "uvsym.diagnosis"])
def test_every_exported_name_is_its_submodules_object_and_dir_lists_it(package):
    module = importlib.import_module(package)
    for name, submodule in module._EXPORTS.items():
        assert getattr(module, name) is getattr(importlib.import_module(f"{package}.{submodule}"), name)
    assert set(module.__all__) <= set(dir(module))


def test_a_function_named_as_its_submodule_stays_the_function_after_the_submodule_is_imported():
    import types

    for name in ("ekf", "ukf"):
        submodule = importlib.import_module(f"uvsym.observers.{name}")
        function = getattr(importlib.import_module("uvsym.observers"), name)
        assert not isinstance(function, types.ModuleType) and function is getattr(submodule, name)
    with pytest.raises(ValueError, match="uvsym.observers: ekf, lms named as a submodule: import it eagerly instead"):
        lazy_exports("uvsym.observers", {"ekf": "ekf", "lms": "mmae", "other": "ekf"})  # its own and a sibling


def test_an_unknown_name_raises_attribute_error_and_a_known_one_is_kept_after_its_first_use(monkeypatch):
    import types

    package = types.ModuleType("fake_package")
    package.__path__ = []  # a package without submodules on disk
    monkeypatch.setitem(sys.modules, "fake_package", package)
    monkeypatch.setitem(sys.modules, "fake_package.numbers", types.SimpleNamespace(answer=42))
    package.__getattr__, package.__dir__ = lazy_exports("fake_package", {"answer": "numbers"})
    with pytest.raises(AttributeError, match="module 'fake_package' has no attribute 'question'"):
        package.question  # noqa: B018
    assert "answer" not in vars(package) and "answer" in package.__dir__()
    assert package.answer == 42 and vars(package)["answer"] == 42
    from fake_package import answer

    assert answer == 42


def test_the_command_line_answers_help_and_misspelt_names_without_the_numerical_libraries_or_a_derivation():
    """``uvsym --help``, every ``COMMAND --help`` and a misspelt scenario, derivation or file: answered (with the
    closest name where one is close) before CasADi, scipy, cvxpy, matplotlib, pyarrow or a derivation is imported."""
    code = (
        "import contextlib, io, sys\nfrom uvsym.cli import main\n"
        "calls = [['--help']] + [[c, '--help'] for c in ('models', 'report', 'simulate', 'codegen', 'campaign', "
        "'verify')] + [['simulate', 'compas_30deg'], ['verify', 'actuator-observer'], ['report', 'nosuch'], "
        "['codegen', 'nosuch'], ['campaign', 'nosuch.toml'], ['verify', 'sensor-fdi-lms', 'nosuch']]\n"
        "for call in calls:\n"
        "    err = io.StringIO()\n"
        "    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):\n"
        "        try:\n            status = main(call)\n"
        "        except SystemExit as stop:\n            status = stop.code\n"
        "    print(status, err.getvalue().strip().splitlines()[-1] if err.getvalue().strip() else '')\n"
        "print('loaded:', ' '.join(sorted({m.split('.')[0] for m in sys.modules} & "
        "{'casadi', 'scipy', 'cvxpy', 'matplotlib', 'pyarrow'}) + [m for m in sys.modules "
        "if m.startswith('derivations.')]))\n")  # (their package's __init__ is found, not their modules)
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    lines = run.stdout.splitlines()
    assert lines[-1].split() == ["loaded:"]
    assert [line.split()[0] for line in lines[:7]] == ["0"] * 7  # the helps
    simulate, verify, report, codegen, campaign, second = lines[7:13]
    assert simulate.startswith("2 uvsym: error: no scenario file 'compas_30deg'") and \
        "(did you mean 'compass_30deg'?)" in simulate
    assert "unknown derivation 'actuator-observer' (did you mean 'actuator-observers'?)" in verify
    assert "unknown derivation 'nosuch'; known: actuator-observers" in report
    assert "give the output folder with -o/--out DIR" in codegen and "cannot be read" in campaign
    assert "unknown derivation 'nosuch'" in second  # a good name before it is not loaded either
