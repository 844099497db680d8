"""``uvsym codegen FILE.toml`` and ``uvsym verify FILE.toml``: a scenario's blocks as C, claims about its estimators."""

from __future__ import annotations

import json
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

from uvsym.cli import main
from uvsym.codegen.check import check_package
from uvsym.scenario_exports import scenario_claims, scenario_package
from uvsym.sim.system_scenario import parse_system_scenario, simulate_system_scenario

EXAMPLE = Path(__file__).parents[1] / "examples" / "dc_motor"
SCENARIO = EXAMPLE / "speed_sensor_bias.toml"


def _table(**changes) -> dict:
    return tomllib.loads(SCENARIO.read_text()) | {"duration": 1.0, "faults": []} | changes


@pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler on PATH")
def test_the_blocks_of_a_scenario_compile_strictly_and_match_casadi(tmp_path):
    scenario = parse_system_scenario(_table(), root=EXAMPLE)
    package = scenario_package(scenario)
    assert [e.function.name() for e in package.exported] == ["speed_step", "luenberger_step", "ukf_step"]
    package.write(tmp_path)
    check = check_package(tmp_path, list(package.exported), package.package_name, calls=5)
    assert check.max_relative_difference <= 1e-12 and "-Werror" in check.flags
    manifest = json.loads((tmp_path / "manifest.json").read_text())
    luenberger = manifest["functions"][1]
    assert [(a["entries"], a["units"]) for a in luenberger["inputs"]] == [
        (["i_hat", "omega_hat"], ["A", "rad/s"]), (["i_meas", "omega_meas", "V"], ["A", "rad/s", "V"])]


def test_the_example_states_are_the_blocks_own_run_in_the_loop():
    """Stepping the PI block from its initial state through the logged reads gives back the voltage
    the loop applied (the plant's input u is the PI output, within its limits)."""
    scenario = parse_system_scenario(_table(), root=EXAMPLE)
    result = simulate_system_scenario(scenario)
    example = scenario_package(scenario, ["speed"], result).example
    states, reads = example.inputs
    pid = next(b for b in scenario.loop.blocks if b.name == "speed")
    published = np.array([np.asarray(pid.step(s, r)[1]).ravel() for s, r in zip(states, reads)])
    np.testing.assert_allclose(published[:, 0], result["u"]["V"][:len(states)], rtol=1e-12, atol=1e-12)
    assert reads.shape == (len(states), 2) and np.any(reads[:, 1] == 100.0)   # omega_meas, omega_ref


def test_a_block_selection_names_an_unknown_block_with_the_known_ones(tmp_path, capsys):
    assert main(["codegen", str(SCENARIO), "-o", str(tmp_path / "c"), "--blocks", "luenberg"]) == 2
    assert ("blocks: dc_motor_speed_sensor_bias has no block 'luenberg' (did you mean 'luenberger'?); its blocks: "
            "speed, luenberger, ukf"
            in capsys.readouterr().err)
    assert not (tmp_path / "c").exists()


def test_codegen_refuses_a_vehicle_scenario_and_observer_set_options(tmp_path, capsys):
    from uvsym.sim.scenario import shipped_scenarios

    docking = next(iter(shipped_scenarios().values()))
    assert main(["codegen", str(docking), "-o", str(tmp_path / "c")]) == 2
    assert "a vehicle scenario (no 'plant')" in capsys.readouterr().err
    assert main(["codegen", str(SCENARIO), "-o", str(tmp_path / "c"), "--vehicle", "otter"]) == 2
    assert "--vehicle, --form and set options are for observer sets" in capsys.readouterr().err
    assert not (tmp_path / "c").exists()


def test_verify_proves_the_luenberger_design_and_says_what_it_cannot_claim(tmp_path, capsys):
    assert main(["verify", str(SCENARIO), "--out", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    assert "luenberger on dc_motor: linearised error decays at rate 20 1/s" in text
    assert "ukf: its state (5 entries) is not an estimate" in text and "speed: runs no observer" in text
    rows = json.loads((tmp_path / "dc_motor_speed_sensor_bias" / "proofs.json").read_text())
    assert [r["status"] for r in rows] == ["proved", "proved"]


def test_verify_refutes_a_gain_that_makes_the_sampled_observer_expand(tmp_path):
    """Adversarial: a gain typed in the file (no design) with the wrong sign, L = -3000 on both outputs,
    pushes the sampled error away; the contraction claim must come back refuted."""
    table = _table(blocks=[b for b in _table()["blocks"] if b["type"] != "ukf"])
    for b in table["blocks"]:
        if b["type"] == "luenberger":
            b.pop("decay")
            b["gain"] = [[-3000.0, 0.0], [0.0, -3000.0]]
    table["detectors"] = [d for d in table["detectors"] if d["name"] != "ukf_fd"]
    table["detectors"][0]["std"] = [0.01, 0.1]
    scenario = parse_system_scenario(table, root=EXAMPLE)
    certificates, _ = scenario_claims(scenario, table)
    assert [c.status for c in certificates] == ["refuted"]
    assert not certificates[0].as_expected


def test_a_shipped_scenario_is_exported_and_verified_by_its_name(tmp_path, capsys):
    assert main(["verify", "rov_yaw_compass_bias", "--out", str(tmp_path)]) == 0
    assert "observer on rov_yaw: linearised error decays at rate 1 1/s" in capsys.readouterr().out
    assert main(["codegen", "rov_yaw_compass_bias", "-o", str(tmp_path / "c")]) == 0
    assert (tmp_path / "c" / "src" / "rov_yaw_compass_bias.c").exists()


def test_the_package_is_written_again_over_its_own_make_products_but_not_over_a_users_file(tmp_path, capsys):
    out = tmp_path / "c"
    assert main(["codegen", "rov_yaw_compass_bias", "-o", str(out)]) == 0
    from uvsym.codegen.build_files import make_products

    for product in make_products("rov_yaw_compass_bias"):      # as `make` leaves them
        (out / product).parent.mkdir(parents=True, exist_ok=True)
        (out / product).write_bytes(b"built")
    assert main(["codegen", "rov_yaw_compass_bias", "-o", str(out)]) == 0
    (out / "notes.txt").write_text("mine")
    assert main(["codegen", "rov_yaw_compass_bias", "-o", str(out)]) == 2
    assert "holds files uvsym did not write (notes.txt)" in capsys.readouterr().err
    assert (out / "notes.txt").read_text() == "mine"
