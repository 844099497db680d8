"""uvsym does not overwrite what it did not write: folders holding someone's files are refused
unless --force, existing result files unless overwrite/--force, and paths are checked before any work."""

import json

import pytest

from uvsym.cli import main
from uvsym.errors import PathError
from uvsym.paths import claim_folder, output_file


def test_a_folder_with_someone_elses_files_is_refused_unless_forced(tmp_path):
    mine = tmp_path / "pkg"
    mine.mkdir()
    (mine / "Makefile").write_text("all:\n\techo mine\n")
    with pytest.raises(PathError, match=r"pkg holds files uvsym did not write \(Makefile\).*--force"):
        claim_folder(mine, "the C package", "package")
    assert claim_folder(mine, "the C package", "package", force=True) == mine
    assert (mine / "Makefile").read_text() == "all:\n\techo mine\n"  # claiming writes nothing
    assert not claim_folder(tmp_path / "new" / "deeper", "the C package", "package").exists()  # not made
    empty = tmp_path / "empty"
    empty.mkdir()
    assert claim_folder(empty, "a report", "report") == empty


def test_a_hand_written_manifest_is_not_mistaken_for_uvsyms(tmp_path):
    folder = tmp_path / "pkg"
    folder.mkdir()
    (folder / "manifest.json").write_text(json.dumps({"name": "my robot", "version": 3}))
    with pytest.raises(PathError, match=r"\(manifest.json\)"):
        claim_folder(folder, "the C package", "package")
    (folder / "manifest.json").write_text(json.dumps({"package": "p", "precision": "double", "functions": []}))
    assert claim_folder(folder, "the C package", "package") == folder
    report = tmp_path / "rep"
    report.mkdir()
    (report / "report.md").write_text("# A study\n")
    with pytest.raises(PathError):  # a report.md alone is not a uvsym report
        claim_folder(report, "a report", "report")
    (report / "results.json").write_text("{}")
    assert claim_folder(report, "a report", "report") == report


def test_codegen_refuses_a_folder_with_a_hand_written_main_and_accepts_its_own(tmp_path, capsys):
    out = tmp_path / "c"
    out.mkdir()
    (out / "main.c").write_text("int main(void) { return 42; }\n")
    assert main(["codegen", "motor-luenberger", "-o", str(out)]) == 2
    assert "holds files uvsym did not write (main.c)" in capsys.readouterr().err
    assert (out / "main.c").read_text() == "int main(void) { return 42; }\n"
    assert main(["codegen", "motor-luenberger", "-o", str(out), "--force"]) == 0
    assert json.loads((out / "manifest.json").read_text())["functions"]
    assert claim_folder(out, "the C package", "package") == out  # now its own package: rewritten without --force


def test_report_checks_every_folder_before_building_any(tmp_path, capsys):
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "notes.txt").write_text("keep")
    assert main(["report", "motor-luenberger", "models", "--out", str(tmp_path)]) == 2
    assert "models holds files uvsym did not write (notes.txt)" in capsys.readouterr().err
    assert not (tmp_path / "motor-luenberger").exists()  # refused before motor-luenberger was built


def test_simulate_checks_its_output_before_the_run(tmp_path, capsys):
    assert main(["simulate", "docking_faults", "--out", str(tmp_path / "run.xyz")]) == 2
    err = capsys.readouterr()
    assert "unknown result format '.xyz'" in err.err and "final state" not in err.out  # nothing ran
    existing = tmp_path / "run.csv"
    existing.write_text("mine")
    assert main(["simulate", "docking_faults", "--out", str(existing)]) == 2
    assert "run.csv exists; refusing to overwrite" in capsys.readouterr().err
    assert existing.read_text() == "mine"
    assert main(["simulate", "docking_faults", "--out", str(existing), "--force"]) == 0
    assert not existing.read_text().startswith("mine")  # overwritten with the run: asked for
    afile = tmp_path / "afile"
    afile.write_text("x")
    assert main(["simulate", "docking_faults", "--out", str(afile / "run.npz")]) == 2
    assert "afile is a file, not a folder" in capsys.readouterr().err


def test_output_files_are_checked_as_files(tmp_path):
    with pytest.raises(PathError, match="it is a folder"):
        output_file(tmp_path, "the result")
    assert output_file(tmp_path / "sub" / "r.npz", "the result") == tmp_path / "sub" / "r.npz"


def test_folders_that_cannot_be_made_are_typed_errors_before_any_work(tmp_path, monkeypatch, capsys):
    from pathlib import Path

    def refuse(self, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(self))

    monkeypatch.setattr(Path, "mkdir", refuse)
    for argv, what in ((["simulate", "docking_faults", "--out", str(tmp_path / "new" / "run.npz")], "the result"),
                       (["codegen", "motor-luenberger", "-o", str(tmp_path / "pkg")], "the C package"),
                       (["report", "models", "--out", str(tmp_path / "reports")], "a report")):
        assert main(argv) == 2
        captured = capsys.readouterr()
        assert f"cannot make the folder {tmp_path}" in captured.err and f"for {what}: Permission denied" in captured.err
        assert "final state" not in captured.out  # refused before the run


def test_quick_look_figures_make_their_folder_and_type_their_errors(tmp_path):
    import numpy as np

    from uvsym.sim.result import Signal, SimResult

    result = SimResult(np.array([0.0, 1.0]), {"x": Signal(np.array([[0.0], [1.0]]), ("a",), ("m",))})
    result.plot(tmp_path / "new" / "run.png")
    assert (tmp_path / "new" / "run.png").read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(PathError, match=r"run.xyz"):
        result.plot(tmp_path / "run.xyz")
    (tmp_path / "afile").write_text("x")
    with pytest.raises(PathError, match="afile is a file, not a folder"):
        result.plot(tmp_path / "afile" / "run.svg")
