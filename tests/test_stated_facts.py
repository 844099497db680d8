"""Statements in the README, the examples and the command's messages checked against what the code does."""

import re
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def test_the_readme_names_the_observer_sets_whose_main_c_runs_on_experiment_data():
    from uvsym.derivation import observer_set, observer_sets

    text = " ".join((ROOT / "README.md").read_text().split())
    stated = re.search(r"where the observer set gives an example \(([^)]*)\), else on zero inputs", text)
    assert stated, "the README no longer says which main.c runs on experiment data"
    with_data = {name for name in observer_sets() if observer_set(name).example is not None}
    assert {n.strip() for n in stated.group(1).split(",")} == with_data


def test_the_docking_campaign_example_sweeps_what_its_comments_say():
    from uvsym.campaign import load_campaign

    path = ROOT / "examples" / "campaign_docking.toml"
    spec = tomllib.loads(path.read_text())
    campaign = load_campaign(path)
    header = "".join(line for line in path.read_text().splitlines(keepends=True) if line.startswith("#"))
    assert f"{len(campaign.runs)} runs" in header
    swept = {key for case in spec["case"] for key in case.get("grid", {})}
    assert not any("current" in key for key in swept) and "current" not in spec["description"]


def test_codegen_list_describes_each_set_in_a_whole_sentence_without_markup(capsys):
    from uvsym.cli import main

    assert main(["codegen", "--list"]) == 0
    rows = capsys.readouterr().out.splitlines()[2:]
    assert rows
    for row in rows:
        description = re.split(r"\s{2,}", row.strip(), maxsplit=3)[-1]
        assert description.endswith("."), row
        assert "`" not in description, row


def test_a_single_vertex_lmi_is_described_in_the_singular():
    from uvsym.verify.lyapunov import lyapunov_decrease

    certificate = lyapunov_decrease("decay", [-np.eye(2)], 0.1, "one matrix")
    assert certificate.status == "proved"
    assert "at 1 vertex," in certificate.method


def test_the_refusal_to_overwrite_names_the_command_line_option_first(tmp_path):
    import pytest

    from uvsym.errors import PathError
    from uvsym.paths import output_file

    existing = tmp_path / "run.csv"
    existing.write_text("x\n")
    with pytest.raises(PathError, match="refusing to overwrite") as refused:
        output_file(existing, "a result", overwrite=False)
    message = str(refused.value)
    assert "--force" in message and message.index("--force") < message.index("overwrite=True")


def test_the_sphinx_build_folder_is_ignored():
    assert "docs/_build/" in (ROOT / ".gitignore").read_text().splitlines()
