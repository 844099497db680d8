"""The uvsym command line: version, vehicle listing and inspection, reports."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

import uvsym
from uvsym.cli import main


def test_version_through_the_module_entry_point():
    """One of the two tests that start ``python -m uvsym.cli`` in its own process (the others call ``main``)."""
    result = subprocess.run([sys.executable, "-m", "uvsym.cli", "--version"], capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0 and result.stdout.strip() == f"uvsym {uvsym.__version__}"


def test_the_module_entry_point_exits_with_the_status_main_returns():
    result = subprocess.run([sys.executable, "-m", "uvsym.cli", "models", "show", "nosuch"], capture_output=True,
                            text=True, timeout=300)
    assert result.returncode == 2 and result.stderr.startswith("uvsym: error:") and "nosuch" in result.stderr


def exit_status(capsys, *args) -> tuple[int, str]:
    """``main(args)``'s exit status (argparse's SystemExit included) and what it wrote to stderr."""
    try:
        status = main(list(args))
    except SystemExit as stop:
        status = stop.code
    return status, capsys.readouterr().err


def test_models_json_lists_the_library(capsys):
    assert main(["models", "--json"]) == 0
    listing = json.loads(capsys.readouterr().out)
    assert [v["name"] for v in listing if v["kind"] == "vehicle"] == uvsym.vehicle_names()
    assert {v["name"]: v["dof"] for v in listing}["otter3dof"] == 3
    plants = {v["name"]: v for v in listing if v["kind"] == "plant"}
    assert set(plants) == {"induction_motor", "quadrotor", "rov_yaw"}
    assert plants["induction_motor"]["states"] == ["i_sq", "i_sd", "lambda_rq", "lambda_rd", "omega_m"]


def test_models_show_a_plant_with_units_and_operating_point(capsys):
    assert main(["models", "show", "induction_motor"]) == 0
    out = capsys.readouterr().out
    assert "omega_m (rad/s)" in out and "u_sq (V)" in out and "omega_m = 250" in out
    assert "Rr" in out and "Ohm" in out and "Modelica" in out
    assert main(["models", "show", "rov_yaw", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert [s["name"] for s in summary["outputs"]] == ["psi"] and summary["time"] == "continuous"


def test_models_show_prints_parameters_with_units(capsys):
    assert main(["models", "show", "remus100"]) == 0
    out = capsys.readouterr().out
    assert "delta_r (rad" in out and "n (rpm" in out
    assert "rho" in out and "kg/m^3" in out and "h = coriolis + damping" in out


def test_models_show_json(capsys):
    assert main(["models", "show", "otter", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["parameters"]["mp"] == {"value": 25.0, "unit": "kg", "description": "payload mass"}
    assert len(summary["M"]) == 6


@pytest.mark.parametrize("args", [["models", "show", "nautilus"], ["models", "show"], ["report", "nonesuch"]])
def test_unknown_names_exit_2_with_a_message(args, capsys):
    status, stderr = exit_status(capsys, *args)
    assert status == 2
    assert "uvsym: error:" in stderr and "Traceback" not in stderr


def test_report_models_is_deterministic(tmp_path, built_report):
    import hashlib

    from uvsym.derivation import derivation, source_fingerprint

    first = built_report("models")
    assert main(["report", "models", "--out", str(tmp_path)]) == 0
    names = sorted(p.name for p in first.iterdir())
    assert names == [".build.json", "report.html", "report.md", "results.json", "step_responses.svg"]
    for name in names:
        assert (first / name).read_bytes() == (tmp_path / "models" / name).read_bytes(), name
    stamp = json.loads((tmp_path / "models" / ".build.json").read_text())
    assert stamp["derivation"] == "models" and stamp["source_fingerprint"] == source_fingerprint(derivation("models"))
    assert sorted(stamp["files"]) == [n for n in names if n != ".build.json"]
    assert stamp["files"]["report.md"] == hashlib.sha256((first / "report.md").read_bytes()).hexdigest()


def test_models_report_checks_the_reference_cases(built_report):
    results = json.loads((built_report("models") / "results.json").read_text())
    assert results["reference_cases_passed"] == results["reference_cases"] == 13
    assert results["docking_auv_B_matches_eq27"] is True


@pytest.mark.slow
def test_actuator_observers_reproduction_meets_every_target(built_report):
    """Liu et al. 2014's experiment, rebuilt: every target met, the faults identified, every figure shown."""
    built = built_report("actuator-observers")
    results = json.loads((built / "results.json").read_text())
    assert results["targets"] and all(results["targets"].values()), results["targets"]
    assert results["thruster_fault_type"] == "bias" and abs(results["f_bar_a"] - 13.0) <= 0.01
    assert results["rudder_fault_type"] == "proportional" and abs(results["f_bar_p"] - 0.8) <= 0.001
    assert results["remus100"]["identified"]["delta_s"]["kind"] == "bias"
    for figure in ("fig4_without_ftc", "fig5_actuation_without_ftc", "fig6_estimates", "fig7_with_ftc",
                   "fig8_actuation_with_ftc"):
        assert (built / f"{figure}.svg").read_text().startswith("<?xml"), figure
        assert f"]({figure}.svg)" in (built / "report.md").read_text(), f"{figure} is shown in the report"
    # the C package the report links to: compiled cleanly by the build, equal to Python
    assert results["c"]["compiled"] and results["c"]["max_relative_difference"] <= 1e-12


def test_simulate_lists_the_shipped_scenarios(capsys):
    assert main(["simulate", "--list"]) == 0
    out = capsys.readouterr().out
    assert "docking_faults" in out and "remus100_stern_plane_bias" in out


def test_simulate_writes_result_and_figure(tmp_path, capsys):
    scenario = tmp_path / "short.toml"
    text = (Path(uvsym.__file__).parent / "sim" / "scenarios" / "docking_faults.toml").read_text()
    scenario.write_text(text.replace("duration = 90.0", "duration = 2.0"))
    out_file = tmp_path / "run.npz"
    assert main(["simulate", str(scenario), "--out", str(out_file), "--plot"]) == 0
    printed = capsys.readouterr().out
    assert "simulated s per wall s" in printed and "final state: x = " in printed
    from uvsym.sim import SimResult

    result = SimResult.load(out_file)
    assert result.t[-1] == pytest.approx(2.0) and result.meta["scenario"] == "docking_faults"
    assert (tmp_path / "run.svg").read_text().startswith("<?xml")


def test_simulate_compresses_its_result_only_when_asked(tmp_path, capsys):
    import zipfile

    scenario = tmp_path / "short.toml"
    text = (Path(uvsym.__file__).parent / "sim" / "scenarios" / "docking_faults.toml").read_text()
    scenario.write_text(text.replace("duration = 90.0", "duration = 2.0"))
    for name, flags, kind in (("plain.npz", [], zipfile.ZIP_STORED),
                              ("packed.npz", ["--compress"], zipfile.ZIP_DEFLATED)):
        assert main(["simulate", str(scenario), "--out", str(tmp_path / name), *flags]) == 0
        with zipfile.ZipFile(tmp_path / name) as archive:
            assert {entry.compress_type for entry in archive.infolist()} == {kind}, name
    capsys.readouterr()
    status, stderr = exit_status(capsys, "simulate", str(scenario), "--compress")
    assert status == 2 and "--compress: it compresses the --out file; give one" in stderr
    status, stderr = exit_status(capsys, "simulate", str(scenario), "--out", str(tmp_path / "run.csv"), "--compress")
    assert status == 2 and "only .npz and .mat files are compressed" in stderr and not (tmp_path / "run.csv").exists()


def test_simulate_reports_a_bad_scenario_field_and_exits_2(tmp_path, capsys):
    scenario = tmp_path / "bad.toml"
    text = (Path(uvsym.__file__).parent / "sim" / "scenarios" / "docking_faults.toml").read_text()
    scenario.write_text(text.replace('kind = "bias"            # proportional', 'kind = "wobble"  #'))
    status, stderr = exit_status(capsys, "simulate", str(scenario))
    assert status == 2
    assert "faults[0]" in stderr and "wobble" in stderr and "Traceback" not in stderr


def test_codegen_writes_the_package_and_refuses_unknown_sets(tmp_path, capsys):
    assert main(["codegen", "actuator-observers", "-o", str(tmp_path / "pkg"), "--vehicle", "otter3dof"]) == 0
    assert "uvsym_otter3dof_observers_bias_step" in capsys.readouterr().out
    manifest = json.loads((tmp_path / "pkg" / "manifest.json").read_text())
    assert manifest["precision"] == "double" and len(manifest["functions"]) == 7
    for path in ("Makefile", "CMakeLists.txt", "main.c", "harness.c", "include/uvsym_otter3dof_observers.h"):
        assert (tmp_path / "pkg" / path).exists(), path
    status, stderr = exit_status(capsys, "codegen", "sliding-mode", "-o", str(tmp_path / "x"))
    assert status == 2 and "unknown observer set" in stderr


def _install(monkeypatch, **entries):
    """Make ``entries`` (entry-point name -> object, set on a scratch module) the installed derivations."""
    import types
    from importlib.metadata import EntryPoint

    import uvsym.derivation

    module = types.ModuleType("scratch_derivations")
    monkeypatch.setitem(sys.modules, module.__name__, module)
    points = []
    for index, (name, value) in enumerate(entries.items()):
        setattr(module, f"entry{index}", value)
        points.append(EntryPoint(name, f"{module.__name__}:entry{index}", uvsym.derivation.GROUP))
    monkeypatch.setattr(uvsym.derivation, "entry_points", lambda group: points)


def _tiny_set():
    """A one-function observer set whose factory takes no options."""
    import casadi as ca

    from uvsym.codegen.observer_sets import ObserverSet
    from uvsym.codegen.package import Exported

    x = ca.SX.sym("x", 2)
    function = ca.Function("bias_step", [x], [-x], ["x"], ["x_next"])
    return ObserverSet("tiny", "a tiny set", (Exported(function, ("x (-)",), ("x_next (-)",), "minus x"),))


def test_the_loader_names_an_entry_point_that_is_not_a_derivation(monkeypatch, capsys):
    from uvsym.derivation import Derivation, DerivationError, load_derivations

    _install(monkeypatch, good=Derivation("good", "Good", lambda out_dir, progress: None), broken=uvsym.vehicle)
    with pytest.raises(DerivationError, match="entry point 'broken' = 'scratch_derivations:entry1'.* not a "):
        load_derivations()
    assert main(["report", "broken"]) == 2
    assert "uvsym: error: entry point 'broken'" in capsys.readouterr().err
    _install(monkeypatch, renamed=Derivation("other", "Other", lambda out_dir, progress: None))
    with pytest.raises(DerivationError, match="called 'other'"):
        load_derivations()
    with pytest.raises(DerivationError, match="not callable: build"):
        Derivation("none", "None", build=None)


def test_codegen_goes_through_the_declared_sets_and_refuses_options_a_set_does_not_take(monkeypatch, tmp_path, capsys):
    from uvsym.derivation import Derivation

    toy = Derivation("toy", "Toy", lambda out_dir, progress: None, observer_sets={"tiny": _tiny_set})
    _install(monkeypatch, toy=toy)
    assert main(["codegen", "--list"]) == 0
    assert capsys.readouterr().out.splitlines()[2].split()[:3] == ["tiny", "toy", "none"]
    assert main(["codegen", "tiny", "-o", str(tmp_path / "pkg")]) == 0
    assert "tiny_bias_step" in capsys.readouterr().out and (tmp_path / "pkg" / "include" / "tiny.h").exists()
    assert main(["codegen", "tiny", "-o", str(tmp_path / "pkg"), "--vehicle", "otter"]) == 2
    assert "observer set 'tiny' takes no option --vehicle; its options: none" in capsys.readouterr().err
    assert main(["codegen", "actuator-observers", "-o", str(tmp_path / "x")]) == 2
    assert "unknown observer set 'actuator-observers'; known: tiny" in capsys.readouterr().err
    assert main(["verify", "toy"]) == 0  # a derivation without claims has nothing to check


def test_unknown_observer_sets_and_options_are_refused_by_name():
    from uvsym.derivation import observer_set
    from uvsym.errors import UnknownNameError

    with pytest.raises(UnknownNameError, match="unknown observer set 'sliding-mode'; known: .*actuator-observers"):
        observer_set("sliding-mode")
    with pytest.raises(UnknownNameError, match="takes no option --colour; its options: --vehicle, --form"):
        observer_set("actuator-observers", colour="red")


def _toy_package(monkeypatch, tmp_path, declared: str = "{p.stem: p for p in SCENARIOS.glob('*.toml')}"):
    """A derivation ``toy`` as a package on disk (``toy_study``) shipping ``scenarios/toy_run.toml`` and declaring
    the scenarios ``declared`` (Python source), installed as the only derivation."""
    from importlib.metadata import EntryPoint

    import uvsym.derivation

    package = tmp_path / "toy_study"
    (package / "scenarios").mkdir(parents=True)
    (package / "scenarios" / "toy_run.toml").write_text(
        'plant = "rov_yaw"\nduration = 2.0\nstep = 0.1\n[[blocks]]\ntype = "open_loop"\n'
        'name = "thrust"\npublishes = "u"\ntimes = [0.0]\nvalues = [0.1]\n')
    (package / "__init__.py").write_text(
        "from pathlib import Path\nfrom uvsym.derivation import Derivation\n"
        "SCENARIOS = Path(__file__).with_name('scenarios')\n"
        f"DERIVATION = Derivation('toy', 'Toy', lambda out_dir, progress: None, scenarios={declared})\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "toy_study", raising=False)
    points = [EntryPoint("toy", "toy_study:DERIVATION", uvsym.derivation.GROUP)]
    monkeypatch.setattr(uvsym.derivation, "entry_points", lambda group: points)
    return package


def test_a_derivation_declaring_scenarios_outside_its_scenarios_folder_is_refused_by_name(monkeypatch, tmp_path):
    from uvsym.derivation import DerivationError, derivation, study_scenarios

    package = _toy_package(monkeypatch, tmp_path, declared="{'elsewhere': SCENARIOS.parent / 'elsewhere.toml'}")
    assert study_scenarios() == {"toy_run": ("toy", package / "scenarios" / "toy_run.toml")}  # nothing imported
    assert "toy_study" not in sys.modules
    with pytest.raises(DerivationError, match=r"declares the scenarios \['elsewhere'\], not the files of its "
                                              r"package's scenarios/ folder \(\['toy_run'\]\)"):
        derivation("toy")


def test_a_derivations_shipped_scenario_runs_by_name_and_an_old_study_file_is_told_what_to_name(
        monkeypatch, tmp_path, capsys):
    _toy_package(monkeypatch, tmp_path)
    assert main(["simulate", "--list"]) == 0
    assert any(line.split()[:2] == ["toy_run", "toy"] for line in capsys.readouterr().out.splitlines())
    assert main(["simulate", "toy_run", "--out", str(tmp_path / "run.npz")]) == 0
    assert (tmp_path / "run.npz").exists() and "toy_run: rov_yaw, 2 s at 0.1 s" in capsys.readouterr().out
    old = tmp_path / "old.toml"
    old.write_text('study = "toy"\ngain = -1\n')           # the format before scenarios over a plant
    assert main(["simulate", str(old)]) == 2
    assert "a scenario over any other System its plant (plant = NAME or module:function" in capsys.readouterr().err


def test_the_source_fingerprint_moves_with_any_source_file_of_the_study(tmp_path, monkeypatch):
    import importlib

    from uvsym.derivation import Derivation, source_fingerprint

    package = tmp_path / "scratch_study"
    package.mkdir()
    (package / "__init__.py").write_text("def build(out_dir, progress):\n    pass\n")
    (package / "data.json").write_text('{"gain": 1.0}\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("scratch_study")
    study = Derivation("scratch", "Scratch", module.build)
    before = source_fingerprint(study)
    assert source_fingerprint(study) == before
    (package / "data.json").write_text('{"gain": 2.0}\n')
    assert source_fingerprint(study) != before


def test_verify_prints_each_claim_readably_in_100_columns(tmp_path, capsys):
    from uvsym.cli import _claim_block

    assert main(["verify", "motor-luenberger", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert max(len(line) for line in out.splitlines() if str(tmp_path) not in line) <= 100
    assert out.count("   claim:  ") == len(json.loads((tmp_path / "motor-luenberger" / "proofs.json").read_text()))
    words = "the error map of the sampled observer contracts at every vertex of the polytope " * 4
    block = _claim_block({"claim": words, "set": "s", "method": "m", "status": "refuted", "expected": "proved",
                          "margin": None, "seconds": 1.0})
    assert block.startswith("!! REFUTED (expected proved") and "polytope" in block
    assert all(len(line) <= 100 and not line.endswith(("contra", "verte")) for line in block.splitlines())


@pytest.mark.parametrize("arguments, kind", [(["--schema"], "vehicle"), (["--schema", "plant"], "plant"),
                                             (["docking_faults", "--schema"], "vehicle"),
                                             (["docking_auv_thruster_bias", "--schema"], "plant"),
                                             (["docking_auv_thruster_bias", "--schema", "vehicle"], "vehicle")])
def test_schema_is_of_the_kind_named_else_of_the_scenario_given(arguments, kind, capsys):
    from uvsym.sim.schema import schema_markdown

    assert main(["simulate", *arguments]) == 0
    assert capsys.readouterr().out.strip() == schema_markdown(kind)
