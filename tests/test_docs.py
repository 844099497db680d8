"""The documentation works: the tutorial's code and the examples run, Sphinx builds without a
warning, and the README cites every paper exactly as derivations/papers.py does."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
import runpy
import sys
from pathlib import Path

import pytest

import uvsym
from derivations.papers import PAPERS

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))


def test_readme_cites_every_paper_as_the_reports_do():
    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("## Papers"):readme.index("\n## ", readme.index("## Papers") + 1)]
    cited = re.findall(r"^- \*\*(.+?)\*\*: (.+)$", section, re.M)
    assert cited == [(p.short, p.reference()) for p in PAPERS.values()]


@pytest.mark.slow
def test_the_tutorial_runs_as_written(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = (ROOT / "docs" / "tutorial.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 6, "the tutorial walks through model, observer, claims, C, simulation, equations"
    namespace: dict = {"__name__": "tutorial"}
    for index, block in enumerate(blocks, 1):
        exec(compile(block, f"docs/tutorial.md, code block {index}", "exec"), namespace)  # noqa: S102


@pytest.mark.slow
@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.name)
def test_every_example_runs(example, tmp_path, monkeypatch, capsys):
    """As ``python examples/NAME.py OUT`` runs it (as __main__, with its argv and in OUT), in this process:
    uvsym is imported here already (an exception fails the test with the example's traceback)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [str(example), str(tmp_path)])
    runpy.run_path(str(example), run_name="__main__")
    assert capsys.readouterr().out.strip(), "an example says what it found"



def test_every_paper_page_includes_the_measured_limits_its_report_writes():
    """Each docs/papers page shows its study's limits by including them from the committed report (numbers
    the report's run computed, never typed into the page); the block holds no link a page could not resolve."""
    from uvsym.report import LIMITS_MARKERS

    pages = sorted(p for p in (ROOT / "docs" / "papers").glob("*.md") if p.name != "index.md")
    assert len(pages) == len(PAPERS)
    for page in pages:
        included = re.findall(r"```\{include\} \.\./\.\./reports/([\w-]+)/report\.md\n:start-after: (.+)\n"
                              r":end-before: (.+)\n```", page.read_text())
        assert included and included[0][1:] == LIMITS_MARKERS, f"{page.name} does not include its report's limits"
        report = (ROOT / "reports" / included[0][0] / "report.md").read_text()
        assert report.count(LIMITS_MARKERS[0]) == 1 and report.count(LIMITS_MARKERS[1]) == 1, included[0][0]
        block = report.split(LIMITS_MARKERS[0])[1].split(LIMITS_MARKERS[1])[0]
        assert "](" not in block and "per hour" in block, f"{included[0][0]}: its limits block"


def test_a_limits_block_refuses_a_link():
    from uvsym.errors import FileFormatError
    from uvsym.report import limits_block

    assert limits_block("Smallest fault: 0.2.\n").startswith("<!-- limits -->\n\nSmallest fault: 0.2.\n\n")
    with pytest.raises(FileFormatError, match="no links"):
        limits_block("see [the table](campaign.md)")


def test_the_api_page_sorts_every_top_level_module_by_subject():
    page = (ROOT / "docs" / "api.md").read_text()
    listed = re.findall(r"^   (uvsym\.\w+)$", page[page.index("## By subject"):], re.M)
    assert sorted(listed) == sorted(f"uvsym.{m.name}" for m in pkgutil.iter_modules(uvsym.__path__))

@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:The mapping interface for autodoc options")  # Sphinx's own
@pytest.mark.filterwarnings("ignore:'sphinx.environment.BuildEnvironment.app' is deprecated")  # myst's include
def test_sphinx_builds_the_documentation_without_a_warning(tmp_path, capsys, monkeypatch):  # napoleon, Sphinx 9
    pytest.importorskip("sphinx", reason="sphinx is in the test extra: pip install -e '.[test]'")
    pytest.importorskip("myst_parser", reason="myst-parser is in the test extra")
    import logging

    from sphinx.cmd.build import build_main

    # in this process: autodoc finds uvsym imported already (a separate process spends most of its time importing);
    # what the build changes here is put back: docs/conf.py's sys.path entry, the handlers of Sphinx's logger
    monkeypatch.setattr(sys, "path", list(sys.path))
    monkeypatch.setattr(logging.getLogger("sphinx"), "handlers", list(logging.getLogger("sphinx").handlers))
    status = build_main(["-W", "--keep-going", "-q", "-b", "html", str(ROOT / "docs"), str(tmp_path / "html")])
    assert status == 0, capsys.readouterr().err[-6000:]
    html = tmp_path / "html"
    assert (html / "tutorial.html").exists()
    modules = [m.name for m in pkgutil.walk_packages(uvsym.__path__, "uvsym.")]
    missing = [m for m in ["uvsym", *modules] if not (html / "api" / f"{m}.html").exists()]
    assert len(modules) > 100 and not missing, f"modules without an API page: {missing}"
    undocumented = []  # every name of a module's __all__ (a package's are documented where they are defined)
    for name in modules:
        module = importlib.import_module(name)
        if not hasattr(module, "__path__"):
            page = (html / "api" / f"{name}.html").read_text()
            undocumented += [f"{name}.{n}" for n in getattr(module, "__all__", ())
                             if not inspect.ismodule(getattr(module, n)) and f'id="{name}.{n}"' not in page]
    assert not undocumented, f"public names missing from the API reference: {undocumented}"
    page = (html / "api" / "uvsym.sim.system_simulation.html").read_text()
    entry = page.split('id="uvsym.sim.system_simulation.simulate_system"')[1].split('id="uvsym.sim.')[0]
    from uvsym.sim.system_simulation import simulate_system
    assert re.findall(r"<strong>(\w+)</strong>", entry) == list(inspect.signature(simulate_system).parameters)
    for example in EXAMPLES:  # the gallery: every script, run, with what it printed and the figure it wrote
        shown = (html / "gallery" / f"{example.stem}.html").read_text()
        assert "sphx-glr-script-out" in shown and re.search(r'<img[^>]+src="[^"]+_001\.svg"', shown), example.name


def test_readme_scenario_schema_is_the_validators():
    from uvsym.sim.schema import schema_markdown

    readme = (ROOT / "README.md").read_text()
    block = readme[readme.index("<!-- scenario-schema -->") + len("<!-- scenario-schema -->"):
                   readme.index("<!-- /scenario-schema -->")].strip()
    assert block == schema_markdown(), "README's schema is stale: paste the output of uvsym simulate --schema"


def test_readme_plant_scenario_schema_is_the_validators():
    from uvsym.sim.schema import schema_markdown

    readme = (ROOT / "README.md").read_text()
    block = readme[readme.index("<!-- plant-scenario-schema -->") + len("<!-- plant-scenario-schema -->"):
                   readme.index("<!-- /plant-scenario-schema -->")].strip()
    assert block == schema_markdown("plant"), "README's plant schema is stale: paste uvsym simulate --schema plant"


def test_the_plant_schema_is_generic_and_gives_each_block_type_its_fields():
    from uvsym.sim.schema import scenario_schema

    fields = {row["field"]: row for row in scenario_schema("plant")}
    assert fields["blocks[pid].kp"]["default"] == "required" and fields["blocks[pid].limits"]["default"] == "none"
    assert fields["blocks[lqr].q"]["rule"].startswith("n_x x n_x")
    assert fields["initial.x"]["default"] == "the plant's operating point"
    assert fields["detectors[threshold].false_alarms_per_hour"]["rule"] == "> 0"
    text = " ".join(str(v) for row in fields.values() for v in row.values())
    for specific in ("quadrotor", "rov_yaw", "'phi'", "'psi'", "/work", "site-packages"):  # no plant's, no machine's
        assert specific not in text, specific


def test_the_schema_names_every_field_a_shipped_scenario_uses_and_the_rules():
    from uvsym.sim.schema import scenario_schema

    fields = {row["field"]: row for row in scenario_schema()}
    assert fields["duration"]["default"] == "required" and fields["duration"]["rule"] == "> 0"
    assert fields["faults[].profile"]["rule"] == "one of step, ramp, incipient, intermittent"
    assert fields["current.speed"]["rule"] == ">= 0" and fields["current.speed"]["default"] == "0"
    assert "faults[].end" in fields and "controller.outputs.<loop>" in fields


@pytest.mark.slow
def test_the_readme_python_examples_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)
    assert len(blocks) >= 4
    namespace: dict = {"__name__": "readme"}
    for index, block in enumerate(blocks, 1):
        exec(compile(block, f"README.md, python block {index}", "exec"), namespace)  # noqa: S102
