"""The mutation driver's bookkeeping (benchmarks/mutation.py) and the equivalents file it reads: an entry excuses
only its own mutant, or the same change renumbered within the same function; every entry says why."""

import importlib.util
import json
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("mutation_driver", ROOT / "benchmarks" / "mutation.py")
mutation = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mutation)

ENTRY = {"mutant": "uvsym.m.x_f__mutmut_7", "change": "return a >= b", "reason": "a tie gives the same answer"}
EQUIVALENTS = {ENTRY["mutant"]: ENTRY}


def test_an_entry_excuses_its_own_mutant_only_while_the_diff_shows_its_change():
    assert mutation._justifying("uvsym.m.x_f__mutmut_7", "-    return a > b\n+    return a >= b", EQUIVALENTS) \
        == "uvsym.m.x_f__mutmut_7"
    assert mutation._justifying("uvsym.m.x_f__mutmut_7", "-    return a > b\n+    return a < b", EQUIVALENTS) is None


def test_a_renumbered_mutant_is_excused_by_the_same_change_in_the_same_function_only():
    moved = "-    return a > b\n+    return a >= b"
    assert mutation._justifying("uvsym.m.x_f__mutmut_9", moved, EQUIVALENTS) == "uvsym.m.x_f__mutmut_7"
    assert mutation._justifying("uvsym.m.x_g__mutmut_7", moved, EQUIVALENTS) is None  # another function
    assert mutation._justifying("uvsym.m.x_f__mutmut_9", "-    return a >= b\n+    return a > b", EQUIVALENTS) is None
    # the change must be the whole added line, not a part of it
    assert mutation._justifying("uvsym.m.x_f__mutmut_9", "-    return a > b\n+    return a >= b or c",
                                EQUIVALENTS) is None


def test_every_equivalent_names_one_mutant_of_a_mutated_module_with_its_change_and_a_reason():
    entries = tomllib.loads((ROOT / "tests" / "mutation_equivalents.toml").read_text())["equivalent"]
    names = [e["mutant"] for e in entries]
    assert len(names) == len(set(names)), "an equivalent is listed twice"
    for entry in entries:
        assert set(entry) == {"mutant", "change", "reason"}, entry["mutant"]
        assert entry["change"].strip() and len(entry["reason"]) > 15, entry["mutant"]
        module = mutation._function_of(entry["mutant"]).rsplit(".", 1)[0]
        assert (ROOT / (module.replace(".", "/") + ".py")).is_file(), f"{entry['mutant']}: no module {module}"


def test_again_puts_back_only_the_kills_mutmut_dropped_unchecked(tmp_path):
    pytest.importorskip("mutmut", reason="mutmut (the [mutation] extra) reads the exit codes")
    # exit codes: 1 killed, 36 timeout (a kill), 0 survived, None not checked (mutmut's convention)
    meta = tmp_path / "mutants" / "uvsym" / "m.py.meta"
    meta.parent.mkdir(parents=True)
    kept = {"uvsym/m.py": {"k": 1, "t": 36, "s": 0, "n": None, "again": 0}}
    # after a run under a new test selection: the old verdicts dropped, the survivor tested again and now killed
    meta.write_text('{"exit_code_by_key": {"k": null, "t": null, "s": null, "n": null, "again": 1}, "other": 7}')
    mutation._keep_kills(tmp_path, kept)
    data = json.loads(meta.read_text())
    assert data["exit_code_by_key"] == {"k": 1, "t": 36, "s": None, "n": None, "again": 1}
    assert data["other"] == 7


def test_the_written_config_keeps_the_modules_and_stands_in_for_missing_selected_tests(tmp_path):
    (tmp_path / "mutants" / "tests").mkdir(parents=True)
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "test_a.py").write_text("def test_a():\n    assert True\n")
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "x"\n\n[tool.mutmut]\nonly_mutate = ["old"]\n\n'
                                             '[tool.ruff]\nline-length = 120\n')
    config = {"only_mutate": ["uvsym/*.py"], "pytest_add_cli_args_test_selection": ["tests/test_a.py",
                                                                                      "tests/test_new.py"]}
    mutation._write_config(tmp_path, config, ["uvsym/m.py"])
    written = tomllib.loads((tmp_path / "pyproject.toml").read_text())
    assert written["tool"]["mutmut"]["only_mutate"] == ["uvsym/m.py"]
    assert written["tool"]["mutmut"]["pytest_add_cli_args_test_selection"] == ["tests/test_a.py", "tests/test_new.py"]
    assert written["tool"]["ruff"] == {"line-length": 120} and written["project"] == {"name": "x"}
    assert (tmp_path / "tests" / "test_a.py").read_text().startswith("def test_a")  # an existing file is left alone
    for folder in (tmp_path, tmp_path / "mutants"):
        assert "Not in the tests measured" in (folder / "tests" / "test_new.py").read_text()


def test_suspect_kills_are_the_kills_of_functions_a_listed_test_ran(tmp_path):
    pytest.importorskip("mutmut", reason="mutmut (the [mutation] extra) reads the exit codes")
    (tmp_path / "mutants" / "uvsym").mkdir(parents=True)
    (tmp_path / "mutants" / "mutmut-stats.json").write_text(json.dumps({"tests_by_mangled_function_name": {
        "uvsym.m.x_f": ["tests/a.py::t1", "tests/c.py::t3"], "uvsym.m.x_g": ["tests/b.py::t2"]}}))
    (tmp_path / "mutants" / "uvsym" / "m.py.meta").write_text(json.dumps({"exit_code_by_key": {
        "uvsym.m.x_f__mutmut_1": 1, "uvsym.m.x_f__mutmut_2": 0, "uvsym.m.x_f__mutmut_3": 36,
        "uvsym.m.x_g__mutmut_1": 1, "uvsym.m.x_h__mutmut_1": 1}}))
    # f's kills (a failure and a timeout) may owe to t1; f's survivor, g's kill (t2 only) and h (no tests) do not
    assert mutation._suspect_kills(tmp_path, ["uvsym/m.py"], {"tests/a.py::t1"}) == [
        "uvsym.m.x_f__mutmut_1", "uvsym.m.x_f__mutmut_3"]
    assert mutation._suspect_kills(tmp_path, ["uvsym/m.py"], {"tests/z.py::t9"}) == []


def test_again_brings_current_sources_and_drops_a_mutated_module_that_changed(tmp_path):
    module, other = "uvsym/faults.py", "uvsym/errors.py"
    for folder in (tmp_path, tmp_path / "mutants"):
        (folder / "uvsym").mkdir(parents=True)
        (folder / other).write_text("# the kept run's copy\n")
        (folder / module).write_text("# mutmut's mutants\n" if folder.name == "mutants" else "")
    (tmp_path / module).write_bytes((ROOT / module).read_bytes())
    assert mutation._current_sources(tmp_path, [module, other]) == [module]  # errors.py changed: dropped
    assert (tmp_path / "mutants" / module).read_text() == "# mutmut's mutants\n"
    for folder in (tmp_path, tmp_path / "mutants"):
        assert (folder / other).read_bytes() == (ROOT / other).read_bytes()  # now as it is, unmutated


def test_again_names_the_modules_a_kept_folder_holds_when_the_one_asked_for_is_not_among_them(tmp_path, capsys):
    (tmp_path / "pyproject.toml").write_text('[tool.mutmut]\nonly_mutate = ["uvsym/faults.py"]\n')
    with pytest.raises(SystemExit):
        mutation.main(["--again", str(tmp_path), "--modules", "uvsym/observers/actuator.py"])
    assert (f"matches none of the modules whose mutants {tmp_path} holds (its last run mutated uvsym/faults.py): run "
            "the module afresh with --keep") in capsys.readouterr().err


def test_the_readme_quotes_the_committed_mutation_results():
    import re

    results = json.loads((ROOT / "benchmarks" / "results" / "mutation.json").read_text())
    quoted = re.search(r"as committed: (\d+) modules, ([\d,]+) mutants, ([\d,]+) killed, ([\d,]+) listed as "
                       r"equivalent, (\w+) surviving", " ".join((ROOT / "README.md").read_text().split()))
    assert quoted, "README.md no longer quotes the committed mutation results"
    modules, mutants, killed, equivalent = (int(g.replace(",", "")) for g in quoted.groups()[:4])
    records = results["modules"].values()
    assert (modules, mutants) == (len(results["modules"]), sum(r["total"] for r in records))
    assert (killed, equivalent) == (sum(r["killed"] for r in records), sum(r["equivalent"] for r in records))
    surviving = sum(r["survived"] for r in records)
    assert quoted.group(5) == ("none" if surviving == 0 else str(surviving))


@pytest.mark.parametrize("argv, message", [
    (["--sample", "0"], "--sample must be at least 1, got 0"),
    (["--max-children", "-2"], "--max-children must be at least 1, got -2"),
    (["--again", "{missing}"], "--again {missing}: not a folder an earlier run kept with --keep"),
    (["--suspect", "{tests}"], "--suspect re-tests kills of a kept run: give --again FOLDER with it"),
    (["--again", "{kept}", "--suspect", "{missing}"], "--suspect {missing}: no such file"),
])
def test_mistaken_arguments_are_refused_before_any_run(tmp_path, capsys, argv, message):
    kept, tests = tmp_path / "kept", tmp_path / "suspects.txt"
    kept.mkdir()
    (kept / "pyproject.toml").write_text('[tool.mutmut]\nonly_mutate = ["uvsym/faults.py"]\n')
    tests.write_text("tests/test_faults.py::test_x\n")
    places = {"missing": tmp_path / "missing", "kept": kept, "tests": tests}
    with pytest.raises(SystemExit):
        mutation.main([a.format(**places) for a in argv])
    assert message.format(**places) in capsys.readouterr().err
