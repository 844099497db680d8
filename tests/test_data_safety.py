"""uvsym does not overwrite what it did not write: folders holding someone's files are refused
unless --force, existing result files unless overwrite/--force, and paths are checked before any work."""

import json
from pathlib import Path

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


def test_simulate_keeps_an_existing_figure_and_refuses_a_folder_before_the_run(tmp_path, capsys):
    mine = tmp_path / "mine.svg"
    mine.write_text("<svg>mine</svg>")
    assert main(["simulate", "docking_faults", "--plot", str(mine)]) == 2
    captured = capsys.readouterr()
    assert "mine.svg exists; refusing to overwrite" in captured.err and "final state" not in captured.out
    assert mine.read_text() == "<svg>mine</svg>"
    beside = tmp_path / "new.svg"  # the figure --out new.npz --plot writes
    beside.write_text("<svg>beside</svg>")
    assert main(["simulate", "docking_faults", "--out", str(tmp_path / "new.npz"), "--plot"]) == 2
    assert "new.svg exists; refusing to overwrite" in capsys.readouterr().err
    assert beside.read_text() == "<svg>beside</svg>" and not (tmp_path / "new.npz").exists()
    folder = tmp_path / "u"
    folder.mkdir()
    assert main(["simulate", "docking_faults", "--plot", str(folder)]) == 2
    captured = capsys.readouterr()
    assert f"cannot write the figure to {folder}: it is a folder" in captured.err and "final state" not in captured.out
    assert not (tmp_path / "u.png").exists() and not list(folder.iterdir())
    assert main(["simulate", "docking_faults", "--plot", str(mine), "--force"]) == 0
    assert f"wrote {mine}\n" in capsys.readouterr().out and mine.read_text().startswith("<?xml")  # asked for


def _package_with(folder, name: str, functions: dict):
    """A uvsym package of ``functions`` (name -> expression of x) written into ``folder``."""
    import casadi as ca

    from uvsym.codegen.package import Exported, write_package

    x = ca.SX.sym("x")
    exported = [Exported(ca.Function(f, [x], [expr(x)], ["x"], ["y"]), ("x (-)",), ("y (-)",), f)
                for f, expr in functions.items()]
    return write_package(folder, exported, name)


def test_an_edited_or_added_file_in_uvsyms_own_package_is_refused_and_named(tmp_path):
    out = tmp_path / "c"
    manifest = _package_with(out, "pkg", {"double": lambda x: 2 * x})
    assert manifest["files"]["main.c"] and "manifest.json" not in manifest["files"]
    assert claim_folder(out, "the C package", "package") == out  # untouched: uvsym's own
    (out / "main.c").write_text("int main(void) { return 42; }\n")
    (out / "notes.txt").write_text("keep")
    with pytest.raises(PathError, match=r"c holds files uvsym did not write \(notes.txt\) and files changed "
                                        r"since uvsym wrote them \(main.c\).*--force"):
        claim_folder(out, "the C package", "package")
    assert claim_folder(out, "the C package", "package", force=True) == out
    legacy = json.loads((out / "manifest.json").read_text())
    del legacy["files"]  # written by an older uvsym: recognised by its manifest as before
    (out / "manifest.json").write_text(json.dumps(legacy))
    assert claim_folder(out, "the C package", "package") == out


def test_codegen_refuses_its_own_package_once_a_user_edited_it(tmp_path, capsys):
    out = tmp_path / "c"
    assert main(["codegen", "motor-luenberger", "-o", str(out)]) == 0
    (out / "main.c").write_text("int main(void) { return 42; }\n")
    assert main(["codegen", "motor-luenberger", "-o", str(out)]) == 2
    assert "files changed since uvsym wrote them (main.c)" in capsys.readouterr().err
    assert (out / "main.c").read_text() == "int main(void) { return 42; }\n"


def test_a_package_written_over_another_removes_only_the_old_packages_files(tmp_path):
    out = tmp_path / "c"
    _package_with(out, "old", {"double": lambda x: 2 * x})
    (out / "src" / "notes.txt").write_text("mine")  # forced in: not the old package's
    manifest = _package_with(out, "new", {"halve": lambda x: x / 2})
    assert not list(out.rglob("old*"))  # src/old.c, src/old_casadi.c, include/old*.h
    assert (out / "src" / "notes.txt").read_text() == "mine"
    files = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}
    assert files == set(manifest["files"]) | {"manifest.json", "src/notes.txt"}


def test_a_report_folder_is_checked_against_its_stamp(tmp_path, capsys):
    import shutil
    from pathlib import Path

    fresh = tmp_path / "models"  # a committed report in a fresh clone: no .build.json
    shutil.copytree(Path(__file__).parent.parent / "reports" / "models", fresh,
                    ignore=shutil.ignore_patterns(".build.json"))
    for _ in range(2):  # the first run by today's rule, the second by the stamp of the first
        assert main(["report", "models", "--out", str(tmp_path)]) == 0
    stamp = json.loads((fresh / ".build.json").read_text())
    assert stamp["source_fingerprint"] and "report.md" in stamp["files"] and ".build.json" not in stamp["files"]
    (fresh / "notes.txt").write_text("keep")
    (fresh / "report.md").write_text("# edited by hand\n")
    assert main(["report", "models", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert ("models holds files uvsym did not write (notes.txt) and files changed since uvsym wrote them "
            "(report.md)") in err
    assert (fresh / "report.md").read_text() == "# edited by hand\n" and (fresh / "notes.txt").read_text() == "keep"


def _recorded(folder, **record):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / ".build.json").write_text(json.dumps({**record, "files": {}}))
    return folder


def test_a_folders_record_says_which_command_wrote_it(tmp_path):
    campaign = _recorded(tmp_path / "campaign", campaign="dc")
    with pytest.raises(PathError, match="holds uvsym campaign's output for 'dc'; refusing to write the report"):
        claim_folder(campaign, "the report", "report", writer=("derivation", "study"), accepts=("verify",))
    with pytest.raises(PathError, match="holds the campaign 'dc'; refusing to write the campaign other"):
        claim_folder(campaign, "the campaign other", "report", writer=("campaign", "other"))
    assert claim_folder(campaign, "the campaign dc", "report", writer=("campaign", "dc")) == campaign
    report = _recorded(tmp_path / "report", derivation="study")
    with pytest.raises(PathError, match="holds uvsym report's output for 'study'; refusing to write the campaign"):
        claim_folder(report, "the campaign dc", "report", writer=("campaign", "dc"))
    proofs = _recorded(tmp_path / "proofs", verify="study")
    assert claim_folder(proofs, "the report", "report", writer=("derivation", "study"), accepts=("verify",)) == proofs
    assert claim_folder(campaign, "the report", "report", force=True, writer=("derivation", "study")) == campaign


def test_a_dangling_symbolic_link_is_refused_as_an_output_folder(tmp_path):
    (tmp_path / "link").symlink_to(tmp_path / "missing")
    with pytest.raises(PathError, match=r"link is a symbolic link to .*missing, which does not exist"):
        claim_folder(tmp_path / "link" / "sub", "the report", "report")
    assert not (tmp_path / "missing").exists()


def test_verify_keeps_a_foreign_proofs_file_and_lists_its_own(tmp_path, capsys):
    source = str(Path(__file__).parents[1] / "examples" / "dc_motor" / "speed_sensor_bias.toml")
    assert main(["verify", source, "--out", str(tmp_path)]) == 0
    folder = next(p for p in tmp_path.iterdir() if p.is_dir())
    assert json.loads((folder / ".build.json").read_text())["files"].keys() == {"proofs.json"}
    assert main(["verify", source, "--out", str(tmp_path)]) == 0  # its own file, replaced
    (folder / "proofs.json").write_text("[]\n")  # edited by hand: no longer what uvsym wrote
    assert main(["verify", source, "--out", str(tmp_path)]) == 2
    assert "changed since uvsym wrote them (proofs.json)" in capsys.readouterr().err
    assert (folder / "proofs.json").read_text() == "[]\n"
